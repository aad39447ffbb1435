//! Limits every sequence and stream is checked against, and the orientation jumps those checks
//! leave out.

use ridi_frames::nalgebra::Vector3;
use ridi_frames::{Device, DeviceVec, World, WorldFromDevice, WorldVec};

/// A turn of the world frame.
type WorldFromWorld = ridi_frames::Rot<World, World>;

use crate::error::{counted, spans_text};
use crate::sequence::{Channel, norm};
use crate::sequence_error::{SequenceError, short};

/// The middle value of `v` (the upper one of an even count; NaN when empty), reordering `v`.
fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// The angle between `gravity` and the up axis of `orientation` in the device frame, degrees;
/// `None` for a zero gravity, which has no direction.
pub fn up_angle_deg(orientation: WorldFromDevice, gravity: DeviceVec) -> Option<f64> {
    let g = gravity.norm();
    (g > 0.0).then(|| {
        let up = ridi_frames::gravity_in_device(orientation, 1.0);
        (up.dot(gravity) / g).clamp(-1.0, 1.0).acos().to_degrees()
    })
}

/// Limits applied when a sequence is built, and by the readers to each stream they parse (so
/// that a bad value is reported on its own line, before any resampling).
///
/// Besides time and gravity, the defaults are hard physical bounds on single values and wide
/// unit checks on whole channels, far from real data. Measured over the bundled sample's 24
/// Nexus 5 runs (`datasets/sample`), the 24 Tyrex runs (Nexus 5, 34 sequences once split at mocap losses,
/// including running with the phone in the hand and in a pocket) and the 12 Indoor Location
/// Competition walks (OPPO PBCM10), streams as read and sequences as built:
///
/// | statistic | real data | limit |
/// | --- | --- | --- |
/// | largest gyro component | 21.7 rad/s | 100 rad/s |
/// | median \|gyro\| per recording | 0.24..4.25 rad/s | 10 rad/s |
/// | largest accelerometer / linear acceleration component | 39.6 / 31.1 m/s^2 | 2000 / 2020 m/s^2 |
/// | largest gravity component | 9.81 m/s^2 | 20 m/s^2 |
/// | mean \|acce\| / mean \|gravity\| | 0.99..1.87 | 0.5..3 |
/// | largest magnetometer component | 67 uT | 10 000 uT |
/// | largest position component | 222 m | 10^6 m |
/// | median interval between timestamps | 5-20 ms | 0.1 ms..1 s |
/// | median ground-truth speed per Tyrex run | 0.17..2.33 m/s | 20 m/s |
/// | largest ground-truth speed between consecutive frames (also over 2-20 frames) | 5.7 m/s | 100 m/s |
/// | median angle of gravity from the orientation's up axis | 0 degrees | 45 degrees |
///
/// Not caught: a gyro in deg/s on a phone that hardly turns (the orientation turning at under
/// [`GYRO_SCALE_MIN_RATE`] RMS and the gyro, in deg/s, under [`ORIENTATION_STILL_GYRO_RATE`]),
/// and a linear acceleration alone in g on a phone that hardly moves (RMS of accelerometer
/// minus gravity under [`LINACCE_SCALE_MIN_RMS`]; there is then too little of it to judge, and
/// too little to matter).
#[derive(Debug, Clone, PartialEq)]
pub struct Validation {
    /// Largest accepted interval between two frames, seconds.
    pub max_gap_s: f64,
    /// Accepted range of the mean gravity magnitude, m/s^2 (catches data in g or in mm/s^2).
    pub gravity_range: (f64, f64),
    /// Largest accepted |component| of the gyro, rad/s: 100. Phone gyroscopes saturate at
    /// about 35 rad/s (2000 deg/s); a larger value is corrupt, or degrees per second.
    pub max_gyro: f64,
    /// Largest accepted |component| of the accelerometer, m/s^2: 2000 (about 200 g, far above
    /// the 16-32 g range of phone accelerometers): a larger value is corrupt, or in mm/s^2.
    /// The linear acceleration's is this plus [`Self::max_gravity`], so that an accelerometer
    /// within its limit never gives a linear acceleration (`acce - gravity`) beyond its own.
    pub max_acce: f64,
    /// Largest accepted |component| of gravity, m/s^2: 20, twice its magnitude.
    pub max_gravity: f64,
    /// Largest accepted |component| of the magnetometer, microtesla: 10 000. The Earth's field
    /// is 25-65 uT and phone magnetometers saturate at a few thousand uT; a larger value is
    /// corrupt, or in nanotesla.
    pub max_magnet: f64,
    /// Largest accepted |component| of a ground-truth position, metres: 10^6 (1000 km from the
    /// origin of a room, building or start-of-service frame).
    pub max_position: f64,
    /// Largest accepted median |gyro|, rad/s: 10. Real recordings stay below 4.25 (running
    /// with the phone in a pocket); a gyro in deg/s multiplies by 57.3, so a recording with a
    /// median rotation rate above 0.17 rad/s (10 deg/s) is caught: every one measured, whose
    /// smallest median is 0.24 rad/s (13.6 once in deg/s).
    pub max_median_gyro: f64,
    /// Accepted range of mean |acce| / mean |gravity|: 0.5..3. Real data lie within 0.99..1.87
    /// (the upper end when running); an accelerometer in g beside gravity in m/s^2 gives 0.1.
    pub acce_gravity_ratio: (f64, f64),
    /// Accepted range of the median interval between timestamps, seconds: 1e-4..1 (10 kHz to
    /// 1 Hz; phone sensors deliver 5-500 Hz). Seconds or milliseconds read as nanoseconds step
    /// by 1e-9 s or less. A unit too coarse shows as gaps instead.
    pub time_step_range: (f64, f64),
    /// Accepted range of the scale that best takes the rotation rate of the orientation onto
    /// the gyro's (magnitudes, least squares over consecutive frames, orientation jumps left
    /// out as [`Self::check_gyro_scale`] says): 0.25..4. Real
    /// recordings give 0.93-1.0 (Tyrex) and 0.57-0.98 (competition walks, a noisier rotation
    /// vector at 50 Hz); a gyro in deg/s gives 57, a gyro of zeros 0. Judged only when the
    /// orientation turns at least [`GYRO_SCALE_MIN_RATE`] (RMS).
    pub gyro_scale_range: (f64, f64),
    /// Accepted range of the scale that best takes the linear acceleration onto accelerometer
    /// minus gravity (least squares over all frames): 0.5..2. Android's linear acceleration
    /// is that difference (scale 1); one in g beside the others in m/s^2 gives 9.8, one in
    /// mm/s^2 gives 0.001. Judged only when the RMS of accelerometer minus gravity is at
    /// least [`LINACCE_SCALE_MIN_RMS`].
    pub linacce_scale_range: (f64, f64),
    /// Largest accepted median speed of the ground truth, m/s: 20 (72 km/h). Pedestrians walk
    /// at 1-2 m/s and run at 3-5; positions in millimetres or centimetres read as metres move
    /// 100-1000 times faster, which the bound on single positions cannot see.
    pub max_median_speed: f64,
    /// Largest accepted speed of the ground truth between two consecutive frames, m/s: 100
    /// (0.5 m in a 5 ms step). The fastest real motion is 5.7 m/s (a phone in a running
    /// hand; no faster over 2-20 frames, so mocap jitter adds nothing; measured on Tyrex
    /// motion capture and competition waypoints, not on RIDI's Tango poses, whose
    /// relocalization jumps, if any exceed 0.5 m in a frame, would be refused), and the readers
    /// interpolate across the mocap losses they bridge, which moves no faster; one corrupt
    /// position jumps metres to kilometres within a step, which the median and the bound on
    /// single positions cannot see.
    pub max_speed: f64,
    /// Largest accepted median angle between gravity and the up axis of the orientation
    /// (world-from-device) in the device frame, degrees: 45. Android's gravity sensor and
    /// rotation vectors are one fusion's, and the readers derive gravity from the orientation
    /// where a format has none: every shared recording gives 0 (`benchmarks/stream_bounds.py`). A quaternion read in the wrong
    /// order or inverted turns a phone held upright by 90-180 degrees; a placeholder
    /// (identity) orientation beside a measured gravity disagrees as much.
    pub max_orientation_gravity_deg: f64,
    /// Least agreement in direction between the gyro and the orientation's rotation rate
    /// ([`GyroFit::agreement`]): [`MIN_GYRO_AGREEMENT`], 0.5. `-1` (or below) turns the check
    /// off, and the per-axis one of [`Self::min_gyro_axis_scale`], for an orientation given
    /// for another device frame than the gyro's.
    pub min_gyro_agreement: f64,
    /// Least scale of each gyro axis against the orientation's rotation rate about that
    /// device axis, where the orientation turns about it enough to judge (see
    /// [`MIN_GYRO_AXIS_SCALE`]): 0.15. A dead axis reads about 0, one with its sign reversed
    /// -1; `0` (or below) turns the check off (as a `min_gyro_agreement` of -1 does).
    pub min_gyro_axis_scale: f64,
}

