//! The feature configuration that a model file carries.

use ridi_frames::UpAxis;
use serde::{Deserialize, Serialize};

use crate::FeatureError;
use crate::gaussian::half_kernel;
use crate::matrix::FeatureMatrix;

/// One IMU channel of the feature window, three values (x, y, z in S) per frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FeatureChannel {
    /// Gyroscope, rad/s.
    Gyro,
    /// Linear acceleration (gravity removed, Android `TYPE_LINEAR_ACCELERATION`), m/s^2.
    LinearAcceleration,
}

/// Which device orientation the inputs of a feature come from. Gravity, and so S and the linear
/// acceleration, follow the orientation, so a model must see at test time what it was trained
/// on. Extraction takes the streams it is given; the pipeline (the `ridi` crate) prepares them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Orientation {
    /// As recorded (RIDI: Tango or game rotation vector; Tyrex: Android rotation vector).
    #[default]
    Recorded,
    /// Estimated from gyro and accelerometer
    /// ([`ridi_frames::estimate_orientation`] with the default filter), gravity and linear
    /// acceleration derived from each frame's estimate by [`ridi_frames::gravity_and_linacce`]
    /// (`ridi_data::Sequence::with_estimated_orientation` makes such a sequence; the `ridi`
    /// facade's pipeline and `LiveTracker` do it themselves). The extractor does not do it:
    /// give it those streams.
    Estimated,
}

/// Everything that determines a feature vector and a target, so that tracking computes exactly
/// the features a model was trained on. [`Default`] is the paper's setting.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FeatureConfig {
    /// Frames per window; the feature of frame `f` covers frames `[f - window, f)`.
    pub window: usize,
    /// Gaussian sigma (in frames) applied inside each window.
    pub feature_sigma: f64,
    /// Gaussian sigma (in frames) applied to the target velocity over the whole sequence.
    pub target_sigma: f64,
    /// Training sample step in frames.
    pub step: usize,
    /// Channels, in the order they appear within each time row of the feature.
    pub channels: Vec<FeatureChannel>,
    /// Gaussian truncation, in sigmas (scipy's `truncate`).
    pub truncate: f64,
    /// Per-dimension z-scoring learned on the training set, applied to every feature computed
    /// with this configuration. `None` in the original RIDI.
    pub standardization: Option<Standardization>,
    /// The definition of S for features and targets, and hence for the regressed velocities
    /// ([`UpAxis::PlusY`] in the original RIDI).
    #[serde(default)]
    pub up_axis: UpAxis,
    /// The orientation the inputs come from ([`Orientation::Recorded`] in the original RIDI).
    #[serde(default)]
    pub orientation: Orientation,
}

impl Default for FeatureConfig {
    fn default() -> Self {
        Self {
            window: 200,
            feature_sigma: 2.0,
            target_sigma: 30.0,
            step: 10,
            channels: vec![FeatureChannel::Gyro, FeatureChannel::LinearAcceleration],
            truncate: 4.0,
            standardization: None,
            up_axis: UpAxis::PlusY,
            orientation: Orientation::Recorded,
        }
    }
}

impl FeatureConfig {
    /// Values per time row: three per channel.
    pub fn row_width(&self) -> usize {
        3 * self.channels.len()
    }

    /// Feature dimension, `window * 3 * channels` (1200 for the paper).
    pub fn feature_dim(&self) -> usize {
        self.window * self.row_width()
    }

    /// Checks every field; a configuration read from a file should pass this before use.
    pub fn validate(&self) -> Result<(), FeatureError> {
        let bad = |m: String| Err(FeatureError::InvalidConfig(m));
        if self.window == 0 {
            return bad("window must be at least 1 frame".into());
        }
        if self.step == 0 {
            return bad("step must be at least 1 frame".into());
        }
        if self.channels.is_empty() {
            return bad("at least one channel is needed".into());
        }
        for (i, c) in self.channels.iter().enumerate() {
            if self.channels[..i].contains(c) {
                return bad(format!("channel {c:?} listed twice"));
            }
        }
        half_kernel(self.feature_sigma, self.truncate)?;
        half_kernel(self.target_sigma, self.truncate)?;
        if self.window.checked_mul(self.row_width()).is_none() {
            return bad("window too large".into());
        }
        if let Some(s) = &self.standardization {
            s.validate(self.feature_dim())?;
        }
        Ok(())
    }
}

