//! The sequence model: one recording on one uniform timeline.

use std::fmt;
use std::ops::Range;

use ridi_frames::{
    DeviceVec, FilterConfig, Frame, HeadingConfig, ImuFrames, Rot, WorldFromDevice, WorldVec,
    estimate_orientation, gravity_and_linacce, with_reference_heading,
};
use serde::{Deserialize, Serialize};

use crate::device::DeviceInfo;
use crate::sequence_error::SequenceError;
use crate::validation::{OrientationJump, Validation, orientation_jumps};

/// Where the device orientation of a sequence comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OrientationSource {
    /// Android game rotation vector (gyro + accelerometer, no magnetometer): RIDI's `rv`.
    GameRotationVector,
    /// Android rotation vector (uses the magnetometer; heading is magnetic north).
    RotationVector,
    /// iOS Core Motion attitude (`CMAttitude`; the Tyrex iPhone runs' heading follows magnetic
    /// north), turned by the Tyrex authors' 90 degrees so that its world is east-north-up like
    /// the rotation vector's.
    CoreMotionAttitude,
    /// Estimated by ridi-frames from gyro and accelerometer.
    Estimated,
    /// Ground-truth orientation (Tango, motion capture) used as the device orientation.
    GroundTruth,
    /// The gyro integrated from a known start orientation (RoNIN's `gyro_integration`, which
    /// RoNIN picks when the game rotation vector's end error is 20 degrees or more and this
    /// one's is the smallest).
    GyroIntegration,
    /// An offline EKF estimate shipped with the data (RoNIN's `pose/ekf_ori`).
    Ekf,
}

impl OrientationSource {
    /// Every source, in declaration order.
    pub const ALL: [OrientationSource; 7] = [
        OrientationSource::GameRotationVector,
        OrientationSource::RotationVector,
        OrientationSource::CoreMotionAttitude,
        OrientationSource::Estimated,
        OrientationSource::GroundTruth,
        OrientationSource::GyroIntegration,
        OrientationSource::Ekf,
    ];

    /// The name in files (`game-rotation-vector`, ...; serde's name too).
    pub fn key(self) -> &'static str {
        match self {
            OrientationSource::GameRotationVector => "game-rotation-vector",
            OrientationSource::RotationVector => "rotation-vector",
            OrientationSource::CoreMotionAttitude => "core-motion-attitude",
            OrientationSource::Estimated => "estimated",
            OrientationSource::GroundTruth => "ground-truth",
            OrientationSource::GyroIntegration => "gyro-integration",
            OrientationSource::Ekf => "ekf",
        }
    }
}

impl fmt::Display for OrientationSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            OrientationSource::GameRotationVector => "game rotation vector",
            OrientationSource::RotationVector => "rotation vector",
            OrientationSource::CoreMotionAttitude => "Core Motion attitude",
            OrientationSource::Estimated => "estimated",
            OrientationSource::GroundTruth => "ground truth",
            OrientationSource::GyroIntegration => "gyro integration",
            OrientationSource::Ekf => "EKF",
        })
    }
}

/// Ground-truth pose per frame. Its world frame is the ground-truth system's (Tango start of
/// service, mocap room): z up like the device orientation's world, but with its own heading and
/// origin.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroundTruth {
    /// Device position, metres.
    pub position: Vec<WorldVec>,
    /// Device orientation, world-from-device.
    pub orientation: Vec<WorldFromDevice>,
}

impl GroundTruth {
    /// The horizontal path, `[x, y]` per frame: what trajectories are evaluated against.
    pub fn horizontal(&self) -> Vec<[f64; 2]> {
        self.position.iter().map(|p| [p.x(), p.y()]).collect()
    }
}