impl Default for Validation {
    fn default() -> Self {
        Self {
            max_gap_s: 1.0,
            gravity_range: (8.5, 11.0),
            max_gyro: 100.0,
            max_acce: 2000.0,
            max_gravity: 20.0,
            max_magnet: 1e4,
            max_position: 1e6,
            max_median_gyro: 10.0,
            acce_gravity_ratio: (0.5, 3.0),
            linacce_scale_range: (0.5, 2.0),
            gyro_scale_range: (0.25, 4.0),
            time_step_range: (1e-4, 1.0),
            max_median_speed: 20.0,
            max_speed: 100.0,
            max_orientation_gravity_deg: 45.0,
            min_gyro_agreement: MIN_GYRO_AGREEMENT,
            min_gyro_axis_scale: MIN_GYRO_AXIS_SCALE,
        }
    }
}

impl Validation {
    /// Largest accepted |component| of `channel` (infinite for time).
    pub fn limit(&self, channel: Channel) -> f64 {
        match channel {
            Channel::Time => f64::INFINITY,
            Channel::Gyro => self.max_gyro,
            Channel::Acce => self.max_acce,
            Channel::Linacce => self.max_acce + self.max_gravity,
            Channel::Gravity => self.max_gravity,
            Channel::Magnet => self.max_magnet,
            Channel::Position => self.max_position,
        }
    }

    /// Checks the 3-vectors of `channel`: for the gyro the median magnitude first (so that a
    /// gyro in deg/s is reported as such), then every component against [`Self::limit`].
    /// Indices in the errors count the items of `values`.
    pub fn check_channel<I>(&self, channel: Channel, values: I) -> Result<(), SequenceError>
    where
        I: IntoIterator<Item = [f64; 3]>,
        I::IntoIter: Clone,
    {
        let values = values.into_iter();
        if channel == Channel::Gyro {
            let mut norms: Vec<f64> = values.clone().map(norm).collect();
            if let Some(e) = self.gyro_units_error(median(&mut norms)) {
                return Err(e);
            }
        }
        for (index, v) in values.enumerate() {
            self.check_value(channel, index, v)?;
        }
        Ok(())
    }

    /// The error for a median |gyro| of `median` rad/s: a gyroscope in deg/s above
    /// [`Self::max_median_gyro`], unless beyond what any gyroscope reads in deg/s
    /// ([`Self::max_gyro`] in deg/s on each axis; corrupt values, which the per-value check
    /// then names on their line).
    pub(crate) fn gyro_units_error(&self, median: f64) -> Option<SequenceError> {
        let in_deg_s = 3f64.sqrt() * self.max_gyro.to_degrees();
        (median > self.max_median_gyro && median <= in_deg_s).then_some(SequenceError::GyroUnits {
            median,
            max: self.max_median_gyro,
        })
    }

    /// Checks one 3-vector of `channel`, frame `index`, against [`Self::limit`] (for a stream
    /// checked as it arrives; a whole channel's statistics need [`Self::check_channel`]).
    pub fn check_value(
        &self,
        channel: Channel,
        index: usize,
        v: [f64; 3],
    ) -> Result<(), SequenceError> {
        let limit = self.limit(channel);
        match v.iter().position(|c| c.abs() > limit) {
            Some(axis) => Err(SequenceError::Implausible {
                channel,
                axis,
                index,
                value: v[axis],
                limit,
            }),
            None => Ok(()),
        }
    }

    /// The rates a uniform timeline may be built at, Hz, both included: one whose frames this
    /// validation accepts, with 0.1 % to spare from its bounds (a timeline at exactly the
    /// bound lands on either side of it once its times are added up in floating point and
    /// written as whole nanoseconds). The default's is [`RESAMPLE_RATE_RANGE_HZ`](crate::RESAMPLE_RATE_RANGE_HZ).
    pub fn output_rate_range(&self) -> (f64, f64) {
        let (min_step, max_step) = self.time_step_range;
        (1.001 / max_step.min(self.max_gap_s), 0.999 / min_step)
    }

    /// Refuses an output rate, `field` of the options a reader was given, outside
    /// [`Self::output_rate_range`]: checked before the timeline is built, which an absurd rate
    /// would make of billions of frames, refused only after.
    pub(crate) fn check_output_rate(
        &self,
        rate_hz: f64,
        at: &std::path::Path,
        field: &str,
    ) -> crate::Result<()> {
        let (min, max) = self.output_rate_range();
        if (min..=max).contains(&rate_hz) {
            return Ok(());
        }
        Err(crate::DataError::format(
            crate::Location::file(at).with_field(field),
            format!(
                "output rate {rate_hz} Hz: expected from {} to {} Hz (the validation's time \
                     steps, with 0.1 % to spare)",
                crate::sequence_error::short(min),
                crate::sequence_error::short(max)
            ),
        ))
    }

    /// Checks the median interval of `time` (seconds, increasing) against
    /// [`Self::time_step_range`]; fewer than two times pass.
    pub fn check_time_step(&self, time: &[f64]) -> Result<(), SequenceError> {
        let mut steps: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
        if steps.is_empty() {
            return Ok(());
        }
        let median = median(&mut steps);
        let (min, max) = self.time_step_range;
        if (min..=max).contains(&median) {
            Ok(())
        } else {
            Err(SequenceError::TimeStep { median, min, max })
        }
    }

    /// Checks the speed of `position` over `time` (seconds, increasing): the median against
    /// [`Self::max_median_speed`] first (so that positions in another unit are reported as
    /// such), then each step between consecutive frames against [`Self::max_speed`]; fewer
    /// than two frames pass.
    pub fn check_speed(&self, time: &[f64], position: &[WorldVec]) -> Result<(), SequenceError> {
        let step_speed =
            |i: usize| Self::step_speed(position[i] - position[i - 1], time[i] - time[i - 1]);
        let n = time.len().min(position.len());
        let mut speeds: Vec<f64> = (1..n).map(step_speed).collect();
        if speeds.is_empty() {
            return Ok(());
        }
        let median = median(&mut speeds);
        if median > self.max_median_speed {
            return Err(SequenceError::GroundTruthSpeed {
                median,
                max: self.max_median_speed,
            });
        }
        // A NaN speed (equal times) must not pass either.
        let too_fast = |v: f64| self.too_fast(v);
        let Some(later) = (1..n).find(|&i| too_fast(step_speed(i))) else {
            return Ok(());
        };
        // A step has two ends: the later one starts a spike or a shift, unless the step is the
        // first and no later step is too fast, when frame 0 alone disagrees with the rest.
        let first_only = later == 1 && !(2..n).any(|i| too_fast(step_speed(i)));
        let index = if first_only { 0 } else { later };
        let step = (position[later] - position[later - 1]).to_array();
        Err(self.jump(index, step, time[later] - time[later - 1]))
    }

    /// The speed of the ground truth's `step` of `dt` seconds, as [`Self::check_speed`]
    /// computes it.
    pub(crate) fn step_speed(step: WorldVec, dt: f64) -> f64 {
        step.norm() / dt
    }

    /// Whether [`Self::check_speed`] counts a step of `speed` as too fast.
    pub(crate) fn too_fast(&self, speed: f64) -> bool {
        speed.is_nan() || speed > self.max_speed
    }

    /// The error of [`Self::check_speed`] for a `step` of `dt` seconds too fast, at frame
    /// `index`.
    pub(crate) fn jump(&self, index: usize, step: [f64; 3], dt: f64) -> SequenceError {
        let axis = (0..3)
            .max_by(|&a, &b| step[a].abs().total_cmp(&step[b].abs()))
            .unwrap_or(0);
        SequenceError::GroundTruthJump {
            index,
            axis,
            distance: norm(step),
            dt,
            max: self.max_speed,
        }
    }

    /// Checks that `gravity` points along the up axis each `orientation` gives in the device
    /// frame, by the median angle over frames ([`Self::max_orientation_gravity_deg`]); frames
    /// with a zero gravity do not count.
    pub fn check_orientation_gravity(
        &self,
        orientation: &[WorldFromDevice],
        gravity: &[DeviceVec],
    ) -> Result<(), SequenceError> {
        let mut angles: Vec<f64> = orientation
            .iter()
            .zip(gravity)
            .filter_map(|(&q, &g)| up_angle_deg(q, g))
            .collect();
        if angles.is_empty() {
            return Ok(());
        }
        let median_deg = median(&mut angles);
        if median_deg <= self.max_orientation_gravity_deg {
            Ok(())
        } else {
            Err(SequenceError::OrientationGravity {
                median_deg,
                max_deg: self.max_orientation_gravity_deg,
            })
        }
    }

