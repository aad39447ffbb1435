//! Feature windows: gyro and linear acceleration in S, smoothed, flattened time-major.

use rayon::prelude::*;
use ridi_frames::{DeviceVec, ImuFrames, ImuStream, UpAxis};

use crate::FeatureError;
use crate::config::{FeatureChannel, FeatureConfig};
use crate::gaussian::{filter_strided_f32, half_kernel};
use crate::matrix::FeatureMatrix;

/// The stream a feature channel reads.
fn channel<'a>(imu: &ImuFrames<'a>, c: FeatureChannel) -> &'a [DeviceVec] {
    match c {
        FeatureChannel::Gyro => imu.gyro,
        FeatureChannel::LinearAcceleration => imu.linacce,
    }
}

/// Per-frame channels already rotated into each frame's own S, as `f32`, row-major
/// `frames x (3 * channels)`. Built once per sequence so that each frame is rotated once, not
/// once for every window that contains it.
#[derive(Debug, Clone, PartialEq)]
pub struct StabilizedChannels {
    width: usize,
    data: Vec<f32>,
}

impl StabilizedChannels {
    /// Rotates every frame's `channels` into S with `up_axis.align(gravity[i])`. Fails on
    /// mismatched lengths, non-finite values or an empty channel list.
    pub fn new(
        imu: &ImuFrames<'_>,
        channels: &[FeatureChannel],
        up_axis: UpAxis,
    ) -> Result<Self, FeatureError> {
        let mut streams = vec![ImuStream::Gravity];
        streams.extend(channels.iter().map(|&c| match c {
            FeatureChannel::Gyro => ImuStream::Gyro,
            FeatureChannel::LinearAcceleration => ImuStream::Linacce,
        }));
        imu.check_streams(&streams)?;
        if channels.is_empty() {
            return Err(FeatureError::InvalidConfig(
                "at least one channel is needed".into(),
            ));
        }
        let streams: Vec<(&'static str, &[DeviceVec])> = std::iter::once(("gravity", imu.gravity))
            .chain(channels.iter().map(|&c| (channel_name(c), channel(imu, c))))
            .collect();
        for (what, s) in &streams {
            if let Some(index) = s.iter().position(|v| !v.is_finite()) {
                return Err(FeatureError::NonFinite { what, index });
            }
        }
        let width = 3 * channels.len();
        let mut data = vec![0.0f32; imu.len() * width];
        data.par_chunks_mut(width * 1024)
            .enumerate()
            .for_each(|(block, rows)| {
                let first = block * 1024;
                for (k, row) in rows.chunks_exact_mut(width).enumerate() {
                    let i = first + k;
                    // One matrix per frame serves all channels: cheaper than a quaternion
                    // sandwich per vector.
                    let m = up_axis.align(imu.gravity[i]).matrix();
                    for (c, out) in channels.iter().zip(row.chunks_exact_mut(3)) {
                        let v = m * channel(imu, *c)[i].vector();
                        out[0] = v.x as f32;
                        out[1] = v.y as f32;
                        out[2] = v.z as f32;
                    }
                }
            });
        Ok(Self { width, data })
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.data.len() / self.width
    }

    /// `true` without frames.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// Values per frame (`3 * channels`).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Frame `i`'s values: channel-major within the frame, x y z per channel.
    ///
    /// # Panics
    /// If `i >= len()`.
    pub fn frame(&self, i: usize) -> &[f32] {
        &self.data[i * self.width..(i + 1) * self.width]
    }

    /// All values, row-major.
    pub fn as_slice(&self) -> &[f32] {
        &self.data
    }
}

fn channel_name(c: FeatureChannel) -> &'static str {
    match c {
        FeatureChannel::Gyro => "gyro",
        FeatureChannel::LinearAcceleration => "linacce",
    }
}

/// Which frames get a sample: `start, start + step, ...` below the sequence length.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleSchedule {
    start: usize,
    step: usize,
}

impl SampleSchedule {
    /// Samples every `step` frames from `start`. `start` below the window length would ask for
    /// frames without a full window; extraction then reports
    /// [`FeatureError::FrameOutOfRange`].
    pub fn new(start: usize, step: usize) -> Result<Self, FeatureError> {
        if step == 0 {
            return Err(FeatureError::InvalidConfig(
                "sample step must be >= 1".into(),
            ));
        }
        Ok(Self { start, step })
    }

    /// The training schedule of `config`: every `config.step` frames from the first frame with
    /// a full window (frame `config.window`).
    pub fn training(config: &FeatureConfig) -> Result<Self, FeatureError> {
        Self::new(config.window, config.step)
    }

    /// Every `step` frames from the first frame with a full window, for tracking.
    pub fn every(config: &FeatureConfig, step: usize) -> Result<Self, FeatureError> {
        Self::new(config.window, step)
    }

    /// First sample frame.
    pub fn start(&self) -> usize {
        self.start
    }

    /// Step between samples.
    pub fn step(&self) -> usize {
        self.step
    }

