//! Double integration with the trapezoidal rule.
//!
//! Both the correction (its velocity model) and every output (batch trajectories, the
//! tracker's poses) use the same scheme, so a corrected velocity that matches a target in the
//! solve matches it in the output too:
//!
//! ```text
//! v(f) = v(f-1) + (a(f-1) + a(f)) / 2 * dt_f      dt_f = t(f) - t(f-1)
//! p(f) = p(f-1) + (v(f-1) + v(f)) / 2 * dt_f
//! ```
//!
//! The original C++ used explicit (left-point) Euler; the trapezoidal rule is second order,
//! has no half-sample lag, and bridges an irregular step by linear interpolation.

use ridi_frames::{WorldVec, nalgebra::Vector3};
use serde::{Deserialize, Serialize};

use crate::error::CorrectError;
use crate::input::{validate_imu, validate_time};
use crate::knots::BiasCurve;
use ridi_frames::ImuFrames;

/// Position and velocity of one frame, world frame.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Pose {
    /// Timestamp, seconds.
    pub time: f64,
    /// Position, m, relative to the start.
    pub position: WorldVec,
    /// Velocity, m/s.
    pub velocity: WorldVec,
}

/// Streaming trapezoidal integrator: the one place where the scheme is implemented.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Integrator {
    time: f64,
    acc: Vector3<f64>,
    vel: Vector3<f64>,
    pos: Vector3<f64>,
}

impl Integrator {
    /// Starts at `time` with world acceleration `acc`, velocity `vel` and position `pos`.
    pub fn new(time: f64, acc: WorldVec, vel: WorldVec, pos: WorldVec) -> Self {
        Self {
            time,
            acc: *acc.vector(),
            vel: *vel.vector(),
            pos: *pos.vector(),
        }
    }

    /// Advances to `time` with the world acceleration `acc` measured there.
    #[inline]
    pub fn step(&mut self, time: f64, acc: WorldVec) -> Pose {
        let dt = time - self.time;
        let acc = *acc.vector();
        let vel = self.vel + (self.acc + acc) * (0.5 * dt);
        self.pos += (self.vel + vel) * (0.5 * dt);
        self.vel = vel;
        self.acc = acc;
        self.time = time;
        self.pose()
    }

    /// The current pose.
    #[inline]
    pub fn pose(&self) -> Pose {
        Pose {
            time: self.time,
            position: WorldVec::from_vector(self.pos),
            velocity: WorldVec::from_vector(self.vel),
        }
    }
}

/// Integrates world-frame accelerations twice from velocity `v0` and position `p0` at
/// `time[0]`: one pose per frame.
///
/// Errors if the lengths differ, a value is not finite or time does not increase.
pub fn integrate(
    time: &[f64],
    acc_world: &[WorldVec],
    v0: WorldVec,
    p0: WorldVec,
) -> Result<Vec<Pose>, CorrectError> {
    if time.is_empty() {
        return Err(CorrectError::Empty);
    }
    if acc_world.len() != time.len() {
        return Err(CorrectError::LengthMismatch {
            what: "acc_world",
            expected: time.len(),
            found: acc_world.len(),
        });
    }
    validate_time(time, f64::INFINITY)?;
    if let Some(f) = acc_world.iter().position(|a| !a.is_finite()) {
        return Err(CorrectError::NonFinite {
            what: "acc_world",
            index: f,
        });
    }
    if !(v0.is_finite() && p0.is_finite()) {
        return Err(CorrectError::NonFinite {
            what: "initial state",
            index: 0,
        });
    }
    Ok(integrate_unchecked(time, acc_world, v0, p0))
}

pub(crate) fn integrate_unchecked(
    time: &[f64],
    acc_world: &[WorldVec],
    v0: WorldVec,
    p0: WorldVec,
) -> Vec<Pose> {
    let mut out = Vec::with_capacity(time.len());
    let mut it = Integrator::new(time[0], acc_world[0], v0, p0);
    out.push(it.pose());
    for (&t, &a) in time.iter().zip(acc_world).skip(1) {
        out.push(it.step(t, a));
    }
    out
}

/// World-frame accelerations `R_WI(f) a_I(f)` (no bias correction).
///
/// # Errors
/// Refuses frames a correction refuses (any time step is accepted).
pub fn world_acceleration(imu: &ImuFrames<'_>) -> Result<Vec<WorldVec>, CorrectError> {
    validate_imu(imu, f64::INFINITY)?;
    Ok(imu
        .orientation
        .iter()
        .zip(imu.linacce)
        .map(|(q, a)| *q * *a)
        .collect())
}

