//! Dataset list files: which sequences make a dataset split, and where each was carried.
//!
//! One entry per line, `path,placement`: the path is absolute or relative to the list file's
//! folder, the placement (e.g. `body`, `handheld`, `bag`, `leg`) is optional (`path` alone or
//! `path,`). Blank lines and lines starting with `#` are skipped. Surrounding spaces are
//! trimmed. A list that lists no sequence is an error, and so is one that is not a regular file
//! or is larger than 64 MiB.
//!
//! [`ListEntry::read`] parses list files (syntax only); [`Listed`] holds the sequences read
//! from them, with the checks that make them a dataset split.

use std::path::{Path, PathBuf};

use crate::detect::{read_sequence, source_files};
use crate::error::{DataError, Location, Result, shown};
use crate::options::ReadOptions;
use crate::text::{self, is_model_file};
use crate::{FileId, Sequence};

/// Largest list file read, bytes: a million entries of 64-byte paths; a list larger than that
/// is not one (`--list /dev/zero` used to grow until the kernel killed it).
const MAX_LIST_BYTES: u64 = 64 << 20;

/// Why `name` cannot be the path of a list line (`path,placement`, `#` comments, trimmed),
/// if it cannot: written, it would be read back as a comment, as several fields or lines, or as
/// another name.
pub fn unlistable_name(name: &str) -> Option<&'static str> {
    if name.is_empty() {
        Some("it is empty")
    } else if name.starts_with('#') {
        Some("a line starting with `#` is a comment")
    } else if name.contains(',') {
        Some("a comma separates the placement")
    } else if name.chars().any(char::is_control) {
        Some("it holds a control character such as a line break")
    } else if name.trim() != name {
        Some("list lines are trimmed of surrounding spaces")
    } else {
        None
    }
}

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

    /// The entries of the list files `lists`, in order. Only the syntax is checked (errors name
    /// the list file and line); [`Listed::load`] reads the sequences.
    pub fn read(lists: &[impl AsRef<Path>]) -> Result<Vec<ListEntry>> {
        let mut entries = Vec::new();
        let mut read: Vec<(FileId, &Path)> = Vec::new();
        for list in lists {
            let path = list.as_ref();
            if path.is_dir() {
                return Err(folder_for_list(path));
            }
            // The same list twice would list each of its recordings twice.
            if let Ok(id) = FileId::of(path) {
                if let Some((_, first)) = read.iter().find(|(i, _)| *i == id) {
                    let also = match *first == path {
                        true => String::new(),
                        false => format!(" (as {})", shown(first)),
                    };
                    return Err(DataError::format(
                        Location::file(path),
                        format!("list file given twice{also}"),
                    ));
                }
                read.push((id, path));
            }
            if is_model_file(path) {
                return Err(DataError::format(
                    Location::file(path),
                    format!(
                        "is {}, not a list file (one `path,placement` line per sequence)",
                        text::A_MODEL_FILE
                    ),
                ));
            }
            let bytes = text::read_file_bounded(path, MAX_LIST_BYTES)?;
            let not_a_list = |format| {
                DataError::format(
                    Location::file(path),
                    format!(
                        "is a recording ({format}), not a list file (one `path,placement` \
                         line per sequence)"
                    ),
                )
            };
            // A competition path file is told by its records, which parse as a list of
            // missing paths; a `.csv` only by its name, so only once it fails to parse.
            let format = recording(path);
            if let Some(f @ crate::Format::Ilc) = format {
                return Err(not_a_list(f));
            }
            entries.extend(parse_list(&bytes, path).map_err(|e| match format {
                Some(f) => not_a_list(f),
                None => e,
            })?);
        }
        Ok(entries)
    }
}

/// The format of a list file when it may be a recording: a `.csv` (`.csv.gz`, by its name) or
/// a competition path file (by its records); a `.txt` of a list cannot be told from a
/// `data_plain.txt` by its name.
fn recording(path: &Path) -> Option<crate::Format> {
    crate::detect(path)
        .ok()
        .filter(|f| matches!(f, crate::Format::RidiCsv | crate::Format::Ilc))
}

