//! Writers of the RIDI processed layout: `data.csv` as pandas writes it and `data_plain.txt` as
//! the C++ tools read it.
//!
//! Every value is written as [`RoundTrip`] formats it (the shortest text that reads back as the
//! same float) and time as integer nanoseconds, so reading a written file gives the same sequence back bit for bit, except that
//! time is rounded to whole nanoseconds, and that what the layout cannot hold is lost: the
//! name (taken from the path when read), placement, steps and the orientation source (read back
//! as the game rotation vector). The device, which RIDI's layout has no column for either, is
//! kept in a sidecar beside the data file ([`sidecar_path`](crate::sidecar_path): `data.csv`
//! gets `data.csv.meta`), which the readers of this crate read back and RIDI's own ignore; a
//! sequence without a device gets none (and an old one at that path is removed).
//!
//! What a sequence lacks is written so that the readers take it as absent again:
//! - no magnetometer: `magnet_*` are zeros (a real magnetometer never reads exactly zero on
//!   every row, so the readers take all zeros as "not recorded");
//! - no ground truth: `pos_*` and `ori_*` are `NaN` on every row. Zeros would pass for a device
//!   standing still at the origin; `NaN` is read as missing by pandas and numpy, and by the
//!   readers of this crate.
//!
//! Files are written atomically: to a temporary file in the target folder, then renamed, so a
//! crash never leaves a half-written file under the final name. The sidecar goes with its data
//! file: both are written in full first, then the old sidecar is removed, the data file renamed
//! into place and the new sidecar after it, so that a failed write leaves the old pair (when it
//! fails while writing) or at worst a data file without its device, never one beside another
//! file's sidecar.

use std::fmt::{self, Write as _};
use std::io::Write;
use std::path::Path;

use crate::Sequence;
use crate::error::{DataError, Location, Result};
use crate::processed::PROCESSED_COLUMNS;
use crate::sidecar;
use crate::temporaries::{
    TEMPORARY_FILE_PREFIX, Temporary, register_temporary, remove_temporary, stale_temporaries,
    temporary_prefix,
};

/// The 27 values of frame `i` in [`PROCESSED_COLUMNS`] order, time excluded (slot 0 is unused).
fn row(seq: &Sequence, i: usize) -> [f64; 27] {
    let mut r = [0.0; 27];
    let mut put = |at: usize, v: &[f64]| r[at..at + v.len()].copy_from_slice(v);
    put(1, &seq.gyro()[i].to_array());
    put(4, &seq.acce()[i].to_array());
    put(7, &seq.linacce()[i].to_array());
    put(10, &seq.gravity()[i].to_array());
    if let Some(m) = seq.magnet() {
        put(13, &m[i].to_array());
    }
    match seq.ground_truth() {
        Some(gt) => {
            put(16, &gt.position[i].to_array());
            put(19, &gt.orientation[i].to_wxyz());
        }
        None => put(16, &[f64::NAN; 7]),
    }
    put(23, &seq.orientation()[i].to_wxyz());
    r
}

/// Time of frame `i` in integer nanoseconds (valid sequences have finite times).
fn time_ns(seq: &Sequence, i: usize) -> i64 {
    (seq.time()[i] * 1e9).round() as i64
}

/// Writes `content` to `path` through a temporary file in the same folder, renamed into place
/// once complete: readers never see a partial file, and a failed write leaves any previous file
/// untouched.
///
/// The one way ridi-rs writes its output files: recordings and list files, reports, plots,
/// trajectories, the models the `ridi` library and command write, and every file of a staged
/// output folder. [`write_pending`] is the same write in two steps, for a file that is to be
/// renamed into place only once another is written too. (`ridi_regress::Cascade::save`, for
/// users of that crate alone, which cannot depend on this one, writes its own temporary file,
/// with the same mode, and refuses a path that is not a regular file rather than write through
/// a link.)
///
/// # Permissions
///
/// On Unix the file is created with mode `0644` less the process umask, as `open(2)` applies
/// it: `0644` (read for everyone, write for the owner) under the usual umask `022`, `0600`
/// under `077`. A file it replaces keeps nothing of its own mode.
pub fn write_atomically(
    path: &Path,
    content: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    write_pending(path, content)?.commit()
}

