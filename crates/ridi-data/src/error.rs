//! Errors of the readers and writers.

use std::fmt;
use std::path::{Path, PathBuf};

use crate::SequenceError;

/// Where in which file something went wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct Location {
    /// The file.
    pub path: PathBuf,
    /// 1-based line number, when the problem is on one line.
    pub line: Option<usize>,
    /// Column or field name, when one is to blame.
    pub field: Option<String>,
}

impl Location {
    /// A whole file.
    pub fn file(path: impl Into<PathBuf>) -> Self {
        Self {
            path: path.into(),
            line: None,
            field: None,
        }
    }

    /// One line of a file.
    pub fn line(path: impl Into<PathBuf>, line: usize) -> Self {
        Self {
            path: path.into(),
            line: Some(line),
            field: None,
        }
    }

    /// Names the field.
    pub fn with_field(mut self, field: impl Into<String>) -> Self {
        self.field = Some(field.into());
        self
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if let Some(field) = &self.field {
            write!(f, ": field `{field}`")?;
        }
        Ok(())
    }
}

/// An error of a reader or writer. Every variant names the file; parse errors name the line and
/// field too. A cause is printed in the message, not also chained as `source()` (a reporter
/// walking the chain would print it twice).
#[derive(Debug, thiserror::Error)]
pub enum DataError {
    /// The file could not be opened, read or written.
    #[error("{}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        error: std::io::Error,
    },
    /// The content is not what the format says.
    #[error("{at}: {message}")]
    Format {
        /// Where.
        at: Location,
        /// What is wrong, in a sentence a user can act on.
        message: String,
    },
    /// The data parsed but do not make a valid sequence.
    #[error("{}: {error}", path.display())]
    Sequence {
        /// The file or folder the sequence came from.
        path: PathBuf,
        /// The cause.
        error: SequenceError,
    },
}

impl DataError {
    /// An I/O error on `path`.
    pub fn io(path: impl AsRef<Path>, error: std::io::Error) -> Self {
        DataError::Io {
            path: path.as_ref().to_path_buf(),
            error,
        }
    }

    /// A format error at `at`.
    pub fn format(at: Location, message: impl Into<String>) -> Self {
        DataError::Format {
            at,
            message: message.into(),
        }
    }

    /// An invalid sequence read from `path`.
    pub fn sequence(path: impl AsRef<Path>, error: SequenceError) -> Self {
        DataError::Sequence {
            path: path.as_ref().to_path_buf(),
            error,
        }
    }
}

/// Result of the readers and writers.
pub type Result<T, E = DataError> = std::result::Result<T, E>;