/// Per-dimension z-scoring, `(x - mean) / std`, learned on the training features.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Standardization {
    /// Mean of each feature dimension.
    pub mean: Vec<f32>,
    /// Standard deviation of each dimension (population, like numpy's default), never zero.
    pub std: Vec<f32>,
}

impl Standardization {
    /// Fits mean and standard deviation over the rows of all `matrices` (the training set,
    /// usually one matrix per sequence). Dimensions with zero variance get `std = 1`, as
    /// scikit-learn does, so they pass through centred instead of dividing by zero.
    pub fn fit<'a, I>(matrices: I) -> Result<Self, FeatureError>
    where
        I: IntoIterator<Item = &'a FeatureMatrix>,
    {
        let mut acc: Option<StandardizationFit> = None;
        for m in matrices {
            let a = acc.get_or_insert_with(|| StandardizationFit::new(m.cols()));
            a.add_matrix(m)?;
        }
        acc.ok_or_else(|| FeatureError::InvalidConfig("no feature rows to standardize".into()))?
            .finish()
    }

    /// Dimension this standardization applies to.
    pub fn dim(&self) -> usize {
        self.mean.len()
    }

    fn validate(&self, dim: usize) -> Result<(), FeatureError> {
        for (what, len) in [
            ("standardization mean", self.mean.len()),
            ("standardization std", self.std.len()),
        ] {
            if len != dim {
                return Err(FeatureError::LengthMismatch {
                    what,
                    expected: dim,
                    found: len,
                });
            }
        }
        if let Some(i) = self.mean.iter().position(|m| !m.is_finite()) {
            return Err(FeatureError::NonFinite {
                what: "standardization mean",
                index: i,
            });
        }
        if let Some(i) = self.std.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(FeatureError::InvalidConfig(format!(
                "standardization std[{i}] = {} is not a positive finite number",
                self.std[i]
            )));
        }
        Ok(())
    }

    /// Standardizes one feature row in place.
    ///
    /// # Errors
    /// A row of another length, and a standardization that is not one (its fields are
    /// public): lengths that differ, a non-finite mean, a standard deviation that is not
    /// positive and finite.
    pub fn apply_row(&self, row: &mut [f32]) -> Result<(), FeatureError> {
        self.validate(self.dim())?;
        if row.len() != self.dim() {
            return Err(FeatureError::LengthMismatch {
                what: "feature row",
                expected: self.dim(),
                found: row.len(),
            });
        }
        self.apply_row_unchecked(row);
        Ok(())
    }

    /// Standardizes every row of `m` in place (in parallel).
    ///
    /// # Errors
    /// As [`Standardization::apply_row`].
    pub fn apply(&self, m: &mut FeatureMatrix) -> Result<(), FeatureError> {
        use rayon::prelude::*;
        self.validate(self.dim())?;
        if m.cols() != self.dim() {
            return Err(FeatureError::LengthMismatch {
                what: "feature matrix row",
                expected: self.dim(),
                found: m.cols(),
            });
        }
        let cols = m.cols();
        if cols == 0 {
            return Ok(());
        }
        m.as_mut_slice()
            .par_chunks_mut(cols)
            .for_each(|row| self.apply_row_unchecked(row));
        Ok(())
    }

    /// Same arithmetic for the fused path in feature extraction and for [`Self::apply`], so
    /// both give bit-identical results.
    #[inline]
    pub(crate) fn apply_row_unchecked(&self, row: &mut [f32]) {
        for ((x, m), s) in row.iter_mut().zip(&self.mean).zip(&self.std) {
            *x = (*x - m) / s;
        }
    }
}

