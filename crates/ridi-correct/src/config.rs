//! Configuration of the correction objective.

use ridi_frames::{UpAxis, WorldVec};
use serde::{Deserialize, Serialize};

use crate::error::CorrectError;

/// How the velocity at the first frame is obtained.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InitialVelocity {
    /// Known initial world velocity (the paper: zero, the walker starts at rest).
    Fixed(WorldVec),
    /// Three more unknowns, without prior: the initial velocity that best explains the targets
    /// (beyond the paper; useful when a recording starts mid-walk). Needs at least one target.
    Estimate,
}

impl Default for InitialVelocity {
    fn default() -> Self {
        Self::Fixed(WorldVec::ZERO)
    }
}

/// Parameters of the correction objective (see the [crate docs](crate#the-objective)).
///
/// Weights multiply *squared* residuals.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CorrectionConfig {
    /// Frames between bias knots (paper: 50).
    pub knot_spacing: usize,
    /// Weight `lambda` of the bias prior `sum ||x_k||²` (paper: 0.1). Finite and positive.
    pub lambda: f64,
    /// Weight `w_h` of the squared horizontal S-frame velocity discrepancy (paper: 1).
    pub horizontal_weight: f64,
    /// Weight `w_v` of the squared vertical world velocity at target frames (paper: 1).
    pub vertical_weight: f64,
    /// Initial velocity: fixed (default zero) or estimated.
    pub initial_velocity: InitialVelocity,
    /// Largest accepted time step, seconds: a longer gap is an error rather than an
    /// integration across missing data. Default 0.1 s (20 samples at 200 Hz).
    pub max_dt: f64,
    /// The definition of S the target velocities are expressed in: the one of the regressor
    /// that produced them. Default: the paper's, [`UpAxis::PlusY`]; models trained by `ridi`
    /// default to [`UpAxis::PlusOrMinusY`], so with a `ridi_regress::Cascade` set
    /// `up_axis: model.feature_config().up_axis` (the [`Tracker`](crate::Tracker) refuses a
    /// mismatch with its regressor; a batch correction cannot see where its targets came
    /// from, and a wrong S turns every target of an upside-down phone by a half turn).
    pub up_axis: UpAxis,
}

impl Default for CorrectionConfig {
    /// The paper's formulation: knots every 50 frames, `lambda = 0.1`, unit weights, start
    /// at rest.
    fn default() -> Self {
        Self {
            knot_spacing: 50,
            lambda: 0.1,
            horizontal_weight: 1.0,
            vertical_weight: 1.0,
            initial_velocity: InitialVelocity::default(),
            max_dt: 0.1,
            up_axis: UpAxis::PlusY,
        }
    }
}

impl CorrectionConfig {
    /// The weighting of the original C++ code: its Ceres residuals are multiplied by 10
    /// (horizontal), 1 (vertical) and 1 (bias prior) before squaring, so the squared-term
    /// weights are 100, 1 and 1.
    pub fn original_cpp() -> Self {
        Self {
            horizontal_weight: 100.0,
            vertical_weight: 1.0,
            lambda: 1.0,
            ..Self::default()
        }
    }

    /// Checks every value's domain.
    pub fn validate(&self) -> Result<(), CorrectError> {
        if self.knot_spacing == 0 {
            return Err(CorrectError::InvalidConfig(
                "knot_spacing must be at least 1",
            ));
        }
        if !(self.lambda.is_finite() && self.lambda > 0.0) {
            return Err(CorrectError::InvalidConfig(
                "lambda must be finite and positive",
            ));
        }
        // Both weights must be positive: the exact elimination inverts the per-target
        // 3x3 weight matrix (see the solve module).
        if !(self.horizontal_weight.is_finite() && self.horizontal_weight > 0.0) {
            return Err(CorrectError::InvalidConfig(
                "horizontal_weight must be finite and positive",
            ));
        }
        if !(self.vertical_weight.is_finite() && self.vertical_weight > 0.0) {
            return Err(CorrectError::InvalidConfig(
                "vertical_weight must be finite and positive",
            ));
        }
        if let InitialVelocity::Fixed(v) = self.initial_velocity
            && !v.is_finite()
        {
            return Err(CorrectError::InvalidConfig(
                "initial velocity must be finite",
            ));
        }
        if self.max_dt.is_nan() || self.max_dt <= 0.0 {
            return Err(CorrectError::InvalidConfig("max_dt must be positive"));
        }
        Ok(())
    }
}
