//! Error type of the crate.

use ridi_features::FeatureError;
use thiserror::Error;

/// Everything that can go wrong while training, predicting or reading a model.
#[derive(Debug, Error)]
pub enum RegressError {
    /// A feature matrix refused by its checks (not whole rows, a non-finite value): the view
    /// belongs to ridi-features, and so do its errors.
    #[error(transparent)]
    Features(#[from] FeatureError),
    /// Inputs that must be parallel, or a row and the model, disagree in length.
    #[error("length of {what} is {found}, expected {expected}")]
    LengthMismatch {
        /// Which input.
        what: &'static str,
        /// Length the other inputs or the model imply.
        expected: usize,
        /// Length found.
        found: usize,
    },
    /// A NaN or infinite target.
    #[error("non-finite {what} at sample {index}")]
    NonFinite {
        /// Which input.
        what: &'static str,
        /// Sample index.
        index: usize,
    },
    /// A value to store is beyond the half-precision range of the model's samples.
    #[error(
        "{what} {value} at row {row}, column {column} exceeds the half-precision range of the \
         model (±{max}); standardize the features",
        max = crate::f16mat::F16_MAX
    )]
    BeyondHalfPrecision {
        /// Which value: a feature, or a principal coordinate of one.
        what: &'static str,
        /// The value.
        value: f32,
        /// Its row (training sample).
        row: usize,
        /// Its column.
        column: usize,
    },
    /// A training sample's placement is not an index into the placement names.
    #[error("sample {index} has placement {placement}, only {names} names")]
    PlacementOutOfRange {
        /// Sample index.
        index: usize,
        /// Its placement.
        placement: usize,
        /// Number of placement names.
        names: usize,
    },
    /// [`Cascade::rounding_effect`](crate::Cascade::rounding_effect) was not given the rows
    /// the model was trained on.
    #[error("stored sample {index} of placement {placement} is not a training row")]
    NotTrainingRow {
        /// Placement index.
        placement: usize,
        /// Index of the stored sample in that placement.
        index: usize,
    },
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
    #[error("not a ridi model file: its first bytes are not a model file's")]
    BadMagic,
    /// The file was written by another format version: an older one (retrain the model) or a
    /// newer or unknown one.
    #[error(
        "unsupported model file version {found}: this build reads versions {exact} (exact \
         models) and {supported} (Nyström models) only (retrain a model from an older build; \
         a newer one needs a newer build)",
        exact = crate::model_file::EXACT_VERSION
    )]
    UnsupportedVersion {
        /// Version in the file.
        found: u32,
        /// Newest version this build writes and reads ([`crate::MODEL_FORMAT_VERSION`]).
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
    /// A [`Cascade`](crate::Cascade) deserialized by serde alone, without the checks and the
    /// parts of [`Cascade::from_bytes`](crate::Cascade::from_bytes): refused by prediction.
    #[error(
        "the model was deserialized by serde alone, unchecked and incomplete: read model files \
         with Cascade::from_bytes or Cascade::load"
    )]
    Unchecked,
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

impl RegressError {
    /// This error as the cause of a message that names `path` already ("cannot load model
    /// `path`"): an I/O error of `path` itself becomes the system's error alone, since its own
    /// message would name the file again; any other error stays as it is.
    pub fn under(self, path: &std::path::Path) -> Box<dyn std::error::Error + Send + Sync> {
        match self {
            RegressError::Io { path: p, error } if p == path => Box::new(error),
            e => Box::new(e),
        }
    }
}
