//! Orientation from gyroscope and accelerometer alone (no magnetometer).
//!
//! A Mahony complementary filter: the gyroscope is integrated, and the disagreement between the
//! measured specific force (the accelerometer, which reads "up" when the phone is still) and the
//! estimated up direction feeds back as a proportional correction plus an integral term that
//! absorbs the gyroscope bias. Unlike textbook Mahony, the accelerometer is not normalized:
//! the error is `a / g_ref x up_est`, linear in `a`, so a zero-mean linear acceleration
//! (walking, running, swinging) averages out instead of biasing the tilt through the
//! normalization. Gravity only observes pitch and roll, so heading is pure gyro
//! integration and drifts; the bias estimate only covers the two horizontal axes (the vertical
//! component of the integral stays at what tilt corrections put there).
//!
//! The heading reference is the first frame: the initial orientation is built from the first
//! accelerometer samples so that the stabilized frame S of that moment has zero yaw in W
//! (S-x along W-x, S-forward `-z` along W+y, see [`initial_orientation`]).
//!
//! [`tilt_error`], [`heading_difference`] and [`orientation_errors`] compare an estimate with a
//! reference orientation (e.g. motion capture), for evaluating this filter or any other
//! orientation source.

use nalgebra::{UnitQuaternion, Vector3};

use crate::gravity::{UP_W, align_gravity};
use crate::rotation::{Rot, WorldFromDevice};
use crate::vector::DeviceVec;
use crate::{Frame, Stabilized, World};

/// Why orientation estimation refused its input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EstimateError {
    /// Two inputs that must be parallel have different lengths.
    #[error("{what} has {found} samples but time has {expected}")]
    LengthMismatch {
        /// Which input.
        what: &'static str,
        /// Length of the time stamps.
        expected: usize,
        /// Length found.
        found: usize,
    },
    /// A NaN or infinite value.
    #[error("non-finite {what} at sample {index}")]
    NonFinite {
        /// Which input.
        what: &'static str,
        /// Sample index.
        index: usize,
    },
    /// `time[index] < time[index - 1]`.
    #[error("time decreases at sample {index}")]
    TimeDecreases {
        /// Sample index.
        index: usize,
    },
    /// Every accelerometer sample is zero, so there is no gravity to start from.
    #[error("no nonzero accelerometer sample to initialize the tilt from")]
    NoGravity,
    /// A configuration value is out of range.
    #[error("invalid filter configuration: {0}")]
    InvalidConfig(&'static str),
}

/// Gains and limits of the complementary filter. [`Default`] suits a phone carried by a walking
/// person at 50-200 Hz.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FilterConfig {
    /// Proportional gain, 1/s: the tilt error decays roughly as `exp(-kp t)`. Higher follows
    /// gravity faster but lets walking accelerations tilt the estimate.
    pub kp: f64,
    /// Integral gain, 1/s^2, for the gyroscope bias. Zero disables bias estimation.
    pub ki: f64,
    /// Bound on the magnitude of the bias estimate, rad/s, so that a long dynamic stretch cannot
    /// wind the integral up to absurd values.
    pub max_bias: f64,
    /// The bias integral only accumulates while the tilt error (sine of the angle between
    /// measured and estimated up) is below this: larger errors are transients (a wrong start,
    /// strong motion), and integrating them would leave a fake bias that decays only with the
    /// slow closed-loop pole.
    pub integral_max_error: f64,
    /// Longest time step integrated, s. Gaps in the recording (a dropped buffer, a clock jump)
    /// would otherwise turn one gyro sample into a large bogus rotation.
    pub max_dt: f64,
    /// Gravity correction is skipped for samples whose accelerometer norm differs from the
    /// reference norm (the mean norm of the initialization samples) by more than this fraction.
    ///
    /// The default (2.0) only drops readings above three times gravity. A tight gate looks
    /// attractive (strong accelerations say little about up) but is harmful for periodic
    /// motion: the samples that pass are locked to one phase of the stride, whose acceleration
    /// does not average out, and the filter converges to a wrong tilt. On the Tyrex Nexus 5
    /// runs (all samples pooled; `cargo xtask eval orientation`, `docs/bench-orientation.md`) a
    /// gate of 0.3 gives a tilt RMS of 32 degrees (89 over the hand-held running runs) against
    /// 3.6 with the default.
    pub accel_tolerance: f64,
    /// Number of leading nonzero accelerometer samples averaged for the initial tilt.
    pub init_samples: usize,
    /// Seconds of a settling pass, 0 for none: the filter runs forward over the first
    /// `settle_time` seconds from the initial tilt and back to the first sample, and starts
    /// from the tilt reached there (with zero heading). The mean of 0.1 s of accelerometer
    /// while walking is several degrees off, and the filter forgets a start error only as
    /// `exp(-kp t)`; the two passes spend that time before the first output instead of on
    /// it. A stream holds its first `settle_time` seconds back.
    pub settle_time: f64,
}

impl Default for FilterConfig {
    fn default() -> Self {
        Self {
            kp: 0.5,
            ki: 0.01,
            max_bias: 0.1,
            integral_max_error: 0.05,
            max_dt: 0.1,
            accel_tolerance: 2.0,
            init_samples: 20,
            settle_time: 2.0,
        }
    }
}