    /// Checks mean |acce| against mean |gravity| (both m/s^2) with
    /// [`Self::acce_gravity_ratio`].
    pub fn check_acce_scale(&self, acce: f64, gravity: f64) -> Result<(), SequenceError> {
        let (min, max) = self.acce_gravity_ratio;
        if (min * gravity..=max * gravity).contains(&acce) {
            Ok(())
        } else {
            Err(SequenceError::AcceScale {
                acce,
                gravity,
                min,
                max,
            })
        }
    }

    /// Checks the gyro against the rotation rate of `orientation` over `time`: its scale with
    /// [`Self::gyro_scale_range`] (magnitudes), then its direction with
    /// [`Self::min_gyro_agreement`], then each axis with [`Self::min_gyro_axis_scale`]. Where
    /// the orientation hardly turns ([`GYRO_SCALE_MIN_RATE`]) it passes, unless the gyro turns
    /// ([`ORIENTATION_STILL_GYRO_RATE`]) and no orientation jump was left out: an orientation
    /// that stays put (or a slow turn read in deg/s). The steps where the orientation turns more
    /// than [`ORIENTATION_JUMP_RATE`] faster than the gyro are left out of the fit while they
    /// are at most [`MAX_JUMP_SHARE`] of the steps: a few frames of an OS orientation turning
    /// at hundreds of rad/s would otherwise outweigh thousands that agree. More such steps are
    /// no glitches but a gyro that disagrees (a slow gyro of another recording under a fast
    /// swing): then every step counts.
    pub fn check_gyro_scale(
        &self,
        time: &[f64],
        gyro: &[DeviceVec],
        orientation: &[WorldFromDevice],
    ) -> Result<(), SequenceError> {
        let mut steps = GyroSteps::default();
        for step in step_rates(time, gyro, orientation) {
            steps.add(&step);
        }
        self.gyro_verdict(steps.fit())
    }

    /// [`Self::check_gyro_scale`] of the sums of its steps.
    pub(crate) fn gyro_verdict(&self, fit: &GyroFit) -> Result<(), SequenceError> {
        let GyroFit { gw, gg, n, .. } = *fit;
        let ww = fit.ww();
        if n == 0 {
            return Ok(());
        }
        let (orientation_rms, gyro_rms) = ((ww / n as f64).sqrt(), (gg / n as f64).sqrt());
        if orientation_rms < GYRO_SCALE_MIN_RATE {
            // Too still to fit a scale, unless the gyro turns: then the orientation stays put
            // while the phone turns, or a slow turn reads in deg/s. An orientation that turns
            // in the steps left out as jumps (one held between updates at a lower rate) does
            // not stay put.
            let held = fit.left_out >= HELD_ORIENTATION_MIN_JUMPS;
            if gyro_rms < ORIENTATION_STILL_GYRO_RATE || held {
                return Ok(());
            }
            let scale = gw / ww;
            let (min, max) = self.gyro_scale_range;
            return Err(match ww > 0.0 && DEG_S_SCALES.contains(&scale) {
                true => SequenceError::GyroScale { scale, min, max },
                false => SequenceError::OrientationStill {
                    orientation_rms,
                    gyro_rms,
                },
            });
        }
        let scale = gw / ww;
        let (min, max) = self.gyro_scale_range;
        if !(min..=max).contains(&scale) {
            return Err(SequenceError::GyroScale { scale, min, max });
        }
        if let Some(agreement) = fit.agreement()
            && agreement < self.min_gyro_agreement
        {
            return Err(SequenceError::GyroDirection {
                agreement,
                min: self.min_gyro_agreement,
            });
        }
        // A dead axis leaves the others' agreement high: each axis on its own (but for an
        // orientation of another device frame, the direction check off).
        let axes_comparable = self.min_gyro_agreement > -1.0
            && self.min_gyro_axis_scale > 0.0
            && n >= GYRO_AXIS_MIN_STEPS;
        for axis in (0..3).filter(|_| axes_comparable) {
            let (axis_gw, axis_ww) = (fit.axis_gw[axis], fit.axis_ww[axis]);
            // An axis the phone hardly turns about holds mostly the orientation's noise.
            let judged = (axis_ww / n as f64).sqrt() >= GYRO_SCALE_MIN_RATE
                && axis_ww >= GYRO_AXIS_MIN_SHARE * ww;
            if judged && axis_gw < self.min_gyro_axis_scale * axis_ww {
                return Err(SequenceError::GyroAxis {
                    axis,
                    scale: axis_gw / axis_ww,
                    min: self.min_gyro_axis_scale,
                });
            }
        }
        Ok(())
    }

    /// Checks the linear acceleration's scale against accelerometer minus gravity (all in the
    /// same frame, one triple per frame) with [`Self::linacce_scale_range`]; passes when that
    /// difference is too small to judge ([`LINACCE_SCALE_MIN_RMS`]).
    pub fn check_linacce_scale<I>(&self, frames: I) -> Result<(), SequenceError>
    where
        I: IntoIterator<Item = ([f64; 3], [f64; 3], [f64; 3])>,
    {
        let (mut dl, mut ll, mut dd, mut n) = (0.0, 0.0, 0.0, 0usize);
        for (acce, gravity, linacce) in frames {
            for k in 0..3 {
                let d = acce[k] - gravity[k];
                dl += d * linacce[k];
                ll += linacce[k] * linacce[k];
                dd += d * d;
            }
            n += 1;
        }
        self.linacce_scale_verdict(dl, ll, dd, n)
    }

    /// [`Self::check_linacce_scale`] of its sums over `n` frames: of (acce - gravity) times
    /// linacce (`dl`), linacce squared (`ll`) and (acce - gravity) squared (`dd`). A stream's
    /// check keeps those sums over its last frames (`ridi::LiveTracker`).
    pub fn linacce_scale_verdict(
        &self,
        dl: f64,
        ll: f64,
        dd: f64,
        n: usize,
    ) -> Result<(), SequenceError> {
        if n == 0 {
            return Ok(());
        }
        // acce - gravity ~ scale * linacce; an all-zero linear acceleration is no scale at all.
        let scale = if ll > 0.0 { dl / ll } else { f64::INFINITY };
        let (min, max) = self.linacce_scale_range;
        let (rms, linacce_rms) = ((dd / n as f64).sqrt(), (ll / n as f64).sqrt());
        // NaN sums pass as too small to judge, not as a scale.
        if rms.is_nan() || rms < LINACCE_SCALE_MIN_RMS {
            // A phone too still to fit a scale still has no linear acceleration of its own: a
            // large one there is gravity left in it (the accelerometer given for it).
            let still_but_large = linacce_rms > LINACCE_STILL_MAX_RMS && linacce_rms > 4.0 * rms;
            return if still_but_large {
                Err(SequenceError::LinacceScale { scale, min, max })
            } else {
                Ok(())
            };
        }
        if (min..=max).contains(&scale) {
            Ok(())
        } else {
            Err(SequenceError::LinacceScale { scale, min, max })
        }
    }
}

/// The sums [`Validation::check_gyro_scale`] fits the gyro to an orientation with, over the
/// steps of a recording, or of a stream as it arrives (`ridi::LiveTracker` judges the
/// direction of its samples' gyro with [`Self::agreement`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GyroFit {
    /// Gyro rate times orientation rate (magnitudes), summed.
    pub(crate) gw: f64,
    /// Gyro rate squared, summed.
    pub(crate) gg: f64,
    /// Per device axis: gyro rate times orientation rate, summed.
    pub(crate) axis_gw: [f64; 3],
    /// Per device axis: orientation rate squared, summed (the orientation rate squared is
    /// their sum over the axes).
    pub(crate) axis_ww: [f64; 3],
    /// Steps left out as orientation jumps.
    pub(crate) left_out: usize,
    /// Dot product of the two rate vectors, summed (step by step: summed over the axes
    /// instead, opposite rates read an agreement a rounding below -1).
    pub(crate) dot: f64,
    /// Steps.
    pub(crate) n: usize,
}

impl GyroFit {
    /// Adds a step.
    pub(crate) fn add(&mut self, step: &StepRate) {
        self.gw += step.g * step.w;
        self.gg += step.g * step.g;
        self.dot += step.gyro.dot(&step.rate);
        for k in 0..3 {
            self.axis_gw[k] += step.gyro[k] * step.rate[k];
            self.axis_ww[k] += step.rate[k] * step.rate[k];
        }
        self.n += 1;
    }

