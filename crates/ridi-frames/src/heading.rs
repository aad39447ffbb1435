//! The heading drift of a gyro + accelerometer estimate, corrected by a recorded orientation.
//!
//! The estimate of [`crate::estimate_orientation`] has a good tilt but a heading that drifts
//! with the gyro's bias about the vertical, which gravity cannot observe (28 degrees/min on the
//! Tyrex iPhone 4S, 7.5 on the Nexus 5). An OS orientation (Core Motion's attitude, Android's
//! rotation vector or game rotation vector) estimates that bias over minutes of use and drifts
//! less, but jumps at resets, and where it uses the magnetometer (the rotation vector, Core
//! Motion's magnetic frames) at magnetic corrections, bends with a disturbed field, and may lose
//! its tilt while running. [`HeadingCorrector`] keeps the estimate and turns it about the vertical by
//! the slow part of the difference of the two headings: each change of the difference is
//! clamped to [`HeadingConfig::max_rate`] times its time step (a reset or a magnetic correction
//! turns faster than any gyro bias: it passes at that rate only), and the sum passes a
//! first-order low-pass of [`HeadingConfig::time_constant`]. The tilt, and so gravity, S and
//! every feature computed in S, stay the estimate's.
//!
//! The filter is causal, one sample at a time, so that a live stream and a whole recording get
//! the same orientation. ridi-data's `ORIENTATION_JUMP_RATE` names the jumps a reader reports;
//! `max_rate` is far below it because what it bounds is a drift, not a jump.

use nalgebra::Vector3;

use crate::estimate::{EstimateError, heading_difference, same_lengths, wrap_angle};
use crate::rotation::{Rot, WorldFromDevice};

/// Parameters of [`HeadingCorrector`]. [`Default`] is what `ridi` tracks with.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct HeadingConfig {
    /// Time constant of the low-pass on the heading difference, s. Shorter follows the
    /// reference's heading more closely, with its errors; longer keeps more of the gyro's
    /// drift. The default, 5 s, gave the smallest heading error against motion capture
    /// pooled over the Tyrex runs of both phones among 2, 5, 10, 20 and 40 s (`cargo xtask
    /// eval orientation`, with and without `--phone iphone4s`).
    pub time_constant: f64,
    /// Fastest change of the heading difference taken from the reference, rad/s, finite: about
    /// six times the largest heading drift of the estimate on the Tyrex phones (55.5
    /// degrees/min), so drift passes and a reset or a magnetic correction of the reference
    /// mostly does not. Of 0.1, 0.3, 1, 5 and no limit it
    /// gave the smallest heading error against motion capture pooled over both phones (the
    /// iPhone 4S's Core Motion attitude corrects itself at 1-5 rad/s).
    pub max_rate: f64,
}

impl Default for HeadingConfig {
    fn default() -> Self {
        Self {
            time_constant: 5.0,
            max_rate: 0.1,
        }
    }
}

impl HeadingConfig {
    /// Checks every value's domain: a finite, positive time constant and a finite,
    /// non-negative rate.
    pub fn validate(&self) -> Result<(), EstimateError> {
        if !(self.time_constant.is_finite() && self.time_constant > 0.0) {
            return Err(EstimateError::InvalidConfig(
                "heading time_constant must be finite and > 0",
            ));
        }
        if !(self.max_rate.is_finite() && self.max_rate >= 0.0) {
            return Err(EstimateError::InvalidConfig(
                "heading max_rate must be finite and >= 0",
            ));
        }
        Ok(())
    }
}

