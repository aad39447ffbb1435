//! Rust errors as Python exceptions: `OSError` (and its subclasses) for files that cannot be
//! read or written, `ValueError` for data, lists and options that are wrong. The message is the
//! one line the command line prints after `error:`, naming the file, line and field, or the
//! sequence, array and frame, with control characters escaped as it escapes them
//! ([`ridi::data::shown`]): a file name holding a line break or a terminal escape sequence does
//! not split the message or reach the user's terminal raw.

use std::io::ErrorKind;
use std::path::Path;

use pyo3::PyErr;
use pyo3::exceptions::{
    PyFileExistsError, PyFileNotFoundError, PyIsADirectoryError, PyNotADirectoryError, PyOSError,
    PyPermissionError, PyValueError,
};
use ridi::data::{DataError, one_line, shown};
use ridi::regress::RegressError;
use ridi::{OutputError, PipelineError};

/// The `OSError` subclass Python raises for `kind`.
fn os_error(kind: ErrorKind, message: String) -> PyErr {
    let message = shown(message);
    match kind {
        ErrorKind::NotFound => PyFileNotFoundError::new_err(message),
        ErrorKind::PermissionDenied => PyPermissionError::new_err(message),
        ErrorKind::AlreadyExists => PyFileExistsError::new_err(message),
        ErrorKind::IsADirectory => PyIsADirectoryError::new_err(message),
        ErrorKind::NotADirectory => PyNotADirectoryError::new_err(message),
        _ => PyOSError::new_err(message),
    }
}

/// What kind of exception an error is: `Some(kind)` for a file that could not be read or
/// written, `None` for bad data.
fn file_kind(e: &PipelineError) -> Option<ErrorKind> {
    match e {
        PipelineError::Data(d) => data_kind(d),
        PipelineError::Regress(r) => regress_kind(r),
        PipelineError::Output(o) => Some(match o {
            OutputError::Io { error, .. } => error.kind(),
            OutputError::NoFolder { .. } => ErrorKind::NotFound,
            OutputError::FolderIsFile { .. } => ErrorKind::NotADirectory,
            OutputError::IsFolder { .. } | OutputError::FolderName { .. } => {
                ErrorKind::IsADirectory
            }
            OutputError::FolderNotWritable { kind, .. }
            | OutputError::ParentNotWritable { kind, .. } => *kind,
            _ => ErrorKind::Other,
        }),
        // A placement map that is not there (`PlacementMap::from_arg`); maps and reports that
        // do not parse are data errors.
        PipelineError::File { path, .. } if !path.exists() => Some(ErrorKind::NotFound),
        PipelineError::Listed { source, .. } => file_kind(source),
        _ => None,
    }
}

fn data_kind(e: &DataError) -> Option<ErrorKind> {
    match e {
        DataError::Io { error, .. } => Some(error.kind()),
        // A source that is not there (a list line naming a missing recording is the list's
        // error, at its line).
        DataError::Format { at, .. } if at.line.is_none() && !at.path.exists() => {
            Some(ErrorKind::NotFound)
        }
        _ => None,
    }
}

fn regress_kind(e: &RegressError) -> Option<ErrorKind> {
    match e {
        RegressError::Io { error, .. } => Some(error.kind()),
        _ => None,
    }
}

/// A pipeline error as a Python exception.
pub(crate) fn pipeline(e: PipelineError) -> PyErr {
    pipeline_in(e, None)
}

/// A pipeline error as a Python exception, its message prefixed with `context` when given
/// (`cannot write m.ridi`, as the command line says it).
pub(crate) fn pipeline_in(e: PipelineError, context: Option<String>) -> PyErr {
    let line = one_line(&e);
    // An output's own error says "cannot write <path>" already, a sequence's its name.
    let message = match context {
        Some(c) if line != c && !line.starts_with(&format!("{c}: ")) => format!("{c}: {line}"),
        _ => line,
    };
    match file_kind(&e) {
        Some(kind) => os_error(kind, message),
        // As Python's `threading` says "can't start new thread".
        None if matches!(e, PipelineError::Workers { .. }) => {
            pyo3::exceptions::PyRuntimeError::new_err(shown(message))
        }
        None => value(message),
    }
}

/// An error of `doing` (`"cannot track"`) with sequence `name`: the sequence named once.
pub(crate) fn of_sequence(e: PipelineError, doing: &str, name: &str) -> PyErr {
    let names_it = matches!(&e, PipelineError::Sequence { sequence, .. } if sequence == name);
    pipeline_in(e, (!names_it).then(|| format!("{doing} {name}")))
}

/// A reader's error as a Python exception.
pub(crate) fn data(e: DataError) -> PyErr {
    pipeline(PipelineError::Data(e))
}

/// A model file's error (loading or saving `path`), worded as the command line words it.
pub(crate) fn model_file(e: RegressError, doing: &str, path: &Path) -> PyErr {
    let kind = regress_kind(&e);
    // Named once, as the command line names it.
    let message = format!("{doing} {}: {}", path.display(), one_line(&*e.under(path)));
    match kind {
        Some(kind) => os_error(kind, message),
        None => value(message),
    }
}

/// A `ValueError`: bad data, or bad input of the Python caller itself (an option, an array).
pub(crate) fn value(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(shown(message.into()))
}