    /// Adds the steps between consecutive frames of `time`, `gyro` (rad/s) and `orientation`,
    /// but for those of an orientation jump (turning more than [`ORIENTATION_JUMP_RATE`] faster
    /// than the gyro) and those whose time does not increase.
    pub fn add_steps(&mut self, time: &[f64], gyro: &[DeviceVec], orientation: &[WorldFromDevice]) {
        for step in step_rates(time, gyro, orientation) {
            match step.is_jump() {
                true => self.left_out += 1,
                false => self.add(&step),
            }
        }
    }

    /// How the gyro agrees in direction with the orientation's rotation rate over the steps
    /// added: the sum of the rate vectors' dot products over the sum of their magnitudes'
    /// products, 1 when they turn about the same axes, -1 when opposite
    /// ([`MIN_GYRO_AGREEMENT`]). `None` while the orientation turns too little to judge
    /// ([`GYRO_SCALE_MIN_RATE`] RMS) or the gyro reads nothing.
    pub fn agreement(&self) -> Option<f64> {
        let turns = self.n > 0 && (self.ww() / self.n as f64).sqrt() >= GYRO_SCALE_MIN_RATE;
        (turns && self.gw > 0.0).then(|| self.dot / self.gw)
    }

    /// The orientation rate squared, summed over the steps.
    fn ww(&self) -> f64 {
        self.axis_ww.iter().sum()
    }
}

/// The least agreement in direction between the gyro and the orientation's rotation rate that
/// [`Validation::check_gyro_scale`] accepts by default ([`Validation::min_gyro_agreement`]):
/// the sum over steps of the two rate vectors' dot product over the sum of their magnitudes'
/// product (1 when they turn about the same axes, -1 when opposite). Measured on real
/// recordings (`benchmarks/gyro_direction.py`, 127 sequences: every Tyrex run of both phones
/// and conditions, the 12 Indoor Location Competition walks): 0.78-1.00 as recorded (the
/// lowest near magnetic disturbance, where the OS orientation drifts against the gyro);
/// -1.00..-0.78 with the gyro's sign flipped; -0.77..0.76 with the quaternion's components in
/// another order (x, y, z, w read as w, x, y, z, or the reverse), 94 % of them under 0.5
/// and so refused.
pub const MIN_GYRO_AGREEMENT: f64 = 0.5;

/// The least scale of a gyro axis against the orientation's rotation rate about that device
/// axis that [`Validation::check_gyro_scale`] accepts by default
/// ([`Validation::min_gyro_axis_scale`]): least squares over the steps, where the orientation
/// turns about the axis at [`GYRO_SCALE_MIN_RATE`] RMS or more and with
/// [`GYRO_AXIS_MIN_SHARE`] of its rotation, over [`GYRO_AXIS_MIN_STEPS`] steps or more.
/// Measured on real recordings (`benchmarks/gyro_direction.py --axes`, 127 sequences: every
/// Tyrex run of both phones and conditions, the 12 Indoor Location Competition walks):
/// 333 of their 381 axes judged, 0.33-1.02, 1 % under 0.51 (the lowest near magnetic
/// disturbance); a dead axis reads 0, one with its sign reversed -1.
pub const MIN_GYRO_AXIS_SCALE: f64 = 0.15;

/// Least share of the orientation's squared rotation rate about a device axis for
/// [`Validation::check_gyro_scale`] to judge that gyro axis ([`MIN_GYRO_AXIS_SCALE`]): an
/// axis the phone hardly turns about holds mostly the orientation's noise (quaternions written
/// with 3 decimals read 0.2 rad/s of it at 200 Hz).
pub const GYRO_AXIS_MIN_SHARE: f64 = 0.1;

/// Fewest steps left out as orientation jumps for [`Validation::check_gyro_scale`] to take a
/// still orientation under a turning gyro for one held between updates at a lower rate (under
/// a gyro turning at 0.3 rad/s, one updated at 12 Hz or less jumps at most updates), rather
/// than for one that stays put with a glitch (which jumps out and back: 2 steps).
const HELD_ORIENTATION_MIN_JUMPS: usize = 4;

/// Scales of the gyro against the orientation's rotation rate that read as a gyroscope in
/// deg/s (57.3) where the orientation turns too little to judge the scale otherwise.
const DEG_S_SCALES: std::ops::Range<f64> = 20.0..200.0;

/// Fewest steps over which [`Validation::check_gyro_scale`] judges each gyro axis
/// ([`MIN_GYRO_AXIS_SCALE`]): a second at 200 Hz, four at 50 Hz; over a few steps one axis's
/// noise can read any scale.
pub const GYRO_AXIS_MIN_STEPS: usize = 200;

/// How much faster than the gyro the orientation may turn between two frames, rad/s, before
/// the step belongs to an orientation jump (see [`orientation_jumps`]). Where the orientation
/// is right the two agree within 2 rad/s in every clean Tyrex run (hand swinging and running
/// included); the OS orientation's magnetic corrections and resets turn at 5-460 rad/s while
/// the gyro reads under 2.
pub const ORIENTATION_JUMP_RATE: f64 = 5.0;

/// The largest share of a recording's steps that [`Validation::check_gyro_scale`] leaves out
/// as orientation jumps: the disturbed Tyrex runs have at most 1.4 % (a part with a magnetic
/// correction every few seconds); a gyro of another, slower recording under a swinging phone
/// would have a fifth to most of its steps left out.
pub const MAX_JUMP_SHARE: f64 = 0.05;

/// Steps closer than this, seconds, belong to one [`OrientationJump`]: a rotation vector that
/// updates slower than the timeline shows one correction as several bursts.
const JUMP_JOIN_S: f64 = 0.1;

/// A stretch where the orientation turns much faster than the gyro: the OS orientation
/// (Android's rotation vector, Core Motion's attitude) corrected its heading against the
/// magnetometer or reset, which the phone itself never did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientationJump {
    /// First and last frame, inclusive (the frame before the first fast step to the last frame
    /// of the last).
    pub frames: (usize, usize),
    /// Steps in it where the orientation turns more than [`ORIENTATION_JUMP_RATE`] faster than
    /// the gyro.
    pub fast_steps: usize,
    /// Time of the first and the last of those frames, seconds.
    pub time: (f64, f64),
    /// The fastest the orientation turns in it, rad/s.
    pub peak_rate: f64,
    /// The angle the orientation turns in it beyond the gyro's, radians (summed over steps).
    pub excess_angle: f64,
}

/// One step `k - 1 -> k` of [`step_rates`]: the orientation's rotation rate and the gyro's
/// (the mean of the two readings), rad/s, both vectors in the device frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepRate {
    pub(crate) k: usize,
    pub(crate) dt: f64,
    pub(crate) rate: Vector3<f64>,
    pub(crate) gyro: Vector3<f64>,
    /// `rate`'s and `gyro`'s norms: the rates' magnitudes.
    pub(crate) w: f64,
    pub(crate) g: f64,
}

impl StepRate {
    /// Whether the orientation turns so much faster than the gyro that the step belongs to an
    /// orientation jump ([`ORIENTATION_JUMP_RATE`]).
    pub(crate) fn is_jump(&self) -> bool {
        self.w - self.g > ORIENTATION_JUMP_RATE
    }
}

/// A recording's steps as [`Validation::check_gyro_scale`] sums them, as they come (a stream's
/// too): the fit of every step and the fit without the orientation jumps; [`Self::fit`] is
/// the one judged.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct GyroSteps {
    all: GyroFit,
    kept: GyroFit,
}

impl GyroSteps {
    pub(crate) fn add(&mut self, step: &StepRate) {
        self.all.add(step);
        match step.is_jump() {
            true => self.kept.left_out += 1,
            false => self.kept.add(step),
        }
    }

    /// Without the jumps while they are at most [`MAX_JUMP_SHARE`] of the steps; beyond, they
    /// are no glitches but a gyro that disagrees, and every step counts.
    pub(crate) fn fit(&self) -> &GyroFit {
        let leave_out = self.kept.left_out as f64 <= MAX_JUMP_SHARE * self.all.n as f64;
        if leave_out { &self.kept } else { &self.all }
    }
}

/// The steps `k - 1 -> k` of a recording, those whose time does not increase skipped.
pub(crate) fn step_rates<'a>(
    time: &'a [f64],
    gyro: &'a [DeviceVec],
    orientation: &'a [WorldFromDevice],
) -> impl Iterator<Item = StepRate> + 'a {
    let n = time.len().min(gyro.len()).min(orientation.len());
    (1..n).filter_map(move |k| {
        let dt = time[k] - time[k - 1];
        (dt > 0.0).then(|| {
            // The step's rotation in the device frame (world-from-device q_k = q_{k-1} * step),
            // as a rotation vector: the rate the gyro should read, direction included.
            let step = orientation[k - 1].inverse() * orientation[k];
            let rate = step.quaternion().scaled_axis() / dt;
            let gyro = (*gyro[k - 1].vector() + *gyro[k].vector()) * 0.5;
            StepRate {
                k,
                dt,
                w: rate.norm(),
                g: gyro.norm(),
                rate,
                gyro,
            }
        })
    })
}

