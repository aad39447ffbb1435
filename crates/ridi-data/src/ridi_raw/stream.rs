//! A raw folder read as a stream of rows ([`RowReader`](crate::RowReader)), in memory that
//! does not grow with the recording.
//!
//! [`Rows::open`] reads each file once, in the whole-folder reader's order, and makes the
//! checks [`read`](super::read) makes on it before it synchronizes anything, with the same
//! errors in the same order: a failed read first, then a line that is not UTF-8, then the
//! first record that does not parse, a last record cut off, the first time going back or gap;
//! then, once every file is read, each file's median time step and values, the sensors'
//! common span, the pose timeline and the rotations. What the whole reader judges on all of a
//! file's records (a median) is counted ([`MedianTest`]) and, only when out of range, named by
//! reading that file again. The pose records kept are a range of indices, found from the
//! first pass without holding them.
//!
//! [`Rows::next_row`] then reads the files side by side, each record once, and interpolates
//! each sensor at the next time of the timeline with the whole reader's arithmetic
//! ([`Interpolator`]): the rows are the frames of the sequence [`read`](super::read) builds,
//! bit for bit. The checks of that sequence are the [`RowReader`](crate::RowReader)'s, with
//! [`Rows::error`] naming the file as the whole reader does.

use std::path::{Path, PathBuf};

use ridi_frames::{DeviceVec, Frame, Vec3, WorldFromDevice};

use super::{
    ACCE, GRAVITY, GYRO, LINACCE, MAGNET, POSE_FILE, POSE_ROTATION_AT, ROTATION, RV_AT, RawFields,
    STEP_FILE, Spec, check_required, common_span, kept_poses, name_of, no_frame, no_rows,
    parse_record, rotation, synchronized_error,
};
use crate::error::{DataError, Location, Result};
use crate::options::ReadOptions;
use crate::resample::{Interpolator, lerp_scalar, lerp_vec3, slerp, uniform_len, uniform_time};
use crate::sequence::{check_step, norm};
use crate::stream::{Lines, MedianTest, Row, select};
use crate::{Channel, SequenceError, Validation, text};

/// The most values a record has (`pose.txt`: position and rotation).
const WIDTH: usize = 7;

/// One record of a file: its time (seconds), its values (the fields but `t`) and its line.
#[derive(Debug, Clone, Copy)]
struct Record {
    time: f64,
    values: [f64; WIDTH],
    line: usize,
}

impl Record {
    fn vec3<F: Frame>(&self) -> Vec3<F> {
        Vec3::new(self.values[0], self.values[1], self.values[2])
    }

    fn first3(&self) -> [f64; 3] {
        [self.values[0], self.values[1], self.values[2]]
    }
}

/// The records of one file, parsed as the whole reader parses them, repeated timestamps
/// dropped, time order and gaps checked: for a file that the first pass found sound.
struct RecordReader {
    lines: Lines,
    path: PathBuf,
    fields: &'static [&'static str],
    max_gap_s: f64,
    row: Vec<f64>,
    /// Time and line of the previous record.
    previous: Option<(f64, usize)>,
}

impl RecordReader {
    fn open(path: &Path, spec: &Spec, opts: &ReadOptions) -> Result<Self> {
        Ok(Self {
            lines: Lines::open(path)?,
            path: path.to_path_buf(),
            fields: spec.fields,
            max_gap_s: max_gap(spec, opts),
            row: Vec::with_capacity(WIDTH),
            previous: None,
        })
    }

    fn next_record(&mut self) -> Result<Option<Record>> {
        while let Some((line, content)) = self.lines.next()? {
            let Some(t) = parse_record(content, &self.path, line, self.fields, &mut self.row)?
            else {
                continue;
            };
            if let Some(p) = self.previous {
                if p.0 == t {
                    continue;
                }
                text::check_step(p, (t, line), &self.path, "t", self.max_gap_s)?;
            }
            self.previous = Some((t, line));
            let mut values = [0.0; WIDTH];
            values[..self.row.len()].copy_from_slice(&self.row);
            return Ok(Some(Record {
                time: t,
                values,
                line,
            }));
        }
        Ok(None)
    }

