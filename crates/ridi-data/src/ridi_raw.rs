//! Reader of RIDI raw recorder folders.
//!
//! A folder holds `gyro.txt`, `acce.txt`, `linacce.txt`, `gravity.txt` and `orientation.txt`
//! ([`REQUIRED`]: a folder with only some of them is an error naming those it lacks) and
//! `magnet.txt`, `pose.txt`, `step.txt` (optional; a file with no rows counts as absent). Each
//! starts with a `#` header line (any `#` line is skipped), then space-separated rows
//! `t_ns values...`: `x y z` for the IMU files, `x y z w` for the game rotation vector in
//! `orientation.txt`, `tx ty tz qx qy qz qw` for the Tango pose, `count` for `step.txt`. Extra
//! trailing values are ignored; fewer are an error, and so is a last record without a line break
//! after it (a file cut off while being written, whose last value may be cut short).
//!
//! Like the original processing, the pose timeline is the master clock: [`ReadOptions::pose_trim`]
//! records are dropped at each end, then every sensor is linearly interpolated onto the pose
//! times (the rotation vector is slerped) and the pose is the ground truth. Pose times outside
//! the span every sensor covers are dropped too, so nothing is extrapolated. Without `pose.txt`
//! the timeline is uniform at [`ReadOptions::rate_without_pose_hz`] over that common span and
//! there is no ground truth. Repeated timestamps within a file keep their first record;
//! decreasing ones are an error, and so is a gap longer than the validation's `max_gap_s` in any
//! file but `step.txt` (written only when a step is taken) and `pose.txt` (checked after
//! trimming, on the sequence itself). A failed check of an interpolated stream (such as a mean
//! gravity magnitude in the wrong units) names that stream's file.
//!
//! Before the synchronization, each file but `step.txt` is checked against the
//! [`Validation`] limits on its own lines: its median time step, and every value of the IMU
//! files and the pose position against the channel's physical bound (the gyro's median
//! magnitude too). The accelerometer's scale against gravity is checked on the sequence and
//! reported on `acce.txt`.

use std::path::{Path, PathBuf};

use ridi_frames::{DeviceVec, Vec3, WorldFromDevice, WorldVec};

use crate::error::{DataError, Location, Result};
use crate::options::ReadOptions;
use crate::resample::{interpolate_rot, interpolate_scalar, interpolate_vec3, uniform_timeline};
use crate::text;
use crate::{
    Channel, GroundTruth, OrientationSource, Sequence, SequenceError, SequenceParts, Validation,
};

const XYZ: &[&str] = &["t", "x", "y", "z"];
const QUAT: &[&str] = &["t", "x", "y", "z", "w"];
const POSE: &[&str] = &["t", "tx", "ty", "tz", "qx", "qy", "qz", "qw"];
const STEP: &[&str] = &["t", "count"];

/// The files of a raw folder, with the fields of their rows (`t` is in nanoseconds).
pub const FILES: [(&str, &[&str]); 8] = [
    ("gyro.txt", XYZ),
    ("acce.txt", XYZ),
    ("linacce.txt", XYZ),
    ("gravity.txt", XYZ),
    ("magnet.txt", XYZ),
    ("orientation.txt", QUAT),
    ("pose.txt", POSE),
    ("step.txt", STEP),
];

/// The raw files' names: `t`, `x y z` (`tx ty tz` in `pose.txt`).
struct RawFields;

impl text::Fields for RawFields {
    fn field(&self, channel: Channel, axis: Option<usize>) -> String {
        match channel {
            Channel::Time => "t".to_owned(),
            Channel::Position => text::axis_field(["tx", "ty", "tz"], axis),
            _ => text::axis_field(["x", "y", "z"], axis),
        }
    }
    fn time_unit(&self) -> &str {
        "nanoseconds"
    }
}

/// The files a raw folder must have.
pub const REQUIRED: [&str; 5] = [
    "gyro.txt",
    "acce.txt",
    "linacce.txt",
    "gravity.txt",
    "orientation.txt",
];