/// Corrected world-frame accelerations `R_WI(f) (a_I(f) + x(f))`, `x` the bias curve (frames
/// past its last knot take the last knot's value).
///
/// # Errors
/// Refuses frames a correction refuses (any time step is accepted), and a curve whose knots'
/// times do not increase strictly.
pub fn corrected_acceleration(
    imu: &ImuFrames<'_>,
    bias: &BiasCurve,
) -> Result<Vec<WorldVec>, CorrectError> {
    validate_imu(imu, f64::INFINITY)?;
    bias.knots().check_times()?;
    Ok(corrected_acceleration_unchecked(imu, bias))
}

/// [`corrected_acceleration`] of slices already validated.
pub(crate) fn corrected_acceleration_unchecked(
    imu: &ImuFrames<'_>,
    bias: &BiasCurve,
) -> Vec<WorldVec> {
    (0..imu.len())
        .map(|f| imu.orientation[f] * (imu.linacce[f] + bias.at(f, imu.time[f])))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trapezoid_is_exact_for_linear_acceleration() {
        // a(t) = t  =>  v = t^2/2 (trapezoid exact), p = t^3/6 (error O(dt^2)).
        let time: Vec<f64> = (0..101).map(|i| i as f64 * 0.01).collect();
        let acc: Vec<WorldVec> = time.iter().map(|&t| WorldVec::new(t, 0.0, -t)).collect();
        let out = integrate(&time, &acc, WorldVec::ZERO, WorldVec::ZERO).unwrap();
        let last = out.last().unwrap();
        assert!((last.velocity.x() - 0.5).abs() < 1e-12);
        assert!((last.velocity.z() + 0.5).abs() < 1e-12);
        assert!((last.position.x() - 1.0 / 6.0).abs() < 1e-4);
    }

    #[test]
    fn integrate_rejects_bad_input() {
        let t = [0.0, 0.1, 0.1];
        let a = [WorldVec::ZERO; 3];
        assert_eq!(
            integrate(&t, &a, WorldVec::ZERO, WorldVec::ZERO),
            Err(CorrectError::TimeNotIncreasing { frame: 2 })
        );
        let t = [0.0, 0.1, 0.2];
        let mut a = [WorldVec::ZERO; 3];
        a[1] = WorldVec::new(f64::NAN, 0.0, 0.0);
        assert!(matches!(
            integrate(&t, &a, WorldVec::ZERO, WorldVec::ZERO),
            Err(CorrectError::NonFinite { index: 1, .. })
        ));
        assert!(matches!(
            integrate(&t, &a[..2], WorldVec::ZERO, WorldVec::ZERO),
            Err(CorrectError::LengthMismatch { .. })
        ));
        assert_eq!(
            integrate(&[], &[], WorldVec::ZERO, WorldVec::ZERO),
            Err(CorrectError::Empty)
        );
    }

    #[test]
    fn world_accelerations_refuse_slices_of_other_lengths() {
        use crate::knots::Knots;
        use ridi_frames::{DeviceVec, WorldFromDevice};
        let time: Vec<f64> = (0..20).map(|i| f64::from(i) * 0.005).collect();
        let linacce = vec![DeviceVec::new(0.1, 0.0, 0.0); 20];
        let orientation = vec![WorldFromDevice::identity(); 20];
        let gravity = vec![DeviceVec::new(0.0, 0.0, 9.81); 20];
        let gyro = vec![DeviceVec::ZERO; 20];
        let mut imu = ImuFrames::new(&time, &gyro, &linacce, &gravity, &orientation).unwrap();
        let bias = BiasCurve::zero(Knots::new(&time, 5));
        assert_eq!(
            world_acceleration(&imu).unwrap()[3],
            WorldVec::new(0.1, 0.0, 0.0)
        );
        assert_eq!(corrected_acceleration(&imu, &bias).unwrap().len(), 20);
        imu.orientation = &orientation[..10];
        let short = Err(CorrectError::LengthMismatch {
            what: "orientation",
            expected: 20,
            found: 10,
        });
        assert_eq!(world_acceleration(&imu), short);
        assert_eq!(corrected_acceleration(&imu, &bias), short);
        // Knots at one time (built from another timeline) would weigh 0 / 0: refused.
        imu.orientation = &orientation;
        let stuck = BiasCurve::zero(Knots::new(&[0.0; 20], 5));
        assert_eq!(
            corrected_acceleration(&imu, &stuck),
            Err(CorrectError::InvalidKnots(
                "times must be finite and increasing"
            ))
        );
    }
}
