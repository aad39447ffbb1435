//! Error type of the crate.

use thiserror::Error;

/// Everything that can go wrong while training, predicting or reading a model.
#[derive(Debug, Error)]
pub enum RegressError {
    /// Inconsistent dimensions between inputs.
    #[error("shape mismatch: {0}")]
    Shape(String),
    /// NaN or infinite input.
    #[error("non-finite input: {0}")]
    NonFinite(String),
    /// A hyper-parameter outside its valid range.
    #[error("invalid parameter: {0}")]
    InvalidParam(String),
    /// Not enough data to train what was asked (e.g. a placement class with too few samples).
    #[error("not enough data: {0}")]
    NotEnoughData(String),
    /// Grid search cross-validates by sequence, and a placement has fewer than two.
    #[error(
        "{}cross-validation by sequence needs at least 2 sequences, found {found} (with one, \
         train with fixed C and epsilon instead of a search)",
        if placement.is_empty() { String::new() } else { format!("placement '{placement}': ") }
    )]
    TooFewSequences {
        /// The placement searched (empty where it is not known).
        placement: String,
        /// Its distinct sequences.
        found: usize,
    },
    /// The training was cancelled by the progress callback.
    #[error("training cancelled")]
    Cancelled,
    /// The file does not start with the model magic number.
    #[error("not a ridi-regress model file (bad magic number)")]
    BadMagic,
    /// The file was written by another format version: an older one (retrain the model) or a
    /// newer or unknown one.
    #[error(
        "unsupported model file version {found}: this build reads version {supported} only \
         (retrain a model from an older build; a newer one needs a newer build)"
    )]
    UnsupportedVersion {
        /// Version in the file.
        found: u32,
        /// Version this build writes and reads.
        supported: u32,
    },
    /// The file ends before the length its header announces (or that length is corrupt).
    #[error("model file truncated (or its header corrupt): {found} of {expected} bytes")]
    Truncated {
        /// Bytes announced by the header (header included).
        expected: u64,
        /// Bytes present.
        found: u64,
    },
    /// Payload checksum mismatch: the file is corrupt.
    #[error("model file corrupt: checksum {found:#010x}, expected {expected:#010x}")]
    Checksum {
        /// CRC32 stored in the header.
        expected: u32,
        /// CRC32 of the payload read.
        found: u32,
    },
    /// The payload passed the checksum but does not decode into a consistent model.
    #[error("model file invalid: {0}")]
    Decode(String),
    /// Encoding failure.
    #[error("model encoding failed: {0}")]
    Encode(String),
    /// Filesystem error.
    #[error("i/o error on {path}: {error}")]
    Io {
        /// File concerned.
        path: std::path::PathBuf,
        /// Underlying error (printed, not chained).
        error: std::io::Error,
    },
}
