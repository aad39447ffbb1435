//! Reading sequences from any supported layout, including those that yield several sequences.

use std::path::{Path, PathBuf};

use ridi_data::ilc::{self, IlcOptions};
use ridi_data::tyrex::{self, TyrexOptions};
use ridi_data::{
    DataError, FileId, Format, Location, ReadOptions, Sequence, detect, read_sequence,
};

/// Sequences read from one source, with the format they came in.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// Format of the source.
    pub format: Format,
    /// The sequences (a Tyrex recording split at a long mocap loss gives several).
    pub sequences: Vec<Sequence>,
    /// Things a user should know (splits, dropped parts, sensor dropouts kept as gaps).
    pub warnings: Vec<String>,
}

/// Whether `path` is, by itself, one source of the format `want`. A folder with any RIDI raw
/// file is a raw folder even when it also holds `processed/data.csv` (as RIDI capture folders
/// do); `data_plain.txt` counts as a RIDI processed csv, but only a `data_plain.txt` (or a
/// folder holding one) is a `data_plain.txt`.
pub(crate) fn is_a(path: &Path, want: Format) -> bool {
    match want {
        Format::RidiRaw => path.is_dir() && ridi_data::ridi_raw::looks_like(path),
        Format::RidiCsv => matches!(detect(path), Ok(Format::RidiCsv | Format::RidiPlain)),
        Format::RidiPlain if path.is_dir() => {
            ridi_data::processed_file(path, Format::RidiPlain).is_some()
        }
        Format::RidiPlain => detect(path).is_ok_and(|f| f == Format::RidiPlain),
        Format::Tyrex | Format::Ilc | Format::Ronin => detect(path).is_ok_and(|f| f == want),
    }
}

/// The error for a source given as `want` that is not one: what it is instead, when it is
/// something known, and what a `want` looks like.
pub(crate) fn not_a(path: &Path, want: Format) -> DataError {
    let found = match detect(path) {
        // Told by its name alone, an empty file is of no format.
        _ if std::fs::metadata(path).is_ok_and(|m| m.is_file() && m.len() == 0) => {
            " (it is empty)".to_string()
        }
        Ok(found) => format!(" (it is {})", with_article(&found.to_string())),
        // A link that cannot be followed says why.
        Err(DataError::Io { error, .. }) => format!(" ({error})"),
        Err(_) if !path.exists() => " (no such file or folder)".to_string(),
        Err(_) => String::new(),
    };
    DataError::format(
        Location::file(path),
        format!(
            "not {}{found}: {}",
            with_article(&want.to_string()),
            want.layout()
        ),
    )
}

/// `a name` or `an name`.
pub(crate) fn with_article(name: &str) -> String {
    let vowel = name.starts_with(|c: char| "AEIOUaeiou".contains(c));
    format!("{} {name}", if vowel { "an" } else { "a" })
}

/// The format [`read_any`] reads `path` as: `from` when `path` is one (a folder of nothing
/// known counts as a RIDI raw folder, whose reader names the files it lacks), else what
/// [`detect`] finds.
///
/// # Errors
/// A `path` that is not `from` (saying what it is and what `from` looks like), or of no known
/// format.
pub fn source_format(path: &Path, from: Option<Format>) -> Result<Format, DataError> {
    Ok(match from {
        None => detect(path)?,
        Some(Format::RidiCsv) if is_a(path, Format::RidiCsv) => detect(path)?,
        Some(want) if is_a(path, want) => want,
        Some(Format::RidiRaw) if path.is_dir() && detect(path).is_err() => Format::RidiRaw,
        Some(want) => return Err(not_a(path, want)),
    })
}

/// `path`, or for a folder read as [`Format::RidiPlain`] its `data_plain.txt`
/// ([`ridi_data::processed_file`]): detection prefers the folder's `data.csv` when it has both.
pub(crate) fn forced_file(path: &Path, from: Option<Format>) -> std::borrow::Cow<'_, Path> {
    match from {
        Some(Format::RidiPlain) if path.is_dir() => {
            ridi_data::processed_file(path, Format::RidiPlain).map_or(path.into(), Into::into)
        }
        _ => path.into(),
    }
}

