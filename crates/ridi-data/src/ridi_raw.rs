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
use crate::stream::Lines;
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
    (GYRO.name, GYRO.fields),
    (ACCE.name, ACCE.fields),
    (LINACCE.name, LINACCE.fields),
    (GRAVITY.name, GRAVITY.fields),
    (MAGNET.name, MAGNET.fields),
    (ROTATION.name, ROTATION.fields),
    (POSE_FILE.name, POSE_FILE.fields),
    (STEP_FILE.name, STEP_FILE.fields),
];

/// The most values a record of any of the [`FILES`] has (the fields but `t`).
const WIDTH: usize = {
    let (mut width, mut i) = (0, 0);
    while i < FILES.len() {
        if FILES[i].1.len() - 1 > width {
            width = FILES[i].1.len() - 1;
        }
        i += 1;
    }
    width
};

/// How the reader takes one file of a folder.
struct Spec {
    name: &'static str,
    fields: &'static [&'static str],
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
    const fn sensor(name: &'static str, channel: Channel) -> Spec {
        Spec {
            name,
            fields: XYZ,
            gap: true,
            checked: true,
            channel: Some(channel),
            rotation_at: None,
        }
    }

    /// Whether the file is one of [`REQUIRED`].
    fn required(&self) -> bool {
        REQUIRED.contains(&self.name)
    }

    /// The longest gap the file's own clock may have under `limits`: none unless [`Spec::gap`].
    fn max_gap_s(&self, limits: &Validation) -> f64 {
        match self.gap {
            true => limits.max_gap_s,
            false => f64::INFINITY,
        }
    }
}

const GYRO: Spec = Spec::sensor("gyro.txt", Channel::Gyro);
const ACCE: Spec = Spec::sensor("acce.txt", Channel::Acce);
const LINACCE: Spec = Spec::sensor("linacce.txt", Channel::Linacce);
const GRAVITY: Spec = Spec::sensor("gravity.txt", Channel::Gravity);
const ROTATION: Spec = Spec {
    name: "orientation.txt",
    fields: QUAT,
    gap: true,
    checked: true,
    channel: None,
    rotation_at: Some(RV_AT),
};
const MAGNET: Spec = Spec::sensor("magnet.txt", Channel::Magnet);
const POSE_FILE: Spec = Spec {
    name: "pose.txt",
    fields: POSE,
    gap: false,
    checked: true,
    channel: Some(Channel::Position),
    rotation_at: Some(POSE_ROTATION_AT),
};
const STEP_FILE: Spec = Spec {
    name: "step.txt",
    fields: STEP,
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
    GYRO.name,
    ACCE.name,
    LINACCE.name,
    GRAVITY.name,
    ROTATION.name,
];

/// Whether `folder` holds any of the [`REQUIRED`] files: a RIDI raw folder, complete or not
/// (the reader names what is missing).
pub fn looks_like(folder: &Path) -> bool {
    REQUIRED.iter().any(|f| text::present(&folder.join(f)))
}

/// Fails naming every [`REQUIRED`] file `folder` lacks.
fn check_required(folder: &Path) -> Result<()> {
    let missing: Vec<&str> = REQUIRED
        .into_iter()
        .filter(|f| !text::present(&folder.join(f)))
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

/// One record of a file: its time (seconds), its values (the fields but `t`, then zeros) and
/// its line.
#[derive(Debug, Clone, Copy)]
struct Record {
    time: f64,
    values: [f64; WIDTH],
    line: usize,
}

impl Record {
    fn vec3<F: ridi_frames::Frame>(&self) -> Vec3<F> {
        Vec3::new(self.values[0], self.values[1], self.values[2])
    }

    fn first3(&self) -> [f64; 3] {
        [self.values[0], self.values[1], self.values[2]]
    }
}

/// Parses the non-blank `content` of `line`: `None` for a `#` line, else the record (its time
/// in seconds, its values `fields` but `t`).
fn parse_record(
    content: &str,
    path: &Path,
    line: usize,
    fields: &[&str],
) -> Result<Option<Record>> {
    if content.trim_start().starts_with('#') {
        return Ok(None);
    }
    let mut cells = content.split_ascii_whitespace();
    let t = text::number(
        cells.next().unwrap_or(""),
        path,
        line,
        "t",
        text::Nan::Reject,
    )?;
    let mut values = [0.0; WIDTH];
    let mut parsed = 0;
    for (&field, cell) in fields[1..].iter().zip(cells.by_ref()) {
        values[parsed] = text::number(cell, path, line, field, text::Nan::Reject)?;
        parsed += 1;
    }
    if parsed < fields.len() - 1 {
        return Err(DataError::format(
            Location::line(path, line).with_field(fields[parsed + 1]),
            format!(
                "{} fields, expected {} (`{}`; truncated line?)",
                parsed + 1,
                fields.len(),
                fields.join(" ")
            ),
        ));
    }
    Ok(Some(Record {
        // Division by the exact 1e9 rounds once; multiplying by the inexact 1e-9 would not,
        // and times would then differ from the same nanoseconds read from a processed file.
        time: t / 1e9,
        values,
        line,
    }))
}

/// Where a [`RecordReader`] takes the lines of a file from: the file in memory
/// ([`TextLines`]) or read as a stream ([`Lines`]).
trait LineSource {
    /// The next non-blank line and its number, without its line ending; the inner error is a
    /// line that is not UTF-8 text, after which the lines can be read on, the outer one a
    /// failed read.
    fn next_text(&mut self) -> Result<Option<(usize, Result<&str>)>>;

    /// Whether the file so far ends in a line break (trailing spaces, tabs and `\r` aside).
    fn ends_in_break(&self) -> bool;
}

impl LineSource for Lines {
    fn next_text(&mut self) -> Result<Option<(usize, Result<&str>)>> {
        Lines::next_text(self)
    }

    fn ends_in_break(&self) -> bool {
        self.ends_in_break
    }
}

/// The lines of a file's `text` in memory, as [`text::lines`] numbers them.
struct TextLines<'a, I> {
    text: &'a str,
    lines: I,
}

