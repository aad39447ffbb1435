//! A raw folder read as a stream of rows ([`RowReader`](crate::RowReader)), in memory that
//! does not grow with the recording.
//!
//! [`Rows::open`] reads each file once, in the whole-folder reader's order, and makes the
//! checks [`read`](super::read) makes on it before it synchronizes anything, with the same
//! errors in the same order (the whole reader's [`RecordReader`] reads the records of both):
//! a failed read first, then a line that is not UTF-8, then the first record that does not
//! parse, a last record cut off, the first time going back or gap; then, once every file is
//! read, each file's median time step and values, the sensors'
//! common span, the pose timeline and the rotations. What the whole reader judges on all of a
//! file's records (a median) is counted ([`MedianTest`]) and, only when out of range, named by
//! reading that file again. The pose records kept are a range of indices, found from the
//! first pass without holding them.
//!
//! [`Rows::next_row`] then reads the files side by side, each record once, and interpolates
//! each sensor at the next time of the timeline with the whole reader's arithmetic
//! ([`Interpolator`]): the rows are the frames of the sequence [`read`](super::read) builds,
//! bit for bit. The checks of that sequence are the [`RowReader`](crate::RowReader)'s, with
//! [`Rows::error`] naming the file as the whole reader does. Every file is read to its end,
//! what the frames did not reach after the last: one that changed since the first pass is
//! refused as changed ([`Reread`]) when it has more records than that pass counted or fewer,
//! or its last is not at the time that pass read, on the record that says so (a step it now
//! refuses is that step's error).

use std::path::{Path, PathBuf};

use ridi_frames::{DeviceVec, WorldFromDevice};

use super::{
    ACCE, GRAVITY, GYRO, LINACCE, MAGNET, POSE_FILE, POSE_ROTATION_AT, ROTATION, RV_AT, RawFields,
    Record, RecordReader, STEP_FILE, Spec, check_required, common_span, kept_poses, name_of,
    no_frame, no_rows, rotation, synchronized_error,
};
use crate::error::{DataError, Location, Result};
use crate::options::ReadOptions;
use crate::resample::{Interpolator, lerp_scalar, lerp_vec3, slerp, uniform_len, uniform_time};
use crate::sequence::{check_frame_step, norm};
use crate::stream::{Lines, MedianTest, Row, select};
use crate::{Channel, SequenceError, Validation, text};

/// A file as the first pass found it: what the second must find again.
#[derive(Clone)]
struct Found {
    path: PathBuf,
    spec: &'static Spec,
    /// Records kept (repeated timestamps dropped).
    records: usize,
    /// Times of the first and the last record.
    span: (f64, f64),
}

/// A file read again after the first pass found it sound, its records checked against what
/// that pass found: refused as changed ([`changed`]) at a record beyond those it counted, at
/// a last record not at the time it read, and at an end before it; a step refused is refused
/// as soon as it is read.
struct Reread {
    records: RecordReader<Lines>,
    /// Records the first pass found, and the time of the last.
    expected: (usize, f64),
    /// Records read so far.
    read: usize,
}

impl Reread {
    fn open(found: &Found, opts: &ReadOptions) -> Result<Self> {
        let lines = Lines::open(&found.path)?;
        Ok(Self {
            records: RecordReader::new(lines, &found.path, found.spec, &opts.validation),
            expected: (found.records, found.span.1),
            read: 0,
        })
    }

    fn path(&self) -> &Path {
        &self.records.path
    }

    /// The next record, `None` at the end of the file.
    fn next(&mut self) -> Result<Option<Record>> {
        let (records, last_time) = self.expected;
        let Some(r) = self.records.next()? else {
            if self.read < records {
                return Err(changed(self.path(), None));
            }
            self.records.finish()?;
            return Ok(None);
        };
        self.read += 1;
        if self.read > records || (self.read == records && r.time != last_time) {
            return Err(changed(self.path(), Some(r.line)));
        }
        match self.records.step.take() {
            Some(e) => Err(e),
            None => Ok(Some(r)),
        }
    }

    /// The `k`-th smallest of `quantity` over the records of the file `found`, given the
    /// previous one, read again in a few passes ([`select`]).
    fn select(
        found: &Found,
        opts: &ReadOptions,
        k: usize,
        quantity: impl Fn(Option<&Record>, &Record) -> Option<f64>,
    ) -> Result<f64> {
        select(k, |f| {
            let mut records = Self::open(found, opts)?;
            let mut previous = None;
            while let Some(r) = records.next()? {
                if let Some(v) = quantity(previous.as_ref(), &r) {
                    f(v);
                }
                previous = Some(r);
            }
            Ok(())
        })
    }
}

