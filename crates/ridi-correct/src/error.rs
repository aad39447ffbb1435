//! Errors of the batch correction and of the streaming tracker.

use thiserror::Error;

/// `v` for a message, as the other crates print numbers: at most three decimals (a step
/// between two timestamps is `0.505` s, not `0.5050000000000008`), four significant digits
/// below a thousandth, so that a tiny step does not print as `0`.
pub(crate) fn rounded(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let a = v.abs();
    let digits = if a >= 1e-3 {
        3
    } else {
        3 - a.log10().floor() as i32
    };
    let scale = 10f64.powi(digits);
    (v * scale).round() / scale
}

/// Why a batch correction (or an integration) was refused.
///
/// Every check happens before any arithmetic, so an error never leaves a partly written result.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CorrectError {
    /// The sequence has no frame.
    #[error("the sequence is empty")]
    Empty,
    /// Two per-frame slices have different lengths.
    #[error("{what} has {found} entries, expected {expected} (one per frame)")]
    LengthMismatch {
        /// Which input.
        what: &'static str,
        /// Number of frames (length of `time`).
        expected: usize,
        /// Length found.
        found: usize,
    },
    /// A NaN or infinite value.
    #[error("{what} is not finite at frame {index}")]
    NonFinite {
        /// Which input.
        what: &'static str,
        /// Frame index.
        index: usize,
    },
    /// A velocity target with a NaN or infinite component.
    #[error("velocity target {index} (frame {frame}) is not finite")]
    NonFiniteTarget {
        /// Target index.
        index: usize,
        /// The frame it is for.
        frame: usize,
    },
    /// `time[frame] <= time[frame - 1]`.
    #[error("time does not increase at frame {frame}")]
    TimeNotIncreasing {
        /// First frame whose time is not after its predecessor's.
        frame: usize,
    },
    /// The time step before `frame` exceeds the configured maximum.
    #[error("gap of {} s before frame {frame} exceeds max_dt = {max_dt} s", rounded(*dt))]
    Gap {
        /// First frame after the gap.
        frame: usize,
        /// The time step found, seconds.
        dt: f64,
        /// The configured limit, seconds.
        max_dt: f64,
    },
    /// A velocity target refers to a frame outside the sequence.
    #[error("target {index} is at frame {frame}, but the sequence has {len} frames")]
    TargetOutOfRange {
        /// Index of the target.
        index: usize,
        /// Its frame.
        frame: usize,
        /// Number of frames.
        len: usize,
    },
    /// Target frames must be strictly increasing.
    #[error("target {index} is not after target {}", index - 1)]
    TargetsNotIncreasing {
        /// Index of the first out-of-order target.
        index: usize,
    },
    /// The initial velocity cannot be estimated without any velocity target.
    #[error("estimating the initial velocity needs at least one velocity target")]
    NoTargets,
    /// A configuration value is out of its domain.
    #[error("invalid configuration: {0}")]
    InvalidConfig(&'static str),
    /// A bias curve with another number of values than knots.
    #[error("a bias curve needs one value per knot: {knots} knots, {values} values")]
    BiasLength {
        /// Number of knots.
        knots: usize,
        /// Number of values.
        values: usize,
    },
    /// Stored knots that [`Knots::new`](crate::Knots::new) cannot have made.
    #[error("invalid knots: {0}")]
    InvalidKnots(&'static str),
    /// At a target frame, the horizontal S rows and the world vertical are (nearly) linearly
    /// dependent: gravity and orientation disagree by about 90 degrees.
    #[error("inconsistent gravity and orientation at target frame {frame}")]
    DegenerateFrame {
        /// The target's frame.
        frame: usize,
    },
    /// The reduced normal equations were not numerically positive definite (extreme weights).
    #[error("the correction system is not numerically positive definite")]
    NotPositiveDefinite,
    /// Allocation of the factorization workspace failed.
    #[error("out of memory while factorizing the correction system")]
    OutOfMemory,
}

/// An [`ImuFrames`](ridi_frames::ImuFrames) length error is this crate's `LengthMismatch`, so
/// that a caller matches one spelling for every input of the crate, whichever check found it.
impl From<ridi_frames::ImuError> for CorrectError {
    fn from(e: ridi_frames::ImuError) -> Self {
        let ridi_frames::ImuError::LengthMismatch {
            what,
            expected,
            found,
        } = e;
        CorrectError::LengthMismatch {
            what,
            expected,
            found,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gap_is_printed_rounded() {
        let e = CorrectError::Gap {
            frame: 120,
            dt: 0.5050000000000008,
            max_dt: 0.1,
        };
        assert_eq!(
            e.to_string(),
            "gap of 0.505 s before frame 120 exceeds max_dt = 0.1 s"
        );
        assert_eq!(rounded(0.000123456), 0.0001235);
        assert_eq!(rounded(1234.5678), 1234.568);
        assert_eq!(rounded(0.0), 0.0);
    }
}
