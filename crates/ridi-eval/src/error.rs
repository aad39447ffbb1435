//! The one error type of this crate.

/// Why an evaluation could not be computed.
///
/// Every public function validates its inputs and returns one of these instead of panicking, so
/// a batch evaluation can report a bad sequence and carry on with the others.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EvalError {
    /// An input that needs at least one element was empty.
    #[error("{what} is empty")]
    Empty {
        /// Which input.
        what: &'static str,
    },
    /// Two inputs that must describe the same frames have different lengths.
    #[error("{what}: lengths differ ({expected} vs {found})")]
    LengthMismatch {
        /// Which pair of inputs.
        what: &'static str,
        /// Length of the first input, the one the second must match.
        expected: usize,
        /// Length of the second input.
        found: usize,
    },
    /// An input holds NaN or an infinity.
    #[error("{what}: non-finite value at index {index}")]
    NonFinite {
        /// Which input.
        what: &'static str,
        /// First offending element.
        index: usize,
    },
    /// Timestamps go backwards.
    #[error("times decrease at index {index}")]
    TimeDecreasing {
        /// First index whose time is smaller than the previous one.
        index: usize,
    },
    /// A sequence is shorter than a computation needs.
    #[error("{what} needs at least {needed} frames, got {got}")]
    TooShort {
        /// Which computation.
        what: &'static str,
        /// Minimum number of frames.
        needed: usize,
        /// Number of frames given.
        got: usize,
    },
    /// A configuration value is out of its domain.
    #[error("invalid parameter {name}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// The timeline's mean sampling rate ([`crate::estimate_rate_hz`]) is more than
    /// [`crate::RATE_TOLERANCE`] away from [`crate::EvalConfig::rate_hz`], the rate the RTE
    /// windows are counted at: every RTE would be over windows of the wrong duration (100 Hz
    /// data with the default 200 Hz gives windows twice as long, and about twice the RTE).
    #[error(
        "the timeline is sampled at {timeline_hz:.1} Hz but EvalConfig::rate_hz is {config_hz} Hz \
         (more than {pct:.0} % apart): the RTE windows would last {ratio:.2} times their nominal \
         seconds; set `rate_hz` to `estimate_rate_hz(times)`",
        pct = crate::RATE_TOLERANCE * 100.0,
        ratio = .config_hz / .timeline_hz
    )]
    RateMismatch {
        /// Mean rate of the timeline, Hz: `(N − 1) / (t_{N−1} − t₀)`.
        timeline_hz: f64,
        /// `EvalConfig::rate_hz`, Hz.
        config_hz: f64,
    },
    /// A class label is not one of the declared classes.
    #[error("label {label} is not a declared class ({classes} classes)")]
    UnknownLabel {
        /// The offending label, as text.
        label: String,
        /// Number of declared classes.
        classes: usize,
    },
    /// Step indices are out of range or not strictly increasing.
    #[error("step index {step} at position {position} is out of order or out of range")]
    BadStepIndex {
        /// Position in the step list.
        position: usize,
        /// The offending frame index.
        step: usize,
    },
}

/// Result alias for this crate.
pub type Result<T> = std::result::Result<T, EvalError>;

pub(crate) fn check_finite_points(what: &'static str, points: &[[f64; 2]]) -> Result<()> {
    match points
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        Some(index) => Err(EvalError::NonFinite { what, index }),
        None => Ok(()),
    }
}

pub(crate) fn check_finite(what: &'static str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(EvalError::NonFinite { what, index }),
        None => Ok(()),
    }
}

pub(crate) fn check_same_len(what: &'static str, left: usize, right: usize) -> Result<()> {
    if left == right {
        Ok(())
    } else {
        Err(EvalError::LengthMismatch {
            what,
            expected: left,
            found: right,
        })
    }
}

pub(crate) fn check_non_empty(what: &'static str, len: usize) -> Result<()> {
    if len == 0 {
        Err(EvalError::Empty { what })
    } else {
        Ok(())
    }
}

/// Validates a timeline: non-empty, finite, non-decreasing.
pub(crate) fn check_times(times: &[f64]) -> Result<()> {
    check_non_empty("times", times.len())?;
    check_finite("times", times)?;
    match times.windows(2).position(|w| w[1] < w[0]) {
        Some(i) => Err(EvalError::TimeDecreasing { index: i + 1 }),
        None => Ok(()),
    }
}

/// Validates an estimated/ground-truth pair on one timeline.
pub(crate) fn check_pair(est: &[[f64; 2]], gt: &[[f64; 2]]) -> Result<()> {
    check_non_empty("estimate", est.len())?;
    check_same_len("estimate vs ground truth", est.len(), gt.len())?;
    check_finite_points("estimate", est)?;
    check_finite_points("ground truth", gt)
}

pub(crate) fn check_positive(name: &'static str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(EvalError::InvalidParameter {
            name,
            reason: format!("must be finite and > 0, got {value}"),
        })
    }
}
