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
//!
//! [`RowReader`](crate::RowReader) reads a folder as a stream of the rows [`read`] gives, in
//! memory that does not grow with the recording, with the same errors: one pass over each
//! file for its checks, then one over all of them side by side.

pub(crate) mod stream;

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
/// Where the rotation `x y z w` starts in a record of `orientation.txt` and of `pose.txt`.
const RV_AT: usize = 0;
const POSE_ROTATION_AT: usize = 3;

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

/// How the reader takes one file of a folder.
struct Spec {
    name: &'static str,
    fields: &'static [&'static str],
    /// One of [`REQUIRED`].
    required: bool,
    /// Whether a gap longer than the validation's `max_gap_s` on the file's own clock is
    /// refused: in every file but `step.txt` (written only when a step is taken) and
    /// `pose.txt` (checked after trimming, on the sequence itself).
    gap: bool,
    /// Whether the file's own lines are checked (its median time step, and its first three
    /// values as `channel`): every file but `step.txt`, which has no unit to check.
    checked: bool,
    channel: Option<Channel>,
    /// Where a record's rotation `x y z w` starts among its values, if it has one.
    rotation_at: Option<usize>,
}

impl Spec {
    const fn sensor(name: &'static str, required: bool, channel: Channel) -> Spec {
        Spec {
            name,
            fields: XYZ,
            required,
            gap: true,
            checked: true,
            channel: Some(channel),
            rotation_at: None,
        }
    }
}

const GYRO: Spec = Spec::sensor("gyro.txt", true, Channel::Gyro);
const ACCE: Spec = Spec::sensor("acce.txt", true, Channel::Acce);
const LINACCE: Spec = Spec::sensor("linacce.txt", true, Channel::Linacce);
const GRAVITY: Spec = Spec::sensor("gravity.txt", true, Channel::Gravity);
const ROTATION: Spec = Spec {
    name: "orientation.txt",
    fields: QUAT,
    required: true,
    gap: true,
    checked: true,
    channel: None,
    rotation_at: Some(RV_AT),
};
const MAGNET: Spec = Spec::sensor("magnet.txt", false, Channel::Magnet);
const POSE_FILE: Spec = Spec {
    name: "pose.txt",
    fields: POSE,
    required: false,
    gap: false,
    checked: true,
    channel: Some(Channel::Position),
    rotation_at: Some(POSE_ROTATION_AT),
};
const STEP_FILE: Spec = Spec {
    name: "step.txt",
    fields: STEP,
    required: false,
    gap: false,
    checked: false,
    channel: None,
    rotation_at: None,
};

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
        rotation(self.row(i), offset, &self.path, self.lines[i], self.fields)
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
}

/// The rotation `x y z w` at `offset` in the `values` of a record of `path`, on `line`.
fn rotation(
    values: &[f64],
    offset: usize,
    path: &Path,
    line: usize,
    fields: &[&str],
) -> Result<WorldFromDevice> {
    let r = &values[offset..offset + 4];
    WorldFromDevice::from_xyzw([r[0], r[1], r[2], r[3]]).map_err(|e| {
        DataError::format(
            Location::line(path, line).with_field(format!(
                "{}..{}",
                fields[offset + 1],
                fields[offset + 4]
            )),
            format!("not a rotation: {e}"),
        )
    })
}

/// Parses the non-blank `content` of `line`: `None` for a `#` line, else the record's time in
/// seconds, its values (`fields` but `t`) put into `row`.
fn parse_record(
    content: &str,
    path: &Path,
    line: usize,
    fields: &[&str],
    row: &mut Vec<f64>,
) -> Result<Option<f64>> {
    if content.trim_start().starts_with('#') {
        return Ok(None);
    }
    let width = fields.len() - 1;
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
    Ok(Some(t / 1e9))
}