impl FilterConfig {
    fn validate(&self) -> Result<(), EstimateError> {
        let ok = |v: f64| v.is_finite() && v >= 0.0;
        if !ok(self.kp) {
            return Err(EstimateError::InvalidConfig("kp must be finite and >= 0"));
        }
        if !ok(self.ki) {
            return Err(EstimateError::InvalidConfig("ki must be finite and >= 0"));
        }
        if !ok(self.max_bias) {
            return Err(EstimateError::InvalidConfig(
                "max_bias must be finite and >= 0",
            ));
        }
        if self.integral_max_error.is_nan() || self.integral_max_error < 0.0 {
            return Err(EstimateError::InvalidConfig(
                "integral_max_error must be >= 0",
            ));
        }
        if !(self.max_dt.is_finite() && self.max_dt > 0.0) {
            return Err(EstimateError::InvalidConfig(
                "max_dt must be finite and > 0",
            ));
        }
        if self.accel_tolerance.is_nan() || self.accel_tolerance < 0.0 {
            return Err(EstimateError::InvalidConfig("accel_tolerance must be >= 0"));
        }
        if !(self.settle_time.is_finite() && self.settle_time >= 0.0) {
            return Err(EstimateError::InvalidConfig(
                "settle_time must be finite and >= 0",
            ));
        }
        if self.init_samples == 0 {
            return Err(EstimateError::InvalidConfig("init_samples must be >= 1"));
        }
        Ok(())
    }
}

/// Fixed rotation taking S to W when the heading is zero: S-up (+y) to W-up (+z), S-x to W-x,
/// S-forward (-z) to W+y.
fn world_from_stab_zero_heading() -> Rot<World, Stabilized> {
    Rot::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2)
}

/// Orientation with zero heading whose up direction is `up` (device frame; an accelerometer
/// reading at rest, or Android's gravity vector): `R_x(90°) * align_gravity(up)`.
///
/// "Zero heading" means the stabilized frame S of this orientation has no yaw in W:
/// `stab_from_world(q, up)` is the fixed axis swap S-x = W-x, S-up = W-up, S-forward = W+y.
/// A flat phone (`up` along device +z) gives the identity. A zero or non-finite `up` gives the
/// orientation of a flat phone.
pub fn initial_orientation(up: DeviceVec) -> WorldFromDevice {
    world_from_stab_zero_heading() * align_gravity(up)
}

/// Estimates the device orientation at every sample from time stamps (s), gyroscope (rad/s)
/// and accelerometer (m/s^2, including gravity, i.e. reading up at rest), all in the device
/// frame. Starts from [`initial_orientation`] of the mean of the first
/// [`FilterConfig::init_samples`] nonzero accelerometer samples, settled over the first
/// [`FilterConfig::settle_time`] seconds.
///
/// Time must not decrease; steps longer than [`FilterConfig::max_dt`] are clamped to it and
/// repeated time stamps integrate nothing. Zero accelerometer samples skip the gravity
/// correction. Empty input gives an empty output. The same as pushing every sample through an
/// [`OrientationFilter`] and finishing it.
pub fn estimate_orientation(
    time: &[f64],
    gyro: &[DeviceVec],
    acce: &[DeviceVec],
    config: &FilterConfig,
) -> Result<Vec<WorldFromDevice>, EstimateError> {
    run_batch(OrientationFilter::new(*config)?, time, gyro, acce)
}

/// Like [`estimate_orientation`] but starting from a given orientation (for instance the last
/// state of a previous run, or a deliberately wrong one in tests). The reference accelerometer
/// norm for [`FilterConfig::accel_tolerance`] still comes from the leading samples; without any
/// nonzero sample the correction never runs.
pub fn estimate_orientation_from(
    initial: WorldFromDevice,
    time: &[f64],
    gyro: &[DeviceVec],
    acce: &[DeviceVec],
    config: &FilterConfig,
) -> Result<Vec<WorldFromDevice>, EstimateError> {
    run_batch(
        OrientationFilter::starting_at(initial, *config)?,
        time,
        gyro,
        acce,
    )
}

fn run_batch(
    mut filter: OrientationFilter,
    time: &[f64],
    gyro: &[DeviceVec],
    acce: &[DeviceVec],
) -> Result<Vec<WorldFromDevice>, EstimateError> {
    same_lengths(time.len(), [("gyro", gyro.len()), ("acce", acce.len())])?;
    let mut out = Vec::with_capacity(time.len());
    for i in 0..time.len() {
        filter.push(time[i], gyro[i], acce[i], &mut out)?;
    }
    filter.finish(&mut out)?;
    Ok(out)
}

/// The estimator of [`estimate_orientation`], one sample at a time, for live streams.
///
/// The first orientation needs the initial tilt, the mean of the first
/// [`FilterConfig::init_samples`] nonzero accelerometer samples settled over the first
/// [`FilterConfig::settle_time`], so samples are held until both have arrived (2 s with the
/// defaults) and then come out together;
/// from then on each [`push`](Self::push) gives the orientation of its own sample.
/// [`finish`](Self::finish) releases samples still held at the end of a stream. Pushing a
/// whole recording and finishing gives exactly [`estimate_orientation`]'s result, whatever
/// the chunking.
///
/// ```
/// use ridi_frames::{DeviceVec, FilterConfig, OrientationFilter};
///
/// let mut filter = OrientationFilter::new(FilterConfig::default())?;
/// let mut orientations = Vec::new();
/// for i in 0..400 {
///     // A phone lying flat and still, at 200 Hz.
///     let (gyro, acce) = (DeviceVec::ZERO, DeviceVec::new(0.0, 0.0, 9.81));
///     filter.push(i as f64 * 0.005, gyro, acce, &mut orientations)?;
/// }
/// filter.finish(&mut orientations)?;
/// assert_eq!(orientations.len(), 400);
/// # Ok::<(), ridi_frames::EstimateError>(())
/// ```
#[derive(Debug, Clone)]
pub struct OrientationFilter {
    config: FilterConfig,
    /// The caller's starting orientation ([`Self::starting_at`]); otherwise the initial tilt.
    start: Option<WorldFromDevice>,
    /// Samples waiting for the initial tilt: time, gyro, acce.
    pending: Vec<(f64, DeviceVec, DeviceVec)>,
    pending_nonzero: usize,
    running: Option<Running>,
    /// Samples accepted so far (for error indices) and the last one's time.
    count: usize,
    last_time: Option<f64>,
}

