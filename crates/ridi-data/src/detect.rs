//! Format detection and the reader dispatch.

use std::fmt;
use std::path::{Path, PathBuf};

use crate::Sequence;
use crate::error::{DataError, Location, Result};
use crate::options::ReadOptions;
use crate::{ilc, ridi_csv, ridi_plain, ridi_raw, ronin, tyrex};

/// The dataset formats ridi-data knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    /// RIDI processed `data.csv` (see [`ridi_csv`]).
    RidiCsv,
    /// RIDI `data_plain.txt` (see [`ridi_plain`]).
    RidiPlain,
    /// RIDI raw recorder folder (see [`ridi_raw`]).
    RidiRaw,
    /// Tyrex smartphone benchmark run folder, Android or iOS layout (see [`tyrex`]).
    Tyrex,
    /// Indoor Location Competition 2.0 path file (see [`ilc`]).
    Ilc,
    /// RoNIN sequence folder with `data.hdf5` and `info.json` (see [`ronin`]).
    Ronin,
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Format::RidiCsv => "RIDI processed csv",
            Format::RidiPlain => "RIDI data_plain.txt",
            Format::RidiRaw => "RIDI raw folder",
            Format::Tyrex => "Tyrex folder",
            Format::Ilc => "Indoor Location Competition path file",
            Format::Ronin => "RoNIN folder",
        })
    }
}

impl Format {
    /// Every format, in the order the command line and Python list them.
    pub const ALL: [Format; 6] = [
        Format::RidiCsv,
        Format::RidiPlain,
        Format::RidiRaw,
        Format::Tyrex,
        Format::Ilc,
        Format::Ronin,
    ];

    /// The format's name wherever one is typed or read back: `ridi convert --from`, Python's
    /// `format=` and `Sequence.format`, `ridi inspect --json` (`ridi-csv`, `ridi-plain`,
    /// `ridi-raw`, `tyrex`, `ilc`, `ronin`). [`Display`](fmt::Display) is the format in words.
    pub fn key(self) -> &'static str {
        match self {
            Format::RidiCsv => "ridi-csv",
            Format::RidiPlain => "ridi-plain",
            Format::RidiRaw => "ridi-raw",
            Format::Tyrex => "tyrex",
            Format::Ilc => "ilc",
            Format::Ronin => "ronin",
        }
    }

    /// Whether a reader of this format given an unbounded
    /// [`Validation::max_gap_s`](crate::Validation::max_gap_s) keeps every pause of the recording
    /// as a gap between frames, where [`Sequence::split_at_gaps`](crate::Sequence::split_at_gaps)
    /// can cut it, and invents no value inside it: the frames are the file's rows (RIDI's
    /// processed files), or the reader cuts its timeline at each dropout of a sensor stream
    /// (Tyrex; the Indoor Location Competition's, which leaves out a magnetometer that drops
    /// out for longer than [`ilc::MAX_MAGNET_FILL_S`](crate::ilc::MAX_MAGNET_FILL_S)). Not a
    /// RIDI raw folder, whose sensors are interpolated onto the pose's times (there the limit
    /// also bounds a hole in one sensor), nor RoNIN, whose gyro-integrated orientation would
    /// take a pause in one step.
    pub fn keeps_gaps(self) -> bool {
        !matches!(self, Format::RidiRaw | Format::Ronin)
    }

    /// What a source of this format looks like, for errors about a source that is not one.
    pub fn layout(self) -> &'static str {
        match self {
            Format::RidiCsv => {
                "a RIDI processed csv is a `data.csv` (or `.csv.gz`) with the RIDI columns, or a \
                 folder holding one (or `processed/data.csv`)"
            }
            Format::RidiPlain => {
                "a RIDI `data_plain.txt` starts with `N 27`, then N tab-separated rows"
            }
            Format::RidiRaw => {
                "a RIDI raw folder holds gyro.txt, acce.txt, linacce.txt, gravity.txt and \
                 orientation.txt (and optionally magnet.txt, pose.txt, step.txt)"
            }
            Format::Tyrex => {
                "a Tyrex run is a folder <Person>_<Phone>_<Dist>_<Motion> with \
                 accelerometer.txt, gyroscope-calibrated.txt, rotation-vector.txt and \
                 timeAlignment.txt (Android), or accelerometer.txt, gyroscope.txt, attitude.txt, \
                 description.txt and timeAlignment.txt (iOS); a Tyrex root holds the runs in \
                 datasets/android/ and datasets/ios/"
            }
            Format::Ilc => {
                "an Indoor Location Competition path file is a `.txt` of \
                 `unix_ms<TAB>TYPE_...` records"
            }
            Format::Ronin => {
                "a RoNIN sequence is a folder (a000_1, ...) with data.hdf5 and info.json; a \
                 RoNIN split folder (train_dataset_1, ...) holds the sequence folders"
            }
        }
    }
}