/// Where a write to `path` lands: `path` itself, or, where it is a symbolic link, the file it
/// leads to (created if missing, as `cp` does), so that the link stays a link. Refused: a
/// device, a pipe or a socket (the rename into place would replace the node with a regular
/// file: `/dev/null` written as root would be one no more) and links in a loop.
pub fn output_target(path: &Path) -> std::io::Result<std::path::PathBuf> {
    let mut target = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&target) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = std::fs::read_link(&target)?;
                target = target.parent().unwrap_or(Path::new("")).join(to);
            }
            Ok(m) if !m.is_file() && !m.is_dir() => {
                return Err(std::io::Error::other(
                    "is a device, a pipe or a socket, which ridi's atomic write (a new file \
                     renamed into place) would replace with a regular file",
                ));
            }
            _ => return Ok(target),
        }
    }
    Err(std::io::Error::other(
        "is a symbolic link that cannot be followed (links in a loop)",
    ))
}

/// [`write_atomically`] up to the rename: `content` is written in full (and synced) to a temporary
/// file in `path`'s folder (`.ridi-tmp-<pid>-XXXXXX`, locked while written: see
/// [`register_temporary`](crate::register_temporary), and those that killed runs left there are
/// removed first), which [`PendingFile::commit`] renames to `path`. Dropped without a commit, the
/// temporary file is removed and `path` left as it was. For outputs that are to replace their files
/// together, or not at all.
pub fn write_pending(
    path: &Path,
    content: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<PendingFile> {
    let io = |e| DataError::io(path, e);
    let target = output_target(path).map_err(io)?;
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    // What a killed run of any ridi-rs program left here goes first.
    for stale in stale_temporaries(dir, TEMPORARY_FILE_PREFIX) {
        remove_temporary(&stale.path);
    }
    let prefix = temporary_prefix(TEMPORARY_FILE_PREFIX);
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix);
    // Temporary files are private (0600) by default; an output file is for others to read too.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o644));
    }
    let (mut tmp, registered) = register_temporary(|| {
        let tmp = builder.tempfile_in(dir)?;
        // Locked while this process writes it: a later run tells it from a killed one's.
        tmp.as_file().lock()?;
        let path = tmp.path().to_path_buf();
        Ok((tmp, path))
    })
    .map_err(io)?;
    {
        let mut w = std::io::BufWriter::with_capacity(1 << 16, tmp.as_file_mut());
        content(&mut w).map_err(io)?;
        w.flush().map_err(io)?;
    }
    tmp.as_file().sync_all().map_err(io)?;
    Ok(PendingFile {
        tmp,
        path: path.to_path_buf(),
        target,
        _registered: registered,
    })
}

/// A file [`write_pending`] wrote in full under a temporary name beside its path.
#[derive(Debug)]
pub struct PendingFile {
    tmp: tempfile::NamedTempFile,
    path: std::path::PathBuf,
    /// Where it is renamed to: `path`, or the file a link there leads to ([`output_target`]).
    target: std::path::PathBuf,
    _registered: Temporary,
}

impl PendingFile {
    /// The path the file goes to.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Renames the file into place, replacing any file of that name (through a symbolic link
    /// there, the file it leads to).
    pub fn commit(self) -> Result<()> {
        let path = self.path;
        self.tmp
            .persist(&self.target)
            .map_err(|e| DataError::io(&path, e.error))?;
        Ok(())
    }
}

/// How numbers are written.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Precision {
    /// Shortest text that reads back as the same `f64`: exact round trips.
    #[default]
    F64,
    /// Shortest text that reads back as the same `f32`: about 7 significant digits, well
    /// beyond phone sensor resolution, and files about 40 % smaller.
    F32,
}

