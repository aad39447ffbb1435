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

/// `n` and `noun` in agreement, for a message: `1 run`, `2 runs`, `3 stretches` (`noun` is
/// singular; `-es` after s, x, ch and sh).
pub fn counted(n: usize, noun: &str) -> String {
    let ending = match n {
        1 => "",
        _ if ["s", "x", "ch", "sh"].iter().any(|e| noun.ends_with(e)) => "es",
        _ => "s",
    };
    format!("{n} {noun}{ending}")
}

/// How often something happened: `once`, `2 times`, ...
pub(crate) fn times(n: usize) -> String {
    match n {
        1 => "once".to_owned(),
        n => format!("{n} times"),
    }
}

/// The first `shown` of `items` and how many more there are, for a message: `a, b, c, and 2
/// more`.
pub fn first_few(
    items: impl ExactSizeIterator<Item = impl std::fmt::Display>,
    shown: usize,
) -> String {
    let total = items.len();
    let mut text: Vec<String> = items.take(shown).map(|i| i.to_string()).collect();
    if total > shown {
        text.push(format!("and {} more", total - shown));
    }
    text.join(", ")
}

/// The first few of `spans`, `a-b s`, and how many more there are: where a warning's findings
/// are.
pub fn spans_text(spans: &[(f64, f64)]) -> String {
    first_few(spans.iter().map(|(a, b)| format!("{a:.2}-{b:.2} s")), 5)
}

/// An error and its causes on one line, as the `ridi` command and the Python package print
/// them: each cause once (one whose text the line holds already is left out), and a context
/// its cause repeats ("cannot write m.ridi" over "cannot write m.ridi: the folder . does not
/// exist") replaced by the cause.
pub fn one_line(e: &(dyn std::error::Error + 'static)) -> String {
    let mut line = String::new();
    let mut next = Some(e);
    while let Some(cause) = next {
        let text = cause.to_string();
        if !line.is_empty() && text.starts_with(&format!("{line}: ")) {
            line = text;
        } else if !line.contains(&text) {
            if !line.is_empty() {
                line.push_str(": ");
            }
            line.push_str(&text);
        }
        next = cause.source();
    }
    line
}

/// `text` (a path, a sequence name, a message) for a message, with control characters escaped
/// (`\n`, `\u{1b}`; DEL and the C1 controls U+0080-U+009F too, `\u{9b}` being a CSI to some
/// terminals): a file or sequence name may hold a line break or a terminal escape
/// sequence, which printed raw would split the one-line error or retitle and clear the user's
/// terminal. The one escaping of ridi-rs: its messages and the `ridi` command's output go
/// through it. Bytes that are not UTF-8 are shown as U+FFFD, as `Path::display` shows them.
pub fn shown(text: impl AsRef<std::ffi::OsStr>) -> String {
    let text = Path::new(text.as_ref()).display().to_string();
    if !text.chars().any(char::is_control) {
        return text;
    }
    text.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&shown(&self.path))?;
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
    #[error("{}: {error}", shown(path))]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        error: std::io::Error,
    },
    /// The content is not what the format says.
    #[error("{at}: {}", shown(message))]
    Format {
        /// Where.
        at: Location,
        /// What is wrong, in a sentence a user can act on.
        message: String,
    },
    /// The data parsed but do not make a valid sequence.
    #[error("{}: {error}", shown(path))]
    Sequence {
        /// The file or folder the sequence came from.
        path: PathBuf,
        /// The cause.
        error: SequenceError,
    },
}

impl DataError {
    /// An I/O error on `path`. A missing file reads "no such file or folder", as the readers
    /// say it for a path that names neither (the error's kind is kept).
    ///
    /// A symbolic link that cannot be followed (its target missing, links in a loop) says
    /// so, with its target (a relative one joined to the link's folder): the name is there,
    /// so "no such file" would contradict what the user sees.
    pub fn io(path: impl AsRef<Path>, error: std::io::Error) -> Self {
        let path = path.as_ref();
        let link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
        let error = match error.kind() {
            _ if link && std::fs::metadata(path).is_err() => {
                let folder = path.parent().unwrap_or(Path::new(""));
                let to = std::fs::read_link(path)
                    .map(|t| format!(" to {}", shown(folder.join(t))))
                    .unwrap_or_default();
                let why = match error.kind() {
                    std::io::ErrorKind::NotFound => "its target does not exist".to_string(),
                    _ => error.to_string(),
                };
                std::io::Error::new(
                    error.kind(),
                    format!("is a symbolic link{to} that cannot be followed ({why})"),
                )
            }
            std::io::ErrorKind::NotFound => {
                std::io::Error::new(error.kind(), "no such file or folder")
            }
            _ => error,
        };
        DataError::Io {
            path: path.to_path_buf(),
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_in_file_names_are_escaped_in_messages() {
        let evil = Path::new("data/\u{1b}]0;owned\u{7}\u{1b}[2J\nnext/data.csv");
        let at = Location::line(evil, 3).with_field("time");
        let text = at.to_string();
        assert_eq!(
            text,
            "data/\\u{1b}]0;owned\\u{7}\\u{1b}[2J\\nnext/data.csv:3: field `time`"
        );
        assert!(!text.chars().any(char::is_control));
        let io = DataError::io(evil, std::io::Error::other("gone")).to_string();
        assert!(!io.chars().any(char::is_control), "{io:?}");
        // Plain names are unchanged.
        assert_eq!(
            Location::file(Path::new("a b/ü.csv")).to_string(),
            "a b/ü.csv"
        );
    }

    #[test]
    fn shown_escapes_every_control_character_del_and_c1_included() {
        // C0, DEL (U+007F) and C1 (U+0080-U+009F: U+009B is a one-character CSI that some
        // terminals obey) alike; the characters around them, and `\` itself, unchanged (so
        // that escaping twice changes nothing).
        assert_eq!(shown("del\u{7f}"), "del\\u{7f}");
        assert_eq!(shown("csi\u{9b}31m"), "csi\\u{9b}31m");
        assert_eq!(shown("c1\u{80}\u{9f}"), "c1\\u{80}\\u{9f}");
        assert_eq!(shown("tab\tline\nbell\u{7}"), "tab\\tline\\nbell\\u{7}");
        assert_eq!(shown("\u{a0}é\u{ff}"), "\u{a0}é\u{ff}");
        for text in ["esc\u{1b}[31m\u{7f}\u{85}\u{9b}", "a\\b"] {
            let once = shown(text);
            assert!(!once.chars().any(char::is_control), "{once:?}");
            assert_eq!(shown(&once), once);
        }
    }

    #[test]
    fn counts_agree_with_their_nouns_and_missing_files_are_worded_as_the_readers_word_them() {
        assert_eq!(counted(1, "run folder"), "1 run folder");
        assert_eq!(counted(0, "frame step"), "0 frame steps");
        assert_eq!(counted(2, "stretch"), "2 stretches");
        assert_eq!(counted(3, "box"), "3 boxes");
        let gone = std::io::Error::from(std::io::ErrorKind::NotFound);
        let e = DataError::io("a/list.txt", gone);
        assert_eq!(e.to_string(), "a/list.txt: no such file or folder");
        let DataError::Io { error, .. } = e else {
            panic!("{e:?}")
        };
        assert_eq!(error.kind(), std::io::ErrorKind::NotFound);
    }
}