/// A format by its [`Format::key`]; the error lists the keys.
impl std::str::FromStr for Format {
    type Err = String;

    fn from_str(text: &str) -> std::result::Result<Self, String> {
        Format::ALL
            .into_iter()
            .find(|f| f.key() == text)
            .ok_or_else(|| {
                let keys: Vec<&str> = Format::ALL.iter().map(|f| f.key()).collect();
                format!(
                    "`{text}` is not a format; expected one of {}",
                    keys.join(", ")
                )
            })
    }
}

/// As its [`Format::key`].
impl serde::Serialize for Format {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.key())
    }
}

/// A folder's processed RIDI files, in the order detection takes them. A RIDI capture folder
/// often holds the raw files and `processed/`: the processed file is what the published
/// dataset ships, with the trimmed, synchronized timeline, so it wins.
const PROCESSED_FILES: [(&str, Format); 6] = [
    ("processed/data.csv", Format::RidiCsv),
    ("processed/data.csv.gz", Format::RidiCsv),
    ("data.csv", Format::RidiCsv),
    ("data.csv.gz", Format::RidiCsv),
    ("processed/data_plain.txt", Format::RidiPlain),
    ("data_plain.txt", Format::RidiPlain),
];

/// The file in `folder` a processed recording of `format` is read from, when it holds one
/// (present, even as a link that cannot be followed, whose reading then says so): for a
/// folder holding both a `data.csv` and a `data_plain.txt`, which [`detect`] reads as its
/// `data.csv`, the file a reader forced to `data_plain.txt` takes.
pub fn processed_file(folder: &Path, format: Format) -> Option<PathBuf> {
    PROCESSED_FILES
        .iter()
        .filter(|(_, f)| *f == format)
        .map(|(rel, _)| folder.join(rel))
        .find(|file| crate::text::present(file))
}