#[derive(Debug, Clone, Copy)]
struct Running {
    q: UnitQuaternion<f64>,
    integral: Vector3<f64>,
    reference_norm: f64,
    time: f64,
    gyro: DeviceVec,
    acce: DeviceVec,
}

impl OrientationFilter {
    /// A filter starting from [`initial_orientation`] of its first samples.
    ///
    /// # Errors
    /// [`EstimateError::InvalidConfig`] for gains or limits out of range.
    pub fn new(config: FilterConfig) -> Result<Self, EstimateError> {
        config.validate()?;
        Ok(Self {
            config,
            start: None,
            pending: Vec::new(),
            pending_nonzero: 0,
            running: None,
            count: 0,
            last_time: None,
        })
    }

    /// A filter starting from `initial` (as [`estimate_orientation_from`]).
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn starting_at(
        initial: WorldFromDevice,
        config: FilterConfig,
    ) -> Result<Self, EstimateError> {
        Ok(Self {
            start: Some(initial),
            ..Self::new(config)?
        })
    }

    /// Adds one sample and appends the orientations that became known to `out`: none while
    /// the initial tilt is being gathered, then the held ones, then one per sample.
    ///
    /// # Errors
    /// A non-finite field or a time before the previous sample's; the sample is dropped and
    /// the filter unchanged. Indices in errors count the samples accepted before.
    pub fn push(
        &mut self,
        time: f64,
        gyro: DeviceVec,
        acce: DeviceVec,
        out: &mut Vec<WorldFromDevice>,
    ) -> Result<(), EstimateError> {
        let index = self.count;
        for (what, ok) in [
            ("time", time.is_finite()),
            ("gyro", gyro.is_finite()),
            ("acce", acce.is_finite()),
        ] {
            if !ok {
                return Err(EstimateError::NonFinite { what, index });
            }
        }
        if self.last_time.is_some_and(|t| time < t) {
            return Err(EstimateError::TimeDecreases { index });
        }
        self.count += 1;
        self.last_time = Some(time);
        if let Some(r) = &mut self.running {
            out.push(r.step(time, gyro, acce, &self.config));
            return Ok(());
        }
        self.pending.push((time, gyro, acce));
        if acce.norm() > 0.0 {
            self.pending_nonzero += 1;
        }
        let settled = self.start.is_some() || time - self.pending[0].0 >= self.config.settle_time;
        if self.pending_nonzero >= self.config.init_samples && settled {
            self.release(out)?;
        }
        Ok(())
    }

    /// Releases the samples still held (a stream shorter than the initial tilt needs).
    ///
    /// # Errors
    /// [`EstimateError::NoGravity`] when every sample held has a zero accelerometer reading
    /// and the filter has no starting orientation of its own.
    pub fn finish(&mut self, out: &mut Vec<WorldFromDevice>) -> Result<(), EstimateError> {
        if self.running.is_none() && !self.pending.is_empty() {
            self.release(out)?;
        }
        Ok(())
    }

    /// Time of the latest sample accepted, if any.
    pub fn last_time(&self) -> Option<f64> {
        self.last_time
    }

    /// The latest orientation, once the filter runs.
    pub fn orientation(&self) -> Option<WorldFromDevice> {
        self.running.map(|r| Rot::from_unit_quaternion(r.q))
    }

    fn release(&mut self, out: &mut Vec<WorldFromDevice>) -> Result<(), EstimateError> {
        let acce: Vec<DeviceVec> = self.pending.iter().map(|p| p.2).collect();
        let mean_up = mean_leading_nonzero(&acce, self.config.init_samples);
        let reference_norm = mean_up.map_or(0.0, |g| g.norm());
        let initial = match (self.start, mean_up) {
            (Some(q), _) => q,
            (None, Some(up)) if self.config.settle_time > 0.0 => settled_start(
                initial_orientation(up),
                reference_norm,
                &self.pending,
                &self.config,
            ),
            (None, Some(up)) => initial_orientation(up),
            (None, None) => return Err(EstimateError::NoGravity),
        };
        let mut r = Running::at(initial, reference_norm, self.pending[0]);
        out.push(initial);
        for &(t, g, a) in &self.pending[1..] {
            out.push(r.step(t, g, a, &self.config));
        }
        self.running = Some(r);
        self.pending = Vec::new();
        Ok(())
    }
}

/// The start [`FilterConfig::settle_time`] asks for: from `initial`, forward over `held` and
/// back to its first sample (time and gyro negated, so the filter turns the other way), then
/// the tilt reached with zero heading, so that the heading reference stays the first frame.
fn settled_start(
    initial: WorldFromDevice,
    reference_norm: f64,
    held: &[(f64, DeviceVec, DeviceVec)],
    config: &FilterConfig,
) -> WorldFromDevice {
    let (Some((first, rest)), Some(&(t, g, a))) = (held.split_first(), held.last()) else {
        return initial;
    };
    let mut r = Running::at(initial, reference_norm, *first);
    for &(t, g, a) in rest {
        r.step(t, g, a, config);
    }
    let mut back = Running {
        // The bias the forward pass learnt is the gyro's; backwards the gyro is negated.
        integral: -r.integral,
        ..Running::at(Rot::from_unit_quaternion(r.q), reference_norm, (-t, -g, a))
    };
    for &(t, g, a) in held.iter().rev().skip(1) {
        back.step(-t, -g, a, config);
    }
    let up = back.q.inverse_transform_vector(UP_W.vector());
    initial_orientation(DeviceVec::from_vector(up))
}