    /// The sample frames of a sequence of `n_frames` frames (empty if it is too short).
    pub fn frames(&self, n_frames: usize) -> Vec<usize> {
        (self.start..n_frames).step_by(self.step).collect()
    }
}

/// Computes feature rows for a [`FeatureConfig`] (validated once, kernel prepared once).
#[derive(Debug, Clone)]
pub struct FeatureExtractor {
    config: FeatureConfig,
    half: Vec<f32>,
}

impl FeatureExtractor {
    /// Validates `config` and prepares its smoothing kernel.
    pub fn new(config: FeatureConfig) -> Result<Self, FeatureError> {
        config.validate()?;
        let half = half_kernel(config.feature_sigma, config.truncate)?
            .into_iter()
            .map(|w| w as f32)
            .collect();
        Ok(Self { config, half })
    }

    /// The configuration.
    pub fn config(&self) -> &FeatureConfig {
        &self.config
    }

    /// Feature dimension.
    pub fn dim(&self) -> usize {
        self.config.feature_dim()
    }

    /// The per-frame S channels of a sequence, for [`Self::features`] and [`Self::row_into`].
    pub fn stabilize(&self, imu: &ImuFrames<'_>) -> Result<StabilizedChannels, FeatureError> {
        StabilizedChannels::new(imu, &self.config.channels, self.config.up_axis)
    }

    /// Writes the feature of sample frame `frame` into `out` (length [`Self::dim`]): frames
    /// `[frame - window, frame)`, each channel smoothed within the window, time-major, then
    /// standardized if the configuration says so. Valid frames are `window..=len`.
    pub fn row_into(
        &self,
        stab: &StabilizedChannels,
        frame: usize,
        out: &mut [f32],
    ) -> Result<(), FeatureError> {
        self.check_stab(stab)?;
        if out.len() != self.dim() {
            return Err(FeatureError::LengthMismatch {
                what: "feature row",
                expected: self.dim(),
                found: out.len(),
            });
        }
        self.check_frame(stab, frame)?;
        self.row_unchecked(stab, frame, out);
        Ok(())
    }

    /// Features at `frames` (each in `window..=len`), one row each, computed in parallel on the
    /// current rayon pool.
    pub fn features(
        &self,
        stab: &StabilizedChannels,
        frames: &[usize],
    ) -> Result<FeatureMatrix, FeatureError> {
        let mut m = FeatureMatrix::default();
        self.features_into(stab, frames, &mut m)?;
        Ok(m)
    }

    /// [`Self::features`] into an existing matrix, which is reshaped to `frames.len() x dim`
    /// and reuses its allocation. Worth it when extracting repeatedly (tracking, benchmarks):
    /// a fresh 12,000 x 1200 matrix is 58 MB whose first touch costs page faults comparable
    /// to the smoothing itself. On error `out` is left unchanged.
    pub fn features_into(
        &self,
        stab: &StabilizedChannels,
        frames: &[usize],
        out: &mut FeatureMatrix,
    ) -> Result<(), FeatureError> {
        self.check_stab(stab)?;
        for &f in frames {
            self.check_frame(stab, f)?;
        }
        let dim = self.dim();
        out.reshape(frames.len(), dim);
        if dim > 0 && !frames.is_empty() {
            out.as_mut_slice()
                .par_chunks_mut(dim)
                .zip(frames.par_iter())
                .for_each(|(row, &f)| self.row_unchecked(stab, f, row));
        }
        Ok(())
    }

    fn check_stab(&self, stab: &StabilizedChannels) -> Result<(), FeatureError> {
        if stab.width() != self.config.row_width() {
            return Err(FeatureError::LengthMismatch {
                what: "stabilized frame (values per frame)",
                expected: self.config.row_width(),
                found: stab.width(),
            });
        }
        Ok(())
    }

    fn check_frame(&self, stab: &StabilizedChannels, frame: usize) -> Result<(), FeatureError> {
        let w = self.config.window;
        if frame < w || frame > stab.len() {
            return Err(FeatureError::FrameOutOfRange {
                frame,
                min: w,
                max: stab.len(),
            });
        }
        Ok(())
    }

    #[inline]
    fn row_unchecked(&self, stab: &StabilizedChannels, frame: usize, out: &mut [f32]) {
        let width = stab.width();
        let src = &stab.as_slice()[(frame - self.config.window) * width..frame * width];
        // The window slice is smoothed straight into the output row: the S channels are already
        // time-major, which is the feature layout, so no copy or scratch is needed.
        filter_strided_f32(src, out, width, &self.half);
        if let Some(s) = &self.config.standardization {
            s.apply_row_unchecked(out);
        }
    }
}

/// Features of `imu` at `frames` with `config`: [`FeatureExtractor::new`], then
/// [`FeatureExtractor::stabilize`] and [`FeatureExtractor::features`].
pub fn compute_features(
    imu: &ImuFrames<'_>,
    config: &FeatureConfig,
    frames: &[usize],
) -> Result<FeatureMatrix, FeatureError> {
    let fx = FeatureExtractor::new(config.clone())?;
    let stab = fx.stabilize(imu)?;
    fx.features(&stab, frames)
}