/// Everything a [`Sequence`] is made of, before validation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SequenceParts {
    /// Sequence name (usually the folder name).
    pub name: String,
    /// Placement label (e.g. `handheld`, `bag`), if known.
    pub placement: Option<String>,
    /// Timestamps, seconds, strictly increasing.
    pub time: Vec<f64>,
    /// Calibrated gyroscope, rad/s, device frame.
    pub gyro: Vec<DeviceVec>,
    /// Accelerometer including gravity, m/s^2, device frame.
    pub acce: Vec<DeviceVec>,
    /// Linear acceleration (accelerometer minus gravity), m/s^2, device frame.
    pub linacce: Vec<DeviceVec>,
    /// Gravity, pointing up (about +9.8 along the upward axis at rest), m/s^2, device frame.
    pub gravity: Vec<DeviceVec>,
    /// Magnetometer, microtesla, device frame, if recorded.
    pub magnet: Option<Vec<DeviceVec>>,
    /// Device orientation, world-from-device.
    pub orientation: Vec<WorldFromDevice>,
    /// Where `orientation` comes from.
    pub orientation_source: Option<OrientationSource>,
    /// Ground-truth pose, if any.
    pub ground_truth: Option<GroundTruth>,
    /// Step counter (steps since start), if recorded.
    pub steps: Option<Vec<f64>>,
    /// The phone it was recorded with, when the source says (Tyrex: `record.properties` or the
    /// run's name; Indoor Location Competition: the header; RIDI's processed files: the
    /// optional sidecar ridi-rs writes beside them, see [`sidecar_path`](crate::sidecar_path)).
    pub device: Option<DeviceInfo>,
}

impl SequenceParts {
    /// Replaces the orientation by a gyro + accelerometer estimate
    /// ([`ridi_frames::estimate_orientation`]), gravity by the estimate's (standard magnitude),
    /// linear acceleration by accelerometer minus that gravity, and the source by
    /// [`OrientationSource::Estimated`]: what
    /// [`Sequence::with_estimated_orientation`] does before any heading correction, for parts
    /// that have no orientation yet (a sequence built from gyro and accelerometer alone).
    ///
    /// # Errors
    /// The errors [`Sequence::new`] gives for an empty or non-finite time, time that does not
    /// increase, and a gyro or accelerometer of another length or with a non-finite value
    /// (checked first, so that they are named as a sequence's are); [`SequenceError::Estimate`]
    /// when the estimator refuses the input otherwise.
    pub fn estimate_orientation(&mut self, filter: &FilterConfig) -> Result<(), SequenceError> {
        let n = self.time.len();
        // Gaps are judged by the validation that follows, with its limits.
        check_time(&self.time, f64::INFINITY)?;
        check_vecs("gyro", n, &self.gyro)?;
        check_vecs("acce", n, &self.acce)?;
        let q =
            estimate_orientation(&self.time, &self.gyro, &self.acce, filter).map_err(|error| {
                SequenceError::Estimate {
                    what: "orientation estimate",
                    error,
                }
            })?;
        // From the estimate itself: a turn about the vertical changes neither, and so the
        // features are bit for bit those of training, which skips the heading.
        (self.gravity, self.linacce) = q
            .iter()
            .zip(&self.acce)
            .map(|(&q, &a)| gravity_and_linacce(q, a))
            .unzip();
        self.orientation = q;
        self.orientation_source = Some(OrientationSource::Estimated);
        Ok(())
    }
}

/// A channel of a sequence, as named in a [`SequenceError`] and given to the checks of
/// [`Validation`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Channel {
    /// Timestamps, seconds.
    Time,
    /// Gyroscope, rad/s.
    Gyro,
    /// Accelerometer with gravity, m/s^2.
    Acce,
    /// Linear acceleration, m/s^2.
    Linacce,
    /// Gravity, m/s^2.
    Gravity,
    /// Magnetometer, microtesla.
    Magnet,
    /// Ground-truth position, metres.
    Position,
}