/// The error for a file whose records are not those the first pass read, at `line` when a
/// record there says so.
fn changed(path: &Path, line: Option<usize>) -> DataError {
    let at = match line {
        Some(line) => Location::line(path, line),
        None => Location::file(path),
    };
    DataError::format(
        at,
        "changed while being read: its records are not those read before",
    )
}

/// The records of a file as samples of an [`Interpolator`]: time and value.
struct Samples<T> {
    records: Reread,
    value: fn(&Reread, &Record) -> Result<T>,
}

impl<T> Iterator for Samples<T> {
    type Item = Result<(f64, T)>;

    fn next(&mut self) -> Option<Result<(f64, T)>> {
        match self.records.next() {
            Ok(Some(r)) => Some((self.value)(&self.records, &r).map(|v| (r.time, v))),
            Ok(None) => None,
            Err(e) => Some(Err(e)),
        }
    }
}

fn vec3_of(_: &Reread, r: &Record) -> Result<DeviceVec> {
    Ok(r.vec3())
}

fn rotation_of(records: &Reread, r: &Record) -> Result<WorldFromDevice> {
    let (path, fields) = (records.path(), records.records.fields);
    rotation(&r.values, RV_AT, path, r.line, fields)
}

fn scalar_of(_: &Reread, r: &Record) -> Result<f64> {
    Ok(r.values[0])
}

/// One sensor file interpolated onto the timeline.
type Sensor<T> = Interpolator<T, Samples<T>>;

/// The file `found` interpolated onto the timeline, its `value` read from each record.
fn sensor<T: Clone>(
    found: &Found,
    opts: &ReadOptions,
    value: fn(&Reread, &Record) -> Result<T>,
) -> Result<Sensor<T>> {
    let records = Reread::open(found, opts)?;
    let mut samples = Samples { records, value };
    let first = samples
        .next()
        .transpose()?
        .ok_or_else(|| changed(&found.path, None))?;
    Interpolator::new(first, samples, found.span.1)
}

/// What the first pass learns of one file: what the second must find again, and what the
/// whole reader checks on it.
struct Scan {
    found: Found,
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
    /// when it is optional and absent, or without records (which [`Rows::open`] refuses of a
    /// required one).
    fn read(
        folder: &Path,
        spec: &'static Spec,
        opts: &ReadOptions,
        keep: Option<Keep>,
    ) -> Result<Option<Scan>> {
        let path = folder.join(spec.name);
        if !spec.required() && !text::present(&path) {
            return Ok(None);
        }
        let limits = &opts.validation;
        let mut records = RecordReader::new(Lines::open(&path)?, &path, spec, limits);
        let mut scan = Scan {
            found: Found {
                path,
                spec,
                records: 0,
                span: (f64::NAN, f64::NAN),
            },
            intervals: MedianTest::default(),
            norms: MedianTest::default(),
            beyond: None,
            not_rotation: None,
            kept: (None, None),
        };
        while let Some(r) = records.next()? {
            scan.record(&r, limits, keep);
        }
        records.finish()?;
        Ok((scan.found.records > 0).then_some(scan))
    }