    /// The `k`-th smallest of `quantity` over the file's records (given the previous one),
    /// read again in a few passes ([`select`]).
    fn select(
        path: &Path,
        spec: &Spec,
        opts: &ReadOptions,
        k: usize,
        quantity: impl Fn(Option<&Record>, &Record) -> Option<f64>,
    ) -> Result<f64> {
        select(k, |f| {
            let mut records = Self::open(path, spec, opts)?;
            let mut previous = None;
            while let Some(r) = records.next_record()? {
                if let Some(v) = quantity(previous.as_ref(), &r) {
                    f(v);
                }
                previous = Some(r);
            }
            Ok(())
        })
    }
}

/// The gap a file's own clock may have.
fn max_gap(spec: &Spec, opts: &ReadOptions) -> f64 {
    match spec.gap {
        true => opts.validation.max_gap_s,
        false => f64::INFINITY,
    }
}

/// The records of a file as samples of an [`Interpolator`]: time and value.
struct Samples<T> {
    records: RecordReader,
    value: fn(&RecordReader, &Record) -> Result<T>,
}

impl<T> Iterator for Samples<T> {
    type Item = Result<(f64, T)>;

    fn next(&mut self) -> Option<Result<(f64, T)>> {
        match self.records.next_record() {
            Ok(Some(r)) => Some((self.value)(&self.records, &r).map(|v| (r.time, v))),
            Ok(None) => None,
            Err(e) => Some(Err(e)),
        }
    }
}

fn vec3_of(_: &RecordReader, r: &Record) -> Result<DeviceVec> {
    Ok(r.vec3())
}

fn rotation_of(records: &RecordReader, r: &Record) -> Result<WorldFromDevice> {
    rotation(&r.values, RV_AT, &records.path, r.line, records.fields)
}

fn scalar_of(_: &RecordReader, r: &Record) -> Result<f64> {
    Ok(r.values[0])
}

/// One sensor file interpolated onto the timeline.
type Sensor<T> = Interpolator<T, Samples<T>>;

/// What the first pass learns of one file: its span and what the whole reader checks on it.
struct Scan {
    path: PathBuf,
    spec: &'static Spec,
    records: usize,
    /// Times of the first and the last record.
    span: (f64, f64),
    /// Intervals below and above the validation's time step range.
    intervals: MedianTest,
    /// Magnitudes of the first three values above the gyro's median bound (`gyro.txt`).
    norms: MedianTest,
    /// The first record whose first three values are beyond the channel's bound.
    beyond: Option<DataError>,
    /// The first record that is no rotation (`orientation.txt`: any record; `pose.txt`: one
    /// from the trim on within the sensors' span), and its index.
    not_rotation: Option<(usize, DataError)>,
    /// `pose.txt`: the first record from the trim on that is not before the sensors' span,
    /// and the last record not after it (indices).
    kept: (Option<usize>, Option<usize>),
}

/// What the pose file's scan needs to know of the timeline: the records trimmed at each end
/// and the sensors' span.
#[derive(Debug, Clone, Copy)]
struct Keep {
    trim: usize,
    span: (f64, f64),
}

