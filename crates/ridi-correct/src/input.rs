//! Inputs of a correction: checks of its frames, and of the velocities at frames it follows.

use ridi_frames::{ImuFrames, ImuStream, StabHorizontal};
use serde::{Deserialize, Serialize};

use crate::error::CorrectError;

/// Checks a correction's frames: not empty; linear acceleration, gravity and orientation as
/// long as `time` and finite; time finite and increasing by at most `max_dt`. The gyro is not
/// read (it may be empty).
pub(crate) fn validate_imu(imu: &ImuFrames<'_>, max_dt: f64) -> Result<(), CorrectError> {
    let n = imu.len();
    if n == 0 {
        return Err(CorrectError::Empty);
    }
    imu.check_streams(&[
        ImuStream::Linacce,
        ImuStream::Gravity,
        ImuStream::Orientation,
    ])?;
    validate_time(imu.time, max_dt)?;
    // Branch-free scan first (one pass, no early exit); the loop below only runs to name
    // the culprit.
    let mut ok = true;
    for f in 0..n {
        let (a, g) = (imu.linacce[f].vector(), imu.gravity[f].vector());
        let q = &imu.orientation[f].quaternion().coords;
        let s = a.x + a.y + a.z + g.x + g.y + g.z + q.x + q.y + q.z + q.w;
        // A sum of finite values can only overflow, which the slow path then clears.
        ok &= s.is_finite();
    }
    if ok {
        return Ok(());
    }
    for f in 0..n {
        if !imu.linacce[f].is_finite() {
            return Err(CorrectError::NonFinite {
                what: "linacce",
                index: f,
            });
        }
        if !imu.gravity[f].is_finite() {
            return Err(CorrectError::NonFinite {
                what: "gravity",
                index: f,
            });
        }
        if !imu.orientation[f]
            .quaternion()
            .coords
            .iter()
            .all(|c| c.is_finite())
        {
            return Err(CorrectError::NonFinite {
                what: "orientation",
                index: f,
            });
        }
    }
    Ok(())
}

/// Checks that `time` is finite, strictly increasing, with steps of at most `max_dt`.
pub(crate) fn validate_time(time: &[f64], max_dt: f64) -> Result<(), CorrectError> {
    let finite = time.iter().fold(true, |ok, t| ok & t.is_finite());
    let (lo, hi) = time
        .windows(2)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), w| {
            let dt = w[1] - w[0];
            (lo.min(dt), hi.max(dt))
        });
    if finite && lo > 0.0 && hi <= max_dt {
        return Ok(());
    }
    for (f, &t) in time.iter().enumerate() {
        if !t.is_finite() {
            return Err(CorrectError::NonFinite {
                what: "time",
                index: f,
            });
        }
        if f > 0 {
            let dt = t - time[f - 1];
            if dt <= 0.0 {
                return Err(CorrectError::TimeNotIncreasing { frame: f });
            }
            if dt > max_dt {
                return Err(CorrectError::Gap {
                    frame: f,
                    dt,
                    max_dt,
                });
            }
        }
    }
    Ok(())
}

/// A velocity at a frame: the horizontal velocity in the stabilized frame S that the
/// correction makes the integrated velocity follow there (a regressed one, or a ground-truth
/// one for an oracle). Not a training target (ridi-features' targets are those). S is the
/// correction's [`CorrectionConfig::up_axis`](crate::CorrectionConfig::up_axis): set it to
/// the S the velocities were regressed in (a trained model's), which a bare velocity cannot
/// say (the [`Tracker`](crate::Tracker) checks it against its regressor's
/// [`up_axis`](crate::VelocityRegressor::up_axis)).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FrameVelocity {
    /// Frame index (into the slices of the correction).
    pub frame: usize,
    /// `[S-x, S-z]` velocity, m/s (forward is -z).
    pub velocity: StabHorizontal,
}

/// Checks that targets are finite, strictly increasing and inside `0..len`.
pub(crate) fn validate_targets(targets: &[FrameVelocity], len: usize) -> Result<(), CorrectError> {
    for (i, t) in targets.iter().enumerate() {
        if t.frame >= len {
            return Err(CorrectError::TargetOutOfRange {
                index: i,
                frame: t.frame,
                len,
            });
        }
        if i > 0 && t.frame <= targets[i - 1].frame {
            return Err(CorrectError::TargetsNotIncreasing { index: i });
        }
        if !t.velocity.is_finite() {
            return Err(CorrectError::NonFiniteTarget {
                index: i,
                frame: t.frame,
            });
        }
    }
    Ok(())
}
