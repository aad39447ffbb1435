//! The project's rule for errors about input: the message names the file, and the line and
//! field where there is one.

use std::fmt::{Debug, Display};
use std::path::{MAIN_SEPARATOR, Path, PathBuf};

/// What an error message blames: the file, and the line and field where it names them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Blame {
    /// The file named: the one given to [`assert_names_file`] or, when that is a folder, a file
    /// in it.
    pub file: PathBuf,
    /// The 1-based line, written `path:line`.
    pub line: Option<usize>,
    /// The field, written ``path[:line]: field `name` ``.
    pub field: Option<String>,
}

impl Blame {
    /// Asserts that a named line is a line of `text`, the content of the blamed file (text
    /// after the last line break is a line too; an empty file has line 1).
    #[track_caller]
    pub fn assert_line_in(&self, text: &[u8]) -> &Self {
        if let Some(line) = self.line {
            let breaks = text.iter().filter(|&&b| b == b'\n').count();
            let lines = breaks + usize::from(!text.ends_with(b"\n"));
            assert!(
                line <= lines.max(1),
                "{} names line {line} of {}, which has {lines} line(s)",
                self.file.display(),
                self.file.display()
            );
        }
        self
    }
}

/// Asserts the project's rule for an error about the input `file` and returns what it blames.
///
/// The message names `file` (or, when `file` is a folder, a file in it) as a word of its own,
/// in the form the readers write: `path`, then `:line` where there is a line, then
/// ``: field `name` `` where there is a field, then what is wrong (`data.csv:7: field
/// `gyro_x`: not a number`); `i/o error on path: ...` names the file too. A named line is at
/// least 1 (check it against the content with [`Blame::assert_line_in`]), a named field is not
/// empty, and something follows the location.
#[track_caller]
pub fn assert_names_file(error: &dyn Display, file: &Path) -> Blame {
    let message = error.to_string();
    let shown = file.display().to_string();
    assert!(!shown.is_empty(), "no file to look for in `{message}`");
    let at = message
        .match_indices(&shown)
        .map(|(at, _)| at)
        .find(|&at| {
            let before = message[..at].chars().next_back();
            let after = message[at + shown.len()..].chars().next();
            before.is_none_or(|c| " `'\"(".contains(c))
                && after.is_none_or(|c| c == ':' || c == MAIN_SEPARATOR || " `'\",)".contains(c))
        })
        .unwrap_or_else(|| panic!("the error does not name {shown}: `{message}`"));
    let mut rest = &message[at + shown.len()..];
    let mut blamed = file.to_path_buf();
    if let Some(inner) = rest.strip_prefix(MAIN_SEPARATOR) {
        let end = inner
            .find([':', ' ', '`', '\'', '"', ',', ')'])
            .unwrap_or(inner.len());
        assert!(
            end > 0,
            "the error names {shown} with an empty file name: `{message}`"
        );
        blamed = file.join(&inner[..end]);
        rest = &inner[end..];
    }
    let mut line = None;
    if let Some(after) = rest.strip_prefix(':') {
        let digits = after.len() - after.trim_start_matches(|c: char| c.is_ascii_digit()).len();
        if digits > 0 {
            let n: usize = after[..digits]
                .parse()
                .unwrap_or_else(|_| panic!("line number out of range in `{message}`"));
            assert!(n >= 1, "lines count from 1: `{message}`");
            line = Some(n);
            rest = &after[digits..];
        }
    }
    let mut field = None;
    if let Some(after) = rest.strip_prefix(": field `") {
        let end = after
            .find('`')
            .unwrap_or_else(|| panic!("unclosed field name in `{message}`"));
        assert!(end > 0, "empty field name in `{message}`");
        field = Some(after[..end].to_owned());
        rest = &after[end + 1..];
    }
    let what = rest.trim_start_matches([':', ' ']).trim();
    assert!(
        !what.is_empty(),
        "the error names {shown} but not what is wrong: `{message}`"
    );
    Blame {
        file: blamed,
        line,
        field,
    }
}

/// Asserts that `result` failed with a message containing every one of `parts`; returns the
/// error.
#[track_caller]
pub fn assert_err<T: Debug, E: Display>(result: Result<T, E>, parts: &[&str]) -> E {
    let e = match result {
        Ok(v) => panic!("expected an error, got Ok({v:?})"),
        Err(e) => e,
    };
    let msg = e.to_string();
    for p in parts {
        assert!(msg.contains(p), "`{msg}` should contain `{p}`");
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_file_line_and_field() {
        let b = assert_names_file(
            &"walk/data.csv:7: field `gyro_x`: not a number",
            Path::new("walk/data.csv"),
        );
        assert_eq!(b.line, Some(7));
        assert_eq!(b.field.as_deref(), Some("gyro_x"));
        b.assert_line_in(b"a\nb\nc\nd\ne\nf\ng");
        let b = assert_names_file(
            &"bad.mat: field `header`: the file is empty",
            Path::new("bad.mat"),
        );
        assert_eq!((b.line, b.field.as_deref()), (None, Some("header")));
        let b = assert_names_file(&"i/o error on /m.ridi: not found", Path::new("/m.ridi"));
        assert_eq!((b.line, b.field), (None, None));
    }

    #[test]
    fn a_file_in_a_folder_is_blamed() {
        let dir = Path::new("run");
        let b = assert_names_file(&format!("{}:3: bad", dir.join("gyro.txt").display()), dir);
        assert_eq!(b.file, dir.join("gyro.txt"));
        assert_eq!(b.line, Some(3));
    }

    #[test]
    #[should_panic(expected = "does not name")]
    fn another_file_is_not_this_one() {
        assert_names_file(&"data.csv.gz: bad", Path::new("data.csv"));
    }

    #[test]
    #[should_panic(expected = "does not name")]
    fn no_file_is_a_failure() {
        assert_names_file(&"not a number", Path::new("data.csv"));
    }

    #[test]
    #[should_panic(expected = "not what is wrong")]
    fn the_location_alone_is_not_enough() {
        assert_names_file(&"data.csv:3: ", Path::new("data.csv"));
    }

    #[test]
    #[should_panic(expected = "has 2 line(s)")]
    fn a_line_beyond_the_text_is_a_failure() {
        assert_names_file(&"data.csv:3: bad", Path::new("data.csv")).assert_line_in(b"a\nb\n");
    }
}
