//! Inputs of a correction: per-frame IMU slices and regressed velocity targets.

use ridi_frames::{DeviceVec, StabHorizontal, WorldFromDevice};
use serde::{Deserialize, Serialize};

use crate::error::CorrectError;

/// Per-frame inputs of a correction, as plain slices (one entry per frame).
///
/// All slices must have the length of `time`.
#[derive(Debug, Clone, Copy)]
pub struct ImuSlices<'a> {
    /// Timestamps, seconds, strictly increasing.
    pub time: &'a [f64],
    /// Linear acceleration (gravity removed), device frame, m/s².
    pub linacce: &'a [DeviceVec],
    /// Device orientation, world-from-device.
    pub orientation: &'a [WorldFromDevice],
    /// Gravity as the Android gravity sensor reports it (pointing up), device frame. Only the
    /// target frames use it, to build the stabilized frame S.
    pub gravity: &'a [DeviceVec],
}

impl ImuSlices<'_> {
    /// Number of frames.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// `true` when there is no frame.
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// Checks lengths, finiteness, increasing time and the largest step `max_dt`.
    pub fn validate(&self, max_dt: f64) -> Result<(), CorrectError> {
        let n = self.time.len();
        if n == 0 {
            return Err(CorrectError::Empty);
        }
        for (what, got) in [
            ("linacce", self.linacce.len()),
            ("orientation", self.orientation.len()),
            ("gravity", self.gravity.len()),
        ] {
            if got != n {
                return Err(CorrectError::LengthMismatch {
                    what,
                    expected: n,
                    found: got,
                });
            }
        }
        validate_time(self.time, max_dt)?;
        // Branch-free scan first (one pass, no early exit); the loop below only runs to name
        // the culprit.
        let mut ok = true;
        for f in 0..n {
            let (a, g) = (self.linacce[f].vector(), self.gravity[f].vector());
            let q = &self.orientation[f].quaternion().coords;
            let s = a.x + a.y + a.z + g.x + g.y + g.z + q.x + q.y + q.z + q.w;
            // A sum of finite values can only overflow, which the slow path then clears.
            ok &= s.is_finite();
        }
        if ok {
            return Ok(());
        }
        for f in 0..n {
            if !self.linacce[f].is_finite() {
                return Err(CorrectError::NonFinite {
                    what: "linacce",
                    index: f,
                });
            }
            if !self.gravity[f].is_finite() {
                return Err(CorrectError::NonFinite {
                    what: "gravity",
                    index: f,
                });
            }
            if !self.orientation[f]
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

/// A regressed velocity: the horizontal velocity in the stabilized frame S at one frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct VelocityTarget {
    /// Frame index (into the slices of the correction).
    pub frame: usize,
    /// `[S-x, S-z]` velocity, m/s (forward is -z).
    pub velocity: StabHorizontal,
}

/// Checks that targets are finite, strictly increasing and inside `0..len`.
pub(crate) fn validate_targets(targets: &[VelocityTarget], len: usize) -> Result<(), CorrectError> {
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