/// The stretches where `orientation` turns more than [`ORIENTATION_JUMP_RATE`] faster than
/// `gyro` (magnitudes, so the two may be given in different device frames), in time order;
/// steps less than 0.1 s apart are one jump. What [`Validation::check_gyro_scale`] leaves out,
/// and what readers report as a warning.
pub fn orientation_jumps(
    time: &[f64],
    gyro: &[DeviceVec],
    orientation: &[WorldFromDevice],
) -> Vec<OrientationJump> {
    let mut out: Vec<OrientationJump> = Vec::new();
    for step in step_rates(time, gyro, orientation) {
        if !step.is_jump() {
            continue;
        }
        let StepRate { k, dt, w, g, .. } = step;
        let excess = (w - g) * dt;
        match out.last_mut() {
            Some(j) if time[k - 1] - j.time.1 <= JUMP_JOIN_S => {
                j.frames.1 = k;
                j.fast_steps += 1;
                j.time.1 = time[k];
                j.peak_rate = j.peak_rate.max(w);
                j.excess_angle += excess;
            }
            _ => out.push(OrientationJump {
                frames: (k - 1, k),
                fast_steps: 1,
                time: (time[k - 1], time[k]),
                peak_rate: w,
                excess_angle: excess,
            }),
        }
    }
    out
}

/// `orientation` with each of `jumps` ([`orientation_jumps`]) bridged by the gyro: through a
/// jump the orientation follows the gyro from the frame before it; from its last frame on, the
/// recorded orientation is turned about the vertical by the heading the jump added beyond the
/// gyro. The heading so stays continuous (an OS correction turns a track by up to 160 degrees on
/// the Tyrex runs), while the tilt after a jump is the recorded one: the accelerometer makes it
/// observable, and the jumps leave it nearly unchanged. Whether that helps depends on the jumps:
/// where they correct a heading a magnetic field had bent (the disturbed Tyrex runs) it keeps
/// the bent heading, and tracking gets worse (docs/bench-devices.md). The stretch after the last jump keeps
/// its recorded heading, the others are turned to join it. `gyro` must be in the orientation's
/// device frame, rad/s.
pub fn bridge_orientation_jumps(
    time: &[f64],
    gyro: &[DeviceVec],
    orientation: &[WorldFromDevice],
    jumps: &[OrientationJump],
) -> Vec<WorldFromDevice> {
    let mut out = orientation.to_vec();
    // World-frame turn about z applied to the recorded orientation from the current frame on.
    let mut turn = WorldFromWorld::identity();
    let mut next = 0;
    // Frames every slice has: a jump beyond a shorter time or gyro is skipped, not indexed.
    let frames = orientation.len().min(time.len()).min(gyro.len());
    for jump in jumps {
        let (a, b) = jump.frames;
        if a < next || b >= frames || b <= a {
            continue; // overlapping or outside the slices: nothing sound to do
        }
        for k in next..=a {
            out[k] = turn * orientation[k];
        }
        let mut q = out[a];
        for k in a + 1..b {
            q = q * gyro_step(time[k] - time[k - 1], gyro[k - 1], gyro[k]);
            out[k] = q;
        }
        let bridged = q * gyro_step(time[b] - time[b - 1], gyro[b - 1], gyro[b]);
        turn = yaw_between(bridged, turn * orientation[b]) * turn;
        next = b;
    }
    for k in next..orientation.len() {
        out[k] = turn * orientation[k];
    }
    // Turns about z commute: re-based on the last stretch, whose heading, the OS's most settled
    // (a filter converging after its start jumps too), is kept as recorded.
    let last = turn.inverse();
    for q in &mut out {
        *q = last * *q;
    }
    out
}

/// The device's rotation over one step of the gyro (the mean of its two readings).
pub(crate) fn gyro_step(dt: f64, g0: DeviceVec, g1: DeviceVec) -> ridi_frames::Rot<Device, Device> {
    let w = ((g0 + g1) * (0.5 * dt)).to_array();
    ridi_frames::Rot::from_scaled_axis(Vector3::new(w[0], w[1], w[2]))
}

/// The turn about the world's z axis that takes the heading of `from` to that of `to`: the twist
/// about z of `to * from^-1`.
fn yaw_between(to: WorldFromDevice, from: WorldFromDevice) -> WorldFromWorld {
    let [w, _, _, z] = (to * from.inverse()).to_wxyz();
    let angle = 2.0 * z.atan2(w);
    WorldFromWorld::from_axis_angle(&Vector3::z_axis(), angle)
}

/// One line for a reader's warnings about `jumps` in the orientation read from `file`:
/// how many, where (the first few), how fast; `None` without jumps.
pub(crate) fn orientation_jump_warning(file: &str, jumps: &[OrientationJump]) -> Option<String> {
    let peak = jumps.iter().map(|j| j.peak_rate).fold(0.0, f64::max);
    let steps: usize = jumps.iter().map(|j| j.fast_steps).sum();
    let at: Vec<(f64, f64)> = jumps.iter().map(|j| j.time).collect();
    (!jumps.is_empty()).then(|| {
        format!(
            "{file}: the orientation jumps {} ({} turning at up to {} \
             rad/s, more than {ORIENTATION_JUMP_RATE} rad/s faster than the gyro) at {} (phone \
             clock): OS heading corrections or resets, left out of the gyro check",
            crate::error::times(jumps.len()),
            counted(steps, "frame step"),
            short(peak),
            spans_text(&at)
        )
    })
}

/// Smallest RMS rotation rate of the orientation, rad/s, at which
/// [`Validation::check_gyro_scale`] judges the gyro's scale (the Tyrex and competition walks
/// turn at 0.5-2.6 rad/s RMS).
pub const GYRO_SCALE_MIN_RATE: f64 = 0.1;

/// RMS rotation rate of the gyro, rad/s, from which [`Validation::check_gyro_scale`] refuses
/// an orientation that turns under [`GYRO_SCALE_MIN_RATE`] RMS: one that stays put while the
/// phone turns (a placeholder such as the identity, or an orientation of another, still
/// recording). A phone lying still reads about 0.01; the slowest Tyrex and competition walks
/// turn at 0.5.
pub const ORIENTATION_STILL_GYRO_RATE: f64 = 0.3;

/// Largest RMS linear acceleration, m/s^2, that [`Validation::check_linacce_scale`] accepts
/// where accelerometer minus gravity is too small to fit a scale (below
/// [`LINACCE_SCALE_MIN_RMS`]): a still phone's is noise (hundredths), one with gravity left in
/// it about 9.8.
pub const LINACCE_STILL_MAX_RMS: f64 = 2.0;

/// Smallest RMS of accelerometer minus gravity, m/s^2, at which [`Validation::check_linacce_scale`]
/// judges the linear acceleration's scale: a phone lying still has mostly sensor noise there,
/// whose fit says nothing (walking gives 1-14 m/s^2).
pub const LINACCE_SCALE_MIN_RMS: f64 = 0.5;

#[cfg(test)]
mod tests {
    use super::*;

    /// A phone turning at 0.5 rad/s about its own z (lying flat), 200 Hz, whose OS orientation
    /// jumps by `jump` (a world turn, applied from frame 400 on, reached over 3 frames).
    fn jumping(
        jump: WorldFromWorld,
    ) -> (
        Vec<f64>,
        Vec<DeviceVec>,
        Vec<WorldFromDevice>,
        Vec<WorldFromDevice>,
    ) {
        let n = 1000;
        let time: Vec<f64> = (0..n).map(|i| i as f64 / 200.0).collect();
        let gyro = vec![DeviceVec::new(0.0, 0.0, 0.5); n];
        let truth: Vec<WorldFromDevice> = time
            .iter()
            .map(|&t| WorldFromDevice::from_axis_angle(&Vector3::z_axis(), 0.5 * t))
            .collect();
        let recorded = truth
            .iter()
            .enumerate()
            .map(|(k, &q)| match k {
                0..400 => q,
                400..403 => WorldFromWorld::identity().slerp(&jump, (k - 399) as f64 / 4.0) * q,
                _ => jump * q,
            })
            .collect();
        (time, gyro, truth, recorded)
    }

