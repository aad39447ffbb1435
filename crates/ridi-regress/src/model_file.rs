//! The model file codec: [`Cascade::to_bytes`], [`Cascade::from_bytes`], [`Cascade::save`] and
//! [`Cascade::load`].
//!
//! Layout (little-endian):
//!
//! | bytes | content                                   |
//! |-------|-------------------------------------------|
//! | 8     | magic [`MODEL_MAGIC`], `b"RIDIREG\0"`      |
//! | 4     | format version ([`MODEL_FORMAT_VERSION`]) |
//! | 8     | payload length in bytes                   |
//! | 4     | CRC32 of the payload                      |
//! | n     | payload: bincode 2 (standard config, serde) of the [`Cascade`] |
//!
//! Version 7 stores each placement's samples as little-endian IEEE binary16 in one byte
//! string: principal-component coordinates (with their residual norms, next to the projection's
//! mean and directions) or the features themselves ([`crate::Storage`]); squared norms are
//! recomputed on load; classifier coefficients only for the pairs a placement takes part in;
//! an optional speed regressor per placement ([`crate::CascadeParams::speed`]); the feature
//! configuration with its definition of S (`up_axis`) and the orientation its inputs come from
//! (`orientation`).
//! Version 8 is a Nyström model ([`crate::Solver::Nystrom`]): a kind tag (2), the cascade
//! exactly as version 7 lays it out (each placement's samples are its regressors' landmarks,
//! its coefficients their weights), then the classifier's landmarks in the same storage and
//! one weight per landmark and pair. An exact model is still written as version 7, so its
//! bytes did not change; both are read. Kind 1 (Nyström models whose regressors shared the
//! classifier's landmarks) is refused with a message to retrain; an unknown kind is a decode
//! error.
//!
//! Older files are refused with [`RegressError::UnsupportedVersion`] (retrain the model):
//! version 6 had neither `up_axis` nor `orientation` (its S was always the paper's, its
//! orientation whatever the caller passed), version 5 no speed regressor, version 4 stored
//! every pair's coefficient for every classifier sample, version 3 the leading coordinates as
//! a separate `f32` block, version 2 binary16 features only, version 1 `f32` features.
//!
//! The header is checked before the payload is decoded, so a newer version, a truncated file
//! or a corrupt payload each give their own error. Encoding is deterministic (no maps, no
//! timestamps), so the same model always gives the same bytes. Writing goes to a temporary
//! file in the target directory, is flushed to disk, then renamed over the target.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::cascade::Cascade;
use crate::error::RegressError;

/// The first bytes of every model file.
pub const MODEL_MAGIC: [u8; 8] = *b"RIDIREG\0";
/// The newest model file format version this build writes and reads: 8, a Nyström model
/// ([`crate::Solver::Nystrom`]). An exact model is written as version 7, byte for byte as
/// before version 8 existed; this build reads both ([`Cascade::format_version`]).
pub const MODEL_FORMAT_VERSION: u32 = NYSTROM_VERSION;
/// Format of an exact model.
pub(crate) const EXACT_VERSION: u32 = 7;
/// Format of a Nyström model: a kind tag, the cascade as in version 7, the Nyström part.
pub(crate) const NYSTROM_VERSION: u32 = 8;
/// The kind tag of a version-8 payload that is a Nyström model (the tag leaves room for
/// other approximate kinds without another version).
const NYSTROM_KIND: u32 = 2;
/// The kind of the first Nyström models: regressors on the classifier's landmarks.
const SHARED_NYSTROM_KIND: u32 = 1;
const HEADER: usize = 8 + 4 + 8 + 4;
/// Refuses to allocate for absurd payload lengths from a corrupt header.
const MAX_PAYLOAD: u64 = 1 << 40;

fn bincode_config() -> impl bincode::config::Config {
    bincode::config::standard().with_limit::<{ MAX_PAYLOAD as usize }>()
}

impl Cascade {
    /// Encodes the model into the bytes of a model file; the same model always gives the same
    /// bytes.
    pub fn to_bytes(&self) -> Result<Vec<u8>, RegressError> {
        encode(self)
    }

    /// Decodes the bytes of a model file, checking magic number, version, length, checksum and
    /// the model's internal consistency.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, RegressError> {
        decode(bytes)
    }

    /// Writes the model file atomically: a temporary file in the same directory
    /// (`.<name>.tmp<pid>-<n>`), `fsync`, rename. An error removes the temporary file; a process
    /// killed while saving leaves it, since this crate keeps no record of other processes'
    /// files. `ridi::save_model` writes through `ridi_data::write_atomically` instead, which
    /// removes what killed runs left and writes through a symbolic link.
    ///
    /// # Errors
    /// Encoding or I/O failures, and a `path` that exists and is not a regular file (a
    /// symbolic link, a device, a pipe: the rename would replace it).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), RegressError> {
        save(self, path.as_ref())
    }

    /// Reads and validates a model file. The header is read and checked first, and the
    /// payload length it declares must match the file's size, so a device, a huge file or
    /// one of another kind is refused after 24 bytes, not read whole.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, RegressError> {
        let path = path.as_ref();
        decode(&read_bounded(path)?)
    }
}