/// Whether `folder` holds any of the [`REQUIRED`] files: a RIDI raw folder, complete or not
/// (the reader names what is missing).
pub fn looks_like(folder: &Path) -> bool {
    REQUIRED.iter().any(|f| folder.join(f).is_file())
}

/// Fails naming every [`REQUIRED`] file `folder` lacks.
fn check_required(folder: &Path) -> Result<()> {
    let missing: Vec<&str> = REQUIRED
        .into_iter()
        .filter(|f| !folder.join(f).is_file())
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    Err(DataError::format(
        Location::file(folder),
        format!(
            "RIDI raw folder without {}: it needs {}",
            missing.join(", "),
            REQUIRED.join(", ")
        ),
    ))
}

/// One parsed file: times in seconds, strictly increasing, with `fields.len() - 1` values each.
struct Records {
    path: PathBuf,
    fields: &'static [&'static str],
    time: Vec<f64>,
    values: Vec<f64>,
    lines: Vec<usize>,
}

impl Records {
    fn width(&self) -> usize {
        self.fields.len() - 1
    }

    fn row(&self, i: usize) -> &[f64] {
        let w = self.width();
        &self.values[i * w..(i + 1) * w]
    }

    fn vec3<F: ridi_frames::Frame>(&self, i: usize) -> Vec3<F> {
        let r = self.row(i);
        Vec3::new(r[0], r[1], r[2])
    }

    fn vecs(&self) -> Vec<DeviceVec> {
        (0..self.time.len()).map(|i| self.vec3(i)).collect()
    }

    /// Rotation of row `i` from `x y z w` at `offset` in the row.
    fn rotation(&self, i: usize, offset: usize) -> Result<WorldFromDevice> {
        let r = &self.row(i)[offset..offset + 4];
        WorldFromDevice::from_xyzw([r[0], r[1], r[2], r[3]]).map_err(|e| {
            DataError::format(
                Location::line(&self.path, self.lines[i]).with_field(format!(
                    "{}..{}",
                    self.fields[offset + 1],
                    self.fields[offset + 4]
                )),
                format!("not a rotation: {e}"),
            )
        })
    }

    fn span(&self) -> (f64, f64) {
        (self.time[0], self.time[self.time.len() - 1])
    }

    /// Checks the time step and, for `channel`, the first three values of every row.
    fn check(&self, limits: &Validation, channel: Option<Channel>) -> Result<()> {
        let xyz = (0..self.time.len()).map(|i| {
            let r = self.row(i);
            [r[0], r[1], r[2]]
        });
        let (path, lines) = (&self.path, &self.lines);
        text::check_stream(limits, path, lines, &RawFields, &self.time, channel, xyz)
    }

    /// A validation failure of this file, on its line when it is about one record.
    fn error(&self, e: SequenceError) -> DataError {
        text::sequence_error(&self.path, Some(&self.lines), &RawFields, e)
    }
}

/// Parses one raw file. Records with a timestamp equal to the previous one are dropped.
fn parse_records(
    bytes: &[u8],
    path: &Path,
    fields: &'static [&'static str],
    max_gap_s: Option<f64>,
) -> Result<Records> {
    let width = fields.len() - 1;
    let mut rec = Records {
        path: path.to_path_buf(),
        fields,
        time: Vec::new(),
        values: Vec::new(),
        lines: Vec::new(),
    };
    let mut row = Vec::with_capacity(width);
    // The line of the last record, unless a `#` line follows it.
    let mut last_record = None;
    let text = text::as_text(bytes, path)?;
    for (line, content) in text::lines(text) {
        if content.trim_start().starts_with('#') {
            last_record = None;
            continue;
        }
        last_record = Some(line);
        let mut cells = content.split_ascii_whitespace();
        let t = text::number(
            cells.next().unwrap_or(""),
            path,
            line,
            "t",
            text::Nan::Reject,
        )?;
        row.clear();
        for (&field, cell) in fields[1..].iter().zip(cells.by_ref()) {
            row.push(text::number(cell, path, line, field, text::Nan::Reject)?);
        }
        if row.len() < width {
            return Err(DataError::format(
                Location::line(path, line).with_field(fields[row.len() + 1]),
                format!(
                    "{} fields, expected {} (`{}`; truncated line?)",
                    row.len() + 1,
                    fields.len(),
                    fields.join(" ")
                ),
            ));
        }
        // Division by the exact 1e9 rounds once; multiplying by the inexact 1e-9 would not, and
        // times would then differ from the same nanoseconds read from a processed file.
        let t = t / 1e9;
        if rec.time.last() == Some(&t) {
            continue;
        }
        rec.time.push(t);
        rec.values.extend_from_slice(&row);
        rec.lines.push(line);
    }
    text::check_line_break(text, last_record.map(|l| Location::line(path, l)), "")?;
    // Duplicates are gone, so equal times cannot occur here; decreasing ones and gaps can.
    text::check_time(
        &rec.time,
        &rec.lines,
        path,
        "t",
        max_gap_s.unwrap_or(f64::INFINITY),
    )?;
    Ok(rec)
}