impl Scan {
    /// Reads the file `spec` names in `folder` once (see the module's documentation): `None`
    /// when it is optional and absent or without records.
    fn read(
        folder: &Path,
        spec: &'static Spec,
        opts: &ReadOptions,
        keep: Option<Keep>,
    ) -> Result<Option<Scan>> {
        let path = folder.join(spec.name);
        if !spec.required && !path.exists() {
            return Ok(None);
        }
        let limits = &opts.validation;
        let max_gap_s = max_gap(spec, opts);
        let mut lines = Lines::open(&path)?;
        let mut scan = Scan {
            path: path.clone(),
            spec,
            records: 0,
            span: (f64::NAN, f64::NAN),
            intervals: MedianTest::default(),
            norms: MedianTest::default(),
            beyond: None,
            not_rotation: None,
            kept: (None, None),
        };
        // The first error of each kind, reported in the whole reader's order.
        let (mut not_text, mut not_parsed, mut time) = (None, None, None);
        let mut row = Vec::with_capacity(WIDTH);
        // The line of the last record, unless a `#` line follows it.
        let mut last_record = None;
        let mut previous: Option<(f64, usize)> = None;
        while let Some((line, content)) = lines.next_text()? {
            let content = match content {
                Ok(c) if not_text.is_none() && not_parsed.is_none() => c,
                // Past a fault that comes first, only a failed read can still come before it.
                Ok(_) => continue,
                Err(e) => {
                    not_text.get_or_insert(e);
                    continue;
                }
            };
            let t = match parse_record(content, &path, line, spec.fields, &mut row) {
                Ok(Some(t)) => t,
                Ok(None) => {
                    last_record = None;
                    continue;
                }
                Err(e) => {
                    not_parsed = Some(e);
                    continue;
                }
            };
            last_record = Some(line);
            if previous.is_some_and(|p| p.0 == t) {
                continue;
            }
            if let Some(p) = previous {
                if time.is_none() {
                    time = text::check_step(p, (t, line), &path, "t", max_gap_s).err();
                }
                let dt = t - p.0;
                let (min, max) = limits.time_step_range;
                scan.intervals.push(dt < min, dt > max);
            }
            let mut record = Record {
                time: t,
                values: [0.0; WIDTH],
                line,
            };
            record.values[..row.len()].copy_from_slice(&row);
            scan.record(&record, limits, keep);
            previous = Some((t, line));
        }
        if let Some(e) = not_text.or(not_parsed) {
            return Err(e);
        }
        if let Some(line) = last_record
            && !lines.ends_in_break
        {
            return Err(text::cut_off(Location::line(&path, line), ""));
        }
        if let Some(e) = time {
            return Err(e);
        }
        match scan.records {
            0 if spec.required => Err(no_rows(&path)),
            0 => Ok(None),
            _ => Ok(Some(scan)),
        }
    }

    /// Counts `r`, the next record kept (the `self.records`-th).
    fn record(&mut self, r: &Record, limits: &Validation, keep: Option<Keep>) {
        let index = self.records;
        self.records += 1;
        if index == 0 {
            self.span.0 = r.time;
        }
        self.span.1 = r.time;
        if let Some(channel) = self.spec.channel {
            let v = r.first3();
            if channel == Channel::Gyro {
                self.norms.push(false, norm(v) > limits.max_median_gyro);
            }
            if self.beyond.is_none()
                && let Err(e) = limits.check_value(channel, index, v)
            {
                let line_of = |i: usize| (i == index).then_some(r.line);
                self.beyond = Some(text::sequence_error_at(&self.path, line_of, &RawFields, e));
            }
        }
        let (start, end) = keep.map_or((f64::MIN, f64::MAX), |k| k.span);
        let from_trim = keep.is_none_or(|k| index >= k.trim);
        if keep.is_some() {
            if from_trim && r.time >= start && self.kept.0.is_none() {
                self.kept.0 = Some(index);
            }
            if r.time <= end {
                self.kept.1 = Some(index);
            }
        }
        if let Some(at) = self.spec.rotation_at
            && self.not_rotation.is_none()
            && from_trim
            && (start..=end).contains(&r.time)
            && let Err(e) = rotation(&r.values, at, &self.path, r.line, self.spec.fields)
        {
            self.not_rotation = Some((index, e));
        }
    }

