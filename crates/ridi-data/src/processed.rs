//! The RIDI processed layout shared by `data.csv`, `data_plain.txt` and the writers: the 27
//! columns, and how one table of rows becomes a [`Sequence`].

use std::path::Path;

use ridi_frames::{DeviceVec, EstimateError, FilterConfig, OrientationFilter, WorldFromDevice};

use crate::error::{DataError, Location, Result};
use crate::options::ReadOptions;
use crate::text;
use crate::{Channel, GroundTruth, OrientationSource, Sequence, SequenceError, SequenceParts};

/// The 27 columns of the RIDI processed layout, in the order the original writes them. `time`
/// is in nanoseconds; `ori_*` is the Tango ground-truth orientation and `rv_*` the game
/// rotation vector, both world-from-device in `w, x, y, z` order.
pub const PROCESSED_COLUMNS: [&str; 27] = [
    "time",
    "gyro_x",
    "gyro_y",
    "gyro_z",
    "acce_x",
    "acce_y",
    "acce_z",
    "linacce_x",
    "linacce_y",
    "linacce_z",
    "grav_x",
    "grav_y",
    "grav_z",
    "magnet_x",
    "magnet_y",
    "magnet_z",
    "pos_x",
    "pos_y",
    "pos_z",
    "ori_w",
    "ori_x",
    "ori_y",
    "ori_z",
    "rv_w",
    "rv_x",
    "rv_y",
    "rv_z",
];

pub(crate) const TIME: usize = 0;
pub(crate) const GYRO: usize = 1;
pub(crate) const ACCE: usize = 4;
pub(crate) const LINACCE: usize = 7;
pub(crate) const GRAV: usize = 10;
pub(crate) const MAGNET: usize = 13;
pub(crate) const POS: usize = 16;
pub(crate) const ORI: usize = 19;
pub(crate) const RV: usize = 23;

/// The processed layout's names: `gyro_x`, and `gyro_x..gyro_z` for the whole channel.
pub(crate) struct ProcessedFields;

impl text::Fields for ProcessedFields {
    fn field(&self, channel: Channel, axis: Option<usize>) -> String {
        let first = match channel {
            Channel::Time => return PROCESSED_COLUMNS[TIME].to_owned(),
            Channel::Gyro => GYRO,
            Channel::Acce => ACCE,
            Channel::Linacce => LINACCE,
            Channel::Gravity => GRAV,
            Channel::Magnet => MAGNET,
            Channel::Position => POS,
        };
        text::axis_field([0, 1, 2].map(|a| PROCESSED_COLUMNS[first + a]), axis)
    }
    fn time_unit(&self) -> &str {
        "nanoseconds"
    }
}

/// Whether a column may hold NaN: only the ground truth, where NaN on every row is how the
/// writers say "no ground truth".
pub(crate) fn nan_policy(column: usize) -> text::Nan {
    if (POS..RV).contains(&column) {
        text::Nan::Accept
    } else {
        text::Nan::Reject
    }
}

/// Parsed rows in [`PROCESSED_COLUMNS`] order, each with its line number.
pub(crate) struct Table {
    pub rows: Vec<[f64; 27]>,
    pub lines: Vec<usize>,
    /// `magnet_*` columns exist (they may still be all zeros, meaning "not recorded").
    pub has_magnet: bool,
    /// `pos_*` and `ori_*` columns exist (they may still be all NaN, meaning "none").
    pub has_ground_truth: bool,
    /// `linacce_*`, `grav_*` and `rv_*` columns exist; without them the orientation is
    /// estimated ([`SequenceParts::estimate_orientation`]).
    pub has_orientation: bool,
}

/// Parses one data line of the processed layout: `cells()` yields its cells, `column_of(c)`
/// says which of the [`PROCESSED_COLUMNS`] cell `c` holds (`None`: not read), `width` is how
/// many cells a line must have and `width_error(n)` the error for a line with `n`. Columns no
/// cell fills stay NaN. A cut line often ends in a partial cell, so a bad number on a line of
/// the wrong width is reported as the wrong width.
pub(crate) fn parse_row<'a, I: Iterator<Item = &'a str>>(
    cells: impl Fn() -> I,
    column_of: impl Fn(usize) -> Option<usize>,
    width: usize,
    width_error: impl Fn(usize) -> DataError,
    path: &Path,
    line: usize,
) -> Result<[f64; 27]> {
    let mut row = [f64::NAN; 27];
    let mut fields = 0;
    for (c, cell) in cells().enumerate() {
        if let Some(k) = column_of(c) {
            row[k] = text::number(cell, path, line, PROCESSED_COLUMNS[k], nan_policy(k)).map_err(
                |e| match cells().count() {
                    n if n != width => width_error(n),
                    _ => e,
                },
            )?;
        }
        fields = c + 1;
    }
    if fields != width {
        return Err(width_error(fields));
    }
    Ok(row)
}