/// Reads `name` in `folder`: `Ok(None)` when it is optional and absent or without rows.
fn read_records(
    folder: &Path,
    name: &str,
    fields: &'static [&'static str],
    required: bool,
    max_gap_s: Option<f64>,
) -> Result<Option<Records>> {
    let path = folder.join(name);
    if !required && !path.exists() {
        return Ok(None);
    }
    let rec = parse_records(&text::read_file(&path)?, &path, fields, max_gap_s)?;
    if rec.time.is_empty() {
        if required {
            return Err(DataError::format(Location::file(&path), "has no data rows"));
        }
        return Ok(None);
    }
    Ok(Some(rec))
}

fn required(
    folder: &Path,
    name: &str,
    fields: &'static [&'static str],
    gap: f64,
) -> Result<Records> {
    read_records(folder, name, fields, true, Some(gap))?
        .ok_or_else(|| DataError::format(Location::file(folder.join(name)), "has no data rows"))
}

/// Reads a RIDI raw recorder folder into a sequence named after the folder, with the game
/// rotation vector as orientation source. A folder lacking [`REQUIRED`] files is an error naming
/// every one it lacks.
pub fn read(folder: impl AsRef<Path>, opts: &ReadOptions) -> Result<Sequence> {
    let folder = folder.as_ref();
    check_required(folder)?;
    let gap = opts.validation.max_gap_s;
    let gyro = required(folder, "gyro.txt", XYZ, gap)?;
    let acce = required(folder, "acce.txt", XYZ, gap)?;
    let linacce = required(folder, "linacce.txt", XYZ, gap)?;
    let gravity = required(folder, "gravity.txt", XYZ, gap)?;
    let rv = required(folder, "orientation.txt", QUAT, gap)?;
    let magnet = read_records(folder, "magnet.txt", XYZ, false, Some(gap))?;
    let pose = read_records(folder, "pose.txt", POSE, false, None)?;
    let step = read_records(folder, "step.txt", STEP, false, None)?;
    // Each file on its own lines (`step.txt` is written only when a step is taken, and has
    // no unit to check).
    let checked = [
        (Some(&gyro), Some(Channel::Gyro)),
        (Some(&acce), Some(Channel::Acce)),
        (Some(&linacce), Some(Channel::Linacce)),
        (Some(&gravity), Some(Channel::Gravity)),
        (Some(&rv), None),
        (magnet.as_ref(), Some(Channel::Magnet)),
        (pose.as_ref(), Some(Channel::Position)),
    ];
    for (records, channel) in checked {
        if let Some(r) = records {
            r.check(&opts.validation, channel)?;
        }
    }

    let sensors: Vec<&Records> = [&gyro, &acce, &linacce, &gravity, &rv]
        .into_iter()
        .chain(magnet.as_ref())
        .collect();
    let start = sensors.iter().map(|r| r.span().0).fold(f64::MIN, f64::max);
    let end = sensors.iter().map(|r| r.span().1).fold(f64::MAX, f64::min);
    if start > end {
        return Err(DataError::format(
            Location::file(folder),
            "the sensor files do not overlap in time",
        ));
    }

    // Frame index -> (pose row, line) when the pose is the clock.
    let (time, pose_rows) = match &pose {
        Some(p) => pose_timeline(p, opts.pose_trim, start, end)?,
        None => (
            uniform_timeline(start, end, opts.rate_without_pose_hz),
            Vec::new(),
        ),
    };
    if time.is_empty() {
        return Err(DataError::format(
            Location::file(folder),
            format!(
                "no frame fits the common span of the sensors at {} Hz",
                opts.rate_without_pose_hz
            ),
        ));
    }

    let rv_rot = (0..rv.time.len())
        .map(|i| rv.rotation(i, 0))
        .collect::<Result<Vec<_>>>()?;
    let ground_truth = match &pose {
        Some(p) => Some(GroundTruth {
            position: pose_rows
                .iter()
                .map(|&i| p.vec3::<ridi_frames::World>(i))
                .collect::<Vec<WorldVec>>(),
            orientation: pose_rows
                .iter()
                .map(|&i| p.rotation(i, 3))
                .collect::<Result<_>>()?,
        }),
        None => None,
    };
    let lerp = |r: &Records| interpolate_vec3(&r.time, &r.vecs(), &time);
    let parts = SequenceParts {
        name: folder
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        placement: None,
        gyro: lerp(&gyro),
        acce: lerp(&acce),
        linacce: lerp(&linacce),
        gravity: lerp(&gravity),
        magnet: magnet.as_ref().map(lerp),
        orientation: interpolate_rot(&rv.time, &rv_rot, &time),
        orientation_source: Some(OrientationSource::GameRotationVector),
        ground_truth,
        steps: step
            .as_ref()
            .map(|s| interpolate_scalar(&s.time, &s.values, &time)),
        device: None,
        time,
    };
    Sequence::with_validation(parts, &opts.validation).map_err(|e| match (&e, stream_file(&e)) {
        (SequenceError::AcceScale { .. }, _) => acce.error(e),
        (SequenceError::LinacceScale { .. }, _) => linacce.error(e),
        (SequenceError::GyroScale { .. }, _) => gyro.error(e),
        // Interpolated onto the pose times: the file, but no line, is to blame.
        (_, Some(name)) => text::sequence_error(&folder.join(name), None, &RawFields, e),
        (_, None) => match &pose {
            Some(p) => {
                let lines: Vec<usize> = pose_rows.iter().map(|&i| p.lines[i]).collect();
                text::sequence_error(&p.path, Some(&lines), &RawFields, e)
            }
            None => text::sequence_error(folder, None, &RawFields, e),
        },
    })
}