    /// The checks of the file's own lines (its median time step, its values as its channel),
    /// with the whole reader's errors.
    fn check(&mut self, opts: &ReadOptions) -> Result<()> {
        let limits = &opts.validation;
        if !self.spec.checked {
            return Ok(());
        }
        let whole = |e| text::sequence_error_at(&self.path, |_| None, &RawFields, e);
        let (min, max) = limits.time_step_range;
        if self.intervals.median_low() || self.intervals.median_high() {
            let interval = |p: Option<&Record>, r: &Record| p.map(|p| r.time - p.time);
            let k = self.intervals.len() / 2;
            let median = RecordReader::select(&self.path, self.spec, opts, k, interval)?;
            return Err(whole(SequenceError::TimeStep { median, min, max }));
        }
        if self.norms.median_high() {
            let magnitude = |_: Option<&Record>, r: &Record| Some(norm(r.first3()));
            let k = self.norms.len() / 2;
            let median = RecordReader::select(&self.path, self.spec, opts, k, magnitude)?;
            let max = limits.max_median_gyro;
            return Err(whole(SequenceError::GyroUnits { median, max }));
        }
        match self.beyond.take() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// The file's sensor interpolated onto the timeline, its `value` read from each record.
    fn sensor<T: Clone>(
        &self,
        opts: &ReadOptions,
        value: fn(&RecordReader, &Record) -> Result<T>,
    ) -> Result<Sensor<T>> {
        let records = RecordReader::open(&self.path, self.spec, opts)?;
        let mut samples = Samples { records, value };
        let first = samples
            .next()
            .transpose()?
            .ok_or_else(|| changed(&self.path))?;
        Interpolator::new(first, samples, self.span.1)
    }
}

/// The error for a file whose records are not those the first pass read.
fn changed(path: &Path) -> DataError {
    DataError::format(
        Location::file(path),
        "changed while being read: its records are not those read before",
    )
}

/// The frames' times: the kept pose records, or a uniform timeline.
enum Timeline {
    Pose {
        records: RecordReader,
        /// The index of the next record, and the first and last kept.
        next: usize,
        kept: (usize, usize),
    },
    Uniform {
        start: f64,
        rate_hz: f64,
        frames: usize,
        next: usize,
    },
}

impl Timeline {
    /// The next frame's time and pose record.
    fn next_frame(&mut self) -> Result<Option<(f64, Option<Record>)>> {
        match self {
            Timeline::Pose {
                records,
                next,
                kept,
            } => {
                while *next <= kept.1 {
                    let Some(r) = records.next_record()? else {
                        return Err(changed(&records.path));
                    };
                    *next += 1;
                    if *next > kept.0 {
                        return Ok(Some((r.time, Some(r))));
                    }
                }
                Ok(None)
            }
            Timeline::Uniform {
                start,
                rate_hz,
                frames,
                next,
            } => {
                if *next == *frames {
                    return Ok(None);
                }
                let t = uniform_time(*start, *rate_hz, *next);
                *next += 1;
                Ok(Some((t, None)))
            }
        }
    }
}

/// A raw folder's rows, made as they are asked for.
pub(crate) struct Rows {
    folder: PathBuf,
    /// `pose.txt`, when it is the clock.
    pose: Option<PathBuf>,
    max_gap_s: f64,
    timeline: Timeline,
    gyro: Sensor<DeviceVec>,
    acce: Sensor<DeviceVec>,
    linacce: Sensor<DeviceVec>,
    gravity: Sensor<DeviceVec>,
    magnet: Option<Sensor<DeviceVec>>,
    orientation: Sensor<WorldFromDevice>,
    steps: Option<Sensor<f64>>,
    /// Frames made, and the time of the last.
    frames: usize,
    previous: Option<f64>,
}

impl Rows {
    /// Reads every file of `folder` once for its checks and the timeline (see the module's
    /// documentation), and opens them for the rows.
    ///
    /// # Errors
    /// What [`read`](super::read) refuses before it builds the sequence, with its error.
    pub(crate) fn open(folder: &Path, opts: &ReadOptions) -> Result<Rows> {
        check_required(folder)?;
        let required = |spec: &'static Spec| {
            Scan::read(folder, spec, opts, None)?.ok_or_else(|| no_rows(&folder.join(spec.name)))
        };
        let mut gyro = required(&GYRO)?;
        let mut acce = required(&ACCE)?;
        let mut linacce = required(&LINACCE)?;
        let mut gravity = required(&GRAVITY)?;
        let mut rv = required(&ROTATION)?;
        let mut magnet = Scan::read(folder, &MAGNET, opts, None)?;
        // The pose file's kept records depend on the span of the sensors, read by now; if
        // they do not overlap, that error comes before any the span could change.
        let spans = [&gyro, &acce, &linacce, &gravity, &rv]
            .into_iter()
            .chain(magnet.as_ref())
            .map(|s| s.span);
        let span = common_span(folder, spans);
        let keep = span.as_ref().ok().map(|&span| Keep {
            trim: opts.pose_trim,
            span,
        });
        let mut pose = Scan::read(folder, &POSE_FILE, opts, keep)?;
        let mut step = Scan::read(folder, &STEP_FILE, opts, None)?;
        for scan in [&mut gyro, &mut acce, &mut linacce, &mut gravity, &mut rv]
            .into_iter()
            .chain(magnet.as_mut())
            .chain(pose.as_mut())
            .chain(step.as_mut())
        {
            scan.check(opts)?;
        }
        let (start, end) = span?;
        let timeline = match &pose {
            Some(p) => {
                let (first, last) =
                    kept_poses(&p.path, p.records, opts.pose_trim, p.kept.0, p.kept.1)?;
                Timeline::Pose {
                    records: RecordReader::open(&p.path, p.spec, opts)?,
                    next: 0,
                    kept: (first, last),
                }
            }
            None => {
                let rate_hz = opts.rate_without_pose_hz;
                let frames = uniform_len(start, end, rate_hz);
                if frames == 0 {
                    return Err(no_frame(folder, opts));
                }
                Timeline::Uniform {
                    start,
                    rate_hz,
                    frames,
                    next: 0,
                }
            }
        };
        if let Some((_, e)) = rv.not_rotation.take() {
            return Err(e);
        }
        if let (Some(p), Timeline::Pose { kept, .. }) = (&mut pose, &timeline)
            && let Some((index, e)) = p.not_rotation.take()
            && index <= kept.1
        {
            return Err(e);
        }
        Ok(Rows {
            folder: folder.to_path_buf(),
            pose: pose.map(|p| p.path),
            max_gap_s: opts.validation.max_gap_s,
            timeline,
            gyro: gyro.sensor(opts, vec3_of)?,
            acce: acce.sensor(opts, vec3_of)?,
            linacce: linacce.sensor(opts, vec3_of)?,
            gravity: gravity.sensor(opts, vec3_of)?,
            magnet: magnet.map(|m| m.sensor(opts, vec3_of)).transpose()?,
            orientation: rv.sensor(opts, rotation_of)?,
            steps: step.map(|s| s.sensor(opts, scalar_of)).transpose()?,
            frames: 0,
            previous: None,
        })
    }