/// Sequence name from a file path: the capture folder for `<name>/processed/data.csv` and
/// `<name>/data.csv` (also `data_plain.txt`, and both gzipped), the file stem otherwise.
pub(crate) fn name_from_path(path: &Path) -> String {
    let file_name = |p: &Path| p.file_name().map(|s| s.to_string_lossy().into_owned());
    let full = file_name(path).unwrap_or_default();
    let base = full.strip_suffix(".gz").unwrap_or(&full);
    let stem = Path::new(base)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    if !matches!(base, "data.csv" | "data_plain.txt") {
        return stem;
    }
    let Some(dir) = path.parent() else {
        return stem;
    };
    let dir = if file_name(dir).as_deref() == Some("processed") {
        dir.parent().unwrap_or(dir)
    } else {
        dir
    };
    // `data.csv` in the working directory has an empty parent: fall back to the stem.
    file_name(dir).filter(|n| !n.is_empty()).unwrap_or(stem)
}

fn vec3<F: ridi_frames::Frame>(rows: &[[f64; 27]], at: usize) -> Vec<ridi_frames::Vec3<F>> {
    rows.iter()
        .map(|r| ridi_frames::Vec3::new(r[at], r[at + 1], r[at + 2]))
        .collect()
}

fn rotations(table: &Table, at: usize, path: &Path) -> Result<Vec<WorldFromDevice>> {
    table
        .rows
        .iter()
        .zip(&table.lines)
        .map(|(r, &line)| rotation_at(r, at, path, line))
        .collect()
}

/// The rotation in the four columns of `r` from `at` on (`ori_*` or `rv_*`), read from `line`.
pub(crate) fn rotation_at(
    r: &[f64; 27],
    at: usize,
    path: &Path,
    line: usize,
) -> Result<WorldFromDevice> {
    WorldFromDevice::from_wxyz_as_given([r[at], r[at + 1], r[at + 2], r[at + 3]]).map_err(|e| {
        DataError::format(
            Location::line(path, line).with_field(PROCESSED_COLUMNS[at]),
            format!(
                "`{}..{}` is not a rotation: {e}",
                PROCESSED_COLUMNS[at],
                PROCESSED_COLUMNS[at + 3]
            ),
        )
    })
}

pub(crate) fn gt(r: &[f64; 27]) -> &[f64] {
    &r[POS..RV]
}

/// The error for the ground truth of row `r`, read from `line`, which has a NaN while other
/// rows have ground truth (`None`: no NaN in `r`).
pub(crate) fn ground_truth_nan(r: &[f64; 27], path: &Path, line: usize) -> Option<DataError> {
    let k = gt(r).iter().position(|v| v.is_nan())?;
    let (nan, given): (Vec<usize>, Vec<usize>) = (0..gt(r).len()).partition(|&j| gt(r)[j].is_nan());
    let names = |js: &[usize]| -> String {
        let names: Vec<&str> = js.iter().map(|&j| PROCESSED_COLUMNS[POS + j]).collect();
        names.join(", ")
    };
    let message = if given.is_empty() {
        "ground truth is NaN here but present on other rows (all NaN means none)".to_string()
    } else {
        format!(
            "ground truth is incomplete: {} NaN but {} given (give every ground-truth \
             column, or NaN in all of them on every row for none)",
            names(&nan),
            names(&given)
        )
    };
    Some(DataError::format(
        Location::line(path, line).with_field(PROCESSED_COLUMNS[POS + k]),
        message,
    ))
}

/// Ground truth of the table: `None` when its columns are absent or NaN on every row; an error
/// naming the first NaN when only some rows have it.
fn ground_truth(table: &Table, path: &Path) -> Result<Option<GroundTruth>> {
    if !table.has_ground_truth {
        return Ok(None);
    }
    if table.rows.iter().all(|r| gt(r).iter().all(|v| v.is_nan())) {
        return Ok(None);
    }
    for (r, &line) in table.rows.iter().zip(&table.lines) {
        if let Some(e) = ground_truth_nan(r, path, line) {
            return Err(e);
        }
    }
    Ok(Some(GroundTruth {
        position: vec3::<ridi_frames::World>(&table.rows, POS),
        orientation: rotations(table, ORI, path)?,
    }))
}