fn encode(model: &Cascade) -> Result<Vec<u8>, RegressError> {
    let payload = match model.nystrom_parts() {
        None => bincode::serde::encode_to_vec(model, bincode_config()),
        Some(parts) => {
            bincode::serde::encode_to_vec((NYSTROM_KIND, model, parts), bincode_config())
        }
    }
    .map_err(|e| RegressError::Encode(e.to_string()))?;
    let mut out = Vec::with_capacity(HEADER + payload.len());
    out.extend_from_slice(&MODEL_MAGIC);
    out.extend_from_slice(&model.format_version().to_le_bytes());
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    out.extend_from_slice(&payload);
    Ok(out)
}

/// What a model file's header declares.
struct Header {
    version: u32,
    /// Payload length in bytes.
    len: u64,
    crc: u32,
}

/// Checks the header at the start of `bytes`, of a file of `size` bytes (`bytes` may be only
/// its header): magic number, version, and the declared payload length against the size.
fn check_header(bytes: &[u8], size: u64) -> Result<Header, RegressError> {
    if bytes.len() < MODEL_MAGIC.len() || bytes[..MODEL_MAGIC.len()] != MODEL_MAGIC {
        return Err(
            if bytes.len() < MODEL_MAGIC.len() && MODEL_MAGIC.starts_with(bytes) {
                RegressError::Truncated {
                    expected: HEADER as u64,
                    found: size,
                }
            } else {
                RegressError::BadMagic
            },
        );
    }
    if bytes.len() < HEADER {
        return Err(RegressError::Truncated {
            expected: HEADER as u64,
            found: size,
        });
    }
    let word = |r: std::ops::Range<usize>| -> [u8; 8] {
        let mut w = [0u8; 8];
        w[..r.len()].copy_from_slice(&bytes[r]);
        w
    };
    let version = u32::from_le_bytes(word(8..12)[..4].try_into().unwrap_or([0; 4]));
    if version != EXACT_VERSION && version != NYSTROM_VERSION {
        return Err(RegressError::UnsupportedVersion {
            found: version,
            supported: MODEL_FORMAT_VERSION,
        });
    }
    let len = u64::from_le_bytes(word(12..20));
    let crc = u32::from_le_bytes(word(20..24)[..4].try_into().unwrap_or([0; 4]));
    let expected = (HEADER as u64).saturating_add(len);
    if len > MAX_PAYLOAD || size < expected {
        return Err(RegressError::Truncated {
            expected,
            found: size,
        });
    }
    if size > expected {
        let extra = size - expected;
        return Err(RegressError::Decode(format!(
            "{extra} trailing byte{} after the payload",
            if extra == 1 { "" } else { "s" }
        )));
    }
    Ok(Header { version, len, crc })
}

/// What a payload that passed the checksum yet does not decode means for the file, in words:
/// bincode's own text is its debug form (`UnexpectedEnd { additional: 1 }`,
/// `InvalidIntegerType { expected: U32, found: Reserved }`), which says nothing to a user.
fn decode_words(e: &bincode::error::DecodeError) -> String {
    use bincode::error::DecodeError as E;
    match e {
        E::UnexpectedEnd { additional } => format!(
            "its payload ends {additional} byte{} before the model does: the file was cut short \
             before its checksum was written, or edited",
            if *additional == 1 { "" } else { "s" }
        ),
        E::LimitExceeded => {
            "a length in its payload is larger than any model's: the file is corrupt".into()
        }
        _ => "its payload holds a value no model has (a number of the wrong size, an unknown \
              kind or label): the file is corrupt, edited, or from an incompatible build"
            .into(),
    }
}

