//! How to track: the options batch tracking ([`crate::track()`]) and the live tracker
//! ([`crate::LiveTracker`]) share, in a module of their own so that neither imports the other
//! for them.

use ridi_correct::{CorrectionConfig, PlacementSmoother};
use ridi_regress::Cascade;
use serde::{Deserialize, Serialize};

/// How to track.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrackOptions {
    /// Frames between regressions (paper: 50, the residual frames of the correction).
    pub regress_every: usize,
    /// The correction objective (knots, lambda, weights, initial velocity). Its `up_axis` is
    /// replaced by the model's: see [`TrackOptions::correction_for`].
    pub correction: CorrectionConfig,
    /// Streaming mode (paper's online variant): a 1000-frame window corrected every 200
    /// frames, each frame's pose as known when it arrived. Otherwise one global correction.
    pub online: bool,
    /// Each regression's placement becomes the majority label of a time window, and its
    /// velocity comes from that placement's regressors: centred on it in batch, the window
    /// before it when streaming. `None` keeps every window's own label (the paper).
    pub placement_smoothing: Option<PlacementSmoother>,
}

impl Default for TrackOptions {
    fn default() -> Self {
        Self {
            regress_every: 50,
            correction: CorrectionConfig::default(),
            online: false,
            placement_smoothing: Some(PlacementSmoother::default()),
        }
    }
}

impl TrackOptions {
    /// The correction of `model`'s regressions: [`TrackOptions::correction`] with the S its
    /// velocities are expressed in (the model's [`FeatureConfig::up_axis`]).
    ///
    /// [`FeatureConfig::up_axis`]: ridi_features::FeatureConfig::up_axis
    pub fn correction_for(&self, model: &Cascade) -> CorrectionConfig {
        CorrectionConfig {
            up_axis: model.feature_config().up_axis,
            ..self.correction
        }
    }
}