/// Builds and validates the sequence of a processed table; `path` names the file in errors.
pub(crate) fn assemble(table: Table, path: &Path, opts: &ReadOptions) -> Result<Sequence> {
    let rows = &table.rows;
    let time: Vec<f64> = rows.iter().map(|r| r[TIME] / 1e9).collect();
    text::check_time(
        &time,
        &table.lines,
        path,
        PROCESSED_COLUMNS[TIME],
        opts.validation.max_gap_s,
    )?;
    let magnet = table
        .has_magnet
        .then(|| vec3::<ridi_frames::Device>(rows, MAGNET))
        .filter(|m| m.iter().any(|v| *v != DeviceVec::ZERO));
    let at = |e| text::sequence_error(path, Some(&table.lines), &ProcessedFields, e);
    let mut parts = SequenceParts {
        name: name_from_path(path),
        placement: None,
        time,
        gyro: vec3(rows, GYRO),
        acce: vec3(rows, ACCE),
        linacce: Vec::new(),
        gravity: Vec::new(),
        magnet,
        orientation: Vec::new(),
        orientation_source: Some(OrientationSource::GameRotationVector),
        ground_truth: ground_truth(&table, path)?,
        steps: None,
        device: None,
    };
    if table.has_orientation {
        parts.linacce = vec3(rows, LINACCE);
        parts.gravity = vec3(rows, GRAV);
        parts.orientation = rotations(&table, RV, path)?;
    } else {
        check_estimate_starts(&parts, &table.lines, path)?;
        parts
            .estimate_orientation(&FilterConfig::default())
            .map_err(|e| match e {
                SequenceError::Estimate { error, .. } => estimate_error(path, error),
                e => at(e),
            })?;
    }
    Sequence::with_validation(parts, &opts.validation).map_err(at)
}

/// How long the orientation estimate of a file without orientation columns may wait to start,
/// in seconds and in rows from the file's first row: [`OrientationFilter`] holds its samples
/// until it has [`FilterConfig::init_samples`] nonzero accelerometer readings and
/// [`FilterConfig::settle_time`] of samples (2 s), and a stream holds its rows meanwhile, so
/// the limits bound what it holds (100 000 rows: 10 s at 10 kHz, the fastest rate the readers
/// accept). Real recorders log a reading in their first sample.
pub(crate) const MAX_ESTIMATE_WAIT: (f64, usize) = (60.0, 100_000);

/// The filter a file without orientation columns is estimated with, row by row or whole
/// ([`SequenceParts::estimate_orientation`]).
pub(crate) fn estimate_filter() -> OrientationFilter {
    OrientationFilter::new(FilterConfig::default()).expect("the default filter is valid")
}

/// Whether `filter`, fed `rows` rows since the file's first row at `first_time`, has waited
/// too long ([`MAX_ESTIMATE_WAIT`]) when a row at `time` comes and it has not started.
pub(crate) fn estimate_waited_too_long(
    filter: &OrientationFilter,
    rows: usize,
    first_time: f64,
    time: f64,
) -> bool {
    filter.orientation().is_none()
        && (time - first_time > MAX_ESTIMATE_WAIT.0 || rows >= MAX_ESTIMATE_WAIT.1)
}

/// The error for `line` of `path`, where the estimate has waited too long.
pub(crate) fn estimate_wait_error(path: &Path, line: usize) -> DataError {
    let config = FilterConfig::default();
    let (seconds, rows) = MAX_ESTIMATE_WAIT;
    DataError::format(
        Location::line(path, line).with_field(acce_field()),
        format!(
            "the orientation estimate has not started {seconds} s or {rows} rows into the \
             file (the file has no orientation columns; the estimate needs {} nonzero \
             accelerometer readings and {} s of rows): an accelerometer reading zero, or time \
             in another unit than nanoseconds?",
            config.init_samples, config.settle_time
        ),
    )
}

/// The error of the estimate of the orientation of `path`, a file without orientation columns.
pub(crate) fn estimate_error(path: &Path, error: EstimateError) -> DataError {
    match error {
        EstimateError::NoGravity => DataError::format(
            Location::file(path).with_field(acce_field()),
            "no nonzero accelerometer reading to estimate the orientation from (the file has no \
             orientation columns)",
        ),
        error => text::sequence_error_at(
            path,
            |_| None,
            &ProcessedFields,
            SequenceError::Estimate {
                what: "orientation estimate",
                error,
            },
        ),
    }
}

fn acce_field() -> String {
    use text::Fields;
    ProcessedFields.field(Channel::Acce, None)
}

/// Refuses a file without orientation columns whose estimate waits too long to start, at the
/// line where it has: the check the stream makes as the rows come.
fn check_estimate_starts(parts: &SequenceParts, lines: &[usize], path: &Path) -> Result<()> {
    let mut filter = estimate_filter();
    let mut out = Vec::new();
    let time = &parts.time;
    for (i, (&t, &line)) in time.iter().zip(lines).enumerate() {
        if filter.orientation().is_some() {
            break;
        }
        if estimate_waited_too_long(&filter, i, time[0], t) {
            return Err(estimate_wait_error(path, line));
        }
        filter
            .push(t, parts.gyro[i], parts.acce[i], &mut out)
            .map_err(|e| estimate_error(path, e))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_come_from_the_capture_folder() {
        assert_eq!(
            name_from_path(Path::new("/d/seq1/processed/data.csv")),
            "seq1"
        );
        assert_eq!(name_from_path(Path::new("/d/seq2/data.csv")), "seq2");
        assert_eq!(name_from_path(Path::new("seq3/data_plain.txt")), "seq3");
        assert_eq!(name_from_path(Path::new("/d/walk.csv")), "walk");
        assert_eq!(name_from_path(Path::new("data.csv")), "data");
    }
}
