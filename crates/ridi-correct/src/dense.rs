//! The objective, evaluated directly, and a dense reference solver.
//!
//! Both follow the textbook formulation (velocities as prefix sums, a dense design matrix)
//! and share nothing with the banded solver but the knot placement and the input checks,
//! which makes them an independent check of it. The dense solve needs `O(R K)` memory and
//! `O(K³)` time: fine for a minute of data, not for an hour.

use ridi_frames::nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use ridi_frames::{DeviceVec, WorldVec};

use crate::config::{CorrectionConfig, InitialVelocity};
use crate::error::CorrectError;
use crate::input::{FrameVelocity, validate_imu, validate_targets};
use crate::integrate::{corrected_acceleration_unchecked, integrate_unchecked};
use crate::knots::{BiasCurve, Knots};
use crate::solve::Correction;
use ridi_frames::ImuFrames;

/// The value of the correction objective (see the [crate docs](crate#the-objective)) for a
/// given bias and initial velocity, computed by integrating the corrected accelerations.
pub fn objective(
    config: &CorrectionConfig,
    imu: &ImuFrames<'_>,
    targets: &[FrameVelocity],
    correction: &Correction,
) -> Result<f64, CorrectError> {
    config.validate()?;
    validate_imu(imu, config.max_dt)?;
    validate_targets(targets, imu.len())?;
    let acc = corrected_acceleration_unchecked(imu, &correction.bias);
    let poses = integrate_unchecked(imu.time, &acc, correction.initial_velocity, WorldVec::ZERO);
    let mut e = 0.0;
    for t in targets {
        let v = poses[t.frame].velocity;
        let vs = config
            .up_axis
            .stab_from_world(imu.orientation[t.frame], imu.gravity[t.frame])
            * v;
        e += config.horizontal_weight
            * ((vs.x() - t.velocity[0]).powi(2) + (vs.z() - t.velocity[1]).powi(2))
            + config.vertical_weight * v.z().powi(2);
    }
    let prior: f64 = correction
        .bias
        .values
        .iter()
        .map(|x| x.vector().norm_squared())
        .sum();
    Ok(e + config.lambda * prior)
}

/// Reference solver: builds the dense design matrix from prefix sums of the per-step
/// integrals and solves the dense normal equations by Cholesky. Same objective and result as
/// [`Corrector::solve`](crate::Corrector::solve), at a cost that grows cubically with the
/// number of knots; meant for verification and benchmarks.
pub fn solve_dense(
    config: &CorrectionConfig,
    imu: &ImuFrames<'_>,
    targets: &[FrameVelocity],
) -> Result<Correction, CorrectError> {
    config.validate()?;
    validate_imu(imu, config.max_dt)?;
    validate_targets(targets, imu.len())?;
    let knots = Knots::new(imu.time, config.knot_spacing);
    let estimate = config.initial_velocity == InitialVelocity::Estimate;
    if targets.is_empty() {
        return match config.initial_velocity {
            InitialVelocity::Fixed(v) => Ok(Correction {
                bias: BiasCurve::zero(knots),
                initial_velocity: v,
            }),
            InitialVelocity::Estimate => Err(CorrectError::NoTargets),
        };
    }
    let nk = knots.len();
    let nz = 3 * nk + if estimate { 3 } else { 0 };
    // Velocity at the current frame = cum * z + c.
    let mut cum = DMatrix::<f64>::zeros(3, nz);
    let mut c = Vector3::<f64>::zeros();
    match config.initial_velocity {
        InitialVelocity::Fixed(v) => c = *v.vector(),
        InitialVelocity::Estimate => {
            cum.view_mut((0, 3 * nk), (3, 3))
                .copy_from(&Matrix3::<f64>::identity());
        }
    }
    let r = targets.len();
    let mut jac = DMatrix::<f64>::zeros(3 * r, nz);
    let mut rhs = DVector::<f64>::zeros(3 * r);
    let (sh, sv) = (
        config.horizontal_weight.sqrt(),
        config.vertical_weight.sqrt(),
    );
    let mut emit = |j: usize, cum: &DMatrix<f64>, c: &Vector3<f64>| {
        let t = targets[j];
        let rsw = config
            .up_axis
            .stab_from_world(imu.orientation[t.frame], imu.gravity[t.frame])
            .matrix();
        let rows: [(Vector3<f64>, f64, f64); 3] = [
            (rsw.row(0).transpose(), sh, t.velocity[0]),
            (rsw.row(2).transpose(), sh, t.velocity[1]),
            (Vector3::z(), sv, 0.0),
        ];
        for (q, (h, w, u)) in rows.iter().enumerate() {
            let row = h.transpose() * cum * *w;
            jac.row_mut(3 * j + q).copy_from(&row);
            rhs[3 * j + q] = w * (u - h.dot(c));
        }
    };
    let mut j = 0;
    if targets[0].frame == 0 {
        emit(0, &cum, &c);
        j = 1;
    }
    let last = targets[r - 1].frame;
    for s in 1..=last {
        let dt = imu.time[s] - imu.time[s - 1];
        for f in [s - 1, s] {
            let rot = imu.orientation[f].matrix();
            let (k, w) = knots.locate(f, imu.time[f]);
            let mut blk = cum.view_mut((0, 3 * k), (3, 3));
            blk += rot * (0.5 * dt * (1.0 - w));
            if w != 0.0 {
                let mut blk = cum.view_mut((0, 3 * k + 3), (3, 3));
                blk += rot * (0.5 * dt * w);
            }
            c += rot * imu.linacce[f].vector() * (0.5 * dt);
        }
        if j < r && targets[j].frame == s {
            emit(j, &cum, &c);
            j += 1;
        }
    }
    let mut normal = jac.transpose() * &jac;
    for i in 0..3 * nk {
        normal[(i, i)] += config.lambda;
    }
    let b = jac.transpose() * rhs;
    let chol = normal.cholesky().ok_or(CorrectError::NotPositiveDefinite)?;
    let z = chol.solve(&b);
    let values = (0..nk)
        .map(|k| DeviceVec::new(z[3 * k], z[3 * k + 1], z[3 * k + 2]))
        .collect();
    let initial_velocity = match config.initial_velocity {
        InitialVelocity::Fixed(v) => v,
        InitialVelocity::Estimate => WorldVec::new(z[3 * nk], z[3 * nk + 1], z[3 * nk + 2]),
    };
    Ok(Correction {
        bias: BiasCurve { knots, values },
        initial_velocity,
    })
}