impl Channel {
    /// The field name in a [`SequenceParts`] (`ground_truth.position` for the position).
    pub fn name(self) -> &'static str {
        match self {
            Channel::Time => "time",
            Channel::Gyro => "gyro",
            Channel::Acce => "acce",
            Channel::Linacce => "linacce",
            Channel::Gravity => "gravity",
            Channel::Magnet => "magnet",
            Channel::Position => "ground_truth.position",
        }
    }

    /// The unit of the channel in a sequence.
    pub fn unit(self) -> &'static str {
        match self {
            Channel::Time => "s",
            Channel::Gyro => "rad/s",
            Channel::Acce | Channel::Linacce | Channel::Gravity => "m/s^2",
            Channel::Magnet => "uT",
            Channel::Position => "m",
        }
    }

    /// What a value beyond [`Validation::limit`] is beyond, for messages.
    pub(crate) fn beyond(self) -> &'static str {
        match self {
            Channel::Time => "any timestamp",
            Channel::Gyro => "any phone gyroscope",
            Channel::Acce | Channel::Linacce => "any phone accelerometer",
            Channel::Gravity => "any gravity reading",
            Channel::Magnet => "any phone magnetometer",
            Channel::Position => "any plausible ground-truth position",
        }
    }
}

impl fmt::Display for Channel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Device vectors as arrays, for the checks.
fn arrays(v: &[DeviceVec]) -> impl ExactSizeIterator<Item = [f64; 3]> + Clone + '_ {
    v.iter().map(|x| x.to_array())
}

/// Mean magnitude of 3-vectors (NaN when empty).
fn mean_norm(values: impl ExactSizeIterator<Item = [f64; 3]>) -> f64 {
    let n = values.len();
    values.map(norm).sum::<f64>() / n as f64
}

/// Euclidean norm of a 3-vector.
pub(crate) fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// One recording: IMU channels, device orientation and optional ground truth on one timeline.
///
/// Built only through [`Sequence::new`] (or [`Sequence::with_validation`]), so every
/// `Sequence` has equal channel lengths, finite values, strictly increasing time without long
/// gaps, values within physical bounds and channels in plausible units (see [`Validation`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Sequence {
    parts: SequenceParts,
}

fn check_len(field: &'static str, expected: usize, found: usize) -> Result<(), SequenceError> {
    if expected == found {
        Ok(())
    } else {
        Err(SequenceError::LengthMismatch {
            what: field,
            expected,
            found,
        })
    }
}

/// A sequence cut at its gaps ([`Sequence::split_at_gaps`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SplitParts {
    /// The parts kept, in order.
    pub parts: Vec<Sequence>,
    /// The (first, last) frame times of each part dropped as too short, in order.
    pub dropped: Vec<(f64, f64)>,
}

/// The name of part `index` (from 0) of the `parts` a recording named `name` is split into:
/// `name` itself when it is the only one, else `<name>_part1`, `<name>_part2`, ... (the
/// Tyrex reader at a motion-capture loss, [`Sequence::split_at_gaps`] at a gap).
pub fn part_name(name: &str, index: usize, parts: usize) -> String {
    if parts == 1 {
        name.to_owned()
    } else {
        format!("{name}_part{}", index.saturating_add(1))
    }
}

/// Whether an orientation from `source` may correct an estimate's heading
/// ([`Sequence::with_estimated_orientation`]): one a phone recorded, not an estimate, and not
/// the ground truth (which would hand tracking the answer it is judged by).
pub fn heading_reference(source: Option<OrientationSource>) -> bool {
    !matches!(
        source,
        Some(OrientationSource::Estimated | OrientationSource::GroundTruth)
    )
}

/// The rates [`Sequence::resampled`] (and `ridi convert --rate`) resamples to, Hz, both
/// included: 1.001 to 9,990, the default [`Validation`]'s
/// [`output_rate_range`](Validation::output_rate_range). It refuses frames 1 s apart or more
/// (`max_gap_s`) and a median step under 0.1 ms (`time_step_range`); a uniform timeline at
/// exactly 1 Hz or 10 kHz lands on either side of those bounds once its times are added up in
/// floating point (and written as whole nanoseconds), so the range keeps 0.1 % from each.
pub const RESAMPLE_RATE_RANGE_HZ: (f64, f64) = (1.001, 9990.0);