impl Running {
    fn at(
        q: WorldFromDevice,
        reference_norm: f64,
        (time, gyro, acce): (f64, DeviceVec, DeviceVec),
    ) -> Self {
        Self {
            q: *q.quaternion(),
            integral: Vector3::zeros(),
            reference_norm,
            time,
            gyro,
            acce,
        }
    }

    /// Advances from the previous sample to this one and returns this one's orientation.
    fn step(
        &mut self,
        time: f64,
        gyro: DeviceVec,
        acce: DeviceVec,
        config: &FilterConfig,
    ) -> WorldFromDevice {
        let dt = (time - self.time).clamp(0.0, config.max_dt);
        let a = *self.acce.vector();
        let a_norm = a.norm();
        let usable = a_norm > 0.0
            && self.reference_norm > 0.0
            && (a_norm - self.reference_norm).abs() <= config.accel_tolerance * self.reference_norm;
        let mut correction = Vector3::zeros();
        if usable {
            let up_est = self.q.inverse_transform_vector(UP_W.vector());
            // measured x estimated: a rotation rate about this axis turns the estimated up
            // toward the measured one (Mahony's error term). Scaling by the reference norm
            // instead of normalizing keeps it linear in `a`: the mean of a / g_ref is the
            // gravity direction under zero-mean motion, the mean of a / |a| is not.
            let e = (a / self.reference_norm).cross(&up_est);
            if config.ki > 0.0 && e.norm() <= config.integral_max_error {
                self.integral += e * (config.ki * dt);
                let m = self.integral.norm();
                if m > config.max_bias {
                    self.integral *= config.max_bias / m;
                }
            }
            correction = e * config.kp;
        }
        // Trapezoidal gyro: exact for a constant rate, second order for a varying one.
        let omega = (self.gyro.vector() + gyro.vector()) * 0.5 + self.integral + correction;
        self.q *= UnitQuaternion::from_scaled_axis(omega * dt);
        // Renormalizing each step keeps rounding from accumulating over long recordings.
        self.q = UnitQuaternion::new_normalize(self.q.into_inner());
        (self.time, self.gyro, self.acce) = (time, gyro, acce);
        Rot::from_unit_quaternion(self.q)
    }
}