    /// Gravity along the up axis the orientation gives passes; the same orientation read in
    /// the wrong order, inverted, or a placeholder beside a measured gravity does not.
    #[test]
    fn orientation_and_gravity_must_agree() {
        let v = Validation::default();
        let r = std::f64::consts::FRAC_1_SQRT_2;
        // Upright (device y up) and turned about the vertical by 0.3 rad.
        let (c, s) = (0.15f64.cos(), 0.15f64.sin());
        let wxyz = [r * c, r * c, r * s, r * s];
        let q = |c: [f64; 4]| WorldFromDevice::from_wxyz(c).unwrap();
        let gravity = vec![DeviceVec::new(0.0, 9.8, 0.0); 10];
        let check = |o: WorldFromDevice| v.check_orientation_gravity(&vec![o; 10], &gravity);
        assert!(check(q(wxyz)).is_ok());
        let [w, x, y, z] = wxyz;
        for wrong in [
            q([x, y, z, w]),
            q([w, -x, -y, -z]),
            WorldFromDevice::identity(),
        ] {
            let e = check(wrong).unwrap_err();
            assert!(
                matches!(e, SequenceError::OrientationGravity { median_deg, .. } if median_deg > 45.0)
                    && e.to_string()
                        .contains("([x, y, z, w] for [w, x, y, z] or the reverse)"),
                "{e}"
            );
        }
        // A few frames off do not move the median; a zero gravity has no direction.
        let mut mostly = vec![q(wxyz); 10];
        mostly[..4].fill(WorldFromDevice::identity());
        assert!(v.check_orientation_gravity(&mostly, &gravity).is_ok());
        // Half of them off: the upper median of an even count is off, as the streaming
        // reader's counts judge it (`MedianTest::median_high`).
        mostly[4] = WorldFromDevice::identity();
        assert!(v.check_orientation_gravity(&mostly, &gravity).is_err());
        assert!(check(WorldFromDevice::identity()).is_err());
        assert!(
            v.check_orientation_gravity(&[WorldFromDevice::identity()], &[DeviceVec::ZERO])
                .is_ok()
        );
    }

    #[test]
    fn the_default_output_rates_are_the_resampling_rates() {
        assert_eq!(
            Validation::default().output_rate_range(),
            crate::RESAMPLE_RATE_RANGE_HZ
        );
        // Reading pauses (an unbounded gap) keeps the lowest rate at the time steps' bound.
        let pauses = Validation {
            max_gap_s: f64::INFINITY,
            ..Validation::default()
        };
        assert_eq!(pauses.output_rate_range(), crate::RESAMPLE_RATE_RANGE_HZ);
    }