    /// Counts `r`, the next record (the `self.found.records`-th).
    fn record(&mut self, r: &Record, limits: &Validation, keep: Option<Keep>) {
        let found = &mut self.found;
        let index = found.records;
        found.records += 1;
        if index == 0 {
            found.span.0 = r.time;
        } else {
            let dt = r.time - found.span.1;
            let (min, max) = limits.time_step_range;
            self.intervals.push(dt < min, dt > max);
        }
        found.span.1 = r.time;
        let (path, spec) = (&found.path, found.spec);
        if let Some(channel) = spec.channel {
            let v = r.first3();
            if channel == Channel::Gyro {
                self.norms.push(false, norm(v) > limits.max_median_gyro);
            }
            if self.beyond.is_none()
                && let Err(e) = limits.check_value(channel, index, v)
            {
                let line_of = |i: usize| (i == index).then_some(r.line);
                self.beyond = Some(text::sequence_error_at(path, line_of, &RawFields, e));
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
        if let Some(at) = spec.rotation_at
            && self.not_rotation.is_none()
            && from_trim
            && (start..=end).contains(&r.time)
            && let Err(e) = rotation(&r.values, at, path, r.line, spec.fields)
        {
            self.not_rotation = Some((index, e));
        }
    }

    /// The checks of the file's own lines (its median time step, its values as its channel),
    /// with the whole reader's errors.
    fn check(&mut self, opts: &ReadOptions) -> Result<()> {
        let limits = &opts.validation;
        if !self.found.spec.checked {
            return Ok(());
        }
        let whole = |e| text::sequence_error_at(&self.found.path, |_| None, &RawFields, e);
        let (min, max) = limits.time_step_range;
        if self.intervals.median_low() || self.intervals.median_high() {
            let interval = |p: Option<&Record>, r: &Record| p.map(|p| r.time - p.time);
            let k = self.intervals.len() / 2;
            let median = Reread::select(&self.found, opts, k, interval)?;
            return Err(whole(SequenceError::TimeStep { median, min, max }));
        }
        if self.norms.median_high() {
            let magnitude = |_: Option<&Record>, r: &Record| Some(norm(r.first3()));
            let k = self.norms.len() / 2;
            let median = Reread::select(&self.found, opts, k, magnitude)?;
            let max = limits.max_median_gyro;
            return Err(whole(SequenceError::GyroUnits { median, max }));
        }
        match self.beyond.take() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

/// A uniform timeline: `frames` times from `start` on, at `rate_hz`.
#[derive(Debug, Clone, Copy)]
struct Uniform {
    start: f64,
    rate_hz: f64,
    frames: usize,
}

/// Where the frames' times come from, as the first pass found it.
#[derive(Clone)]
enum Clock {
    /// The records of `pose.txt` from index `kept.0` to `kept.1`.
    Pose {
        found: Found,
        kept: (usize, usize),
    },
    Uniform(Uniform),
}

/// The frames' times, as they come.
enum Timeline {
    Pose {
        /// Boxed: far larger than the other variant.
        records: Box<Reread>,
        /// The index of the next record, and the first and last kept.
        next: usize,
        kept: (usize, usize),
    },
    Uniform {
        times: Uniform,
        /// The index of the next time.
        next: usize,
    },
}

impl Timeline {
    fn open(clock: &Clock, opts: &ReadOptions) -> Result<Self> {
        Ok(match *clock {
            Clock::Pose { ref found, kept } => Timeline::Pose {
                records: Box::new(Reread::open(found, opts)?),
                next: 0,
                kept,
            },
            Clock::Uniform(times) => Timeline::Uniform { times, next: 0 },
        })
    }

    /// The next frame's time and pose record. After the last, `pose.txt` is read to its end.
    fn next_frame(&mut self) -> Result<Option<(f64, Option<Record>)>> {
        match self {
            Timeline::Pose {
                records,
                next,
                kept,
            } => {
                while let Some(r) = records.next()? {
                    let index = *next;
                    *next += 1;
                    if (kept.0..=kept.1).contains(&index) {
                        return Ok(Some((r.time, Some(r))));
                    }
                }
                Ok(None)
            }
            Timeline::Uniform { times, next } => {
                if *next == times.frames {
                    return Ok(None);
                }
                let t = uniform_time(times.start, times.rate_hz, *next);
                *next += 1;
                Ok(Some((t, None)))
            }
        }
    }
}

/// What the second pass reads, as the first found it: each file and the clock.
#[derive(Clone)]
struct Plan {
    folder: PathBuf,
    clock: Clock,
    gyro: Found,
    acce: Found,
    linacce: Found,
    gravity: Found,
    rotation: Found,
    magnet: Option<Found>,
    step: Option<Found>,
}

/// A raw folder's rows, made as they are asked for.
pub(crate) struct Rows {
    plan: Plan,
    max_gap_s: f64,
    timeline: Timeline,
    gyro: Sensor<DeviceVec>,
    acce: Sensor<DeviceVec>,
    linacce: Sensor<DeviceVec>,
    gravity: Sensor<DeviceVec>,
    magnet: Option<Sensor<DeviceVec>>,
    orientation: Sensor<WorldFromDevice>,
    steps: Option<Sensor<f64>>,
}

impl Rows {
    /// Reads every file of `folder` once for its checks and the timeline (see the module's
    /// documentation), and opens them for the rows.
    ///
    /// # Errors
    /// What [`read`](super::read) refuses before it builds the sequence, with its error.
    pub(crate) fn open(folder: &Path, opts: &ReadOptions) -> Result<Rows> {
        super::check_rate(folder, opts)?;
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
            .map(|s| s.found.span);
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
        let clock = match &pose {
            Some(p) => {
                let (found, trim) = (&p.found, opts.pose_trim);
                let kept = kept_poses(&found.path, found.records, trim, p.kept.0, p.kept.1)?;
                Clock::Pose {
                    found: found.clone(),
                    kept,
                }
            }
            None => {
                let rate_hz = opts.rate_without_pose_hz;
                let frames = uniform_len(start, end, rate_hz);
                if frames == 0 {
                    return Err(no_frame(folder, opts));
                }
                Clock::Uniform(Uniform {
                    start,
                    rate_hz,
                    frames,
                })
            }
        };
        if let Some((_, e)) = rv.not_rotation.take() {
            return Err(e);
        }
        if let (Some(p), Clock::Pose { kept, .. }) = (&mut pose, &clock)
            && let Some((index, e)) = p.not_rotation.take()
            && index <= kept.1
        {
            return Err(e);
        }
        let plan = Plan {
            folder: folder.to_path_buf(),
            clock,
            gyro: gyro.found,
            acce: acce.found,
            linacce: linacce.found,
            gravity: gravity.found,
            rotation: rv.found,
            magnet: magnet.map(|m| m.found),
            step: step.map(|s| s.found),
        };
        Self::read(plan, opts)
    }

    /// The rows of the files `plan` holds: each opened for the second pass.
    fn read(plan: Plan, opts: &ReadOptions) -> Result<Rows> {
        let vec3 = |found: &Found| sensor(found, opts, vec3_of);
        Ok(Rows {
            max_gap_s: opts.validation.max_gap_s,
            timeline: Timeline::open(&plan.clock, opts)?,
            gyro: vec3(&plan.gyro)?,
            acce: vec3(&plan.acce)?,
            linacce: vec3(&plan.linacce)?,
            gravity: vec3(&plan.gravity)?,
            magnet: plan.magnet.as_ref().map(vec3).transpose()?,
            orientation: sensor(&plan.rotation, opts, rotation_of)?,
            steps: (plan.step.as_ref())
                .map(|s| sensor(s, opts, scalar_of))
                .transpose()?,
            plan,
        })
    }

    /// The same rows again from the first, for another pass over them (a median to name):
    /// the files are opened for the second pass as the first pass found them, without that
    /// pass and its checks again; one changed since is refused as the second pass refuses it.
    pub(crate) fn again(&self, opts: &ReadOptions) -> Result<Rows> {
        Self::read(self.plan.clone(), opts)
    }

    /// The sequence's name, as the whole reader names it.
    pub(crate) fn name(&self) -> String {
        name_of(&self.plan.folder)
    }

    /// Whether the rows have a magnetometer reading (`magnet.txt` has records).
    pub(crate) fn has_magnet(&self) -> bool {
        self.magnet.is_some()
    }

    /// Whether the rows have a step count (`step.txt` has records).
    pub(crate) fn has_steps(&self) -> bool {
        self.steps.is_some()
    }

    /// `pose.txt`, when it is the clock.
    fn pose(&self) -> Option<&Path> {
        match &self.plan.clock {
            Clock::Pose { found, .. } => Some(&found.path),
            Clock::Uniform(_) => None,
        }
    }

    /// Whether the rows have ground truth (the pose is the clock).
    pub(crate) fn has_ground_truth(&self) -> bool {
        self.pose().is_some()
    }

    /// A validation failure of the sequence, naming the file as the whole reader does; a
    /// frame's line (of `pose.txt`) as `line_of` says.
    pub(crate) fn error(
        &self,
        e: SequenceError,
        line_of: impl Fn(usize) -> Option<usize>,
    ) -> DataError {
        synchronized_error(&self.plan.folder, self.pose(), line_of, e)
    }

    /// The next frame, the `index`-th, after `previous`; with its line of `pose.txt` when the
    /// pose is the clock. A step of the timeline that the sequence refuses (a gap) is an error
    /// here, the first the sequence checks. After the last frame, every file is read to its end
    /// ([`Reread`]).
    pub(crate) fn next_row(
        &mut self,
        index: usize,
        previous: Option<&Row>,
    ) -> Result<Option<(Row, Option<usize>)>> {
        let Some((time, pose)) = self.timeline.next_frame()? else {
            self.read_to_end()?;
            return Ok(None);
        };
        let line = pose.map(|r| r.line);
        if let Some(previous) = previous
            && let Err(e) = check_frame_step(index, previous.time, time, self.max_gap_s)
        {
            return Err(self.error(e, |i| line.filter(|_| i == index)));
        }
        let ground_truth = match (pose, self.pose()) {
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
        Ok(Some((row, line)))
    }

    /// Reads every sensor file to its end: one changed since the first pass is refused,
    /// whatever of it the frames reached.
    fn read_to_end(&mut self) -> Result<()> {
        self.gyro.read_to_end()?;
        self.acce.read_to_end()?;
        self.linacce.read_to_end()?;
        self.gravity.read_to_end()?;
        if let Some(magnet) = &mut self.magnet {
            magnet.read_to_end()?;
        }
        self.orientation.read_to_end()?;
        if let Some(steps) = &mut self.steps {
            steps.read_to_end()?;
        }
        Ok(())
    }
}