/// [`EstimateError::LengthMismatch`] for the first input whose length is not `expected` (the
/// time stamps').
pub(crate) fn same_lengths(
    expected: usize,
    inputs: [(&'static str, usize); 2],
) -> Result<(), EstimateError> {
    match inputs.into_iter().find(|&(_, len)| len != expected) {
        Some((what, found)) => Err(EstimateError::LengthMismatch {
            what,
            expected,
            found,
        }),
        None => Ok(()),
    }
}

fn mean_leading_nonzero(acce: &[DeviceVec], count: usize) -> Option<DeviceVec> {
    let mut sum = DeviceVec::ZERO;
    let mut n = 0usize;
    for a in acce.iter().filter(|a| a.norm() > 0.0).take(count) {
        sum += *a;
        n += 1;
    }
    // Samples pointing in opposite directions could cancel: then there is no usable up.
    (n > 0 && sum.norm() > 0.0).then(|| sum / n as f64)
}

/// Tilt error between an estimated and a true orientation, radians in [0, pi]: the angle
/// between the up directions each one implies in the device frame (`q^-1 * UP_W`). It ignores
/// heading entirely, so the two world frames may differ by any rotation about the vertical.
pub fn tilt_error<W1: Frame, W2: Frame>(
    estimate: Rot<W1, crate::Device>,
    truth: Rot<W2, crate::Device>,
) -> f64 {
    let up = *UP_W.vector();
    let a = estimate.quaternion().inverse_transform_vector(&up);
    let b = truth.quaternion().inverse_transform_vector(&up);
    // atan2 of |a x b| and a.b is accurate at small angles, where acos loses half the digits.
    a.cross(&b).norm().atan2(a.dot(&b))
}

/// Heading difference between an estimated and a true orientation, radians in (-pi, pi]: the
/// twist about the vertical of the relative rotation `truth * estimate^-1` (which maps the
/// estimate's world frame into the true one). Positive means the truth is rotated
/// counter-clockwise (seen from above) relative to the estimate.
///
/// With a perfect tilt the relative rotation is a pure yaw and this is its angle; with a tilt
/// error the swing-twist decomposition keeps the value well defined. A constant value over a
/// recording is only a different heading reference (the estimate starts at heading 0); its
/// change over time is the heading drift. If the relative rotation is exactly a half turn about
/// a horizontal axis, the twist is undefined and 0 is returned.
pub fn heading_difference<W1: Frame, W2: Frame>(
    estimate: Rot<W1, crate::Device>,
    truth: Rot<W2, crate::Device>,
) -> f64 {
    let r = truth.quaternion() * estimate.quaternion().inverse();
    if r.w == 0.0 && r.k == 0.0 {
        return 0.0;
    }
    let yaw = 2.0 * r.k.atan2(r.w);
    wrap_angle(yaw)
}

pub(crate) fn wrap_angle(a: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let w = a.rem_euclid(TAU);
    if w > PI { w - TAU } else { w }
}

/// Per-sample comparison of an orientation estimate with a reference.
#[derive(Debug, Clone, PartialEq)]
pub struct OrientationErrors {
    /// [`tilt_error`] per sample, radians.
    pub tilt: Vec<f64>,
    /// [`heading_difference`] per sample, unwrapped (continuous across +-pi) and offset so that
    /// the first sample is 0: the heading drift since the start, radians.
    pub heading_drift: Vec<f64>,
}

impl OrientationErrors {
    /// Root mean square of the tilt error, radians (0 for no samples).
    pub fn tilt_rms(&self) -> f64 {
        if self.tilt.is_empty() {
            return 0.0;
        }
        (self.tilt.iter().map(|t| t * t).sum::<f64>() / self.tilt.len() as f64).sqrt()
    }

    /// Heading drift rate in radians per minute: the least-squares slope of
    /// [`heading_drift`](Self::heading_drift) against `time` (s), times 60. `None` when fewer
    /// than two samples or all times are equal. `time` must have one entry per sample.
    pub fn heading_drift_per_minute(&self, time: &[f64]) -> Option<f64> {
        let n = self.heading_drift.len();
        if n < 2 || time.len() != n {
            return None;
        }
        let mt = time.iter().sum::<f64>() / n as f64;
        let mh = self.heading_drift.iter().sum::<f64>() / n as f64;
        let (mut sxy, mut sxx) = (0.0, 0.0);
        for (t, h) in time.iter().zip(&self.heading_drift) {
            sxy += (t - mt) * (h - mh);
            sxx += (t - mt) * (t - mt);
        }
        (sxx > 0.0).then(|| 60.0 * sxy / sxx)
    }
}

/// Compares two orientation tracks sample by sample (same length, same time stamps). The world
/// frames may differ by a heading offset; see [`OrientationErrors`]. Returns
/// [`EstimateError::LengthMismatch`] for tracks of different lengths.
pub fn orientation_errors<W1: Frame, W2: Frame>(
    estimate: &[Rot<W1, crate::Device>],
    truth: &[Rot<W2, crate::Device>],
) -> Result<OrientationErrors, EstimateError> {
    if estimate.len() != truth.len() {
        return Err(EstimateError::LengthMismatch {
            what: "estimate",
            expected: truth.len(),
            found: estimate.len(),
        });
    }
    let tilt = estimate
        .iter()
        .zip(truth)
        .map(|(e, t)| tilt_error(*e, *t))
        .collect();
    let mut heading_drift = Vec::with_capacity(estimate.len());
    let mut prev = 0.0;
    let mut acc = 0.0;
    for (i, (e, t)) in estimate.iter().zip(truth).enumerate() {
        let h = heading_difference(*e, *t);
        if i > 0 {
            acc += wrap_angle(h - prev);
        }
        prev = h;
        heading_drift.push(acc);
    }
    Ok(OrientationErrors {
        tilt,
        heading_drift,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{UP_S, gravity_in_device, stab_from_world};
    use std::f64::consts::PI;

    const G: f64 = 9.81;

    fn times(n: usize, hz: f64) -> Vec<f64> {
        (0..n).map(|i| i as f64 / hz).collect()
    }

    #[test]
    fn initial_orientation_has_zero_heading() {
        let up = DeviceVec::new(1.0, 3.0, 9.0);
        let q = initial_orientation(up);
        let s_w = stab_from_world(q, up);
        let expected = Rot::<Stabilized, World>::from_axis_angle(
            &Vector3::x_axis(),
            -std::f64::consts::FRAC_PI_2,
        );
        assert!(s_w.angle_to(&expected) < 1e-12, "{s_w:?}");
        assert!(
            initial_orientation(DeviceVec::new(0.0, 0.0, G)).angle_to(&Rot::identity()) < 1e-12
        );
        // S-up is W-up after the swap.
        let up_s = stab_from_world(q, up) * UP_W;
        assert!((up_s - UP_S).norm() < 1e-12);
    }

    #[test]
    fn static_tilted_phone_recovers_tilt() {
        let truth = WorldFromDevice::from_scaled_axis(Vector3::new(0.4, -0.7, 1.1));
        let n = 2000;
        let t = times(n, 200.0);
        let gyro = vec![DeviceVec::ZERO; n];
        let acce = vec![gravity_in_device(truth, G); n];
        let est = estimate_orientation(&t, &gyro, &acce, &FilterConfig::default()).unwrap();
        assert_eq!(est.len(), n);
        for q in &est {
            assert!(tilt_error(*q, truth) < 1e-9);
        }
    }

    #[test]
    fn settling_pass_removes_a_start_error_before_the_first_output() {
        // A still, tilted phone whose first 0.1 s carry a sideways jolt: the initial tilt
        // from those samples is off by about 17 degrees.
        let truth = WorldFromDevice::from_scaled_axis(Vector3::new(0.3, -0.2, 0.5));
        let n = 1200;
        let t = times(n, 200.0);
        let gyro = vec![DeviceVec::ZERO; n];
        let jolt = DeviceVec::new(3.0, 0.0, 0.0);
        let acce: Vec<_> = (0..n)
            .map(|i| gravity_in_device(truth, G) + if i < 20 { jolt } else { DeviceVec::ZERO })
            .collect();
        let first_error = |settle_time: f64| {
            let config = FilterConfig {
                settle_time,
                ..FilterConfig::default()
            };
            let est = estimate_orientation(&t, &gyro, &acce, &config).unwrap();
            tilt_error(est[0], truth).to_degrees()
        };
        assert!(first_error(0.0) > 15.0, "{}", first_error(0.0));
        // Forward and back through 2 s take e^-2 of it; the jolt, met again at the end of
        // the backward pass, puts a little back.
        assert!(first_error(2.0) < 4.0, "{}", first_error(2.0));
        // The settled start keeps the heading reference: S of the first frame has no yaw.
        let est = estimate_orientation(&t, &gyro, &acce, &FilterConfig::default()).unwrap();
        let s_w = stab_from_world(est[0], gravity_in_device(est[0], G));
        let zero = Rot::<Stabilized, World>::from_axis_angle(&Vector3::x_axis(), -PI / 2.0);
        assert!(s_w.angle_to(&zero) < 1e-9);
        // A stream shorter than the settling time still gets every orientation at finish.
        let mut filter = OrientationFilter::new(FilterConfig::default()).unwrap();
        let mut out = Vec::new();
        for i in 0..100 {
            filter.push(t[i], gyro[i], acce[i], &mut out).unwrap();
        }
        assert!(out.is_empty());
        filter.finish(&mut out).unwrap();
        assert_eq!(out.len(), 100);
        assert!(
            FilterConfig {
                settle_time: f64::NAN,
                ..FilterConfig::default()
            }
            .validate()
            .is_err()
        );
    }

    #[test]
    fn constant_yaw_rate_reproduces_heading() {
        let rate = 0.3; // rad/s about world (and device) z for a flat phone
        let hz = 200.0;
        let n = 4001; // 20 s
        let t = times(n, hz);
        let gyro = vec![DeviceVec::new(0.0, 0.0, rate); n];
        let acce = vec![DeviceVec::new(0.0, 0.0, G); n];
        let est = estimate_orientation(&t, &gyro, &acce, &FilterConfig::default()).unwrap();
        for (i, q) in est.iter().enumerate() {
            let truth = WorldFromDevice::from_scaled_axis(Vector3::new(0.0, 0.0, rate * t[i]));
            assert!(
                q.angle_to(&truth) < 1e-9,
                "sample {i}: {}",
                q.angle_to(&truth)
            );
        }
        let truth: Vec<_> = t
            .iter()
            .map(|&ti| WorldFromDevice::from_scaled_axis(Vector3::new(0.0, 0.0, rate * ti)))
            .collect();
        let errs = orientation_errors(&est, &truth).unwrap();
        assert!(errs.heading_drift.iter().all(|h| h.abs() < 1e-9));
        assert!(errs.heading_drift_per_minute(&t).unwrap().abs() < 1e-9);
    }

    #[test]
    fn tilt_converges_from_wrong_start() {
        let truth = WorldFromDevice::from_scaled_axis(Vector3::new(0.2, 0.1, 0.0));
        let wrong = WorldFromDevice::from_scaled_axis(Vector3::new(-0.5, 0.4, 0.0));
        // 30 s at 200 Hz. The proportional part removes most of the error within ~10 s
        // (kp = 0.5); the little fake bias integrated near the end of the transient leaves a
        // residual of about 1e-3 rad that decays with the slow PI pole (~50 s at ki = 0.01).
        let n = 6000;
        let t = times(n, 200.0);
        let gyro = vec![DeviceVec::ZERO; n];
        let acce = vec![gravity_in_device(truth, G); n];
        let est =
            estimate_orientation_from(wrong, &t, &gyro, &acce, &FilterConfig::default()).unwrap();
        let e0 = tilt_error(est[0], truth);
        let e_end = tilt_error(est[n - 1], truth);
        assert!(e0 > 0.6, "{e0}");
        let e_10s = tilt_error(est[2000], truth);
        assert!(e_10s < 0.05 * e0, "{e_10s}");
        let e_20s = tilt_error(est[4000], truth);
        assert!(e_end < 3e-3 && e_end < e_20s, "{e_end} {e_20s}");
    }

    #[test]
    fn moving_phone_keeps_tilt_and_heading() {
        // Turning while pitching and rolling, with 1 m/s^2 of linear acceleration on top of
        // gravity: the filter must follow the gyro and keep tilt close despite the disturbance.
        let truth_at = |t: f64| {
            Rot::<World, World>::from_axis_angle(&Vector3::z_axis(), 0.5 * t)
                * WorldFromDevice::from_axis_angle(&Vector3::x_axis(), 0.3 * (2.0 * t).sin())
                * Rot::<crate::Device, crate::Device>::from_axis_angle(
                    &Vector3::y_axis(),
                    0.2 * (3.0 * t).sin(),
                )
        };
        let body_rate = |t: f64| {
            // omega_body = 2 Im(q* dq/dt), by a central difference.
            let h = 1e-6;
            let a = *truth_at(t - h).quaternion();
            let b = *truth_at(t + h).quaternion();
            (a.inverse() * b).scaled_axis() / (2.0 * h)
        };
        let n = 6000;
        let t = times(n, 200.0);
        let truth: Vec<WorldFromDevice> = t.iter().map(|&ti| truth_at(ti)).collect();
        let gyro: Vec<DeviceVec> = t
            .iter()
            .map(|&ti| DeviceVec::from_vector(body_rate(ti)))
            .collect();
        let run = |amplitude: f64| {
            let acce: Vec<DeviceVec> = t
                .iter()
                .zip(&truth)
                .map(|(&ti, q)| {
                    gravity_in_device(*q, G)
                        + DeviceVec::new((4.0 * ti).sin(), 0.0, (7.0 * ti).cos()) * amplitude
                })
                .collect();
            let est =
                estimate_orientation_from(truth[0], &t, &gyro, &acce, &FilterConfig::default())
                    .unwrap();
            let errs = orientation_errors(&est, &truth).unwrap();
            let tilt = errs.tilt.iter().copied().fold(0.0, f64::max);
            let heading = errs
                .heading_drift
                .iter()
                .map(|h| h.abs())
                .fold(0.0, f64::max);
            (tilt, heading)
        };
        // Exact gravity: only the integration error of 200 Hz trapezoidal steps remains.
        let (tilt, heading) = run(0.0);
        assert!(tilt < 1e-4 && heading < 1e-4, "{tilt} {heading}");
        // 1 m/s^2 (0.1 g) of linear acceleration at 4-7 rad/s: an accelerometer-only tilt would
        // be off by up to 0.1 rad; the filter stays within about 0.02 (measured 0.020).
        let (tilt, heading) = run(1.0);
        assert!(tilt < 0.025 && heading < 0.005, "{tilt} {heading}");
    }

    #[test]
    fn periodic_acceleration_does_not_bias_tilt() {
        // A still phone shaken periodically along a tilted direction (1.5 g, 2 Hz, zero mean).
        // A tight accelerometer-norm gate keeps only the phases where |a| happens to be near g,
        // whose mean is not gravity; without the gate the disturbance averages out.
        let truth = WorldFromDevice::identity();
        let n = 12000;
        let t = times(n, 200.0);
        let gyro = vec![DeviceVec::ZERO; n];
        let dir = DeviceVec::new(1.0, 0.0, 1.0) / 2f64.sqrt();
        let acce: Vec<DeviceVec> = t
            .iter()
            .map(|&ti| DeviceVec::new(0.0, 0.0, G) + dir * (1.5 * G * (4.0 * PI * ti).sin()))
            .collect();
        let mean_tilt = |cfg: &FilterConfig| {
            let est = estimate_orientation_from(truth, &t, &gyro, &acce, cfg).unwrap();
            est[n / 2..]
                .iter()
                .map(|q| tilt_error(*q, truth))
                .sum::<f64>()
                / (n / 2) as f64
        };
        let default = mean_tilt(&FilterConfig::default());
        let gated = mean_tilt(&FilterConfig {
            accel_tolerance: 0.3,
            ..FilterConfig::default()
        });
        assert!(default < 0.03, "default {default}");
        assert!(gated > 5.0 * default, "gated {gated} default {default}");
    }

    #[test]
    fn gyro_bias_is_absorbed_for_tilt() {
        // A constant bias about device x would tilt a pure integrator by 0.02 rad/s * 60 s.
        let truth = WorldFromDevice::identity();
        let n = 12000;
        let t = times(n, 200.0);
        let gyro = vec![DeviceVec::new(0.02, 0.0, 0.0); n];
        let acce = vec![gravity_in_device(truth, G); n];
        // ki = 0.05 puts the slow closed-loop pole at about 1/7 s, so 60 s is ample.
        let with_ki = FilterConfig {
            ki: 0.05,
            ..FilterConfig::default()
        };
        let est = estimate_orientation(&t, &gyro, &acce, &with_ki).unwrap();
        let with_integral = tilt_error(est[n - 1], truth);
        let p_only = FilterConfig {
            ki: 0.0,
            ..FilterConfig::default()
        };
        let est_p = estimate_orientation(&t, &gyro, &acce, &p_only).unwrap();
        let without = tilt_error(est_p[n - 1], truth);
        // Proportional only: steady error bias / kp = 0.04 rad. The integral removes it.
        assert!((without - 0.04).abs() < 2e-3, "{without}");
        assert!(with_integral < 2e-3, "{with_integral}");
    }

    #[test]
    fn dt_spikes_are_clamped_and_repeats_integrate_nothing() {
        let rate = 1.0;
        let t = vec![0.0, 0.01, 0.01, 5.0, 5.01];
        let gyro = vec![DeviceVec::new(0.0, 0.0, rate); 5];
        let acce = vec![DeviceVec::new(0.0, 0.0, G); 5];
        let cfg = FilterConfig::default();
        let est = estimate_orientation(&t, &gyro, &acce, &cfg).unwrap();
        let yaw = |q: &WorldFromDevice| heading_difference(WorldFromDevice::identity(), *q);
        assert!((yaw(&est[1]) - 0.01).abs() < 1e-12);
        assert!((yaw(&est[2]) - 0.01).abs() < 1e-12);
        assert!((yaw(&est[3]) - (0.01 + cfg.max_dt)).abs() < 1e-12);
        assert!((yaw(&est[4]) - (0.02 + cfg.max_dt)).abs() < 1e-12);
    }

    #[test]
    fn streaming_equals_batch_whatever_the_chunks() {
        // A wobbling, turning phone whose first samples read zero (a sensor starting up).
        let n = 900;
        let t = times(n, 200.0);
        let gyro: Vec<DeviceVec> = t
            .iter()
            .map(|&ti| DeviceVec::new(0.3 * (2.0 * ti).sin(), 0.1, 0.5 + 0.2 * ti.cos()))
            .collect();
        let acce: Vec<DeviceVec> = t
            .iter()
            .enumerate()
            .map(|(i, &ti)| {
                if i < 7 {
                    DeviceVec::ZERO
                } else {
                    DeviceVec::new((5.0 * ti).sin(), 1.0 + 0.2 * ti, G)
                }
            })
            .collect();
        let cfg = FilterConfig::default();
        let batch = estimate_orientation(&t, &gyro, &acce, &cfg).unwrap();
        for chunk in [1, 3, 26, 27, 1000] {
            let mut filter = OrientationFilter::new(cfg).unwrap();
            let mut out = Vec::new();
            for (c, range) in (0..n).collect::<Vec<_>>().chunks(chunk).enumerate() {
                for &i in range {
                    filter.push(t[i], gyro[i], acce[i], &mut out).unwrap();
                }
                // Nothing comes out before the initial tilt is known: 7 zero samples and
                // 20 nonzero ones, and the settling time (2 s: sample 400 is the first at
                // or after it).
                let pushed = (c * chunk + range.len()).min(n);
                assert_eq!(
                    out.len(),
                    if pushed < 401 { 0 } else { pushed },
                    "chunk {chunk}"
                );
            }
            filter.finish(&mut out).unwrap();
            assert_eq!(out, batch, "chunk {chunk}");
            assert_eq!(filter.orientation(), batch.last().copied());
        }
        // A stream shorter than the initial tilt needs comes out at `finish`.
        let mut filter = OrientationFilter::new(cfg).unwrap();
        let mut out = Vec::new();
        for i in 0..15 {
            filter.push(t[i], gyro[i], acce[i], &mut out).unwrap();
        }
        assert!(out.is_empty() && filter.orientation().is_none());
        filter.finish(&mut out).unwrap();
        assert_eq!(
            out,
            estimate_orientation(&t[..15], &gyro[..15], &acce[..15], &cfg).unwrap()
        );
        // A refused sample leaves the filter as it was: the stream goes on as if never sent.
        let mut filter = OrientationFilter::starting_at(batch[0], cfg).unwrap();
        let mut out = Vec::new();
        for i in 0..n {
            if i == 400 {
                let bad = DeviceVec::new(f64::NAN, 0.0, 0.0);
                assert_eq!(
                    filter.push(t[i], bad, acce[i], &mut out),
                    Err(EstimateError::NonFinite {
                        what: "gyro",
                        index: 400
                    })
                );
                assert_eq!(
                    filter.push(t[i - 2], gyro[i], acce[i], &mut out),
                    Err(EstimateError::TimeDecreases { index: 400 })
                );
            }
            filter.push(t[i], gyro[i], acce[i], &mut out).unwrap();
        }
        filter.finish(&mut out).unwrap();
        assert_eq!(
            out,
            estimate_orientation_from(batch[0], &t, &gyro, &acce, &cfg).unwrap()
        );
    }

    #[test]
    fn bad_input_is_an_error() {
        let cfg = FilterConfig::default();
        let g = DeviceVec::new(0.0, 0.0, G);
        let z = DeviceVec::ZERO;
        assert_eq!(estimate_orientation(&[], &[], &[], &cfg).unwrap(), vec![]);
        assert!(matches!(
            estimate_orientation(&[0.0, 1.0], &[z], &[g, g], &cfg),
            Err(EstimateError::LengthMismatch { what: "gyro", .. })
        ));
        assert!(matches!(
            estimate_orientation(&[0.0, f64::NAN], &[z, z], &[g, g], &cfg),
            Err(EstimateError::NonFinite {
                what: "time",
                index: 1
            })
        ));
        assert!(matches!(
            estimate_orientation(
                &[0.0, 1.0],
                &[z, z],
                &[g, DeviceVec::new(f64::INFINITY, 0.0, 0.0)],
                &cfg
            ),
            Err(EstimateError::NonFinite {
                what: "acce",
                index: 1
            })
        ));
        assert!(matches!(
            estimate_orientation(&[1.0, 0.0], &[z, z], &[g, g], &cfg),
            Err(EstimateError::TimeDecreases { index: 1 })
        ));
        assert_eq!(
            estimate_orientation(&[0.0, 1.0], &[z, z], &[z, z], &cfg),
            Err(EstimateError::NoGravity)
        );
        let bad = FilterConfig { max_dt: 0.0, ..cfg };
        assert!(matches!(
            estimate_orientation(&[0.0], &[z], &[g], &bad),
            Err(EstimateError::InvalidConfig(_))
        ));
    }

    #[test]
    fn zero_accel_samples_skip_correction() {
        // Free fall for a moment: zero accelerometer must neither panic nor produce NaN.
        let n = 100;
        let t = times(n, 100.0);
        let gyro = vec![DeviceVec::ZERO; n];
        let mut acce = vec![DeviceVec::new(0.0, 0.0, G); n];
        for a in &mut acce[10..60] {
            *a = DeviceVec::ZERO;
        }
        let est = estimate_orientation(&t, &gyro, &acce, &FilterConfig::default()).unwrap();
        assert!(
            est.iter()
                .all(|q| q.to_wxyz().iter().all(|c| c.is_finite()))
        );
        assert!(
            est.iter()
                .all(|q| tilt_error(*q, WorldFromDevice::identity()) < 1e-12)
        );
    }

    #[test]
    fn heading_difference_of_pure_yaw_and_wrapping() {
        let base = WorldFromDevice::from_scaled_axis(Vector3::new(0.3, 0.2, 0.0));
        for &psi in &[0.0, 0.5, -1.0, 3.0, -3.0] {
            let yaw = Rot::<World, World>::from_axis_angle(&Vector3::z_axis(), psi);
            let truth = yaw * base;
            assert!((heading_difference(base, truth) - psi).abs() < 1e-12);
            assert!(tilt_error(base, truth) < 1e-12);
        }
        // Unwrapping: a heading offset growing past pi stays continuous.
        let est: Vec<WorldFromDevice> = vec![base; 50];
        let truth: Vec<WorldFromDevice> = (0..50)
            .map(|i| {
                Rot::<World, World>::from_axis_angle(&Vector3::z_axis(), 0.2 * i as f64) * base
            })
            .collect();
        let errs = orientation_errors(&est, &truth).unwrap();
        assert!((errs.heading_drift[49] - 0.2 * 49.0).abs() < 1e-9);
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
    }
}