/// What [`detect`] found: the format and the file or folder its reader takes.
pub(crate) fn locate(path: &Path) -> Result<(Format, PathBuf)> {
    if path.is_file() {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_lowercase())
            .unwrap_or_default();
        if name.ends_with(".csv") || name.ends_with(".csv.gz") {
            return Ok((Format::RidiCsv, path.to_path_buf()));
        }
        if name.ends_with(".txt") || name.ends_with(".txt.gz") {
            let format = if ilc::is_path_file(path) {
                Format::Ilc
            } else {
                Format::RidiPlain
            };
            return Ok((format, path.to_path_buf()));
        }
        if name == ronin::DATA_FILE || name == ronin::INFO_FILE {
            // A file of a RoNIN sequence stands for its folder.
            if let Some(folder) = path.parent().filter(|f| ronin::looks_like(f)) {
                return Ok((Format::Ronin, folder.to_path_buf()));
            }
        }
        if crate::text::is_model_file(path) {
            return Err(DataError::format(
                Location::file(path),
                format!("is {}, not a recording", crate::text::A_MODEL_FILE),
            ));
        }
        return Err(DataError::format(
            Location::file(path),
            "unknown file type: expected a RIDI `.csv` or `data_plain.txt`, an Indoor \
             Location Competition path `.txt`, or a RoNIN sequence's data.hdf5",
        ));
    }
    if !path.is_dir() {
        // A symbolic link that cannot be followed: the error says so.
        if let (true, Err(e)) = (crate::text::present(path), std::fs::metadata(path)) {
            return Err(DataError::io(path, e));
        }
        return Err(DataError::format(
            Location::file(path),
            if path.exists() {
                "neither a regular file nor a folder (a device, socket or pipe)"
            } else {
                "no such file or folder"
            },
        ));
    }
    let has = |p: &str| crate::text::present_or_error(&path.join(p));
    for (rel, format) in PROCESSED_FILES {
        if has(rel)? {
            return Ok((format, path.join(rel)));
        }
    }
    // Any of the files a format's folder must have makes it one: its reader then names the
    // others it lacks.
    let mut tyrex = false;
    for f in [
        "accelerometer.txt",
        "gyroscope-calibrated.txt",
        "attitude.txt",
    ] {
        tyrex |= has(f)?;
    }
    if tyrex {
        return Ok((Format::Tyrex, path.to_path_buf()));
    }
    if ronin::looks_like(path) {
        return Ok((Format::Ronin, path.to_path_buf()));
    }
    if ridi_raw::looks_like(path) {
        return Ok((Format::RidiRaw, path.to_path_buf()));
    }
    Err(DataError::format(
        Location::file(path),
        "not a known dataset folder: expected processed/data.csv, data.csv, data_plain.txt, \
         a RIDI raw folder (gyro.txt, acce.txt, ...), a Tyrex folder (accelerometer.txt, \
         gyroscope-calibrated.txt or attitude.txt) or a RoNIN folder (data.hdf5, info.json); \
         a folder of recordings (a dataset's root) is read by `ridi convert`",
    ))
}

/// The files a read of `path` takes data from: the file itself (and for a processed file its
/// sidecar, [`sidecar_path`](crate::sidecar_path), when there is one), or for a folder those of
/// its detected format that exist (a Tyrex run: its text files and its `.mat` ground truth
/// beside the `android` or `ios` folder). What a command's output must not overwrite.
///
/// # Errors
/// As [`detect`]: `path` is no sequence of a known format.
pub fn source_files(path: impl AsRef<Path>) -> Result<Vec<PathBuf>> {
    let (format, at) = locate(path.as_ref())?;
    let mut files = match format {
        Format::Ilc => return Ok(vec![at]),
        Format::RidiCsv | Format::RidiPlain => {
            let sidecar = crate::sidecar_path(&at);
            let mut files = vec![at];
            files.extend(sidecar.is_file().then_some(sidecar));
            return Ok(files);
        }
        Format::Ronin => ronin::files(&at).into(),
        Format::RidiRaw => ridi_raw::FILES
            .iter()
            .map(|(name, _)| at.join(name))
            .collect(),
        Format::Tyrex => {
            let entries = std::fs::read_dir(&at).map_err(|e| DataError::io(&at, e))?;
            let mut files = Vec::new();
            for entry in entries {
                files.push(entry.map_err(|e| DataError::io(&at, e))?.path());
            }
            files.extend(tyrex::mat_path(&at));
            files
        }
    };
    files.retain(|f| f.is_file());
    files.sort();
    Ok(files)
}

/// Detects the format of a file or folder.
///
/// Files: `*.csv` is a RIDI processed csv, `*.txt` an Indoor Location Competition path file when
/// its first lines are `unix_ms<TAB>TYPE_...` records or a `#\tstartTime:` header (see
/// [`ilc::looks_like_path_file`]) and a `data_plain.txt` otherwise; either may be
/// gzip-compressed (`*.csv.gz`, `*.txt.gz`). Folders, first match wins: `processed/data.csv`
/// (or `.csv.gz`), `data.csv` (or `.csv.gz`), `processed/data_plain.txt`, `data_plain.txt`, a
/// Tyrex folder of either layout (`accelerometer.txt`, `gyroscope-calibrated.txt` or
/// `attitude.txt`; [`tyrex::layout_of`] tells which), a RoNIN folder (`data.hdf5`; the file
/// itself, or its `info.json`, stands for the folder), a RIDI raw folder (any of
/// [`ridi_raw::REQUIRED`]). A folder with only some of the files its format needs is
/// detected as that format, and reading it names the files it lacks.
pub fn detect(path: impl AsRef<Path>) -> Result<Format> {
    locate(path.as_ref()).map(|(f, _)| f)
}

