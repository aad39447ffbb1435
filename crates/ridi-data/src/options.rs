//! Options shared by every reader.

use crate::{Format, Validation};

/// How readers build and check sequences. [`ReadOptions::default`] follows the original RIDI
/// processing.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadOptions {
    /// Limits every sequence is checked against. Its `max_gap_s` also applies to each raw
    /// sensor file on its own clock, because a gap in one sensor is hidden once it is
    /// interpolated onto the pose timeline.
    pub validation: Validation,
    /// Raw folders: pose records dropped at each end of `pose.txt` (Tango is unreliable while it
    /// starts and stops). The original drops 800 (about 4 s).
    pub pose_trim: usize,
    /// Raw folders without `pose.txt`: rate of the uniform timeline, Hz (checked with a pose
    /// too, within [`Validation::output_rate_range`]); the Tyrex and competition readers' rate
    /// when their options are made from these.
    pub rate_without_pose_hz: f64,
}

impl Default for ReadOptions {
    fn default() -> Self {
        Self {
            validation: Validation::default(),
            pose_trim: 800,
            rate_without_pose_hz: 200.0,
        }
    }
}

impl ReadOptions {
    /// These options with an unbounded `max_gap_s` where `format` keeps a pause as a gap of the
    /// timeline ([`Format::keeps_gaps`]), unchanged for other formats: how a recording paused
    /// for longer than the limit is read to be described or cut there (`ridi inspect`, `ridi
    /// convert --split-at-gaps`).
    pub fn reading_pauses(&self, format: Format) -> ReadOptions {
        let mut opts = self.clone();
        if format.keeps_gaps() {
            opts.validation.max_gap_s = f64::INFINITY;
        }
        opts
    }
}