/// The lines of `text`.
fn text_lines(text: &str) -> TextLines<'_, impl Iterator<Item = (usize, &str)>> {
    TextLines {
        text,
        lines: text::lines(text),
    }
}

impl<'a, I: Iterator<Item = (usize, &'a str)>> LineSource for TextLines<'a, I> {
    fn next_text(&mut self) -> Result<Option<(usize, Result<&str>)>> {
        Ok(self.lines.next().map(|(line, content)| (line, Ok(content))))
    }

    fn ends_in_break(&self) -> bool {
        text::ends_in_break(self.text)
    }
}

/// The records of one file as the whole reader takes them, one at a time: `#` lines skipped,
/// a record with the time of the one before dropped, each step from the one before checked
/// (time order, and gaps as the file's [`Spec`] says). The whole reader's errors, in its
/// order: a failed read, a line that is not UTF-8 text, the first record that does not parse
/// (from [`next`](Self::next), which reads the rest of the file for what comes before it),
/// then a last record cut off and the first step refused (from [`finish`](Self::finish), at
/// the end of the file; [`step`](Self::step) is that step's error as soon as it is read).
struct RecordReader<S> {
    lines: S,
    path: PathBuf,
    fields: &'static [&'static str],
    max_gap_s: f64,
    /// Time and line of the previous record.
    previous: Option<(f64, usize)>,
    /// The line of the last record, unless a `#` line follows it.
    last_record: Option<usize>,
    /// The error of the first step refused.
    step: Option<DataError>,
    /// Records dropped in a row for the time of `previous`.
    repeats: usize,
}

/// Most records in a row a raw sensor file may repeat a timestamp with: a record repeated now
/// and then is dropped, but a clock that stopped leaves records whose times are unknown (20 in
/// a row moved a track by 0.7 m; 3 hours of them were 97 % of a file, dropped). Not for
/// `step.txt` and `pose.txt`, whose gaps are not judged on their own clocks either.
pub const MAX_REPEATED_TIMESTAMPS: usize = 10;

impl<S: LineSource> RecordReader<S> {
    /// The records of the file `spec` names, at `path`, from its `lines`, with gaps refused
    /// beyond `limits`.
    fn new(lines: S, path: &Path, spec: &Spec, limits: &Validation) -> Self {
        Self {
            lines,
            path: path.to_path_buf(),
            fields: spec.fields,
            max_gap_s: spec.max_gap_s(limits),
            previous: None,
            last_record: None,
            step: None,
            repeats: 0,
        }
    }

    /// The next record, `None` at the end of the file.
    fn next(&mut self) -> Result<Option<Record>> {
        while let Some((line, content)) = self.lines.next_text()? {
            let content = match content {
                Ok(content) => content,
                Err(e) => return Err(self.first_fault(e, false)),
            };
            let record = match parse_record(content, &self.path, line, self.fields) {
                Ok(Some(record)) => record,
                Ok(None) => {
                    self.last_record = None;
                    continue;
                }
                Err(e) => return Err(self.first_fault(e, true)),
            };
            self.last_record = Some(line);
            let next = (record.time, line);
            if let Some(previous) = self.previous {
                if previous.0 == record.time {
                    self.repeats += 1;
                    // Where gaps are judged (not step.txt, nor pose.txt, judged once trimmed).
                    let judged = self.max_gap_s.is_finite();
                    if judged && self.repeats == MAX_REPEATED_TIMESTAMPS + 1 && self.step.is_none()
                    {
                        self.step = Some(DataError::format(
                            Location::line(&self.path, line).with_field("t"),
                            format!(
                                "the timestamp of line {} repeated by more than \
                                 {MAX_REPEATED_TIMESTAMPS} records in a row: a clock that \
                                 stopped, whose records' times are unknown (fewer repeats are \
                                 dropped as duplicates)",
                                previous.1
                            ),
                        ));
                    }
                    continue;
                }
                self.repeats = 0;
                if self.step.is_none() {
                    let (path, gap) = (&self.path, self.max_gap_s);
                    self.step = text::check_step(previous, next, path, "t", (gap, false)).err();
                }
            }
            self.previous = Some(next);
            return Ok(Some(record));
        }
        Ok(None)
    }

