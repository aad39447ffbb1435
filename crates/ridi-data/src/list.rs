//! Dataset list files: which sequences make a dataset split, and where each was carried.
//!
//! One entry per line, `path,placement`: the path is absolute or relative to the list file's
//! folder, the placement (e.g. `body`, `handheld`, `bag`, `leg`) is optional (`path` alone or
//! `path,`). Blank lines and lines starting with `#` are skipped. Surrounding spaces are
//! trimmed. A list that lists no sequence is an error.

use std::path::{Path, PathBuf};

use crate::Sequence;
use crate::detect::{read_sequence, source_files};
use crate::error::{DataError, Location, Result};
use crate::options::ReadOptions;
use crate::text;

/// One line of a list file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ListEntry {
    /// The sequence, resolved against the list file's folder.
    pub path: PathBuf,
    /// Placement label, when given.
    pub placement: Option<String>,
    /// The list file, for error messages.
    pub list: PathBuf,
    /// 1-based line of the list file, for error messages.
    pub line: usize,
}

impl ListEntry {
    /// The list file and line of this entry, for errors about the sequence it lists.
    pub fn location(&self) -> Location {
        Location::line(&self.list, self.line)
    }
}

/// Reads a list file. Only the syntax is checked; [`load_list`] checks that the sequences
/// exist.
pub fn read_list(path: impl AsRef<Path>) -> Result<Vec<ListEntry>> {
    let path = path.as_ref();
    parse_list(&text::read_file(path)?, path)
}

/// Parses the content of a list file; `path` is the list file itself (relative entries are
/// resolved against its folder, errors name it). A list without any entry (empty, or only
/// comments and blank lines) is an error: "no sequences listed".
pub fn parse_list(bytes: &[u8], path: &Path) -> Result<Vec<ListEntry>> {
    let base = path.parent().unwrap_or(Path::new(""));
    let mut entries = Vec::new();
    for (line, content) in text::lines(text::as_text(bytes, path)?) {
        let content = content.trim();
        if content.starts_with('#') {
            continue;
        }
        let mut cells = content.split(',');
        let (entry, placement) = (cells.next().unwrap_or("").trim(), cells.next());
        if cells.next().is_some() {
            return Err(DataError::format(
                Location::line(path, line),
                "expected `path,placement`, found more than two comma-separated fields",
            ));
        }
        if entry.is_empty() {
            return Err(DataError::format(
                Location::line(path, line).with_field("path"),
                "empty sequence path",
            ));
        }
        let placement = placement.map(str::trim).filter(|p| !p.is_empty());
        if let Some(p) = placement.filter(|p| p.contains(char::is_whitespace)) {
            return Err(DataError::format(
                Location::line(path, line).with_field("placement"),
                format!("placement `{}` contains spaces", text::snippet(p)),
            ));
        }
        entries.push(ListEntry {
            path: base.join(entry),
            placement: placement.map(str::to_owned),
            list: path.to_path_buf(),
            line,
        });
    }
    if entries.is_empty() {
        return Err(DataError::format(
            Location::file(path),
            "no sequences listed (expected `path,placement` lines)",
        ));
    }
    Ok(entries)
}

/// Reads every sequence of a list file, detecting each one's format (see
/// [`detect`](crate::detect())) and setting its placement from the list when the list gives one.
///
/// Every entry is checked to exist before any is read, so a typo fails fast with the list file
/// and line; errors while reading a sequence name that sequence's file.
pub fn load_list(path: impl AsRef<Path>, opts: &ReadOptions) -> Result<Vec<Sequence>> {
    load_entries(&read_list(path)?, opts)
}