/// Streaming fit of a [`Standardization`] (Welford's algorithm in `f64`, merged with Chan's
/// formula), for training sets that are never all in memory at once.
#[derive(Debug, Clone, PartialEq)]
pub struct StandardizationFit {
    count: u64,
    mean: Vec<f64>,
    m2: Vec<f64>,
}

impl StandardizationFit {
    /// An empty accumulator for `dim`-dimensional rows.
    pub fn new(dim: usize) -> Self {
        Self {
            count: 0,
            mean: vec![0.0; dim],
            m2: vec![0.0; dim],
        }
    }

    /// Rows seen so far.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Adds one row. Non-finite values are rejected so that one bad window cannot poison every
    /// later feature.
    pub fn add_row(&mut self, row: &[f32]) -> Result<(), FeatureError> {
        if row.len() != self.mean.len() {
            return Err(FeatureError::LengthMismatch {
                what: "feature row",
                expected: self.mean.len(),
                found: row.len(),
            });
        }
        if let Some(i) = row.iter().position(|x| !x.is_finite()) {
            return Err(FeatureError::NonFinite {
                what: "feature",
                index: i,
            });
        }
        self.count += 1;
        let inv = 1.0 / self.count as f64;
        for ((&x, mean), m2) in row.iter().zip(&mut self.mean).zip(&mut self.m2) {
            let x = f64::from(x);
            let d = x - *mean;
            *mean += d * inv;
            *m2 += d * (x - *mean);
        }
        Ok(())
    }

    /// Adds every row of `m`, splitting the work over the rayon pool.
    pub fn add_matrix(&mut self, m: &FeatureMatrix) -> Result<(), FeatureError> {
        use rayon::prelude::*;
        if m.cols() != self.mean.len() {
            return Err(FeatureError::LengthMismatch {
                what: "feature matrix row",
                expected: self.mean.len(),
                found: m.cols(),
            });
        }
        if m.rows() == 0 || m.cols() == 0 {
            return Ok(());
        }
        let dim = m.cols();
        let part = m
            .as_slice()
            .par_chunks(dim * 256)
            .try_fold(
                || StandardizationFit::new(dim),
                |mut acc, chunk| {
                    for row in chunk.chunks_exact(dim) {
                        acc.add_row(row)?;
                    }
                    Ok::<_, FeatureError>(acc)
                },
            )
            .try_reduce(
                || StandardizationFit::new(dim),
                |mut a, b| {
                    a.merge(&b);
                    Ok(a)
                },
            )?;
        self.merge(&part);
        Ok(())
    }

    /// Folds another accumulator of the same dimension into this one.
    ///
    /// # Panics
    /// If the dimensions differ (a programming error, not a data error).
    pub fn merge(&mut self, other: &StandardizationFit) {
        assert_eq!(self.mean.len(), other.mean.len(), "dimension mismatch");
        if other.count == 0 {
            return;
        }
        if self.count == 0 {
            *self = other.clone();
            return;
        }
        let (na, nb) = (self.count as f64, other.count as f64);
        let n = na + nb;
        for i in 0..self.mean.len() {
            let d = other.mean[i] - self.mean[i];
            self.mean[i] += d * nb / n;
            self.m2[i] += other.m2[i] + d * d * na * nb / n;
        }
        self.count += other.count;
    }

    /// The fitted standardization. Fails without any row.
    pub fn finish(&self) -> Result<Standardization, FeatureError> {
        if self.count == 0 {
            return Err(FeatureError::InvalidConfig(
                "no feature rows to standardize".into(),
            ));
        }
        let n = self.count as f64;
        let std = self
            .m2
            .iter()
            .map(|&m2| {
                let s = (m2 / n).sqrt() as f32;
                // Below this the dimension is constant up to f32 rounding of its values.
                if s.is_finite() && s > 1e-12 { s } else { 1.0 }
            })
            .collect();
        Ok(Standardization {
            mean: self.mean.iter().map(|&m| m as f32).collect(),
            std,
        })
    }
}