/// A float as ridi-rs writes numbers to files: the shortest text that reads back as the same
/// value. Magnitudes from 1e-4 to 1e16 (and zero, NaN, infinities) are written as `Display`
/// writes them (`0.25`, `-3`, `NaN`); others in exponent notation, as `{:?}` does (`1.28e-300`,
/// `2e20`), since `Display` never uses an exponent and writes 1e-300 with 300 digits. Every
/// float parser (Rust, C, pandas) reads both forms.
///
/// ```
/// use ridi_data::RoundTrip;
/// assert_eq!(RoundTrip(-0.125).to_string(), "-0.125");
/// assert_eq!(RoundTrip(1.28e-300).to_string(), "1.28e-300");
/// assert_eq!(RoundTrip(0.1f32).to_string(), "0.1");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoundTrip<T>(pub T);

/// For `f64` and `f32`, each comparing in its own type (`1e-4f32` is not `1e-4`).
macro_rules! round_trip_display {
    ($($t:ty),*) => {$(
        impl fmt::Display for RoundTrip<$t> {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                let a = self.0.abs();
                if a == 0.0 || !a.is_finite() || (1e-4..1e16).contains(&a) {
                    fmt::Display::fmt(&self.0, f)
                } else {
                    fmt::LowerExp::fmt(&self.0, f)
                }
            }
        }
    )*};
}
round_trip_display!(f64, f32);

/// Appends `v` to `line` at `precision`.
fn push_value(line: &mut String, v: f64, precision: Precision) {
    // Formatting into a String cannot fail.
    let _ = match precision {
        Precision::F64 => write!(line, "{}", RoundTrip(v)),
        Precision::F32 => write!(line, "{}", RoundTrip(v as f32)),
    };
}

/// Writes a processed data file of `seq` with its sidecar: both written in full first (a
/// failure there, such as a full disk, leaves the old pair as it was), then the old sidecar
/// removed, the data file committed and the new sidecar after it. A sidecar is so never beside
/// another file's data; a failure between the renames leaves the data without its sidecar.
fn write_data(
    seq: &Sequence,
    path: &Path,
    content: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    check_writable(seq, path)?;
    let data = pending_text(path, content)?;
    let side = sidecar::pending(seq, path)?;
    sidecar::remove(path)?;
    data.commit()?;
    side.map_or(Ok(()), PendingFile::commit)
}

/// Refuses what the data file could not hold as `seq`, before anything is written: a folder,
/// and times the
/// nanosecond column cannot tell apart or hold (the file's own reader would refuse it).
/// (A path without a file name, `.` or `..`, would also put its sidecar in another folder.)
fn check_writable(seq: &Sequence, path: &Path) -> Result<()> {
    if path.file_name().is_none() || path.is_dir() {
        return Err(DataError::format(
            Location::file(path),
            "a folder, not a file: give the data file's path, such as `walk/data.csv`",
        ));
    }
    let at = || Location::file(path).with_field("time");
    let mut previous = None;
    for (i, &t) in seq.time().iter().enumerate() {
        // i64 nanoseconds reach 9.2e9 s (the year 2262 as Unix time).
        let fits = (t * 1e9).abs() < 9.2e18;
        if !fits {
            return Err(DataError::format(
                at(),
                format!("frame {i} at {t} s: beyond the nanoseconds the column holds"),
            ));
        }
        let ns = time_ns(seq, i);
        if previous.is_some_and(|p| ns <= p) {
            return Err(DataError::format(
                at(),
                format!(
                    "frames {} and {i} are less than a nanosecond apart: the column would give \
                     them one timestamp",
                    i - 1
                ),
            ));
        }
        previous = Some(ns);
    }
    Ok(())
}