/// Reads the sequence(s) at `path`: a RIDI `data.csv`, `data_plain.txt`, RIDI raw folder,
/// Tyrex sequence folder, Indoor Location Competition path file or RoNIN sequence folder. `from` forces a format
/// instead of detecting it: a source that is not one is an error saying what it is and what
/// the format looks like; a folder read as a RIDI raw folder names the raw files it lacks, and
/// one with both a `data.csv` and a `data_plain.txt` is read from the one `from` names.
pub fn read_any(
    path: &Path,
    from: Option<Format>,
    opts: &ReadOptions,
) -> Result<Loaded, DataError> {
    let path = &forced_file(path, from);
    let format = source_format(path, from)?;
    match format {
        Format::Tyrex => {
            let read = tyrex::read(path, &TyrexOptions::from(opts))?;
            Ok(Loaded {
                format,
                sequences: read.sequences,
                warnings: read.warnings,
            })
        }
        Format::Ilc => {
            // A path file is read by itself (detect takes no folder for it).
            let read = ilc::read(path, &IlcOptions::from(opts))?;
            Ok(Loaded {
                format,
                sequences: vec![read.sequence],
                warnings: read.warnings,
            })
        }
        Format::RidiRaw => Ok(Loaded {
            format,
            sequences: vec![ridi_data::ridi_raw::read(path, opts)?],
            warnings: Vec::new(),
        }),
        _ => Ok(Loaded {
            format,
            sequences: vec![read_sequence(path, opts)?],
            warnings: Vec::new(),
        }),
    }
}

/// [`read_any`] for tracking, which needs no ground truth: a Tyrex run that the motion
/// capture's losses split into parts is read again without ground truth, and a warning says
/// so (`ridi convert` writes the parts with theirs): one recording where its phone streams are
/// whole, else the fewer parts their own gaps make. Anything else, and a run whose second read
/// fails a check, is [`read_any`]'s.
///
/// # Errors
/// As [`read_any`].
pub fn read_to_track(
    path: &Path,
    from: Option<Format>,
    opts: &ReadOptions,
) -> Result<Loaded, DataError> {
    let loaded = read_any(path, from, opts)?;
    let by_mocap = loaded.format == Format::Tyrex
        && loaded.sequences.len() > 1
        && loaded.sequences.iter().all(|s| s.ground_truth().is_some());
    if !by_mocap {
        return Ok(loaded);
    }
    let without = TyrexOptions {
        ground_truth: false,
        ..TyrexOptions::from(opts)
    };
    let Ok(whole) = tyrex::read(forced_file(path, from), &without) else {
        return Ok(loaded);
    };
    if whole.sequences.is_empty() || whole.sequences.len() >= loaded.sequences.len() {
        return Ok(loaded);
    }
    let read_as = match whole.sequences.len() {
        1 => "tracked as one recording without it".to_string(),
        n => format!("read without it: {n} parts, cut at gaps in the phone's own streams"),
    };
    let mut warnings = vec![format!(
        "{}: mocap losses split the run into {} parts with ground truth; {read_as} (`ridi \
         convert` writes the parts with theirs)",
        ridi_data::shown(path),
        loaded.sequences.len()
    )];
    warnings.extend(whole.warnings);
    Ok(Loaded {
        format: Format::Tyrex,
        sequences: whole.sequences,
        warnings,
    })
}

/// The files a command reads, resolved once, to refuse an output that would replace one.
#[derive(Debug, Clone, Default)]
pub struct ReadFiles {
    /// (as given, resolved, identity when it exists)
    files: Vec<(PathBuf, PathBuf, Option<FileId>)>,
}

impl ReadFiles {
    /// `paths`, a sequence among them standing for the files its reader takes
    /// ([`ridi_data::source_files`]: a folder's data files, a Tyrex run's `.mat`); any other
    /// path (a model, a list) for itself.
    pub fn of<'a>(paths: impl IntoIterator<Item = &'a PathBuf>) -> Self {
        let files = paths
            .into_iter()
            .flat_map(|p| ridi_data::source_files(p).unwrap_or_else(|_| vec![p.clone()]))
            .filter_map(|f| {
                let id = FileId::of(&f).ok();
                resolved(&f).map(|r| (f, r, id))
            })
            .collect();
        Self { files }
    }

    /// The input `out` would replace, if any: by path (links, `..`) or, when `out` exists, by
    /// file identity (also through hard links and bind mounts, which paths do not show). Files
    /// beside a recording that its reader does not take (a trajectory, notes) are not inputs,
    /// nor is an input that does not exist: its read fails, and that is the error to see.
    pub fn overwritten_by(&self, out: &Path) -> Option<&Path> {
        let target = resolved(out)?;
        let id = FileId::of(out).ok();
        self.files
            .iter()
            .filter(|(_, _, i)| i.is_some())
            .find(|(_, r, i)| *r == target || (id.is_some() && *i == id))
            .map(|(given, _, _)| given.as_path())
    }
}

/// `path` with its folder resolved (links, `..`), whether or not the file exists yet; `None`
/// when its folder does not exist.
pub(crate) fn resolved(path: &Path) -> Option<PathBuf> {
    if let Ok(p) = path.canonicalize() {
        return Some(p);
    }
    Some(folder_of(path).canonicalize().ok()?.join(path.file_name()?))
}

/// The folder a file path is in (`.` for a bare file name).
pub(crate) fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}