/// The error for a folder given as a list file, naming the lists in it (`ridi convert` writes
/// `list_all.txt` and one per person and device).
fn folder_for_list(path: &Path) -> DataError {
    let mut lists: Vec<String> = std::fs::read_dir(path)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("list") && n.ends_with(".txt"))
        .collect();
    lists.sort();
    let hint = match lists.len() {
        0 => String::new(),
        _ => format!(
            "; it holds {}",
            crate::first_few(lists.iter().map(crate::shown), 5)
        ),
    };
    DataError::format(
        Location::file(path),
        format!("is a folder, not a list file (one `path,placement` line per sequence){hint}"),
    )
}

/// Parses the content of a list file; `path` is the list file itself (relative entries are
/// resolved against its folder, errors name it). A list without any entry (empty, or only
/// comments and blank lines) is an error: "no sequences listed".
pub(crate) fn parse_list(bytes: &[u8], path: &Path) -> Result<Vec<ListEntry>> {
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

/// Sequences read from list files, each with the list entry (file and line) it was read from,
/// so that an error found later about one of them (a recording too short to track, say) can
/// name its list line too.
///
/// No recording is in it twice, also not through two paths (a folder and its
/// `processed/data.csv`, a symbolic link) nor as two files of the same data (a copy in another
/// folder, the same recording converted to another format): it would count twice in every
/// mean, and sit on both sides of a cross-validation split. [`Listed::check_distinct`] makes
/// the same check between two of them, such as a training and a test split.
#[derive(Debug, Clone)]
pub struct Listed {
    sequences: Vec<Sequence>,
    entries: Vec<ListEntry>,
}

impl Listed {
    /// Reads every sequence of the list files `lists` ([`ListEntry::read`], then
    /// [`Listed::load`]).
    pub fn read(lists: &[impl AsRef<Path>], opts: &ReadOptions) -> Result<Self> {
        Self::load(ListEntry::read(lists)?, opts)
    }

    /// Reads the sequence of each of `entries`, in order, detecting each one's format (see
    /// [`detect`](crate::detect())) and setting its placement from the entry when it gives one.
    ///
    /// Every entry is checked to exist, and no recording to be listed twice by path, before
    /// any is read, so a typo fails fast with the list file and line; errors while reading a
    /// sequence name that sequence's file. Once read, two entries of the same data are refused.
    pub fn load(entries: Vec<ListEntry>, opts: &ReadOptions) -> Result<Self> {
        let mut seen: Vec<(Vec<FileId>, &ListEntry)> = Vec::new();
        for e in &entries {
            if !text::present(&e.path) {
                let name = e.path.file_name().map(|n| n.to_string_lossy());
                let folder = e.list.parent().filter(|d| !d.as_os_str().is_empty());
                // A tab or a semicolon where the comma goes: the placement read as a path.
                let hint = if name.is_some_and(|n| n.contains(['\t', ';'])) {
                    " (a list line is `path,placement`, separated by a comma)".to_string()
                } else if let Some(dir) = folder.filter(|d| e.path.starts_with(d)) {
                    format!(
                        " (a relative path in a list is read from the list's folder, {})",
                        shown(dir)
                    )
                } else {
                    String::new()
                };
                return Err(DataError::format(
                    e.location().with_field("path"),
                    format!("sequence `{}` does not exist{hint}", shown(&e.path)),
                ));
            }
            // An unknown format is reported by the read below.
            let Some(files) = recording_files(e) else {
                continue;
            };
            if let Some((_, first)) = seen.iter().find(|(f, _)| *f == files) {
                return Err(listed_twice(e, first));
            }
            seen.push((files, e));
        }
        let sequences: Vec<Sequence> = entries
            .iter()
            .map(|e| {
                let mut seq =
                    read_sequence(&e.path, opts).map_err(|err| misplaced(e).unwrap_or(err))?;
                if e.placement.is_some() {
                    seq.set_placement(e.placement.clone());
                }
                Ok(seq)
            })
            .collect::<Result<_>>()?;
        if let Some((first, later)) = Sequence::first_repeated(&sequences) {
            return Err(copy_error(&entries[later], &entries[first]));
        }
        Ok(Self { sequences, entries })
    }

    /// The sequences, in list order.
    pub fn sequences(&self) -> &[Sequence] {
        &self.sequences
    }

    /// The sequences, to relabel (a placement map) or rename; their data is what the checks
    /// compared.
    pub fn sequences_mut(&mut self) -> &mut [Sequence] {
        &mut self.sequences
    }

    /// The list entry of each sequence.
    pub fn entries(&self) -> &[ListEntry] {
        &self.entries
    }

    /// The sequences, without their entries.
    pub fn into_sequences(self) -> Vec<Sequence> {
        self.sequences
    }

    /// Refuses a sequence of `later` that is a recording of `self`: the checks [`Listed::load`]
    /// makes within its entries (the same files, then the same data), across two splits read
    /// apart, such as a training and a test list (a recording in both would be tested on after
    /// training on it). The error names the later entry's list line and the earlier one's.
    pub fn check_distinct(&self, later: &Listed) -> Result<()> {
        let earlier: Vec<_> = self.entries.iter().map(recording_files).collect();
        for e in &later.entries {
            let Some(files) = recording_files(e) else {
                continue;
            };
            if let Some(i) = earlier.iter().position(|f| f.as_ref() == Some(&files)) {
                return Err(listed_twice(e, &self.entries[i]));
            }
        }
        for (seq, e) in later.sequences.iter().zip(&later.entries) {
            if let Some(i) = self.sequences.iter().position(|s| s.is_same_recording(seq)) {
                return Err(copy_error(e, &self.entries[i]));
            }
        }
        Ok(())
    }
}

/// The error for an entry that names no recording but a list file (lists do not nest) or a
/// model file, at the entry's line; `None` for anything else (its reader's error stands).
fn misplaced(e: &ListEntry) -> Option<DataError> {
    let what = if is_model_file(&e.path) {
        text::A_MODEL_FILE
    } else if e.path.is_file()
        && text::read_file_bounded(&e.path, MAX_LIST_BYTES).is_ok_and(|bytes| {
            parse_list(&bytes, &e.path)
                .is_ok_and(|inner| inner.iter().any(|i| text::present(&i.path)))
        })
    {
        "a list file: lists do not nest (give it to `--list` itself)"
    } else {
        return None;
    };
    Some(DataError::format(
        e.location().with_field("path"),
        format!("`{}` is {what}, not a recording", shown(&e.path)),
    ))
}

/// The files a read of `e` takes data from, by identity ([`FileId`]: also through hard links
/// and bind mounts), sorted: two entries with the same are one recording. `None` when the
/// format is unknown or a file cannot be inspected (the read reports it).
fn recording_files(e: &ListEntry) -> Option<Vec<FileId>> {
    let mut files: Vec<FileId> = source_files(&e.path)
        .ok()?
        .iter()
        .map(|f| FileId::of(f).ok())
        .collect::<Option<_>>()?;
    files.sort();
    Some(files)
}

/// `e` lists, by another path or the same, the files `first` listed already.
fn listed_twice(e: &ListEntry, first: &ListEntry) -> DataError {
    DataError::format(
        e.location().with_field("path"),
        format!(
            "sequence `{}` is the recording already listed at {}:{}; a recording listed \
             twice would count twice in a training or in an evaluation's means",
            shown(&e.path),
            shown(&first.list),
            first.line
        ),
    )
}

/// `e` lists the recording that `first` listed already, in other files.
fn copy_error(e: &ListEntry, first: &ListEntry) -> DataError {
    DataError::format(
        e.location().with_field("path"),
        format!(
            "sequence `{}` holds the same recording as `{}`, listed at {}:{} (the same \
             timestamps, gyro and accelerometer samples); a recording listed twice would \
             count twice in a training or in an evaluation's means",
            shown(&e.path),
            shown(&first.path),
            shown(&first.list),
            first.line
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_a_list_file_cannot_hold_are_named() {
        for name in ["#hash", "a,b", "two\nlines", " padded", "tab\t", ""] {
            assert!(unlistable_name(name).is_some(), "{name:?}");
        }
        for name in ["walk_1", "a b", "Jakob_iPhone4S_NoDist_AR_part2", "ünïcode"] {
            assert_eq!(unlistable_name(name), None, "{name:?}");
        }
    }

    #[test]
    fn a_folder_given_as_a_list_names_the_lists_in_it() {
        let dir = tempfile::tempdir().unwrap();
        let e = ListEntry::read(&[dir.path()]).unwrap_err().to_string();
        assert!(
            e.ends_with("is a folder, not a list file (one `path,placement` line per sequence)"),
            "{e}"
        );
        for name in ["list_all.txt", "list_Jakob.txt", "notes.txt"] {
            std::fs::write(dir.path().join(name), "").unwrap();
        }
        let e = ListEntry::read(&[dir.path()]).unwrap_err().to_string();
        assert!(
            e.ends_with("; it holds list_Jakob.txt, list_all.txt"),
            "{e}"
        );
    }

    #[test]
    fn a_list_given_twice_or_a_recording_given_as_a_list_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let list = dir.path().join("list.txt");
        std::fs::write(&list, "walk,Texting\n").unwrap();
        let e = ListEntry::read(&[&list, &list]).unwrap_err().to_string();
        assert!(e.ends_with("list.txt: list file given twice"), "{e}");
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let other = dir.path().join("sub/../list.txt");
        let e = ListEntry::read(&[&list, &other]).unwrap_err().to_string();
        assert!(e.contains("list file given twice (as "), "{e}");
        let csv = dir.path().join("data.csv");
        let recording = "time,gyro_x,gyro_y,gyro_z,acce_x,acce_y,acce_z\n1,2,3,4,5,6,7\n";
        std::fs::write(&csv, recording).unwrap();
        let e = ListEntry::read(&[&csv]).unwrap_err().to_string();
        assert!(
            e.ends_with(
                "data.csv: is a recording (RIDI processed csv), not a list file (one \
                 `path,placement` line per sequence)"
            ),
            "{e}"
        );
        // A list naming a list (itself, here) or a model: named at the entry's line.
        let nested = dir.path().join("nested.txt");
        std::fs::write(&nested, "nested.txt,AR\n").unwrap();
        let entries = ListEntry::read(&[&nested]).unwrap();
        let e = Listed::load(entries, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("nested.txt:1: field `path`: `")
                && e.ends_with(
                    "nested.txt` is a list file: lists do not nest (give it to `--list` itself), \
                     not a recording"
                ),
            "{e}"
        );
        let model = dir.path().join("m.ridi");
        std::fs::write(&model, b"RIDIREG\0\x08\0\0\0").unwrap();
        let e = ListEntry::read(&[&model]).unwrap_err().to_string();
        assert!(
            e.ends_with(
                "m.ridi: is a model file of `ridi train` (load it with `--model`, in Python `ridi.load`), not \
             a list file (one `path,placement` line per sequence)"
            ),
            "{e}"
        );
        std::fs::write(&nested, "m.ridi,AR\n").unwrap();
        let entries = ListEntry::read(&[&nested]).unwrap();
        let e = Listed::load(entries, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("m.ridi` is a model file of `ridi train`"), "{e}");
        // Given as a recording itself.
        let e = crate::read_sequence(&model, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.ends_with(
                "m.ridi: is a model file of `ridi train` (load it with `--model`, \
             in Python `ridi.load`), not a recording"
            ),
            "{e}"
        );
        // Its records would parse as a list of paths that do not exist.
        let ilc = dir.path().join("5dd9e7abc5b77e0006b1732d.txt");
        let records = "#\tstartTime:1574559495000\n1574559495000\tTYPE_ACCELEROMETER\t0\t0\t9.8\n";
        std::fs::write(&ilc, records).unwrap();
        let e = ListEntry::read(&[&ilc]).unwrap_err().to_string();
        assert!(
            e.ends_with(
                "5dd9e7abc5b77e0006b1732d.txt: is a recording (Indoor Location Competition \
                 path file), not a list file (one `path,placement` line per sequence)"
            ),
            "{e}"
        );
    }
}