/// Turns each estimated orientation about the vertical onto the slow part of a reference's
/// heading (see the module docs), one sample at a time.
///
/// The output lives in the reference's world frame (its first output has the reference's
/// heading), unless samples without a reference came first ([`hold`](Self::hold)): then it
/// stays in the estimate's, so that the track does not turn where the reference starts. A
/// reference equal to the previous one (an OS orientation repeated between its updates) is
/// taken as none: the difference is only taken between fresh values.
///
/// ```
/// use ridi_frames::{HeadingConfig, HeadingCorrector, Rot, WorldFromDevice, heading_difference};
/// use ridi_frames::nalgebra::Vector3;
///
/// // The estimate drifts 0.01 rad/s about the vertical; the reference does not.
/// let mut corrector = HeadingCorrector::new(HeadingConfig::default())?;
/// let truth = WorldFromDevice::from_scaled_axis(Vector3::new(0.2, 0.1, 0.0));
/// let mut last = truth;
/// for i in 0..60_000 {
///     let t = i as f64 / 200.0;
///     let drifted = Rot::from_axis_angle(&Vector3::z_axis(), 0.01 * t) * truth;
///     // A real reference never repeats its value exactly unless the OS repeated it (then it
///     // is taken as none): this one sways a little.
///     let reference = Rot::from_axis_angle(&Vector3::z_axis(), 1e-3 * (t * 7.0).sin()) * truth;
///     last = corrector.correct(t, drifted, reference)?;
/// }
/// // After 300 s the estimate is 3 rad off; the corrected heading lags the drift by about
/// // rate x time constant.
/// assert!(heading_difference(last, truth).abs() < 0.1);
/// # Ok::<(), ridi_frames::EstimateError>(())
/// ```
#[derive(Debug, Clone)]
pub struct HeadingCorrector {
    config: HeadingConfig,
    state: Option<State>,
    /// A sample came without a reference before the first that had one.
    held_first: bool,
    count: usize,
}

#[derive(Debug, Clone, Copy)]
struct State {
    time: f64,
    /// The world frames' heading offset, fixed at the first reference (0 after a held start).
    offset: f64,
    /// The latest reference, and the raw heading difference to it, wrapped.
    reference: WorldFromDevice,
    raw: f64,
    /// Sum of the rate-limited changes of the difference since the first reference.
    drift: f64,
    /// `drift` low-passed: the correction applied on top of `offset`.
    smooth: f64,
}

impl HeadingCorrector {
    /// A corrector with no sample yet.
    ///
    /// # Errors
    /// [`EstimateError::InvalidConfig`] for a time constant that is not finite and positive or
    /// a rate that is not finite and at least 0.
    pub fn new(config: HeadingConfig) -> Result<Self, EstimateError> {
        config.validate()?;
        Ok(Self {
            config,
            state: None,
            held_first: false,
            count: 0,
        })
    }

    /// The estimate at `time` (s) turned onto the reference's slow heading.
    ///
    /// # Errors
    /// A non-finite time, or one before the previous reference's; the corrector is unchanged.
    pub fn correct(
        &mut self,
        time: f64,
        estimate: WorldFromDevice,
        reference: WorldFromDevice,
    ) -> Result<WorldFromDevice, EstimateError> {
        let index = self.count;
        if !time.is_finite() {
            return Err(EstimateError::NonFinite {
                what: "time",
                index,
            });
        }
        if let Some(s) = &self.state {
            if time < s.time {
                return Err(EstimateError::TimeDecreases { index });
            }
            if reference == s.reference {
                self.count += 1;
                return Ok(self.turned(estimate));
            }
        }
        let h = heading_difference(estimate, reference);
        let s = match self.state {
            None => State {
                time,
                offset: if self.held_first { 0.0 } else { h },
                reference,
                raw: h,
                drift: 0.0,
                smooth: 0.0,
            },
            Some(s) => {
                let dt = time - s.time;
                // Not `0 * inf` = NaN (a clamp to NaN panics) for times of extreme range.
                let limit = if self.config.max_rate == 0.0 {
                    0.0
                } else {
                    self.config.max_rate * dt
                };
                let drift = s.drift + wrap_angle(h - s.raw).clamp(-limit, limit);
                let gain = 1.0 - (-dt / self.config.time_constant).exp();
                State {
                    time,
                    reference,
                    raw: h,
                    drift,
                    smooth: s.smooth + gain * (drift - s.smooth),
                    ..s
                }
            }
        };
        self.state = Some(s);
        self.count += 1;
        Ok(self.turned(estimate))
    }

    /// The estimate turned by the correction reached so far, for a sample without a reference
    /// (the estimate itself before the first one, and the output then stays in the
    /// estimate's world frame).
    pub fn hold(&mut self, estimate: WorldFromDevice) -> WorldFromDevice {
        if self.state.is_none() {
            self.held_first = true;
        }
        self.count += 1;
        self.turned(estimate)
    }

    fn turned(&self, estimate: WorldFromDevice) -> WorldFromDevice {
        self.state.map_or(estimate, |s| {
            Rot::from_axis_angle(&Vector3::z_axis(), s.offset + s.smooth) * estimate
        })
    }
}