/// `time` not empty, finite, strictly increasing, with no step longer than `max_gap_s`.
fn check_time(time: &[f64], max_gap_s: f64) -> Result<(), SequenceError> {
    if time.is_empty() {
        return Err(SequenceError::Empty);
    }
    if let Some(index) = time.iter().position(|t| !t.is_finite()) {
        return Err(SequenceError::NonFinite {
            what: "time",
            index,
        });
    }
    check_steps(time, max_gap_s)
}

/// `time` strictly increasing, with no step longer than `max_gap_s`.
fn check_steps(time: &[f64], max_gap_s: f64) -> Result<(), SequenceError> {
    for (i, w) in time.windows(2).enumerate() {
        check_frame_step(i + 1, w[0], w[1], max_gap_s)?;
    }
    Ok(())
}

/// [`check_steps`] of the step from `previous` to frame `index` at `next` (for a timeline
/// built as it is read).
pub(crate) fn check_frame_step(
    index: usize,
    previous: f64,
    next: f64,
    max_gap_s: f64,
) -> Result<(), SequenceError> {
    let gap = next - previous;
    if gap <= 0.0 {
        return Err(SequenceError::TimeNotIncreasing {
            index,
            previous,
            next,
        });
    }
    if gap > max_gap_s {
        return Err(SequenceError::Gap {
            index,
            time: next,
            gap_s: gap,
            max_gap_s,
        });
    }
    Ok(())
}

fn check_vecs(field: &'static str, n: usize, v: &[DeviceVec]) -> Result<(), SequenceError> {
    check_len(field, n, v.len())?;
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(SequenceError::NonFinite { what: field, index }),
        None => Ok(()),
    }
}

/// How far a stored rotation's squared norm may be from 1: `Rot`'s constructors and slerp
/// normalize, products of rotations drift by about 1e-13.
const UNIT_TOLERANCE: f64 = 1e-6;

/// Checks that `field` has `n` rotations, each a finite unit quaternion
/// ([`SequenceError::NotRotation`]).
fn check_rots<A: Frame, B: Frame>(
    field: &'static str,
    n: usize,
    r: &[Rot<A, B>],
) -> Result<(), SequenceError> {
    check_len(field, n, r.len())?;
    let unit = |q: &Rot<A, B>| {
        let w = q.to_wxyz();
        let norm2: f64 = w.iter().map(|c| c * c).sum();
        (norm2 - 1.0).abs() < UNIT_TOLERANCE
    };
    match r.iter().position(|q| !unit(q)) {
        Some(index) => Err(SequenceError::NotRotation { what: field, index }),
        None => Ok(()),
    }
}

impl Sequence {
    /// Validates `parts` with the default [`Validation`].
    pub fn new(parts: SequenceParts) -> Result<Self, SequenceError> {
        Self::with_validation(parts, &Validation::default())
    }