    #[test]
    fn a_heading_jump_is_bridged_and_the_heading_kept() {
        let jump = WorldFromWorld::from_axis_angle(&Vector3::z_axis(), 2.0);
        let (time, gyro, truth, recorded) = jumping(jump);
        let jumps = orientation_jumps(&time, &gyro, &recorded);
        assert_eq!(jumps.len(), 1, "{jumps:?}");
        let bridged = bridge_orientation_jumps(&time, &gyro, &recorded, &jumps);
        // The heading after the jump, as recorded, everywhere.
        let worst = bridged
            .iter()
            .zip(&truth)
            .map(|(a, b)| a.angle_to(&(jump * *b)))
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "{worst} rad from the truth");
        assert!(bridged[999].angle_to(&recorded[999]) < 1e-12);
        assert!(orientation_jumps(&time, &gyro, &bridged).is_empty());
        // Without jumps, the orientation as recorded.
        assert_eq!(bridge_orientation_jumps(&time, &gyro, &truth, &[]), truth);
        // A jump beyond a shorter time or gyro is skipped, not indexed out of bounds.
        assert_eq!(
            bridge_orientation_jumps(&[], &[], &recorded, &jumps),
            recorded
        );
    }

    #[test]
    fn after_a_jump_the_tilt_is_the_recorded_one() {
        // A reset that turns the heading by 1 rad and tilts by 0.1 rad about world x.
        let tilt = WorldFromWorld::from_axis_angle(&Vector3::x_axis(), 0.1);
        let jump = tilt * WorldFromWorld::from_axis_angle(&Vector3::z_axis(), 1.0);
        let (time, gyro, truth, recorded) = jumping(jump);
        let jumps = orientation_jumps(&time, &gyro, &recorded);
        let bridged = bridge_orientation_jumps(&time, &gyro, &recorded, &jumps);
        let up = WorldVec::new(0.0, 0.0, 1.0);
        for k in [500, 999] {
            // Gravity in the device frame as recorded; the heading close to the truth's.
            let (b, r) = (bridged[k].inverse() * up, recorded[k].inverse() * up);
            assert!((b - r).norm() < 1e-9, "frame {k}");
            assert!(bridged[k].angle_to(&recorded[k]) < 1e-9, "frame {k}");
        }
        // Before it, the gyro's heading joined to the recorded one after: the truth turned by
        // the jump's heading, within the tilt it added.
        let heading = WorldFromWorld::from_axis_angle(&Vector3::z_axis(), 1.0);
        for k in [0, 200, 399] {
            assert!(
                bridged[k].angle_to(&(heading * truth[k])) < 0.11,
                "frame {k}"
            );
            assert!(recorded[k].angle_to(&(heading * truth[k])) > 0.9);
        }
    }

    #[test]
    fn a_gyro_in_deg_per_s_is_named_as_such_before_any_single_value() {
        let v = Validation::default();
        // 2 of 3 samples at 20 rad/s: the median says deg/s, although 200 is also too large.
        let gyro = [[0.0, 0.0, 20.0], [200.0, 0.0, 0.0], [0.0, 20.0, 0.0]];
        let e = v.check_channel(Channel::Gyro, gyro).unwrap_err();
        assert!(
            matches!(e, SequenceError::GyroUnits { median: 20.0, .. }),
            "{e}"
        );
        let gyro = [[0.0, 0.0, 0.2], [0.0, -200.0, 0.0], [0.0, 0.3, 0.0]];
        let e = v.check_channel(Channel::Gyro, gyro).unwrap_err();
        assert_eq!(
            e.to_string(),
            "`gyro.y` at frame 1: -200 rad/s is beyond any phone gyroscope (|value| <= 100 rad/s)"
        );
        // Every value corrupt (beyond any gyroscope in deg/s too): named on its frame, not
        // taken for deg/s.
        let gyro = [[1e308, 0.0, 0.0]; 3];
        let e = v.check_channel(Channel::Gyro, gyro).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("`gyro.x` at frame 0: 1e308 rad/s is beyond"),
            "{e}"
        );
    }

    #[test]
    fn the_gyro_scale_is_judged_on_a_turning_phone_only() {
        let v = Validation::default();
        // A slow turn of 0.15 rad/s (8.6 deg/s): below the median bound even in deg/s.
        let turn = |rate: f64, gyro_scale: f64| {
            let time: Vec<f64> = (0..400).map(|i| i as f64 * 0.005).collect();
            let orientation: Vec<WorldFromDevice> = time
                .iter()
                .map(|&t| {
                    WorldFromDevice::from_scaled_axis(ridi_frames::nalgebra::Vector3::new(
                        0.0,
                        0.0,
                        rate * t,
                    ))
                })
                .collect();
            let gyro = vec![DeviceVec::new(0.0, 0.0, rate * gyro_scale); time.len()];
            v.check_gyro_scale(&time, &gyro, &orientation)
        };
        turn(0.15, 1.0).unwrap();
        let e = turn(0.15, 180.0 / std::f64::consts::PI).unwrap_err();
        assert!(
            matches!(e, SequenceError::GyroScale { scale, .. } if (scale - 57.29578).abs() < 1e-3),
            "{e}"
        );
        assert!(
            e.to_string()
                .ends_with("gyroscope in deg/s instead of rad/s?"),
            "{e}"
        );
        let e = turn(0.15, 0.0).unwrap_err();
        assert!(e.to_string().contains("another recording or device"), "{e}");
        // Turning at 0.05 rad/s is too little to fit a scale on, but a gyro reading 2.9 rad/s
        // there is in deg/s.
        turn(0.05, 1.5).unwrap();
        let e = turn(0.05, 57.3).unwrap_err();
        assert!(e.to_string().ends_with("deg/s instead of rad/s?"), "{e}");
        // An orientation that stays put (a placeholder identity) under a turning gyro.
        let time: Vec<f64> = (0..400).map(|i| i as f64 * 0.005).collect();
        let still = vec![WorldFromDevice::identity(); time.len()];
        let gyro = |rate| vec![DeviceVec::new(0.0, 0.0, rate); time.len()];
        let e = v.check_gyro_scale(&time, &gyro(0.5), &still).unwrap_err();
        assert!(
            e.to_string().starts_with(
                "the orientation turns at 0 rad/s RMS while the gyro turns at 0.5 rad/s RMS: an \
                 orientation that stays put while the phone turns"
            ),
            "{e}"
        );
        // A phone lying still: its gyro's noise says nothing.
        v.check_gyro_scale(&time, &gyro(0.02), &still).unwrap();
        // Still, with a gyro in deg/s: that is named too.
        let e = v.check_gyro_scale(&time, &gyro(0.4), &still).unwrap_err();
        assert!(
            e.to_string()
                .ends_with("in deg/s on a phone that hardly turns?"),
            "{e}"
        );
        // An orientation held between updates at a twentieth of the rate: its turns are in
        // the steps left out as jumps, so it does not stay put.
        let turning = |t: f64| WorldFromDevice::from_axis_angle(&Vector3::z_axis(), 1.0 * t);
        let held: Vec<WorldFromDevice> =
            (0..time.len()).map(|k| turning(time[k - k % 20])).collect();
        v.check_gyro_scale(&time, &gyro(1.0), &held).unwrap();
        // At 2 Hz, over 10 s: 19 updates, each a jump. (Over these 2 s its 3 would be refused:
        // as few as a glitch's in and out, the bound.)
        let long: Vec<f64> = (0..2000).map(|i| i as f64 * 0.005).collect();
        let slow: Vec<WorldFromDevice> = (0..long.len())
            .map(|k| turning(long[k - k % 100]))
            .collect();
        let turning_gyro = vec![DeviceVec::new(0.0, 0.0, 1.0); long.len()];
        v.check_gyro_scale(&long, &turning_gyro, &slow).unwrap();
        let short: Vec<WorldFromDevice> = (0..time.len())
            .map(|k| turning(time[k - k % 100]))
            .collect();
        v.check_gyro_scale(&time, &gyro(1.0), &short).unwrap_err();
        // One glitch in an orientation that stays put does not pass for that.
        let mut glitch = still.clone();
        glitch[200] = turning(1.0);
        let e = v.check_gyro_scale(&time, &gyro(0.6), &glitch).unwrap_err();
        assert!(matches!(e, SequenceError::OrientationStill { .. }), "{e}");
    }

    /// A dead gyro axis (reading 0 while the orientation turns about it) is refused by name,
    /// although the other axes agree in direction; the check off, it passes.
    #[test]
    fn a_dead_gyro_axis_is_refused() {
        let time: Vec<f64> = (0..1000).map(|i| i as f64 * 0.005).collect();
        // Turning about device z at 0.5 rad/s, and rocking about x.
        let rate = |t: f64| Vector3::new(0.4 * (3.0 * t).cos(), 0.0, 0.5);
        let mut orientation = vec![WorldFromDevice::identity()];
        for w in time.windows(2) {
            let step = ridi_frames::Rot::from_scaled_axis(rate(w[0]) * (w[1] - w[0]));
            orientation.push(*orientation.last().unwrap() * step);
        }
        let gyro = |dead: Option<usize>| -> Vec<DeviceVec> {
            time.iter()
                .map(|&t| {
                    let mut g = rate(t);
                    if let Some(axis) = dead {
                        g[axis] = 0.0;
                    }
                    DeviceVec::new(g.x, g.y, g.z)
                })
                .collect()
        };
        let v = Validation::default();
        v.check_gyro_scale(&time, &gyro(None), &orientation)
            .unwrap();
        // y: the orientation does not turn about it, nothing to judge.
        v.check_gyro_scale(&time, &gyro(Some(1)), &orientation)
            .unwrap();
        let e = v
            .check_gyro_scale(&time, &gyro(Some(2)), &orientation)
            .unwrap_err();
        assert!(
            matches!(e, SequenceError::GyroAxis { axis: 2, scale, .. } if scale.abs() < 0.01),
            "{e}"
        );
        assert!(e.to_string().starts_with("the gyro's z axis reads"), "{e}");
        let off = Validation {
            min_gyro_axis_scale: 0.0,
            ..Validation::default()
        };
        off.check_gyro_scale(&time, &gyro(Some(2)), &orientation)
            .unwrap();
        // Rocking about x with its sign reversed there: named as such, and off is off.
        let reversed: Vec<DeviceVec> = gyro(None)
            .iter()
            .map(|g| DeviceVec::new(-g.x(), g.y(), g.z()))
            .collect();
        let e = v
            .check_gyro_scale(&time, &reversed, &orientation)
            .unwrap_err();
        assert!(
            e.to_string()
                .ends_with("a gyro axis with its sign reversed?"),
            "{e}"
        );
        off.check_gyro_scale(&time, &reversed, &orientation)
            .unwrap();
        // Quaternions written with 3 decimals: their rounding turns every axis at about 0.2
        // rad/s at 200 Hz; an axis the phone hardly turns about is not judged on it.
        let rounded: Vec<WorldFromDevice> = orientation
            .iter()
            .map(|q| {
                let c = q.to_wxyz().map(|v| (v * 1000.0).round() / 1000.0);
                WorldFromDevice::from_wxyz(c).unwrap()
            })
            .collect();
        v.check_gyro_scale(&time, &gyro(None), &rounded).unwrap();
    }

    #[test]
    fn a_gyro_turning_against_the_orientation_is_refused_by_its_direction() {
        let v = Validation::default();
        let check = |w: &(Vec<f64>, Vec<DeviceVec>, Vec<WorldFromDevice>)| {
            v.check_gyro_scale(&w.0, &w.1, &w.2)
        };
        // Tilted 0.4 rad about x, so that a quaternion read in another order turns about other
        // axes than z.
        let tilt = ridi_frames::Rot::<Device, Device>::from_scaled_axis(
            ridi_frames::nalgebra::Vector3::new(0.4, 0.0, 0.0),
        );
        let mut walk = jumpy_walk(0.0, &[], 1.0, false);
        walk.2 = walk.2.iter().map(|&q| q * tilt).collect();
        // In the tilted device frame the yaw rate is about the world's z axis seen from it.
        let up = tilt.inverse() * DeviceVec::new(0.0, 0.0, 1.0);
        walk.1 = walk.1.iter().map(|g| up * g.z()).collect();
        check(&walk).unwrap();
        // The sign flipped: the same magnitudes, the opposite direction.
        let flipped = (
            walk.0.clone(),
            walk.1.iter().map(|&g| g * -1.0).collect(),
            walk.2.clone(),
        );
        let e = check(&flipped).unwrap_err();
        assert!(
            matches!(e, SequenceError::GyroDirection { agreement, .. } if agreement < -0.99),
            "{e}"
        );
        assert!(e.to_string().contains("sign flipped"), "{e}");
        // An orientation of another device frame, say: the check off.
        let off = Validation {
            min_gyro_agreement: -1.0,
            ..Validation::default()
        };
        off.check_gyro_scale(&flipped.0, &flipped.1, &flipped.2)
            .unwrap();
        // The quaternion given x, y, z, w and read w, x, y, z: its rotation rates keep their
        // magnitudes (the angle between two quaternions is their dot product's) but not their
        // axes.
        let reordered = (
            walk.0.clone(),
            walk.1.clone(),
            walk.2
                .iter()
                .map(|q| {
                    let [w, x, y, z] = q.to_wxyz();
                    WorldFromDevice::from_wxyz([x, y, z, w]).unwrap()
                })
                .collect(),
        );
        let e = check(&reordered).unwrap_err();
        assert!(e.to_string().contains("another component order"), "{e}");
    }

    /// A walk turning back and forth (yaw 0.8 sin(2 t), at most 1.6 rad/s) at 200 Hz, with the
    /// orientation jumping by `jump` rad for 3 frames at each of `at`; the gyro is
    /// `gyro_scale` times the true rate, or with `other` that of another, slower walk.
    fn jumpy_walk(
        jump: f64,
        at: &[usize],
        gyro_scale: f64,
        other: bool,
    ) -> (Vec<f64>, Vec<DeviceVec>, Vec<WorldFromDevice>) {
        let n = 6000;
        let time: Vec<f64> = (0..n).map(|i| i as f64 * 0.005).collect();
        let yaw = |t: f64| 0.8 * (2.0 * t).sin();
        let orientation = time
            .iter()
            .enumerate()
            .map(|(i, &t)| {
                let glitch = at.iter().any(|&a| (a..a + 3).contains(&i));
                let z = yaw(t) + if glitch { jump } else { 0.0 };
                WorldFromDevice::from_scaled_axis(ridi_frames::nalgebra::Vector3::new(0.0, 0.0, z))
            })
            .collect();
        let gyro = time
            .iter()
            .map(|&t| {
                let rate = if other {
                    0.2 * (0.7 * t).cos()
                } else {
                    1.6 * (2.0 * t).cos()
                };
                DeviceVec::new(0.0, 0.0, rate * gyro_scale)
            })
            .collect();
        (time, gyro, orientation)
    }

    #[test]
    fn a_few_orientation_jumps_neither_fail_nor_hide_a_wrong_gyro() {
        let v = Validation::default();
        let check = |w: &(Vec<f64>, Vec<DeviceVec>, Vec<WorldFromDevice>)| {
            v.check_gyro_scale(&w.0, &w.1, &w.2)
        };
        // Four jumps of 2.5 rad (500 rad/s): with them in the fit the scale was about 0.01.
        let at = [700, 2100, 3900, 5200];
        let walk = jumpy_walk(2.5, &at, 1.0, false);
        check(&walk).unwrap();
        let jumps = orientation_jumps(&walk.0, &walk.1, &walk.2);
        assert_eq!(jumps.len(), 4, "{jumps:?}");
        for (j, a) in jumps.iter().zip(at) {
            assert_eq!(j.frames, (a - 1, a + 3), "{j:?}");
            assert!((j.peak_rate - 500.0).abs() < 2.0, "{j:?}");
        }
        assert!(
            orientation_jumps(&walk.0, &walk.1, &jumpy_walk(0.0, &[], 1.0, false).2).is_empty()
        );
        // A gyro in deg/s, of zeros, or of a slower walk is still refused. (Magnitudes only:
        // a gyro of a walk that turns as much, at other times, is not caught.)
        for (scale, other, expect) in [
            (
                180.0 / std::f64::consts::PI,
                false,
                "deg/s instead of rad/s",
            ),
            (0.0, false, "another recording or device"),
            (1.0, true, "another recording or device"),
        ] {
            let e = check(&jumpy_walk(2.5, &at, scale, other)).unwrap_err();
            assert!(e.to_string().contains(expect), "{scale} {other}: {e}");
        }
        // A phone swung fast (up to 15 rad/s) under the gyro of a slow walk: most steps turn
        // far faster than that gyro, too many to be jumps, so they all count and it is refused.
        let (time, slow_gyro, _) = jumpy_walk(0.0, &[], 1.0, false);
        let omega = 2.0 * std::f64::consts::PI * 1.5;
        let swing: Vec<WorldFromDevice> = time
            .iter()
            .map(|&t| {
                let yaw = 15.0 / omega * (1.0 - (omega * t).cos());
                WorldFromDevice::from_scaled_axis(ridi_frames::nalgebra::Vector3::new(
                    0.0, 0.0, yaw,
                ))
            })
            .collect();
        let e = v.check_gyro_scale(&time, &slow_gyro, &swing).unwrap_err();
        assert!(e.to_string().contains("another recording or device"), "{e}");
    }

    #[test]
    fn the_linear_acceleration_scale_is_judged_on_a_moving_phone_only() {
        let v = Validation::default();
        let g = [0.0, 0.0, 9.8];
        let frames = |motion: f64, scale: f64| {
            (0..100).map(move |i| {
                let m = [
                    motion * (i as f64 * 0.3).sin(),
                    motion * (i as f64 * 0.7).cos(),
                    0.0,
                ];
                let acce = [m[0] + g[0], m[1] + g[1], m[2] + g[2]];
                (acce, g, [m[0] / scale, m[1] / scale, m[2] / scale])
            })
        };
        v.check_linacce_scale(frames(2.0, 1.0)).unwrap();
        let e = v.check_linacce_scale(frames(2.0, 9.80665)).unwrap_err();
        assert!(
            matches!(e, SequenceError::LinacceScale { scale, .. } if (scale - 9.80665).abs() < 1e-9),
            "{e}"
        );
        assert!(
            e.to_string()
                .ends_with("linear acceleration in g instead of m/s^2?"),
            "{e}"
        );
        let e = v.check_linacce_scale(frames(2.0, 1e-3)).unwrap_err();
        assert!(
            e.to_string().ends_with("in mm/s^2 instead of m/s^2?"),
            "{e}"
        );
        // All zero while the phone moves: no linear acceleration at all.
        let zero = frames(2.0, 1.0).map(|(a, g, _)| (a, g, [0.0; 3]));
        let e = v.check_linacce_scale(zero).unwrap_err();
        assert!(
            e.to_string()
                .ends_with("of zero where the phone accelerates?"),
            "{e}"
        );
        // The accelerometer given for the linear acceleration: gravity left in, moving or not.
        let with_gravity = |motion| frames(motion, 1.0).map(|(a, g, _)| (a, g, a));
        for motion in [2.0, 0.05, 0.0] {
            let e = v.check_linacce_scale(with_gravity(motion)).unwrap_err();
            assert!(
                e.to_string()
                    .ends_with("gravity not taken out of the linear acceleration?"),
                "{motion}: {e}"
            );
        }
        // A phone lying still (sensor noise only) is not judged in another unit.
        v.check_linacce_scale(frames(0.05, 9.80665)).unwrap();
        v.check_linacce_scale(std::iter::empty()).unwrap();
    }

    #[test]
    fn time_steps_and_accelerometer_scale_have_wide_bands() {
        let v = Validation::default();
        v.check_time_step(&[0.0, 0.005, 0.01]).unwrap();
        v.check_time_step(&[0.0]).unwrap();
        assert!(matches!(
            v.check_time_step(&[0.0, 5e-12, 1e-11]),
            Err(SequenceError::TimeStep { .. })
        ));
        v.check_acce_scale(1.87 * 9.8, 9.8).unwrap();
        let e = v.check_acce_scale(1.0, 9.80665).unwrap_err().to_string();
        assert!(
            e.contains("0.102 times") && e.contains("in g instead"),
            "{e}"
        );
        let e = v
            .check_acce_scale(9806.65, 9.80665)
            .unwrap_err()
            .to_string();
        assert!(e.contains("in another unit"), "{e}");
    }

    #[test]
    fn a_single_ground_truth_spike_is_caught_on_its_frame() {
        let v = Validation::default();
        // Walking at 1.4 m/s at 200 Hz, with a 0.8 s gap (no frames) in the middle.
        let time: Vec<f64> = (0..50)
            .map(|i| i as f64 * 0.005 + if i >= 25 { 0.8 } else { 0.0 })
            .collect();
        let walk: Vec<WorldVec> = time
            .iter()
            .map(|t| WorldVec::new(1.4 * t, 0.1, 1.2))
            .collect();
        v.check_speed(&time, &walk).unwrap();
        // The fastest real motion, 5.7 m/s, passes.
        let fast: Vec<WorldVec> = time
            .iter()
            .map(|t| WorldVec::new(0.0, 5.7 * t, 0.0))
            .collect();
        v.check_speed(&time, &fast).unwrap();

        let mut spiked = walk.clone();
        spiked[30] = WorldVec::new(999_999.0, 0.1, 1.2);
        let e = v.check_speed(&time, &spiked).unwrap_err();
        assert!(
            matches!(e, SequenceError::GroundTruthJump { index: 30, axis: 0, dt, .. } if (dt - 0.005).abs() < 1e-12),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            "`ground_truth.position.x` at frame 30: jumps 999997.677 m in 0.005 s (2e8 m/s): \
             faster than any pedestrian (speed <= 100 m/s), a corrupt position?"
        );
        // A spike on the first frame is reported there, not on frame 1; a two-frame glitch
        // from frame 1 on frame 1.
        let mut first = walk.clone();
        first[0] = WorldVec::new(999_999.0, 0.1, 1.2);
        let e = v.check_speed(&time, &first).unwrap_err();
        assert!(
            matches!(e, SequenceError::GroundTruthJump { index: 0, .. }),
            "{e:?}"
        );
        let mut second = walk.clone();
        second[1] = WorldVec::new(999_999.0, 0.1, 1.2);
        second[2] = WorldVec::new(999_999.0, 0.1, 1.2);
        let e = v.check_speed(&time, &second).unwrap_err();
        assert!(
            matches!(e, SequenceError::GroundTruthJump { index: 1, .. }),
            "{e:?}"
        );
        // A lasting shift from frame 30 on is reported at frame 30.
        let shifted: Vec<WorldVec> = walk
            .iter()
            .enumerate()
            .map(|(i, p)| {
                if i >= 30 {
                    *p + WorldVec::new(1e4, 0.0, 0.0)
                } else {
                    *p
                }
            })
            .collect();
        let e = v.check_speed(&time, &shifted).unwrap_err();
        assert!(
            matches!(e, SequenceError::GroundTruthJump { index: 30, .. }),
            "{e:?}"
        );
        // Equal times (which `Sequence::new` refuses before) give no "NaN m/s".
        let mut still_time = time.clone();
        still_time[10] = still_time[9];
        let e = v.check_speed(&still_time, &walk).unwrap_err();
        assert_eq!(
            e.to_string(),
            "`ground_truth.position.x` at frame 10: jumps 0.007 m between frames 0 s apart: time \
             must increase"
        );
        // The limit is the caller's to move.
        let lax = Validation {
            max_speed: f64::INFINITY,
            ..Validation::default()
        };
        lax.check_speed(&time, &spiked).unwrap();
        // Positions in millimetres are named by their median first, not as a jump.
        let mm: Vec<WorldVec> = walk.iter().map(|p| *p * 1000.0).collect();
        assert!(matches!(
            v.check_speed(&time, &mm),
            Err(SequenceError::GroundTruthSpeed { .. })
        ));
    }
}
