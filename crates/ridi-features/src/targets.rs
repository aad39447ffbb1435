//! Velocity targets in the stabilized frame.

use rayon::prelude::*;
use ridi_frames::{DeviceVec, StabHorizontal, StabVec, UpAxis, WorldFromDevice, WorldVec};

use crate::FeatureError;
use crate::config::FeatureConfig;
use crate::gaussian::{filter_strided_f64, half_kernel};

/// Ground truth for targets, one entry per frame on the IMU timeline.
#[derive(Debug, Clone, Copy)]
pub struct GroundTruthView<'a> {
    /// Time stamps, s, strictly increasing.
    pub time: &'a [f64],
    /// Device positions in the ground-truth world frame, m.
    pub position: &'a [WorldVec],
    /// Device orientations, world-from-device, in the same world frame as `position`.
    pub orientation: &'a [WorldFromDevice],
    /// Gravity sensor readings (device frame, pointing up): each frame's S, as for features.
    pub gravity: &'a [DeviceVec],
}

impl GroundTruthView<'_> {
    /// Number of frames.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// `true` without frames.
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    fn validate(&self) -> Result<(), FeatureError> {
        let n = self.time.len();
        for (what, len) in [
            ("position", self.position.len()),
            ("orientation", self.orientation.len()),
            ("gravity", self.gravity.len()),
        ] {
            if len != n {
                return Err(FeatureError::LengthMismatch {
                    what,
                    expected: n,
                    found: len,
                });
            }
        }
        for i in 0..n {
            if !self.time[i].is_finite() {
                return Err(FeatureError::NonFinite {
                    what: "time",
                    index: i,
                });
            }
            if !self.position[i].is_finite() {
                return Err(FeatureError::NonFinite {
                    what: "position",
                    index: i,
                });
            }
            if !self.orientation[i].to_wxyz().iter().all(|c| c.is_finite()) {
                return Err(FeatureError::NonFinite {
                    what: "orientation",
                    index: i,
                });
            }
            if !self.gravity[i].is_finite() {
                return Err(FeatureError::NonFinite {
                    what: "gravity",
                    index: i,
                });
            }
            if i > 0 && self.time[i] <= self.time[i - 1] {
                return Err(FeatureError::TimeNotIncreasing { index: i });
            }
        }
        Ok(())
    }
}

/// Regression targets of one sequence.
#[derive(Debug, Clone, PartialEq)]
pub struct Targets {
    /// The sample frames, as requested.
    pub frames: Vec<usize>,
    /// Smoothed velocity in S at each sample frame, `[S-x, S-z]` in m/s (`f64`: targets are
    /// few, and regression and evaluation want them exact). S-x points right, S-z back:
    /// walking forward gives a negative S-z, as in the original RIDI.
    pub values: Vec<StabHorizontal>,
    /// Smoothed velocity in S at every frame, all three components (S-y is vertical), for
    /// evaluation and plots.
    pub velocity: Vec<StabVec>,
}

/// Per-frame ground-truth velocity in each frame's S, smoothed over the whole sequence:
/// forward differences `(p[i+1] - p[i]) / (t[i+1] - t[i])` (the last frame repeats the one
/// before; a one-frame sequence has zero velocity), rotated into the device frame with the
/// ground-truth orientation and into S with `up_axis.align(gravity[i])`, then smoothed per
/// component with `sigma` frames ('reflect' borders).
pub fn stabilized_velocity(
    gt: &GroundTruthView<'_>,
    up_axis: UpAxis,
    sigma: f64,
    truncate: f64,
) -> Result<Vec<StabVec>, FeatureError> {
    gt.validate()?;
    let half = half_kernel(sigma, truncate)?;
    let n = gt.len();
    if n == 0 {
        return Ok(Vec::new());
    }
    let mut raw = vec![0.0f64; 3 * n];
    raw.par_chunks_mut(3).enumerate().for_each(|(i, out)| {
        // Frame i uses the step to i + 1; the last frame reuses the final step.
        let j = if i + 1 < n { i } else { i.saturating_sub(1) };
        let v_w = if j + 1 < n {
            (gt.position[j + 1] - gt.position[j]) / (gt.time[j + 1] - gt.time[j])
        } else {
            WorldVec::ZERO
        };
        let v_s = up_axis.align(gt.gravity[i]) * (gt.orientation[i].inverse() * v_w);
        out.copy_from_slice(&v_s.to_array());
    });
    let mut smooth = vec![0.0f64; 3 * n];
    // The whole interleaved sequence in one pass per tap: the three components are smoothed
    // independently because taps are three values apart.
    smooth_parallel(&raw, &mut smooth, &half);
    Ok(smooth
        .chunks_exact(3)
        .map(|c| StabVec::new(c[0], c[1], c[2]))
        .collect())
}

/// Splits a long interleaved 3-component sequence into blocks smoothed on the rayon pool. Each
/// block reads a halo of `r` frames around it (reflected at the true sequence ends only).
fn smooth_parallel(raw: &[f64], out: &mut [f64], half: &[f64]) {
    let n = raw.len() / 3;
    let r = half.len() - 1;
    const BLOCK: usize = 8192;
    if n <= BLOCK || r >= BLOCK {
        filter_strided_f64(raw, out, 3, half);
        return;
    }
    out.par_chunks_mut(3 * BLOCK)
        .enumerate()
        .for_each(|(b, out_block)| {
            let first = b * BLOCK;
            let len = out_block.len() / 3;
            // Inner rows of the span see all their taps; the span's own reflected borders only
            // affect halo rows, except where the span ends at a true sequence end, where the
            // reflection is exactly the whole-sequence one (n > BLOCK > r, so no repeated
            // reflection is involved).
            let lo = first.saturating_sub(r);
            let hi = (first + len + r).min(n);
            let span = &raw[3 * lo..3 * hi];
            let mut tmp = vec![0.0f64; span.len()];
            filter_strided_f64(span, &mut tmp, 3, half);
            let off = first - lo;
            out_block.copy_from_slice(&tmp[3 * off..3 * (off + len)]);
        });
}

/// Targets of `gt` at `frames` (each below the sequence length) with `config`'s target sigma
/// and truncation. See [`stabilized_velocity`] and [`Targets`].
pub fn compute_targets(
    gt: &GroundTruthView<'_>,
    config: &FeatureConfig,
    frames: &[usize],
) -> Result<Targets, FeatureError> {
    gt.validate()?;
    let n = gt.len();
    if let Some(&f) = frames.iter().find(|&&f| f >= n) {
        return Err(FeatureError::FrameOutOfRange {
            frame: f,
            min: 0,
            max: n.saturating_sub(1),
        });
    }
    let velocity = stabilized_velocity(gt, config.up_axis, config.target_sigma, config.truncate)?;
    let values = frames.iter().map(|&f| velocity[f].horizontal()).collect();
    Ok(Targets {
        frames: frames.to_vec(),
        values,
        velocity,
    })
}