fn decode(bytes: &[u8]) -> Result<Cascade, RegressError> {
    let Header { version, crc, .. } = check_header(bytes, bytes.len() as u64)?;
    let payload = &bytes[HEADER..];
    let found = crc32fast::hash(payload);
    if found != crc {
        return Err(RegressError::Checksum {
            expected: crc,
            found,
        });
    }
    let decode_err = |e: bincode::error::DecodeError| RegressError::Decode(decode_words(&e));
    let mut rest = payload;
    if version == NYSTROM_VERSION {
        let (kind, used): (u32, usize) =
            bincode::serde::decode_from_slice(rest, bincode_config()).map_err(decode_err)?;
        if kind == SHARED_NYSTROM_KIND {
            return Err(RegressError::Decode(
                "a Nyström model of an earlier ridi-rs (kind 1: regressors on shared \
                 landmarks), which this build no longer reads: retrain it"
                    .into(),
            ));
        }
        if kind != NYSTROM_KIND {
            return Err(RegressError::Decode(format!(
                "unknown model kind {kind} in a version {version} file (this build knows kind \
                 {NYSTROM_KIND}, Nyström)"
            )));
        }
        rest = &rest[used..];
    }
    let (mut model, used): (Cascade, usize) =
        bincode::serde::decode_from_slice(rest, bincode_config()).map_err(decode_err)?;
    rest = &rest[used..];
    if version == NYSTROM_VERSION {
        let (parts, used) =
            bincode::serde::decode_from_slice(rest, bincode_config()).map_err(decode_err)?;
        model.set_nystrom_parts(parts);
        rest = &rest[used..];
    }
    if !rest.is_empty() {
        return Err(RegressError::Decode("payload longer than the model".into()));
    }
    model.finish_decode()?;
    Ok(model)
}

/// The bytes of the model file `path`, read only as far as its header allows: what is not a
/// regular file is refused before it is opened, a file whose header is not a model's or
/// declares another size than the file's after the header.
fn read_bounded(path: &Path) -> Result<Vec<u8>, RegressError> {
    use std::io::Read as _;
    // The metadata first, which does not open the file: opening a FIFO waits for a writer for
    // ever. Worded as ridi-data's readers word it.
    let regular = |meta: std::fs::Metadata| {
        if meta.is_file() {
            return Ok(meta);
        }
        Err(io_err(path)(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            if meta.is_dir() {
                "is a folder: it is not a regular file"
            } else {
                "is a device, a pipe or a socket: it is not a regular file"
            },
        )))
    };
    let meta = std::fs::metadata(path).map_err(|e| match e.kind() {
        // The kind kept (Python maps it to FileNotFoundError), the words the readers use.
        std::io::ErrorKind::NotFound => std::io::Error::new(e.kind(), "no such file or folder"),
        _ => e,
    });
    regular(meta.map_err(io_err(path))?)?;
    let mut file = std::fs::File::open(path).map_err(io_err(path))?;
    // Again of the file opened, whose size the header must match (the path may name another
    // file by now).
    let meta = regular(file.metadata().map_err(io_err(path))?)?;
    let mut bytes = Vec::with_capacity(HEADER);
    (&mut file)
        .take(HEADER as u64)
        .read_to_end(&mut bytes)
        .map_err(io_err(path))?;
    let Header { len, .. } = check_header(&bytes, meta.len())?;
    // A payload this machine cannot hold is an error, not an abort in the allocator.
    bytes.try_reserve_exact(len as usize).map_err(|_| {
        io_err(path)(std::io::Error::new(
            std::io::ErrorKind::OutOfMemory,
            format!(
                "a model of {len} bytes: more than this machine can allocate (ridi's models are \
                 megabytes; a file this large is likely not one)"
            ),
        ))
    })?;
    file.take(len)
        .read_to_end(&mut bytes)
        .map_err(io_err(path))?;
    Ok(bytes)
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> RegressError + '_ {
    move |error| RegressError::Io {
        path: path.to_path_buf(),
        error,
    }
}

fn save(model: &Cascade, path: &Path) -> Result<(), RegressError> {
    // The rename would replace a link, a device, a pipe or a socket with a regular file.
    if let Ok(m) = std::fs::symlink_metadata(path)
        && !m.is_file()
    {
        return Err(io_err(path)(std::io::Error::other(
            "not a regular file (a folder, a symbolic link, a device, a pipe or a socket), which \
             saving would replace: save to a regular file, or through `ridi::save_model`, which \
             writes through links",
        )));
    }
    let bytes = encode(model)?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "model".into());
    // Per save, so that two threads saving one path do not share a temporary file.
    static SAVES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = SAVES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let tmp = dir.join(format!(".{name}.tmp{}-{n}", std::process::id()));
    let result = (|| {
        // A leftover of a killed save would keep its own mode: start from a new file.
        let _ = std::fs::remove_file(&tmp);
        let mut options = std::fs::OpenOptions::new();
        options.write(true).create_new(true);
        // The mode ridi-data's `write_atomically` gives every other file the project writes.
        #[cfg(unix)]
        std::os::unix::fs::OpenOptionsExt::mode(&mut options, 0o644);
        let mut f = options.open(&tmp).map_err(io_err(&tmp))?;
        f.write_all(&bytes).map_err(io_err(&tmp))?;
        f.sync_all().map_err(io_err(&tmp))?;
        std::fs::rename(&tmp, path).map_err(io_err(path))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