/// Reads the sequences of `entries` (from [`read_list`], of one or several list files), in
/// order, as [`load_list`] does: every path is checked to exist before any is read, and the
/// placement is the entry's when it gives one.
///
/// A recording listed twice is refused, also through two paths (a folder and its
/// `processed/data.csv`, a symbolic link) and, once read, as two files of the same data (a
/// copy in another folder, the same recording converted to another format): it would count
/// twice in every mean, and sit on both sides of a cross-validation split.
pub fn load_entries(entries: &[ListEntry], opts: &ReadOptions) -> Result<Vec<Sequence>> {
    check_entries(entries)?;
    let seqs: Vec<Sequence> = entries
        .iter()
        .map(|e| {
            let mut seq = read_sequence(&e.path, opts)?;
            if e.placement.is_some() {
                seq.set_placement(e.placement.clone());
            }
            Ok(seq)
        })
        .collect::<Result<_>>()?;
    for (i, (seq, e)) in seqs.iter().zip(entries).enumerate() {
        if let Some(j) = seqs[..i].iter().position(|s| same_data(s, seq)) {
            return Err(copy_error(e, &entries[j]));
        }
    }
    Ok(seqs)
}

/// Refuses a sequence of `later` that holds the same recording as one of `earlier` (each a
/// list's sequences with their entries, as [`load_entries`] returns them for its entries): the
/// check [`load_entries`] makes within its entries, across two lists loaded apart, such as a
/// training and a test list, where a copy in another folder or format passes
/// [`check_entries`]. The error names the later entry's list line and the earlier one's.
///
/// Each pair holds as many sequences as entries (debug builds assert it).
pub fn check_distinct(
    earlier: (&[Sequence], &[ListEntry]),
    later: (&[Sequence], &[ListEntry]),
) -> Result<()> {
    debug_assert_eq!(earlier.0.len(), earlier.1.len(), "one entry per sequence");
    debug_assert_eq!(later.0.len(), later.1.len(), "one entry per sequence");
    for (seq, e) in later.0.iter().zip(later.1) {
        if let Some((_, first)) = earlier
            .0
            .iter()
            .zip(earlier.1)
            .find(|(s, _)| same_data(s, seq))
        {
            return Err(copy_error(e, first));
        }
    }
    Ok(())
}

/// `e` lists the recording that `first` listed already.
fn copy_error(e: &ListEntry, first: &ListEntry) -> DataError {
    DataError::format(
        e.location().with_field("path"),
        format!(
            "sequence `{}` holds the same recording as `{}`, listed at {}:{} (the same \
             timestamps, gyro and accelerometer samples); a recording listed twice would \
             count twice, or be tested on after training on it",
            e.path.display(),
            first.path.display(),
            first.list.display(),
            first.line
        ),
    )
}

/// Whether two sequences are one recording: the same timestamps, gyro and accelerometer
/// samples, every one of them. Slice comparison stops at the first difference, so two
/// recordings cost a length and a timestamp compare (phone clocks count nanoseconds from boot).
fn same_data(a: &Sequence, b: &Sequence) -> bool {
    a.time() == b.time() && a.gyro() == b.gyro() && a.acce() == b.acce()
}

/// The checks [`load_entries`] makes before reading anything: every listed path exists and no
/// recording is listed twice. Useful on its own over entries that are loaded apart, such as a
/// training and a test list (a recording in both would be tested on after training on it).
pub fn check_entries(entries: &[ListEntry]) -> Result<()> {
    let mut seen: Vec<(Vec<PathBuf>, &ListEntry)> = Vec::new();
    for e in entries {
        if !e.path.exists() {
            return Err(DataError::format(
                e.location().with_field("path"),
                format!("sequence `{}` does not exist", e.path.display()),
            ));
        }
        // What the read takes data from, resolved; an unknown format is reported by the read.
        let Ok(files) = source_files(&e.path) else {
            continue;
        };
        let mut files: Vec<PathBuf> = files
            .iter()
            .map(|f| f.canonicalize().unwrap_or_else(|_| f.clone()))
            .collect();
        files.sort();
        if let Some((_, first)) = seen.iter().find(|(f, _)| *f == files) {
            return Err(DataError::format(
                e.location().with_field("path"),
                format!(
                    "sequence `{}` is the recording already listed at {}:{}; a recording listed \
                     twice would count twice, or be tested on after training on it",
                    e.path.display(),
                    first.list.display(),
                    first.line
                ),
            ));
        }
        seen.push((files, e));
    }
    Ok(())
}