/// [`HeadingCorrector`] over whole tracks: `estimate` turned onto the slow part of
/// `reference`'s heading, sample by sample at `time` (s).
///
/// # Errors
/// [`EstimateError::LengthMismatch`] for tracks of different lengths, and as
/// [`HeadingCorrector::new`] and [`HeadingCorrector::correct`].
pub fn with_reference_heading(
    time: &[f64],
    estimate: &[WorldFromDevice],
    reference: &[WorldFromDevice],
    config: &HeadingConfig,
) -> Result<Vec<WorldFromDevice>, EstimateError> {
    same_lengths(
        time.len(),
        [("estimate", estimate.len()), ("reference", reference.len())],
    )?;
    let mut corrector = HeadingCorrector::new(*config)?;
    time.iter()
        .zip(estimate.iter().zip(reference))
        .map(|(&t, (&e, &r))| corrector.correct(t, e, r))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimate::{orientation_errors, tilt_error};

    fn yaw(angle: f64) -> Rot<crate::World, crate::World> {
        Rot::from_axis_angle(&Vector3::z_axis(), angle)
    }

    /// A phone swaying in tilt and turning about the vertical, at 200 Hz.
    fn walk(n: usize) -> (Vec<f64>, Vec<WorldFromDevice>) {
        let time: Vec<f64> = (0..n).map(|i| i as f64 / 200.0).collect();
        let truth = time
            .iter()
            .map(|t| {
                let tilt = WorldFromDevice::from_scaled_axis(Vector3::new(
                    1.2 + 0.1 * (6.0 * t).sin(),
                    0.05 * (3.0 * t).cos(),
                    0.0,
                ));
                yaw(0.3 * (0.2 * t).sin() + 0.01 * t) * tilt
            })
            .collect();
        (time, truth)
    }

    #[test]
    fn a_drifting_estimate_takes_the_references_heading_and_keeps_its_tilt() {
        let (time, truth) = walk(200 * 240);
        // The estimate drifts 0.01 rad/s (34 degrees/min) in a world turned by 1 rad; its tilt
        // is off by a small swing the reference does not have.
        let swing =
            Rot::<crate::Device, crate::Device>::from_scaled_axis(Vector3::new(0.0, 0.03, 0.0));
        let estimate: Vec<WorldFromDevice> = time
            .iter()
            .zip(&truth)
            .map(|(t, q)| yaw(1.0 - 0.01 * t) * *q * swing)
            .collect();
        let out =
            with_reference_heading(&time, &estimate, &truth, &HeadingConfig::default()).unwrap();
        for (o, e) in out.iter().zip(&estimate) {
            assert!(tilt_error(*o, *e) < 1e-9);
        }
        // The first sample is in the reference's frame.
        assert!(heading_difference(out[0], truth[0]).abs() < 1e-6);
        let before = orientation_errors(&estimate, &truth).unwrap();
        let after = orientation_errors(&out, &truth).unwrap();
        let half = time.len() / 2;
        let slope = |e: &crate::OrientationErrors| {
            crate::OrientationErrors {
                tilt: e.tilt[half..].to_vec(),
                heading_drift: e.heading_drift[half..].to_vec(),
            }
            .heading_drift_per_minute(&time[half..])
            .unwrap()
        };
        assert!((slope(&before) - 0.6).abs() < 0.01, "{}", slope(&before));
        // A ramp through a first-order low-pass leaves a constant lag and no slope.
        assert!(slope(&after).abs() < 1e-3, "{}", slope(&after));
        let lag = after.heading_drift[time.len() - 1];
        let expected = 0.01 * HeadingConfig::default().time_constant;
        assert!((lag - expected).abs() < 0.1 * expected, "{lag}");
    }

    #[test]
    fn jumps_of_the_reference_are_dropped() {
        let (time, truth) = walk(200 * 60);
        // The reference jumps by 0.8 rad at 20 s and back by 0.5 rad at 40 s (a magnetic
        // correction, a reset): the estimate, exact here, must not follow.
        let reference: Vec<WorldFromDevice> = time
            .iter()
            .zip(&truth)
            .map(|(&t, q)| {
                let jump = if t >= 40.0 {
                    0.3
                } else if t >= 20.0 {
                    0.8
                } else {
                    0.0
                };
                yaw(jump) * *q
            })
            .collect();
        let out =
            with_reference_heading(&time, &truth, &reference, &HeadingConfig::default()).unwrap();
        let worst = out
            .iter()
            .zip(&truth)
            .map(|(o, t)| heading_difference(*o, *t).abs())
            .fold(0.0, f64::max);
        // Each jump lets through at most one step's max_rate * dt.
        assert!(worst < 2.0 * 0.1 / 200.0 + 1e-9, "{worst}");
    }

    #[test]
    fn a_constant_offset_is_taken_exactly() {
        let (time, truth) = walk(2000);
        let reference: Vec<WorldFromDevice> = truth.iter().map(|q| yaw(-2.5) * *q).collect();
        let out =
            with_reference_heading(&time, &truth, &reference, &HeadingConfig::default()).unwrap();
        for (o, r) in out.iter().zip(&reference) {
            assert!(o.angle_to(r) < 1e-9);
        }
    }

    #[test]
    fn a_reference_repeated_between_updates_fakes_no_drift() {
        // The OS updates its orientation at 50 Hz and the stream repeats it on every 200 Hz
        // sample while the phone turns: taken between fresh values only, the difference to an
        // exact estimate stays 0. (Clamped sample by sample, the sawtooth would drift.)
        let (time, truth) = walk(200 * 60);
        let mut c = HeadingCorrector::new(HeadingConfig::default()).unwrap();
        for (i, (&t, &q)) in time.iter().zip(&truth).enumerate() {
            let held = truth[i - i % 4];
            let out = c.correct(t, q, yaw(0.7) * held).unwrap();
            assert!(
                (heading_difference(q, out) - 0.7).abs() < 1e-9,
                "sample {i}"
            );
        }
    }

    #[test]
    fn a_reference_that_starts_late_does_not_turn_the_track() {
        let (time, truth) = walk(200 * 10);
        let mut c = HeadingCorrector::new(HeadingConfig::default()).unwrap();
        for (i, (&t, &q)) in time.iter().zip(&truth).enumerate() {
            let out = if i < 300 {
                c.hold(q)
            } else {
                c.correct(t, q, yaw(2.0) * q).unwrap()
            };
            // The estimate's world frame throughout: no turn by 2 rad at sample 300.
            assert!(out.angle_to(&q) < 1e-9, "sample {i}");
        }
        // Started with a reference, the output is in the reference's frame.
        let mut c = HeadingCorrector::new(HeadingConfig::default()).unwrap();
        let out = c.correct(0.0, truth[0], yaw(2.0) * truth[0]).unwrap();
        assert!((heading_difference(truth[0], out) - 2.0).abs() < 1e-9);
    }

    #[test]
    fn bad_input_and_configuration_are_refused() {
        let q = WorldFromDevice::identity();
        for config in [
            HeadingConfig {
                time_constant: 0.0,
                ..HeadingConfig::default()
            },
            HeadingConfig {
                time_constant: f64::INFINITY,
                ..HeadingConfig::default()
            },
            HeadingConfig {
                max_rate: f64::NAN,
                ..HeadingConfig::default()
            },
            HeadingConfig {
                max_rate: f64::INFINITY,
                ..HeadingConfig::default()
            },
            HeadingConfig {
                max_rate: -0.1,
                ..HeadingConfig::default()
            },
        ] {
            assert!(matches!(
                HeadingCorrector::new(config),
                Err(EstimateError::InvalidConfig(_))
            ));
        }
        let mut c = HeadingCorrector::new(HeadingConfig::default()).unwrap();
        c.correct(1.0, q, q).unwrap();
        assert_eq!(
            c.correct(0.5, q, q),
            Err(EstimateError::TimeDecreases { index: 1 })
        );
        assert_eq!(
            c.correct(f64::NAN, q, q),
            Err(EstimateError::NonFinite {
                what: "time",
                index: 1
            })
        );
        // A fresh reference at the same time integrates nothing; one repeated is held.
        let turned = Rot::from_axis_angle(&Vector3::z_axis(), 0.5) * q;
        assert_eq!(c.correct(1.0, q, turned), Ok(q));
        assert_eq!(c.correct(1.5, q, turned), Ok(q));
        assert_eq!(
            with_reference_heading(&[0.0, 1.0], &[q], &[q, q], &HeadingConfig::default()),
            Err(EstimateError::LengthMismatch {
                what: "estimate",
                expected: 2,
                found: 1
            })
        );
        assert_eq!(
            with_reference_heading(&[], &[], &[], &HeadingConfig::default()),
            Ok(Vec::new())
        );
        // No clamp at all across the widest finite step (0 rad/s times an infinite step).
        let mut still = HeadingCorrector::new(HeadingConfig {
            max_rate: 0.0,
            ..HeadingConfig::default()
        })
        .unwrap();
        still.correct(-1.5e308, q, q).unwrap();
        assert_eq!(still.correct(1.5e308, q, turned), Ok(q));
    }
}