/// The file of the sensor stream a validation failure is about, when it is about one (the
/// timeline and the ground truth are the pose file's).
fn stream_file(e: &SequenceError) -> Option<&'static str> {
    let field = match e {
        SequenceError::Gravity { .. } => "gravity",
        SequenceError::NonFinite { what, .. } | SequenceError::LengthMismatch { what, .. } => what,
        _ => return None,
    };
    match field {
        "gyro" => Some("gyro.txt"),
        "acce" => Some("acce.txt"),
        "linacce" => Some("linacce.txt"),
        "gravity" => Some("gravity.txt"),
        "magnet" => Some("magnet.txt"),
        "orientation" => Some("orientation.txt"),
        "steps" => Some("step.txt"),
        _ => None,
    }
}

/// The pose times kept after trimming `trim` records at each end and dropping those outside
/// `start..=end`, with their row indices.
fn pose_timeline(
    pose: &Records,
    trim: usize,
    start: f64,
    end: f64,
) -> Result<(Vec<f64>, Vec<usize>)> {
    let n = pose.time.len();
    if n <= trim.saturating_mul(2) {
        return Err(DataError::format(
            Location::file(&pose.path),
            format!(
                "{n} pose records (after removing repeated timestamps): dropping {trim} at each end leaves none"
            ),
        ));
    }
    let rows: Vec<usize> = (trim..n - trim)
        .filter(|&i| (start..=end).contains(&pose.time[i]))
        .collect();
    if rows.is_empty() {
        return Err(DataError::format(
            Location::file(&pose.path),
            "no kept pose record lies within the time span every sensor covers",
        ));
    }
    Ok((rows.iter().map(|&i| pose.time[i]).collect(), rows))
}