    /// Validates `parts` with explicit limits.
    pub fn with_validation(
        parts: SequenceParts,
        limits: &Validation,
    ) -> Result<Self, SequenceError> {
        let n = parts.time.len();
        check_time(&parts.time, limits.max_gap_s).map_err(|e| match e {
            // Every step a gap: a time in milliseconds, say, which the median step names.
            SequenceError::Gap { .. } => limits.check_time_step(&parts.time).err().unwrap_or(e),
            e => e,
        })?;
        check_vecs("gyro", n, &parts.gyro)?;
        check_vecs("acce", n, &parts.acce)?;
        check_vecs("linacce", n, &parts.linacce)?;
        check_vecs("gravity", n, &parts.gravity)?;
        if let Some(m) = &parts.magnet {
            check_vecs("magnet", n, m)?;
        }
        check_rots("orientation", n, &parts.orientation)?;
        if let Some(gt) = &parts.ground_truth {
            check_rots("ground_truth.orientation", n, &gt.orientation)?;
            check_len("ground_truth.position", n, gt.position.len())?;
            if let Some(index) = gt.position.iter().position(|p| !p.is_finite()) {
                return Err(SequenceError::NonFinite {
                    what: "ground_truth.position",
                    index,
                });
            }
        }
        if let Some(steps) = &parts.steps {
            check_len("steps", n, steps.len())?;
            if let Some(index) = steps.iter().position(|s| !s.is_finite()) {
                return Err(SequenceError::NonFinite {
                    what: "steps",
                    index,
                });
            }
        }
        limits.check_time_step(&parts.time)?;
        // Single values before the means, so that one absurd value is named on its frame rather
        // than skewing a mean; the gyro's median goes first (robust to single values), so that a
        // gyro in deg/s is reported as such and not by its first large value.
        limits.check_channel(Channel::Gyro, arrays(&parts.gyro))?;
        limits.check_channel(Channel::Acce, arrays(&parts.acce))?;
        limits.check_channel(Channel::Linacce, arrays(&parts.linacce))?;
        limits.check_channel(Channel::Gravity, arrays(&parts.gravity))?;
        if let Some(m) = &parts.magnet {
            limits.check_channel(Channel::Magnet, arrays(m))?;
        }
        if let Some(gt) = &parts.ground_truth {
            limits.check_channel(Channel::Position, gt.position.iter().map(|p| p.to_array()))?;
            limits.check_speed(&parts.time, &gt.position)?;
        }
        let mean = mean_norm(arrays(&parts.gravity));
        let (min, max) = limits.gravity_range;
        if !(min..=max).contains(&mean) {
            return Err(SequenceError::Gravity { mean, min, max });
        }
        limits.check_orientation_gravity(&parts.orientation, &parts.gravity)?;
        limits.check_acce_scale(mean_norm(arrays(&parts.acce)), mean)?;
        limits.check_gyro_scale(&parts.time, &parts.gyro, &parts.orientation)?;
        limits.check_linacce_scale(
            arrays(&parts.acce)
                .zip(arrays(&parts.gravity))
                .zip(arrays(&parts.linacce))
                .map(|((a, g), l)| (a, g, l)),
        )?;
        Ok(Self { parts })
    }

    /// The sequence with its orientation replaced by a gyro + accelerometer estimate
    /// ([`ridi_frames::estimate_orientation`]), gravity by the estimate's gravity (standard
    /// magnitude) and linear acceleration by accelerometer minus that gravity: the orientation
    /// models trained on [`Estimated`](OrientationSource::Estimated) orientation are fed (the
    /// Android rotation vector bends with the magnetic field indoors, Core Motion's attitude
    /// loses its tilt while running; the estimate's tilt does neither). With `heading`, the
    /// estimate's heading drift is corrected by the slow heading of the sequence's own
    /// orientation ([`ridi_frames::with_reference_heading`]), unless that orientation is no
    /// [`heading_reference`]. Gravity and linear acceleration, and so features, are the same
    /// with or without `heading`.
    ///
    /// # Errors
    /// [`SequenceError::Estimate`] when the estimator refuses the input; the default
    /// validation of the result.
    pub fn with_estimated_orientation(
        &self,
        filter: &FilterConfig,
        heading: Option<&HeadingConfig>,
    ) -> Result<Sequence, SequenceError> {
        let mut p = self.parts.clone();
        p.estimate_orientation(filter)?;
        if let Some(heading) = heading.filter(|_| heading_reference(self.orientation_source())) {
            p.orientation =
                with_reference_heading(self.time(), &p.orientation, self.orientation(), heading)
                    .map_err(|error| SequenceError::Estimate {
                        what: "heading from the recorded orientation",
                        error,
                    })?;
        }
        Sequence::new(p)
    }

    /// Gives the parts back (to edit and re-validate).
    pub fn into_parts(self) -> SequenceParts {
        self.parts
    }

    /// All parts, read-only.
    pub fn parts(&self) -> &SequenceParts {
        &self.parts
    }