/// Reads a sequence of any detected format (see [`detect`]), **dropping the reader's
/// warnings** (see below). A Tyrex run split into several parts is refused here: use
/// [`tyrex::read`](crate::tyrex::read), which returns every part. An Indoor Location
/// Competition path file is read with [`ilc::IlcOptions`] built from `opts` (placement `hand`).
///
/// # Warnings are dropped
///
/// This returns the sequence only: **the reader's warnings are lost**. Of the readers here the
/// Tyrex one warns, in [`TyrexRead::warnings`](crate::tyrex::TyrexRead::warnings): splits at
/// mocap or sensor gaps, parts shorter than
/// [`TyrexOptions::min_part_s`](crate::tyrex::TyrexOptions::min_part_s) that were dropped, a
/// clipped accelerometer, an unknown motion (so no placement); so does the Indoor Location
/// Competition one, in [`IlcPath::warnings`](crate::ilc::IlcPath::warnings): sensor dropouts
/// kept as gaps, stray records beside them left out, magnetometer dropouts interpolated. A run read here can come back as
/// one clean-looking sequence while its reader warned a dozen times
/// (`Guillaume_Nexus5_NoDist_AR`: 12 warnings, 4 dropped parts). To get them, call
/// [`tyrex::read`](crate::tyrex::read) with `TyrexOptions::from(opts)` (the options this
/// function uses, see [`TyrexOptions`](crate::tyrex::TyrexOptions)), or, from the `ridi`
/// facade crate, `ridi::read_any`, which returns the sequences of any format together with
/// their warnings. [`Listed`](crate::Listed) reads every listed path through this function, so
/// it drops the warnings too.
pub fn read_sequence(path: impl AsRef<Path>, opts: &ReadOptions) -> Result<Sequence> {
    let (format, file) = locate(path.as_ref())?;
    match format {
        Format::RidiCsv => ridi_csv::read(&file, opts),
        Format::RidiPlain => ridi_plain::read(&file, opts),
        Format::RidiRaw => ridi_raw::read(&file, opts),
        Format::Ilc => Ok(ilc::read(&file, &ilc::IlcOptions::from(opts))?.sequence),
        Format::Ronin => Ok(ronin::read(&file, &ronin::RoninOptions::from(opts))?.sequence),
        Format::Tyrex => {
            let mut read = crate::tyrex::read(&file, &crate::tyrex::TyrexOptions::from(opts))?;
            match read.sequences.len() {
                1 => Ok(read.sequences.remove(0)),
                n => Err(DataError::format(
                    Location::file(&file),
                    format!(
                        "the recording has {n} usable parts (split at long tracking or sensor \
                         gaps), which cannot be read as one sequence: convert it with `ridi \
                         convert`, which writes each part as a sequence of its own and lists \
                         them, and use those (in Python `ridi.read_any`, in Rust \
                         `ridi_data::tyrex::read`, give every part)"
                    ),
                )),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_format_parses_from_its_key_and_serializes_as_it() {
        for f in Format::ALL {
            assert_eq!(f.key().parse::<Format>(), Ok(f));
            assert_eq!(
                serde_json::to_string(&f).unwrap(),
                format!("\"{}\"", f.key())
            );
        }
        assert_eq!(
            "csv".parse::<Format>().unwrap_err(),
            "`csv` is not a format; expected one of ridi-csv, ridi-plain, ridi-raw, tyrex, ilc, ronin"
        );
    }
}