/// Parses one raw file. Records with a timestamp equal to the previous one are dropped.
fn parse_records(
    bytes: &[u8],
    path: &Path,
    fields: &'static [&'static str],
    max_gap_s: Option<f64>,
) -> Result<Records> {
    let mut rec = Records {
        path: path.to_path_buf(),
        fields,
        time: Vec::new(),
        values: Vec::new(),
        lines: Vec::new(),
    };
    let mut row = Vec::with_capacity(fields.len() - 1);
    // The line of the last record, unless a `#` line follows it.
    let mut last_record = None;
    let text = text::as_text(bytes, path)?;
    for (line, content) in text::lines(text) {
        let Some(t) = parse_record(content, path, line, fields, &mut row)? else {
            last_record = None;
            continue;
        };
        last_record = Some(line);
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

/// Reads the file `spec` names in `folder`, refusing gaps longer than `max_gap_s` if it says
/// so: `Ok(None)` when it is optional and absent or without rows.
fn read_records(folder: &Path, spec: &Spec, max_gap_s: f64) -> Result<Option<Records>> {
    let path = folder.join(spec.name);
    if !spec.required && !path.exists() {
        return Ok(None);
    }
    let gap = spec.gap.then_some(max_gap_s);
    let rec = parse_records(&text::read_file(&path)?, &path, spec.fields, gap)?;
    if rec.time.is_empty() {
        if spec.required {
            return Err(no_rows(&path));
        }
        return Ok(None);
    }
    Ok(Some(rec))
}

/// The error for a required file without records.
fn no_rows(path: &Path) -> DataError {
    DataError::format(Location::file(path), "has no data rows")
}

fn required(folder: &Path, spec: &Spec, max_gap_s: f64) -> Result<Records> {
    read_records(folder, spec, max_gap_s)?.ok_or_else(|| no_rows(&folder.join(spec.name)))
}

/// Reads a RIDI raw recorder folder into a sequence named after the folder, with the game
/// rotation vector as orientation source. A folder lacking [`REQUIRED`] files is an error naming
/// every one it lacks.
pub fn read(folder: impl AsRef<Path>, opts: &ReadOptions) -> Result<Sequence> {
    let folder = folder.as_ref();
    check_required(folder)?;
    let gap = opts.validation.max_gap_s;
    let gyro = required(folder, &GYRO, gap)?;
    let acce = required(folder, &ACCE, gap)?;
    let linacce = required(folder, &LINACCE, gap)?;
    let gravity = required(folder, &GRAVITY, gap)?;
    let rv = required(folder, &ROTATION, gap)?;
    let magnet = read_records(folder, &MAGNET, gap)?;
    let pose = read_records(folder, &POSE_FILE, gap)?;
    let step = read_records(folder, &STEP_FILE, gap)?;
    // Each file on its own lines, in the order read.
    let checked = [
        (Some(&gyro), &GYRO),
        (Some(&acce), &ACCE),
        (Some(&linacce), &LINACCE),
        (Some(&gravity), &GRAVITY),
        (Some(&rv), &ROTATION),
        (magnet.as_ref(), &MAGNET),
        (pose.as_ref(), &POSE_FILE),
        (step.as_ref(), &STEP_FILE),
    ];
    for (records, spec) in checked {
        if let Some(r) = records.filter(|_| spec.checked) {
            r.check(&opts.validation, spec.channel)?;
        }
    }

    let sensors = [&gyro, &acce, &linacce, &gravity, &rv]
        .into_iter()
        .chain(magnet.as_ref());
    let (start, end) = common_span(folder, sensors.map(Records::span))?;

    // Frame index -> (pose row, line) when the pose is the clock.
    let (time, pose_rows) = match &pose {
        Some(p) => pose_timeline(p, opts.pose_trim, start, end)?,
        None => (
            uniform_timeline(start, end, opts.rate_without_pose_hz),
            Vec::new(),
        ),
    };
    if time.is_empty() {
        return Err(no_frame(folder, opts));
    }

    let rv_rot = (0..rv.time.len())
        .map(|i| rv.rotation(i, RV_AT))
        .collect::<Result<Vec<_>>>()?;
    let ground_truth = match &pose {
        Some(p) => Some(GroundTruth {
            position: pose_rows
                .iter()
                .map(|&i| p.vec3::<ridi_frames::World>(i))
                .collect::<Vec<WorldVec>>(),
            orientation: pose_rows
                .iter()
                .map(|&i| p.rotation(i, POSE_ROTATION_AT))
                .collect::<Result<_>>()?,
        }),
        None => None,
    };
    let lerp = |r: &Records| interpolate_vec3(&r.time, &r.vecs(), &time);
    let parts = SequenceParts {
        name: name_of(folder),
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
    Sequence::with_validation(parts, &opts.validation).map_err(|e| match &pose {
        Some(p) => {
            let line_of = |i: usize| pose_rows.get(i).map(|&r| p.lines[r]);
            synchronized_error(folder, Some(&p.path), line_of, e)
        }
        None => synchronized_error(folder, None, |_| None, e),
    })
}

/// The sequence's name: the folder's.
fn name_of(folder: &Path) -> String {
    folder
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// A validation failure of the sequence synchronized from the raw `folder`, naming the file of
/// the stream it is about ([`stream_file`]); else the pose file (`pose`, the timeline and the
/// ground truth), at the line `line_of` gives a frame, or without one the folder.
fn synchronized_error(
    folder: &Path,
    pose: Option<&Path>,
    line_of: impl Fn(usize) -> Option<usize>,
    e: SequenceError,
) -> DataError {
    match (stream_file(&e), pose) {
        // Interpolated onto the pose times: the file, but no line, is to blame.
        (Some(name), _) => text::sequence_error(&folder.join(name), None, &RawFields, e),
        (None, Some(pose)) => text::sequence_error_at(pose, line_of, &RawFields, e),
        (None, None) => text::sequence_error(folder, None, &RawFields, e),
    }
}

/// The file of the sensor stream a validation failure is about, when it is about one (the
/// timeline and the ground truth are the pose file's).
fn stream_file(e: &SequenceError) -> Option<&'static str> {
    let field = match e {
        SequenceError::Gravity { .. } => "gravity",
        SequenceError::AcceScale { .. } => "acce",
        SequenceError::LinacceScale { .. } => "linacce",
        SequenceError::GyroScale { .. } => "gyro",
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

/// The span every sensor covers, from the `spans` of their files (first and last time).
fn common_span(folder: &Path, spans: impl Iterator<Item = (f64, f64)>) -> Result<(f64, f64)> {
    let (start, end) = spans.fold((f64::MIN, f64::MAX), |(s, e), (a, b)| (s.max(a), e.min(b)));
    if start > end {
        return Err(DataError::format(
            Location::file(folder),
            "the sensor files do not overlap in time",
        ));
    }
    Ok((start, end))
}

/// The error for a uniform timeline without a frame.
fn no_frame(folder: &Path, opts: &ReadOptions) -> DataError {
    DataError::format(
        Location::file(folder),
        format!(
            "no frame fits the common span of the sensors at {} Hz",
            opts.rate_without_pose_hz
        ),
    )
}

/// The pose times kept after trimming `trim` records at each end and dropping those outside
/// `start..=end`, with their row indices.
fn pose_timeline(
    pose: &Records,
    trim: usize,
    start: f64,
    end: f64,
) -> Result<(Vec<f64>, Vec<usize>)> {
    let time = &pose.time;
    let first = Some(trim.max(time.partition_point(|&t| t < start)));
    let last = time.partition_point(|&t| t <= end).checked_sub(1);
    let (first, last) = kept_poses(&pose.path, time.len(), trim, first, last)?;
    Ok((time[first..=last].to_vec(), (first..=last).collect()))
}

/// The first and last pose record kept of the `n` in `path` (in time order) after trimming
/// `trim` at each end and dropping those outside the sensors' span, from `first`, the first
/// record from `trim` on that is not before the span, and `last`, the last not after it.
fn kept_poses(
    path: &Path,
    n: usize,
    trim: usize,
    first: Option<usize>,
    last: Option<usize>,
) -> Result<(usize, usize)> {
    if n <= trim.saturating_mul(2) {
        return Err(DataError::format(
            Location::file(path),
            format!(
                "{n} pose records (after removing repeated timestamps): dropping {trim} at each end leaves none"
            ),
        ));
    }
    match (first, last.map(|l| l.min(n - trim - 1))) {
        (Some(first), Some(last)) if first <= last => Ok((first, last)),
        _ => Err(DataError::format(
            Location::file(path),
            "no kept pose record lies within the time span every sensor covers",
        )),
    }
}