    /// The error the whole reader gives a file whose first fault is `fault`: a failed read in
    /// the rest of the file comes first, and so, for a record that does not parse
    /// (`parse_error`), does a line that is not UTF-8 text.
    fn first_fault(&mut self, mut fault: DataError, mut parse_error: bool) -> DataError {
        loop {
            match self.lines.next_text() {
                Err(e) => return e,
                Ok(None) => return fault,
                Ok(Some((_, Err(e)))) if parse_error => {
                    fault = e;
                    parse_error = false;
                }
                Ok(Some(_)) => {}
            }
        }
    }

    /// At the end of the file: refuses a last record cut off, then the first step refused.
    fn finish(&mut self) -> Result<()> {
        if let Some(line) = self.last_record
            && !self.lines.ends_in_break()
        {
            return Err(text::cut_off(Location::line(&self.path, line), ""));
        }
        self.step.take().map_or(Ok(()), Err)
    }
}

/// Parses one raw file, the one `spec` names, at `path`, with gaps refused beyond `limits`.
fn parse_records(bytes: &[u8], path: &Path, spec: &Spec, limits: &Validation) -> Result<Records> {
    let mut rec = Records {
        path: path.to_path_buf(),
        fields: spec.fields,
        time: Vec::new(),
        values: Vec::new(),
        lines: Vec::new(),
    };
    let width = rec.width();
    let text = text::as_text(bytes, path)?;
    let mut records = RecordReader::new(text_lines(text), path, spec, limits);
    while let Some(r) = records.next()? {
        rec.time.push(r.time);
        rec.values.extend_from_slice(&r.values[..width]);
        rec.lines.push(r.line);
    }
    records.finish()?;
    Ok(rec)
}

/// Reads the file `spec` names in `folder`, refusing gaps beyond `limits` if it says so:
/// `Ok(None)` when it is optional and absent, or without rows ([`required`] refuses that).
fn read_records(folder: &Path, spec: &Spec, limits: &Validation) -> Result<Option<Records>> {
    let path = folder.join(spec.name);
    if !spec.required() && !text::present(&path) {
        return Ok(None);
    }
    let rec = parse_records(&text::read_file(&path)?, &path, spec, limits)?;
    Ok((!rec.time.is_empty()).then_some(rec))
}

/// The error for a required file without records.
fn no_rows(path: &Path) -> DataError {
    DataError::format(Location::file(path), "has no data rows")
}

/// Reads the [`REQUIRED`] file `spec` names in `folder`: one without rows is an error.
fn required(folder: &Path, spec: &Spec, limits: &Validation) -> Result<Records> {
    read_records(folder, spec, limits)?.ok_or_else(|| no_rows(&folder.join(spec.name)))
}

/// Reads a RIDI raw recorder folder into a sequence named after the folder, with the game
/// rotation vector as orientation source. A folder lacking [`REQUIRED`] files is an error naming
/// every one it lacks.
pub fn read(folder: impl AsRef<Path>, opts: &ReadOptions) -> Result<Sequence> {
    let folder = folder.as_ref();
    check_rate(folder, opts)?;
    check_required(folder)?;
    let limits = &opts.validation;
    let gyro = required(folder, &GYRO, limits)?;
    let acce = required(folder, &ACCE, limits)?;
    let linacce = required(folder, &LINACCE, limits)?;
    let gravity = required(folder, &GRAVITY, limits)?;
    let rv = required(folder, &ROTATION, limits)?;
    let magnet = read_records(folder, &MAGNET, limits)?;
    let pose = read_records(folder, &POSE_FILE, limits)?;
    let step = read_records(folder, &STEP_FILE, limits)?;
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
        SequenceError::GyroScale { .. }
        | SequenceError::GyroDirection { .. }
        | SequenceError::GyroAxis { .. } => "gyro",
        // The rotation vector against gravity: the rotation vector's file, whose component
        // order is the likelier mistake.
        SequenceError::OrientationGravity { .. } | SequenceError::OrientationStill { .. } => {
            "orientation"
        }
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

/// Refuses a `rate_without_pose_hz` the validation's time steps exclude, whether or not the
/// folder has a pose (an option is never passed over unsaid).
pub(crate) fn check_rate(folder: &Path, opts: &ReadOptions) -> Result<()> {
    let rate = opts.rate_without_pose_hz;
    opts.validation
        .check_output_rate(rate, folder, "rate_without_pose_hz")
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
