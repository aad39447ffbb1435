//! Synthetic walks with known truth, shared by the integration tests.
#![allow(dead_code)]

use ridi_correct::{FrameVelocity, Integrator, Knots, Pose};
use ridi_frames::nalgebra::Vector3;
use ridi_frames::{DeviceVec, ImuFrames, Rot, World, WorldFromDevice, WorldVec, stab_from_world};

/// A walk whose true world acceleration is known, seen through a biased accelerometer.
pub(crate) struct Walk {
    pub time: Vec<f64>,
    pub gyro: Vec<DeviceVec>,
    pub linacce: Vec<DeviceVec>,
    pub orientation: Vec<WorldFromDevice>,
    pub gravity: Vec<DeviceVec>,
    /// True world acceleration and the poses it integrates to (trapezoidal rule, so that the
    /// correction's own integration reproduces them exactly).
    pub acc_true: Vec<WorldVec>,
    pub poses_true: Vec<Pose>,
    /// True device-frame bias per frame (`linacce = true - bias`).
    pub bias: Vec<DeviceVec>,
    pub knots: Knots,
    pub bias_knots: Vec<DeviceVec>,
}

/// Walk of `n` frames at about 200 Hz (slightly irregular when `jitter`), starting with
/// world velocity `v0`, with a low-frequency bias that is piecewise linear on knots every
/// `spacing` frames.
pub(crate) fn walk(n: usize, spacing: usize, v0: WorldVec, jitter: bool) -> Walk {
    let time: Vec<f64> = (0..n)
        .map(|i| {
            let j = if jitter {
                0.0004 * ((i as f64) * 1.7).sin()
            } else {
                0.0
            };
            i as f64 * 0.005 + j
        })
        .collect();
    let orientation: Vec<WorldFromDevice> = time
        .iter()
        .map(|&t| {
            // A phone carried with a swinging tilt and a slowly turning heading.
            Rot::<World, World>::from_scaled_axis(Vector3::new(0.0, 0.0, 0.3 * t + 0.4))
                * WorldFromDevice::from_scaled_axis(Vector3::new(
                    1.2 + 0.2 * (3.0 * t).sin(),
                    0.15 * (2.1 * t).cos(),
                    0.1,
                ))
        })
        .collect();
    let acc_true: Vec<WorldVec> = time
        .iter()
        .map(|&t| {
            WorldVec::new(
                0.8 * (1.9 * t).sin() - 0.3 * (0.4 * t).cos(),
                0.5 * (2.3 * t + 1.0).cos() + 0.2 * (0.3 * t).sin(),
                0.0,
            )
        })
        .collect();
    let knots = Knots::new(&time, spacing);
    let bias_knots: Vec<DeviceVec> = knots
        .times()
        .iter()
        .map(|&t| {
            DeviceVec::new(
                0.12 * (0.11 * t).sin() + 0.05,
                -0.08 * (0.07 * t + 0.5).cos(),
                0.06 * (0.05 * t).sin() - 0.1,
            )
        })
        .collect();
    let curve = ridi_correct::BiasCurve::new(knots.clone(), bias_knots.clone()).unwrap();
    let bias: Vec<DeviceVec> = (0..n).map(|f| curve.at(f, time[f])).collect();
    let linacce: Vec<DeviceVec> = (0..n)
        .map(|f| orientation[f].inverse() * acc_true[f] - bias[f])
        .collect();
    let gravity: Vec<DeviceVec> = orientation
        .iter()
        .map(|q| ridi_frames::gravity_in_device(*q, 9.81))
        .collect();
    let gyro = vec![DeviceVec::new(0.01, 0.02, 0.3); n];
    let mut it = Integrator::new(time[0], acc_true[0], v0, WorldVec::ZERO);
    let mut poses_true = vec![it.pose()];
    for f in 1..n {
        poses_true.push(it.step(time[f], acc_true[f]));
    }
    Walk {
        time,
        gyro,
        linacce,
        orientation,
        gravity,
        acc_true,
        poses_true,
        bias,
        knots,
        bias_knots,
    }
}

impl Walk {
    pub(crate) fn imu(&self) -> ImuFrames<'_> {
        ImuFrames::new(
            &self.time,
            &self.gyro,
            &self.linacce,
            &self.gravity,
            &self.orientation,
        )
        .unwrap()
    }

    /// Exact regressed velocity (true horizontal S velocity) at `frame`.
    pub(crate) fn target(&self, frame: usize) -> FrameVelocity {
        let vs = stab_from_world(self.orientation[frame], self.gravity[frame])
            * self.poses_true[frame].velocity;
        FrameVelocity {
            frame,
            velocity: vs.horizontal(),
        }
    }

    /// Exact targets at `start, start + every, ...`.
    pub(crate) fn targets(&self, start: usize, every: usize) -> Vec<FrameVelocity> {
        (start..self.time.len())
            .step_by(every)
            .map(|f| self.target(f))
            .collect()
    }
}

pub(crate) fn max_position_error(a: &[Pose], b: &[Pose]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p.position - q.position).norm())
        .fold(0.0, f64::max)
}