    /// Sequence name.
    pub fn name(&self) -> &str {
        &self.parts.name
    }
    /// Placement label, if known.
    pub fn placement(&self) -> Option<&str> {
        self.parts.placement.as_deref()
    }
    /// Sets the placement label (e.g. from a list file).
    pub fn set_placement(&mut self, placement: Option<String>) {
        self.parts.placement = placement;
    }
    /// Renames the sequence.
    pub fn set_name(&mut self, name: impl Into<String>) {
        self.parts.name = name.into();
    }
    /// Number of frames (at least 1).
    pub fn len(&self) -> usize {
        self.parts.time.len()
    }
    /// Always `false`: a valid sequence has frames.
    pub fn is_empty(&self) -> bool {
        false
    }
    /// Whether `other` is the same recording, whatever its name, format or labels: the same
    /// timestamps, gyro and accelerometer samples, every one of them (a recording given twice
    /// would count twice in a mean, or be tested on after training on it). Slice comparison
    /// stops at the first difference, so two recordings cost a length and a timestamp compare
    /// (phone clocks count nanoseconds from boot).
    pub fn is_same_recording(&self, other: &Sequence) -> bool {
        self.time() == other.time() && self.gyro() == other.gyro() && self.acce() == other.acce()
    }

    /// The first pair `(earlier, later)` of `seqs` that are one recording
    /// ([`Sequence::is_same_recording`]), by the later one's position; `None` when all differ.
    pub fn first_repeated(seqs: &[Sequence]) -> Option<(usize, usize)> {
        seqs.iter().enumerate().find_map(|(j, later)| {
            seqs[..j]
                .iter()
                .position(|s| s.is_same_recording(later))
                .map(|i| (i, j))
        })
    }