/// Writes text through [`write_pending`], gzip-compressed when `path` ends in `.gz`; committed
/// by the caller.
fn pending_text(
    path: &Path,
    content: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<PendingFile> {
    let gz = path
        .file_name()
        .is_some_and(|n| n.to_string_lossy().to_lowercase().ends_with(".gz"));
    if !gz {
        return write_pending(path, content);
    }
    write_pending(path, |w| {
        let mut enc = flate2::write::GzEncoder::new(w, flate2::Compression::new(9));
        content(&mut enc)?;
        enc.finish()?;
        Ok(())
    })
}

/// Writes `seq` as a RIDI processed `data.csv`: a header with an empty first name (the pandas
/// index), then one row per frame `index,time_ns,gyro_x,...,rv_z`. A path ending in `.gz` is
/// gzip-compressed (the readers decompress transparently). The device, if any, goes to the
/// sidecar ([`sidecar_path`](crate::sidecar_path)).
pub fn write_ridi_csv(seq: &Sequence, path: impl AsRef<Path>) -> Result<()> {
    write_ridi_csv_with(seq, path, Precision::F64)
}

/// [`write_ridi_csv`] with a choice of number precision.
pub fn write_ridi_csv_with(
    seq: &Sequence,
    path: impl AsRef<Path>,
    precision: Precision,
) -> Result<()> {
    write_data(seq, path.as_ref(), |w| {
        writeln!(w, ",{}", PROCESSED_COLUMNS.join(","))?;
        let mut line = String::with_capacity(512);
        for i in 0..seq.len() {
            line.clear();
            let _ = write!(line, "{i},{}", time_ns(seq, i));
            for &v in &row(seq, i)[1..] {
                line.push(',');
                push_value(&mut line, v, precision);
            }
            line.push('\n');
            w.write_all(line.as_bytes())?;
        }
        Ok(())
    })
}

/// Writes `seq` as a RIDI `data_plain.txt`: `N 27`, then N tab-separated rows without index
/// (gzip-compressed when the path ends in `.gz`).
pub fn write_ridi_plain(seq: &Sequence, path: impl AsRef<Path>) -> Result<()> {
    write_data(seq, path.as_ref(), |w| {
        writeln!(w, "{} {}", seq.len(), PROCESSED_COLUMNS.len())?;
        let mut line = String::with_capacity(512);
        for i in 0..seq.len() {
            line.clear();
            let _ = write!(line, "{}", time_ns(seq, i));
            for &v in &row(seq, i)[1..] {
                line.push('\t');
                push_value(&mut line, v, Precision::F64);
            }
            line.push('\n');
            w.write_all(line.as_bytes())?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floats_round_trip_in_short_text_at_any_magnitude() {
        // Ordinary values are written as `Display` writes them.
        for v in [
            0.0, -0.0, 1.0, -3.5, 0.1, 9.80665, 1e-4, 123456.789, 9.999e15,
        ] {
            assert_eq!(RoundTrip(v).to_string(), v.to_string(), "{v}");
        }
        assert_eq!(RoundTrip(f64::NAN).to_string(), "NaN");
        for (v, text) in [
            (1.28e-300, "1.28e-300"),
            (-9.99e-5, "-9.99e-5"),
            (f64::MIN_POSITIVE / 4.0, "5.562684646268003e-309"),
            (1e16, "1e16"),
            (-f64::MAX, "-1.7976931348623157e308"),
        ] {
            assert_eq!(RoundTrip(v).to_string(), text);
            assert_eq!(text.parse::<f64>().unwrap().to_bits(), v.to_bits());
        }
        assert_eq!(RoundTrip(1e-30f32).to_string(), "1e-30");
        assert_eq!(RoundTrip(1e-4f32).to_string(), "0.0001");
        assert_eq!(RoundTrip(0.1f32).to_string(), "0.1");
        // The longest text any f64 gets, against 300-odd digits with `Display`.
        assert!(f64::MIN_POSITIVE.to_string().len() > 300);
        assert!(RoundTrip(-f64::MIN_POSITIVE).to_string().len() <= 24);
    }
}
