//! How to track: the options batch tracking ([`crate::track()`]) and the live tracker
//! ([`crate::LiveTracker`]) share, in a module of their own so that neither imports the other
//! for them.

use ridi_correct::{CorrectionConfig, PlacementSmoother};
use ridi_frames::HeadingConfig;
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
    /// For a model on the estimated orientation: the recorded orientation's slow heading
    /// corrects the estimate's heading drift ([`HeadingCorrector`]); `None` keeps the gyro's
    /// heading. Features, and so the regressed velocities, are the same either way; the
    /// world frame the correction integrates in is not.
    ///
    /// [`HeadingCorrector`]: ridi_frames::HeadingCorrector
    #[serde(default = "default_recorded_heading")]
    pub recorded_heading: Option<HeadingConfig>,
}

fn default_recorded_heading() -> Option<HeadingConfig> {
    Some(HeadingConfig::default())
}

impl Default for TrackOptions {
    fn default() -> Self {
        Self {
            regress_every: 50,
            correction: CorrectionConfig::default(),
            online: false,
            placement_smoothing: Some(PlacementSmoother::default()),
            recorded_heading: default_recorded_heading(),
        }
    }
}

impl TrackOptions {
    /// Checks every value's domain (the fields are public): tracking, evaluation and the live
    /// tracker call it before any work.
    ///
    /// # Errors
    /// A `regress_every` the streaming tracker refuses (0, or beyond its buffer), and what
    /// [`CorrectionConfig::validate`],
    /// [`PlacementSmoother::validate`] and [`HeadingConfig::validate`] refuse.
    pub fn validate(&self) -> crate::Result<()> {
        use crate::PipelineError;
        // The streaming tracker's rule for `regress_every` (at least 1, a bounded buffer), so
        // that batch and online tracking accept the same.
        ridi_correct::TrackerConfig {
            regress_every: self.regress_every,
            ..ridi_correct::TrackerConfig::default()
        }
        .validate()
        .map_err(PipelineError::Track)?;
        self.correction.validate().map_err(PipelineError::Correct)?;
        if let Some(s) = &self.placement_smoothing {
            s.validate().map_err(PipelineError::Correct)?;
        }
        if let Some(h) = &self.recorded_heading {
            h.validate().map_err(PipelineError::Orientation)?;
        }
        Ok(())
    }

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_written_without_the_heading_read_with_its_default() {
        let json = serde_json::to_value(TrackOptions::default()).unwrap();
        let mut without = json.clone();
        without.as_object_mut().unwrap().remove("recorded_heading");
        let read: TrackOptions = serde_json::from_value(without).unwrap();
        assert_eq!(read, TrackOptions::default());
        let mut gyro = json;
        gyro["recorded_heading"] = serde_json::Value::Null;
        let read: TrackOptions = serde_json::from_value(gyro).unwrap();
        assert_eq!(read.recorded_heading, None);
    }
}