    /// The sequence's name, as the whole reader names it.
    pub(crate) fn name(&self) -> String {
        name_of(&self.folder)
    }

    /// Whether the rows have a magnetometer reading (`magnet.txt` has records).
    pub(crate) fn has_magnet(&self) -> bool {
        self.magnet.is_some()
    }

    /// Whether the rows have a step count (`step.txt` has records).
    pub(crate) fn has_steps(&self) -> bool {
        self.steps.is_some()
    }

    /// Whether the rows have ground truth (the pose is the clock).
    pub(crate) fn has_ground_truth(&self) -> bool {
        self.pose.is_some()
    }

    /// A validation failure of the sequence, naming the file as the whole reader does; a
    /// frame's line (of `pose.txt`) as `line_of` says.
    pub(crate) fn error(
        &self,
        e: SequenceError,
        line_of: impl Fn(usize) -> Option<usize>,
    ) -> DataError {
        synchronized_error(&self.folder, self.pose.as_deref(), line_of, e)
    }

    /// The next frame, with its line of `pose.txt` when the pose is the clock. A step of the
    /// timeline that the sequence refuses (a gap) is an error here, the first the sequence
    /// checks.
    pub(crate) fn next_row(&mut self) -> Result<Option<(Row, Option<usize>)>> {
        let Some((time, pose)) = self.timeline.next_frame()? else {
            return Ok(None);
        };
        let index = self.frames;
        let line = pose.map(|r| r.line);
        if let Some(previous) = self.previous
            && let Err(e) = check_step(index, previous, time, self.max_gap_s)
        {
            return Err(self.error(e, |i| line.filter(|_| i == index)));
        }
        let ground_truth = match (pose, &self.pose) {
            (Some(r), Some(path)) => {
                let at = POSE_ROTATION_AT;
                Some((
                    r.vec3(),
                    rotation(&r.values, at, path, r.line, POSE_FILE.fields)?,
                ))
            }
            _ => None,
        };
        let row = Row {
            time,
            gyro: self.gyro.at(time, lerp_vec3)?,
            acce: self.acce.at(time, lerp_vec3)?,
            linacce: self.linacce.at(time, lerp_vec3)?,
            gravity: self.gravity.at(time, lerp_vec3)?,
            magnet: self
                .magnet
                .as_mut()
                .map(|m| m.at(time, lerp_vec3))
                .transpose()?,
            orientation: self.orientation.at(time, slerp)?,
            ground_truth,
            steps: self
                .steps
                .as_mut()
                .map(|s| s.at(time, lerp_scalar))
                .transpose()?,
        };
        self.frames += 1;
        self.previous = Some(time);
        Ok(Some((row, line)))
    }
}