    /// Timestamps, seconds.
    pub fn time(&self) -> &[f64] {
        &self.parts.time
    }
    /// Gyroscope, rad/s, device frame.
    pub fn gyro(&self) -> &[DeviceVec] {
        &self.parts.gyro
    }
    /// Accelerometer with gravity, m/s^2, device frame.
    pub fn acce(&self) -> &[DeviceVec] {
        &self.parts.acce
    }
    /// Linear acceleration, m/s^2, device frame.
    pub fn linacce(&self) -> &[DeviceVec] {
        &self.parts.linacce
    }
    /// Gravity (pointing up), m/s^2, device frame.
    pub fn gravity(&self) -> &[DeviceVec] {
        &self.parts.gravity
    }
    /// Magnetometer, if recorded.
    pub fn magnet(&self) -> Option<&[DeviceVec]> {
        self.parts.magnet.as_deref()
    }
    /// Device orientation, world-from-device.
    pub fn orientation(&self) -> &[WorldFromDevice] {
        &self.parts.orientation
    }
    /// The IMU streams of every frame, as features, correction and trackers take them.
    pub fn imu(&self) -> ImuFrames<'_> {
        let p = &self.parts;
        ImuFrames {
            time: &p.time,
            gyro: &p.gyro,
            linacce: &p.linacce,
            gravity: &p.gravity,
            orientation: &p.orientation,
        }
    }
    /// Where the orientation jumps against the gyro ([`orientation_jumps`]).
    pub fn orientation_jumps(&self) -> Vec<OrientationJump> {
        orientation_jumps(&self.parts.time, &self.parts.gyro, &self.parts.orientation)
    }
    /// Where the device orientation comes from.
    pub fn orientation_source(&self) -> Option<OrientationSource> {
        self.parts.orientation_source
    }
    /// Ground truth, if any.
    pub fn ground_truth(&self) -> Option<&GroundTruth> {
        self.parts.ground_truth.as_ref()
    }
    /// Step counter, if recorded.
    pub fn steps(&self) -> Option<&[f64]> {
        self.parts.steps.as_deref()
    }
    /// The phone it was recorded with, if known.
    pub fn device(&self) -> Option<&DeviceInfo> {
        self.parts.device.as_ref()
    }
    /// Sets the phone it was recorded with.
    pub fn set_device(&mut self, device: Option<DeviceInfo>) {
        self.parts.device = device;
    }

    /// Sets where the orientation comes from (a reader's sidecar knows better than its layout).
    pub(crate) fn set_orientation_source(&mut self, source: Option<OrientationSource>) {
        self.parts.orientation_source = source;
    }

    /// Duration from first to last frame, seconds.
    pub fn duration(&self) -> f64 {
        self.parts.time[self.len() - 1] - self.parts.time[0]
    }

    /// Measured mean rate, Hz (0 for a single frame).
    pub fn rate_hz(&self) -> f64 {
        let d = self.duration();
        if d > 0.0 {
            (self.len() - 1) as f64 / d
        } else {
            0.0
        }
    }

    /// The stream's rate, Hz: one over the median interval between frames, which gaps do not
    /// change (0 for a single frame). [`Sequence::rate_hz`] is the mean, gaps included.
    pub fn median_rate_hz(&self) -> f64 {
        let mut dt: Vec<f64> = self.parts.time.windows(2).map(|w| w[1] - w[0]).collect();
        if dt.is_empty() {
            return 0.0;
        }
        let mid = dt.len() / 2;
        let (_, median, _) = dt.select_nth_unstable_by(mid, f64::total_cmp);
        1.0 / *median
    }

    /// Longest interval between two frames, seconds (0 for a single frame).
    pub fn max_gap(&self) -> f64 {
        self.parts
            .time
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(0.0, f64::max)
    }

    /// Horizontal path length of the ground truth, metres.
    pub fn path_length(&self) -> Option<f64> {
        let gt = self.ground_truth()?;
        Some(
            gt.position
                .windows(2)
                .map(|w| ((w[1].x() - w[0].x()).powi(2) + (w[1].y() - w[0].y()).powi(2)).sqrt())
                .sum(),
        )
    }

    /// The sequence on a uniform timeline at `rate_hz` from its first frame to at most its
    /// last: vectors (IMU and ground-truth positions) and the step count linearly
    /// interpolated, rotations by slerp, the device kept. For a recording at another rate than a model's (RIDI models
    /// count frames of a 200 Hz stream); `ridi convert --rate` applies it.
    ///
    /// # Errors
    /// [`SequenceError::InvalidRate`] for a `rate_hz` outside [`RESAMPLE_RATE_RANGE_HZ`] or a
    /// `max_gap_s` that is not above 0 (infinity interpolates across every gap, unless the
    /// gaps over 1 s would be most of the result: [`SequenceError::ResampledAcrossGaps`]); a gap
    /// between two frames longer than `max_gap_s` (interpolating would invent the frames of a
    /// gap: split the recording there first); the default validation of the result.
    pub fn resampled(&self, rate_hz: f64, max_gap_s: f64) -> Result<Sequence, SequenceError> {
        use crate::resample::{
            interpolate_rot, interpolate_scalar, interpolate_vec3, uniform_len, uniform_timeline,
        };
        // Checked before the frames are made: a rate the time-step check refuses could first
        // ask for billions of them. An infinite gap limit interpolates across every gap.
        let (min, max) = RESAMPLE_RATE_RANGE_HZ;
        if !((min..=max).contains(&rate_hz) && max_gap_s > 0.0) {
            return Err(SequenceError::InvalidRate { rate_hz, max_gap_s });
        }
        let p = &self.parts;
        let t = &p.time;
        check_steps(t, max_gap_s)?;
        // Before the frames are made: an infinite gap limit across a gap of years would fill it
        // with billions of them. Steps up to the readers' longest gap count as recorded.
        let frames = uniform_len(t[0], t[t.len() - 1], rate_hz);
        let longest = Validation::default().max_gap_s;
        let recorded_s: f64 = t.windows(2).map(|w| (w[1] - w[0]).min(longest)).sum();
        let covered = (recorded_s * rate_hz).ceil() as usize + 1;
        if frames > covered.saturating_mul(2).saturating_add(2) {
            return Err(SequenceError::ResampledAcrossGaps { frames, covered });
        }
        let time = uniform_timeline(t[0], t[t.len() - 1], rate_hz);
        let vec3 = |v: &[DeviceVec]| interpolate_vec3(t, v, &time);
        Sequence::new(SequenceParts {
            name: p.name.clone(),
            placement: p.placement.clone(),
            gyro: vec3(&p.gyro),
            acce: vec3(&p.acce),
            linacce: vec3(&p.linacce),
            gravity: vec3(&p.gravity),
            magnet: p.magnet.as_deref().map(vec3),
            orientation: interpolate_rot(t, &p.orientation, &time),
            orientation_source: p.orientation_source,
            ground_truth: p.ground_truth.as_ref().map(|gt| GroundTruth {
                position: interpolate_vec3(t, &gt.position, &time),
                orientation: interpolate_rot(t, &gt.orientation, &time),
            }),
            steps: p.steps.as_deref().map(|s| interpolate_scalar(t, s, &time)),
            device: p.device.clone(),
            time,
        })
    }

    /// The sequence cut at every gap longer than `max_gap_s` (an interval between frames),
    /// for what cannot cross one (`ridi track` refuses a gap over 0.1 s): the parts at least
    /// `min_duration_s` long, named as the readers name the parts of a recording they split
    /// ([`part_name`]), and the (first, last) frame times of the parts dropped as shorter.
    /// Without such a gap, the sequence itself (taken by value, so that it is not copied then),
    /// or nothing kept when it is shorter than `min_duration_s`.
    ///
    /// # Errors
    /// A `max_gap_s` that is not a finite number above 0 (every frame would be a part), a
    /// `min_duration_s` below 0 or NaN.
    pub fn split_at_gaps(
        self,
        max_gap_s: f64,
        min_duration_s: f64,
    ) -> Result<SplitParts, SequenceError> {
        if !(max_gap_s.is_finite() && max_gap_s > 0.0 && min_duration_s >= 0.0) {
            return Err(SequenceError::InvalidGap {
                max_gap_s,
                min_duration_s,
            });
        }
        let t = self.time();
        let mut bounds: Vec<usize> = std::iter::once(0)
            .chain((1..t.len()).filter(|&i| t[i] - t[i - 1] > max_gap_s))
            .collect();
        if bounds.len() == 1 {
            let (first, last) = (t[0], t[t.len() - 1]);
            return Ok(if last - first >= min_duration_s {
                SplitParts {
                    parts: vec![self],
                    dropped: Vec::new(),
                }
            } else {
                SplitParts {
                    parts: Vec::new(),
                    dropped: vec![(first, last)],
                }
            });
        }
        bounds.push(t.len());
        let (kept, dropped): (Vec<_>, Vec<_>) = bounds
            .windows(2)
            .map(|w| w[0]..w[1])
            .partition(|r| t[r.end - 1] - t[r.start] >= min_duration_s);
        let parts = kept
            .iter()
            .enumerate()
            .map(|(k, r)| {
                let mut part = self.slice(r.clone());
                part.set_name(part_name(self.name(), k, kept.len()));
                part
            })
            .collect();
        let dropped = dropped.iter().map(|r| (t[r.start], t[r.end - 1])).collect();
        Ok(SplitParts { parts, dropped })
    }

    /// The frames in `range`, as a new sequence with the same name, labels and device.
    ///
    /// # Panics
    /// When `range` is empty or out of bounds.
    pub fn slice(&self, range: Range<usize>) -> Sequence {
        assert!(
            range.start < range.end && range.end <= self.len(),
            "slice {range:?} of a {}-frame sequence",
            self.len()
        );
        let p = &self.parts;
        let r = || range.clone();
        Sequence {
            parts: SequenceParts {
                name: p.name.clone(),
                placement: p.placement.clone(),
                time: p.time[r()].to_vec(),
                gyro: p.gyro[r()].to_vec(),
                acce: p.acce[r()].to_vec(),
                linacce: p.linacce[r()].to_vec(),
                gravity: p.gravity[r()].to_vec(),
                magnet: p.magnet.as_ref().map(|m| m[r()].to_vec()),
                orientation: p.orientation[r()].to_vec(),
                orientation_source: p.orientation_source,
                ground_truth: p.ground_truth.as_ref().map(|gt| GroundTruth {
                    position: gt.position[r()].to_vec(),
                    orientation: gt.orientation[r()].to_vec(),
                }),
                steps: p.steps.as_ref().map(|s| s[r()].to_vec()),
                device: p.device.clone(),
            },
        }
    }
}
