//! Trajectory, velocity and placement metrics.
//!
//! Positions are horizontal `[x, y]` pairs in metres; an estimate and its ground truth are
//! sampled on the same timeline (index `i` is the same instant in both). Estimates should be
//! aligned first (see [`crate::align`]); [`evaluate_trajectory`] does both.
//!
//! Two families of trajectory errors are reported, because the literature mixes them up (the
//! "√2 factor" question on RoNIN):
//!
//! - Euclidean forms ([`ate`], [`rte`]): RMS of the 2D error vector length, in metres.
//! - Per-coordinate forms ([`ate_ronin`], [`rte_ronin`]): RoNIN's `np.sqrt(np.mean(err ** 2))`
//!   over an `N × 2` array, i.e. the Euclidean value divided by √2. Compare these with RoNIN's
//!   Table 1.

use serde::{Deserialize, Serialize};

use crate::align::{AlignWindow, AlignmentFit, align_trajectory};
use crate::error::{
    EvalError, Result, check_finite_points, check_non_empty, check_pair, check_positive,
    check_same_len, check_times,
};

/// Trajectory metrics of one method on one sequence, on an aligned estimate.
///
/// With `N` frames, errors `eᵢ = estᵢ − gtᵢ`, `L(·)` the horizontal path length and the RTE
/// rule of [`rte`]:
///
/// | key | formula |
/// |---|---|
/// | `mpe_m` | `(1/N) Σ ‖eᵢ‖` (RIDI's MPE) |
/// | `mpe_pct` | `100 · mpe_m / L(gt)`; `null` if the ground truth does not move |
/// | `ate_m` | `sqrt((1/N) Σ ‖eᵢ‖²)`, Euclidean |
/// | `rte_m` | Euclidean RTE, 60 s window by default |
/// | `ate_ronin_m` | `ate_m / √2`: RoNIN's per-coordinate RMS |
/// | `rte_ronin_m` | `rte_m / √2`: RoNIN's per-coordinate RTE |
/// | `rte_5s_m` | Euclidean RTE over a 5 s window by default |
/// | `path_length_ratio` | `L(est) / L(gt)`; `null` if the ground truth does not move |
///
/// The RTE windows are counted in frames at [`EvalConfig::rate_hz`] (60 s = 12000 frames at the
/// default 200 Hz), so they last their nominal seconds only on data at that rate, which
/// [`evaluate_trajectory`] checks. A figure written as `null` (a NaN), or left out of a
/// hand-edited file, reads back as NaN (`None` for the optional ones).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
// A misspelled figure in a hand-edited report is an error, not a missing figure; a figure
// left out is missing (`TrajectoryMetrics::missing`'s).
#[serde(deny_unknown_fields, default = "TrajectoryMetrics::missing")]
pub struct TrajectoryMetrics {
    /// Mean positional error, metres.
    #[serde(deserialize_with = "crate::bootstrap::nan_if_null")]
    pub mpe_m: f64,
    /// Mean positional error, % of the ground-truth path length.
    pub mpe_pct: Option<f64>,
    /// Absolute trajectory error, Euclidean RMS, metres.
    #[serde(deserialize_with = "crate::bootstrap::nan_if_null")]
    pub ate_m: f64,
    /// Relative trajectory error (long window), Euclidean RMS, metres.
    #[serde(deserialize_with = "crate::bootstrap::nan_if_null")]
    pub rte_m: f64,
    /// Absolute trajectory error, RoNIN per-coordinate RMS, metres.
    #[serde(deserialize_with = "crate::bootstrap::nan_if_null")]
    pub ate_ronin_m: f64,
    /// Relative trajectory error (long window), RoNIN per-coordinate RMS, metres.
    #[serde(deserialize_with = "crate::bootstrap::nan_if_null")]
    pub rte_ronin_m: f64,
    /// Relative trajectory error over [`EvalConfig::short_rte_window_s`], Euclidean RMS,
    /// metres. Named for that window's default, 5 s, which the command line and Python keep: a
    /// report made with another says so in its `config`.
    #[serde(deserialize_with = "crate::bootstrap::nan_if_null")]
    pub rte_5s_m: f64,
    /// Estimated over ground-truth horizontal path length.
    pub path_length_ratio: Option<f64>,
}

impl TrajectoryMetrics {
    /// Every figure missing: NaN, or `None` for the optional ones.
    fn missing() -> Self {
        Self {
            mpe_m: f64::NAN,
            mpe_pct: None,
            ate_m: f64::NAN,
            rte_m: f64::NAN,
            ate_ronin_m: f64::NAN,
            rte_ronin_m: f64::NAN,
            rte_5s_m: f64::NAN,
            path_length_ratio: None,
        }
    }
}

/// Mean positional error (MPE), metres: `(1/N) Σᵢ ‖estᵢ − gtᵢ‖`.
///
/// # Errors
/// Empty inputs, different lengths, non-finite coordinates.
pub fn mean_position_error(est: &[[f64; 2]], gt: &[[f64; 2]]) -> Result<f64> {
    check_pair(est, gt)?;
    let sum: f64 = est.iter().zip(gt).map(|(e, g)| dist(*e, *g)).sum();
    Ok(sum / est.len() as f64)
}

/// Length of a 2D polyline, metres: `Σᵢ ‖pᵢ₊₁ − pᵢ‖` (0 for a single point).
///
/// # Errors
/// Empty input or non-finite coordinates.
pub fn path_length(points: &[[f64; 2]]) -> Result<f64> {
    check_non_empty("path", points.len())?;
    check_finite_points("path", points)?;
    Ok(points.windows(2).map(|w| dist(w[0], w[1])).sum())
}

/// MPE as a percentage of the ground-truth path length: `100 · MPE / L(gt)`.
///
/// `None` when the ground truth does not move (`L(gt) = 0`), where the ratio has no meaning.
///
/// # Errors
/// As [`mean_position_error`].
pub fn mean_position_error_percent(est: &[[f64; 2]], gt: &[[f64; 2]]) -> Result<Option<f64>> {
    let mpe = mean_position_error(est, gt)?;
    let length = path_length(gt)?;
    Ok((length > 0.0).then(|| 100.0 * mpe / length))
}

/// Horizontal path length ratio `L(est) / L(gt)`: 1 for a perfect scale, above 1 when the
/// estimate walks too far (or jitters). `None` when `L(gt) = 0`.
///
/// # Errors
/// Empty inputs, different lengths, non-finite coordinates.
pub fn path_length_ratio(est: &[[f64; 2]], gt: &[[f64; 2]]) -> Result<Option<f64>> {
    check_pair(est, gt)?;
    let l_gt = path_length(gt)?;
    let l_est = path_length(est)?;
    Ok((l_gt > 0.0).then(|| l_est / l_gt))
}

/// Absolute trajectory error, Euclidean form, metres: `sqrt( (1/N) Σᵢ ‖estᵢ − gtᵢ‖² )`.
///
/// Equals `√2 ·` [`ate_ronin`].
///
/// # Errors
/// Empty inputs, different lengths, non-finite coordinates.
pub fn ate(est: &[[f64; 2]], gt: &[[f64; 2]]) -> Result<f64> {
    check_pair(est, gt)?;
    Ok(mean_squared_norm(est.iter().zip(gt).map(|(e, g)| sub(*e, *g))).sqrt())
}

/// Absolute trajectory error as RoNIN computes it (`compute_absolute_trajectory_error`),
/// metres: `sqrt( (1/(2N)) Σᵢ Σ_c (estᵢ,c − gtᵢ,c)² )`, the per-coordinate RMS.
///
/// Equals [`ate`]` / √2`.
///
/// # Errors
/// Empty inputs, different lengths, non-finite coordinates.
pub fn ate_ronin(est: &[[f64; 2]], gt: &[[f64; 2]]) -> Result<f64> {
    Ok(ate(est, gt)? / std::f64::consts::SQRT_2)
}

/// Relative trajectory error over a window of `window` frames, Euclidean form, metres.
///
/// With `N` frames and the displacement error over `d` frames
/// `eᵢ = (estᵢ₊d − estᵢ) − (gtᵢ₊d − gtᵢ)`:
///
/// - `N > window`: `d = window`, `RTE = sqrt( (1/(N−d)) Σᵢ ‖eᵢ‖² )`, `i = 0 … N−d−1`.
/// - `N ≤ window`: RoNIN's short-sequence rule: `d = N − 1` (the single end-to-end drift) and
///   the result is scaled by `window / N`.
///
/// This mirrors RoNIN's `compute_ate_rte`, which switches on `N < window`; at exactly
/// `N = window` RoNIN takes the mean of an empty array (NaN), here the short rule applies
/// (scale factor 1). RoNIN's window is 12000 frames: one minute at 200 Hz, see
/// [`seconds_to_frames`].
///
/// Equals `√2 ·` [`rte_ronin`].
///
/// # Errors
/// Fewer than 2 frames, `window == 0`, different lengths, non-finite coordinates.
pub fn rte(est: &[[f64; 2]], gt: &[[f64; 2]], window: usize) -> Result<f64> {
    check_pair(est, gt)?;
    if window == 0 {
        return Err(EvalError::InvalidParameter {
            name: "rte window",
            reason: "must be at least 1 frame".into(),
        });
    }
    let n = est.len();
    if n < 2 {
        return Err(EvalError::TooShort {
            what: "relative trajectory error",
            needed: 2,
            got: n,
        });
    }
    let (d, scale) = if n > window {
        (window, 1.0)
    } else {
        (n - 1, window as f64 / n as f64)
    };
    let errors = (0..n - d).map(|i| {
        let de = sub(est[i + d], est[i]);
        let dg = sub(gt[i + d], gt[i]);
        sub(de, dg)
    });
    Ok(mean_squared_norm(errors).sqrt() * scale)
}

/// Relative trajectory error as RoNIN computes it (`compute_relative_trajectory_error` inside
/// `compute_ate_rte`): the per-coordinate RMS of the displacement errors, metres. Same windows
/// and short-sequence scaling as [`rte`], and equal to [`rte`]` / √2`.
///
/// # Errors
/// As [`rte`].
pub fn rte_ronin(est: &[[f64; 2]], gt: &[[f64; 2]], window: usize) -> Result<f64> {
    Ok(rte(est, gt, window)? / std::f64::consts::SQRT_2)
}

/// Converts a duration to a frame count at `rate_hz`: `round(seconds · rate_hz)`, at least 1.
///
/// `seconds_to_frames(60.0, 200.0) == 12000`, RoNIN's RTE window.
///
/// # Errors
/// A non-finite or non-positive duration or rate, or a frame count too large for `usize`.
pub fn seconds_to_frames(seconds: f64, rate_hz: f64) -> Result<usize> {
    check_positive("window seconds", seconds)?;
    check_positive("rate_hz", rate_hz)?;
    let frames = (seconds * rate_hz).round();
    if !frames.is_finite() || frames >= usize::MAX as f64 {
        return Err(EvalError::InvalidParameter {
            name: "window seconds",
            reason: format!("{seconds} s at {rate_hz} Hz is too many frames"),
        });
    }
    // A positive duration never means "no window".
    Ok((frames as usize).max(1))
}

/// Mean sampling rate of a timeline, Hz: `(N − 1) / (t_{N−1} − t₀)`.
///
/// # Errors
/// Fewer than 2 times, an invalid timeline, or zero duration.
pub fn estimate_rate_hz(times: &[f64]) -> Result<f64> {
    check_times(times)?;
    if times.len() < 2 {
        return Err(EvalError::TooShort {
            what: "rate estimate",
            needed: 2,
            got: times.len(),
        });
    }
    let span = times[times.len() - 1] - times[0];
    if span <= 0.0 {
        return Err(EvalError::InvalidParameter {
            name: "times",
            reason: "zero duration".into(),
        });
    }
    Ok((times.len() - 1) as f64 / span)
}

/// Checks that `times` is sampled at `config.rate_hz`, the rate [`EvalConfig`]'s RTE windows
/// are counted at: its mean rate ([`estimate_rate_hz`]) must be within [`RATE_TOLERANCE`]
/// (10 %) of `config.rate_hz`. Returns that mean rate.
///
/// [`evaluate_trajectory`] calls it; call it before [`trajectory_metrics`] when the timeline
/// is at hand.
///
/// # Errors
/// A non-positive or non-finite `config.rate_hz`, an invalid timeline (as
/// [`estimate_rate_hz`]), or [`EvalError::RateMismatch`], which names both rates.
pub fn check_rate(times: &[f64], config: &EvalConfig) -> Result<f64> {
    check_positive("rate_hz", config.rate_hz)?;
    let timeline_hz = estimate_rate_hz(times)?;
    if (timeline_hz - config.rate_hz).abs() > RATE_TOLERANCE * config.rate_hz {
        return Err(EvalError::RateMismatch {
            timeline_hz,
            config_hz: config.rate_hz,
        });
    }
    Ok(timeline_hz)
}

/// Velocity mean squared error per channel, (m/s)²:
/// `MSE_c = (1/N) Σᵢ (predᵢ,c − targetᵢ,c)²` for the two horizontal channels `c ∈ {0, 1}`.
///
/// This is the regression metric of RIDI's Table (0.016 / 0.015 m²/s² for the cascaded
/// regressor).
///
/// # Errors
/// Empty inputs, different lengths, non-finite values.
pub fn velocity_mse(pred: &[[f64; 2]], target: &[[f64; 2]]) -> Result<[f64; 2]> {
    check_non_empty("predicted velocity", pred.len())?;
    check_same_len("predicted vs target velocity", pred.len(), target.len())?;
    check_finite_points("predicted velocity", pred)?;
    check_finite_points("target velocity", target)?;
    let n = pred.len() as f64;
    let mut acc = [0.0; 2];
    for (p, t) in pred.iter().zip(target) {
        for c in 0..2 {
            acc[c] += (p[c] - t[c]).powi(2);
        }
    }
    Ok([acc[0] / n, acc[1] / n])
}

/// Classification accuracy: `#{i : truthᵢ = predictedᵢ} / N`, in `[0, 1]`.
///
/// Works on any label type (indices, names, an enum).
///
/// # Errors
/// Empty inputs or different lengths.
pub fn accuracy<T: PartialEq>(truth: &[T], predicted: &[T]) -> Result<f64> {
    check_non_empty("truth labels", truth.len())?;
    check_same_len("truth vs predicted labels", truth.len(), predicted.len())?;
    let hits = truth.iter().zip(predicted).filter(|(t, p)| t == p).count();
    Ok(hits as f64 / truth.len() as f64)
}

/// Confusion matrix over named classes: `counts[t][p]` is the number of samples of true class
/// `t` predicted as class `p` (rows: truth, columns: prediction).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ConfusionMatrix {
    /// Class names, in row/column order.
    pub classes: Vec<String>,
    /// `classes.len() × classes.len()` counts, rows = truth.
    pub counts: Vec<Vec<usize>>,
}

impl ConfusionMatrix {
    /// Builds the matrix from class indices into `classes`.
    ///
    /// # Errors
    /// Empty or mismatched label lists, no classes, or an index `≥ classes.len()`.
    pub fn from_indices(truth: &[usize], predicted: &[usize], classes: &[&str]) -> Result<Self> {
        check_non_empty("truth labels", truth.len())?;
        check_same_len("truth vs predicted labels", truth.len(), predicted.len())?;
        check_non_empty("classes", classes.len())?;
        let k = classes.len();
        let mut counts = vec![vec![0; k]; k];
        for (&t, &p) in truth.iter().zip(predicted) {
            for label in [t, p] {
                if label >= k {
                    return Err(EvalError::UnknownLabel {
                        label: label.to_string(),
                        classes: k,
                    });
                }
            }
            counts[t][p] += 1;
        }
        Ok(Self {
            classes: classes.iter().map(|c| (*c).to_owned()).collect(),
            counts,
        })
    }

    /// Builds the matrix from class names; every name must be one of `classes`.
    ///
    /// # Errors
    /// As [`ConfusionMatrix::from_indices`], with an unknown name as [`EvalError::UnknownLabel`].
    pub fn from_names(truth: &[&str], predicted: &[&str], classes: &[&str]) -> Result<Self> {
        let index = |name: &str| {
            classes
                .iter()
                .position(|c| *c == name)
                .ok_or_else(|| EvalError::UnknownLabel {
                    label: name.to_owned(),
                    classes: classes.len(),
                })
        };
        let t = truth.iter().map(|n| index(n)).collect::<Result<Vec<_>>>()?;
        let p = predicted
            .iter()
            .map(|n| index(n))
            .collect::<Result<Vec<_>>>()?;
        Self::from_indices(&t, &p, classes)
    }

    /// Total number of samples, `Σ counts`.
    pub fn total(&self) -> usize {
        count_sum(self.counts.iter().flatten())
    }

    /// Overall accuracy, `Σ_c counts[c][c] / total`; `None` for an empty matrix.
    pub fn accuracy(&self) -> Option<f64> {
        let total = self.total();
        let diag = count_sum((0..self.counts.len()).filter_map(|c| self.counts[c].get(c)));
        (total > 0).then(|| diag as f64 / total as f64)
    }

    /// Recall of class `c`, `counts[c][c] / Σ_p counts[c][p]`; `None` if the class never occurs
    /// in the truth or `c` is out of range.
    pub fn recall(&self, c: usize) -> Option<f64> {
        let row = self.counts.get(c)?;
        let n = count_sum(row);
        (n > 0).then(|| row.get(c).copied().unwrap_or(0) as f64 / n as f64)
    }

    /// Precision of class `c`, `counts[c][c] / Σ_t counts[t][c]`; `None` if the class is never
    /// predicted or `c` is out of range.
    pub fn precision(&self, c: usize) -> Option<f64> {
        let hit = *self.counts.get(c)?.get(c)?;
        let n = count_sum(self.counts.iter().filter_map(|row| row.get(c)));
        (n > 0).then(|| hit as f64 / n as f64)
    }
}

/// A sum of confusion counts, saturating: the fields are public (and read from reports), and
/// counts no recording reaches must not overflow.
fn count_sum<'a>(counts: impl IntoIterator<Item = &'a usize>) -> usize {
    counts.into_iter().fold(0, |a, &c| a.saturating_add(c))
}

/// How far the mean rate of a timeline ([`estimate_rate_hz`]) may be from
/// [`EvalConfig::rate_hz`], as a fraction of `rate_hz`, in the functions that take both
/// ([`evaluate_trajectory`], [`check_rate`]): 10 %, as phones' nominal rates vary by a few
/// percent (the pipeline accepts 180-220 Hz recordings for the same reason).
pub const RATE_TOLERANCE: f64 = 0.1;

/// Settings of a per-sequence trajectory evaluation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EvalConfig {
    /// Initial stretch the rigid alignment is fitted on (RIDI: 10 s).
    pub align: AlignWindow,
    /// RTE window, seconds (RoNIN: 60 s), counted as frames at [`EvalConfig::rate_hz`].
    pub rte_window_s: f64,
    /// Short RTE window, seconds, for local drift (5 s), counted as frames at
    /// [`EvalConfig::rate_hz`].
    pub short_rte_window_s: f64,
    /// Rate used to turn the RTE windows into frame counts ([`seconds_to_frames`]): 200 Hz by
    /// default, RoNIN's nominal rate (12000 frames per minute).
    ///
    /// It must match the data. [`evaluate_trajectory`] refuses a timeline whose mean rate
    /// ([`estimate_rate_hz`]) is more than [`RATE_TOLERANCE`] (10 %) away
    /// ([`EvalError::RateMismatch`]): with the default, 100 Hz data would otherwise get RTE
    /// over windows twice as long (2 min and 10 s), silently. For data at another rate set it
    /// to `estimate_rate_hz(times)?`. [`trajectory_metrics`], which has no timeline, trusts it:
    /// call it on an [`align_trajectory`] result to count windows in frames whatever the rate
    /// (RoNIN's fixed 12000 frames on data that is not at 200 Hz).
    pub rate_hz: f64,
}

impl Default for EvalConfig {
    fn default() -> Self {
        Self {
            align: AlignWindow::default(),
            rte_window_s: 60.0,
            short_rte_window_s: 5.0,
            rate_hz: 200.0,
        }
    }
}

/// Computes every trajectory metric of one method on one sequence, for an estimate that is
/// already aligned (the alignment setting of `config` is not used).
///
/// See [`TrajectoryMetrics`] for each field's formula.
///
/// Without a timeline this cannot check the rate: the RTE windows are
/// `seconds_to_frames(config.rte_window_s, config.rate_hz)` and
/// `seconds_to_frames(config.short_rte_window_s, config.rate_hz)` frames, i.e. they last the
/// configured seconds only if the frames really are at `config.rate_hz`. Set `rate_hz` to the
/// data's rate ([`estimate_rate_hz`]), check it with [`check_rate`], or use
/// [`evaluate_trajectory`], which refuses a mismatch.
///
/// # Errors
/// Fewer than 2 frames, mismatched lengths, non-finite coordinates, invalid windows or rate.
pub fn trajectory_metrics(
    est: &[[f64; 2]],
    gt: &[[f64; 2]],
    config: &EvalConfig,
) -> Result<TrajectoryMetrics> {
    check_pair(est, gt)?;
    let window = seconds_to_frames(config.rte_window_s, config.rate_hz)?;
    let short_window = seconds_to_frames(config.short_rte_window_s, config.rate_hz)?;
    let rte_m = rte(est, gt, window)?;
    let ate_m = ate(est, gt)?;
    Ok(TrajectoryMetrics {
        mpe_m: mean_position_error(est, gt)?,
        mpe_pct: mean_position_error_percent(est, gt)?,
        ate_m,
        rte_m,
        ate_ronin_m: ate_m / std::f64::consts::SQRT_2,
        rte_ronin_m: rte_m / std::f64::consts::SQRT_2,
        rte_5s_m: rte(est, gt, short_window)?,
        path_length_ratio: path_length_ratio(est, gt)?,
    })
}

/// Result of [`evaluate_trajectory`].
#[derive(Debug, Clone, PartialEq)]
pub struct TrajectoryEval {
    /// The alignment that was fitted.
    pub alignment: AlignmentFit,
    /// The estimate after alignment, one point per frame.
    pub aligned: Vec<[f64; 2]>,
    /// Metrics of the aligned estimate.
    pub metrics: TrajectoryMetrics,
}

/// Aligns `est` onto `gt` over `config.align`, then computes [`trajectory_metrics`].
///
/// `times` must be sampled at `config.rate_hz`, the rate the RTE windows are counted at: a
/// mean rate ([`estimate_rate_hz`]) more than [`RATE_TOLERANCE`] (10 %) away is refused
/// ([`check_rate`]). For data at another rate than the default 200 Hz, set
/// `rate_hz: estimate_rate_hz(times)?`.
///
/// # Errors
/// [`EvalError::RateMismatch`] for a timeline at another rate than `config.rate_hz`, a
/// non-positive `config.rate_hz`, a timeline of fewer than 2 frames or zero duration, and as
/// [`align_trajectory`](crate::align_trajectory) and [`trajectory_metrics`].
///
/// ```
/// use ridi_eval::{EvalConfig, EvalError, estimate_rate_hz, evaluate_trajectory};
///
/// // 30 s at 100 Hz: the default config counts its windows at 200 Hz, and is refused.
/// let times: Vec<f64> = (0..3000).map(|i| f64::from(i) / 100.0).collect();
/// let gt: Vec<[f64; 2]> = times.iter().map(|&t| [t, 0.0]).collect();
/// let est: Vec<[f64; 2]> = times.iter().map(|&t| [t, 0.01 * t]).collect();
/// let err = evaluate_trajectory(&times, &est, &gt, &EvalConfig::default()).unwrap_err();
/// assert!(matches!(err, EvalError::RateMismatch { .. }));
///
/// let config = EvalConfig { rate_hz: estimate_rate_hz(&times)?, ..EvalConfig::default() };
/// let out = evaluate_trajectory(&times, &est, &gt, &config)?;
/// assert!(out.metrics.rte_5s_m > 0.0);
/// # Ok::<(), EvalError>(())
/// ```
pub fn evaluate_trajectory(
    times: &[f64],
    est: &[[f64; 2]],
    gt: &[[f64; 2]],
    config: &EvalConfig,
) -> Result<TrajectoryEval> {
    check_rate(times, config)?;
    let (alignment, aligned) = align_trajectory(times, est, gt, config.align)?;
    let metrics = trajectory_metrics(&aligned, gt, config)?;
    Ok(TrajectoryEval {
        alignment,
        aligned,
        metrics,
    })
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = sub(a, b);
    d[0].hypot(d[1])
}

/// `(1/n) Σ ‖v‖²` over a non-empty iterator.
fn mean_squared_norm(vs: impl Iterator<Item = [f64; 2]>) -> f64 {
    let (sum, n) = vs.fold((0.0, 0usize), |(s, n), v| {
        (s + v[0] * v[0] + v[1] * v[1], n + 1)
    });
    sum / n as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::align::Rigid2;

    const SQRT_2: f64 = std::f64::consts::SQRT_2;

    fn line(n: usize) -> Vec<[f64; 2]> {
        (0..n).map(|i| [i as f64, 0.0]).collect()
    }

    fn approx(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * (1.0 + b.abs())
    }

    #[test]
    fn constant_offset() {
        // A 3-4-5 offset on a 10 m straight walk.
        let gt = line(11);
        let est: Vec<[f64; 2]> = gt.iter().map(|p| [p[0] + 3.0, p[1] + 4.0]).collect();
        assert!(approx(mean_position_error(&est, &gt).unwrap(), 5.0));
        assert!(approx(ate(&est, &gt).unwrap(), 5.0));
        assert!(approx(ate_ronin(&est, &gt).unwrap(), 12.5f64.sqrt()));
        assert!(approx(
            mean_position_error_percent(&est, &gt).unwrap().unwrap(),
            50.0
        ));
        // A rigid offset does not change displacements.
        assert_eq!(rte(&est, &gt, 3).unwrap(), 0.0);
        assert_eq!(rte(&est, &gt, 100).unwrap(), 0.0);
        assert!(approx(path_length_ratio(&est, &gt).unwrap().unwrap(), 1.0));
    }

    #[test]
    fn rte_short_sequence_scales_end_drift() {
        // N = 4 < window = 8: d = 3, single error (est₃ − est₀) − (gt₃ − gt₀) = (3,4) − (3,0)
        // = (0,4); Euclidean 4 · 8/4 = 8, per-coordinate sqrt(16/2) · 2 = 4√2.
        let gt = line(4);
        let est = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 4.0]];
        assert!(approx(rte(&est, &gt, 8).unwrap(), 8.0));
        assert!(approx(rte_ronin(&est, &gt, 8).unwrap(), 4.0 * SQRT_2));
        // N = window: short rule with scale 1 (RoNIN would return NaN here).
        assert!(approx(rte(&est, &gt, 4).unwrap(), 4.0));
    }

    #[test]
    fn rte_long_sequence_sliding_windows() {
        // N = 5, window 2: errors at i = 0, 1, 2.
        // est x drifts by +1 per frame after frame 2: est = gt + (0, 0, 0, 1, 2) in x.
        // e₀ = (est₂−est₀) − (gt₂−gt₀) = 0; e₁ = 1; e₂ = 2 (all along x).
        // Euclidean sqrt((0 + 1 + 4)/3); per-coordinate sqrt(5/6).
        let gt = line(5);
        let est = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [4.0, 0.0], [6.0, 0.0]];
        assert!(approx(rte(&est, &gt, 2).unwrap(), (5.0f64 / 3.0).sqrt()));
        assert!(approx(
            rte_ronin(&est, &gt, 2).unwrap(),
            (5.0f64 / 6.0).sqrt()
        ));
        // ATE: errors 0,0,0,1,2 → sqrt(5/5) = 1; MPE = 3/5; path ratio 6/4.
        assert!(approx(ate(&est, &gt).unwrap(), 1.0));
        assert!(approx(mean_position_error(&est, &gt).unwrap(), 0.6));
        assert!(approx(path_length_ratio(&est, &gt).unwrap().unwrap(), 1.5));
    }

    #[test]
    fn rte_errors() {
        assert!(matches!(
            rte(&[[0.0; 2]], &[[0.0; 2]], 10),
            Err(EvalError::TooShort { .. })
        ));
        assert!(matches!(
            rte(&line(3), &line(3), 0),
            Err(EvalError::InvalidParameter { .. })
        ));
        assert!(rte(&line(3), &line(4), 2).is_err());
    }

    #[test]
    fn window_conversion() {
        assert_eq!(seconds_to_frames(60.0, 200.0).unwrap(), 12000);
        assert_eq!(seconds_to_frames(5.0, 200.0).unwrap(), 1000);
        assert_eq!(seconds_to_frames(1e-9, 200.0).unwrap(), 1);
        assert!(seconds_to_frames(-1.0, 200.0).is_err());
        assert!(seconds_to_frames(1.0, 0.0).is_err());
        assert!(seconds_to_frames(1e300, 1e300).is_err());
        let times: Vec<f64> = (0..=400).map(|i| f64::from(i) / 200.0).collect();
        assert!(approx(estimate_rate_hz(&times).unwrap(), 200.0));
        assert!(estimate_rate_hz(&[1.0, 1.0]).is_err());
        assert!(estimate_rate_hz(&[1.0]).is_err());
    }

    #[test]
    fn stationary_ground_truth_has_no_percentages() {
        let gt = vec![[1.0, 1.0]; 3];
        let est = vec![[1.0, 2.0]; 3];
        assert_eq!(mean_position_error_percent(&est, &gt).unwrap(), None);
        assert_eq!(path_length_ratio(&est, &gt).unwrap(), None);
        let m = trajectory_metrics(&est, &gt, &EvalConfig::default()).unwrap();
        assert_eq!(m.mpe_pct, None);
        assert!(approx(m.mpe_m, 1.0));
    }

    #[test]
    fn velocity_mse_per_channel() {
        let pred = [[1.0, 0.0], [2.0, 1.0]];
        let target = [[0.0, 0.0], [0.0, 0.0]];
        assert_eq!(velocity_mse(&pred, &target).unwrap(), [2.5, 0.5]);
        assert!(velocity_mse(&[], &[]).is_err());
        assert!(velocity_mse(&pred, &target[..1]).is_err());
    }

    #[test]
    fn confusion_counts_and_accuracy() {
        let classes = ["leg", "bag", "body", "handheld"];
        let truth = ["leg", "leg", "bag", "body", "handheld", "handheld"];
        let pred = ["leg", "bag", "bag", "body", "handheld", "body"];
        let cm = ConfusionMatrix::from_names(&truth, &pred, &classes).unwrap();
        assert_eq!(
            cm.counts,
            vec![
                vec![1, 1, 0, 0],
                vec![0, 1, 0, 0],
                vec![0, 0, 1, 0],
                vec![0, 0, 1, 1],
            ]
        );
        assert_eq!(cm.total(), 6);
        assert!(approx(cm.accuracy().unwrap(), 4.0 / 6.0));
        assert!(approx(accuracy(&truth, &pred).unwrap(), 4.0 / 6.0));
        assert!(approx(cm.recall(0).unwrap(), 0.5));
        assert!(approx(cm.precision(1).unwrap(), 0.5));
        assert!(approx(cm.precision(2).unwrap(), 0.5));
        assert_eq!(cm.recall(9), None);
        let by_index =
            ConfusionMatrix::from_indices(&[0, 0, 1, 2, 3, 3], &[0, 1, 1, 2, 3, 2], &classes)
                .unwrap();
        assert_eq!(by_index, cm);
        // Counts no recording reaches (a report edited by hand) saturate, not overflow.
        let huge = ConfusionMatrix {
            classes: vec!["a".into(), "b".into()],
            counts: vec![vec![usize::MAX, 1], vec![1, usize::MAX]],
        };
        assert_eq!(huge.total(), usize::MAX);
        assert!(huge.accuracy().is_some_and(f64::is_finite));
        assert!(huge.recall(0).is_some_and(f64::is_finite));
        assert!(huge.precision(1).is_some_and(f64::is_finite));
    }

    #[test]
    fn confusion_rejects_unknown_labels() {
        assert!(matches!(
            ConfusionMatrix::from_indices(&[0, 4], &[0, 0], &["a", "b"]),
            Err(EvalError::UnknownLabel { .. })
        ));
        assert!(matches!(
            ConfusionMatrix::from_names(&["a"], &["c"], &["a", "b"]),
            Err(EvalError::UnknownLabel { .. })
        ));
        assert!(ConfusionMatrix::from_indices(&[], &[], &["a"]).is_err());
        assert!(ConfusionMatrix::from_indices(&[0], &[0], &[]).is_err());
        assert!(accuracy::<usize>(&[], &[]).is_err());
    }

    /// `n` frames at `rate` Hz; ground truth walks along x at 1 m/s and the estimate walks
    /// `drift` m/s faster, so the displacement error over any `d` seconds is `drift · d`.
    fn drifting_walk(n: usize, rate: f64, drift: f64) -> (Vec<f64>, Vec<[f64; 2]>, Vec<[f64; 2]>) {
        let times: Vec<f64> = (0..n).map(|i| i as f64 / rate).collect();
        let gt = times.iter().map(|&t| [t, 0.0]).collect();
        let est = times.iter().map(|&t| [(1.0 + drift) * t, 0.0]).collect();
        (times, est, gt)
    }

    #[test]
    fn evaluate_refuses_a_timeline_at_another_rate_than_the_config() {
        // 100 Hz data, default config (200 Hz): refused, naming both rates and the fix.
        let (times, est, gt) = drifting_walk(4000, 100.0, 0.1);
        let err = evaluate_trajectory(&times, &est, &gt, &EvalConfig::default()).unwrap_err();
        match err {
            EvalError::RateMismatch {
                timeline_hz,
                config_hz,
            } => {
                assert!(approx(timeline_hz, 100.0), "{timeline_hz}");
                assert_eq!(config_hz, 200.0);
            }
            other => panic!("{other:?}"),
        }
        let text = err.to_string();
        for part in [
            "sampled at 100.0 Hz",
            "EvalConfig::rate_hz is 200 Hz",
            "more than 10 % apart",
            "2.00 times their nominal",
            "set `rate_hz` to `estimate_rate_hz(times)`",
        ] {
            assert!(text.contains(part), "`{part}` not in: {text}");
        }

        // The fix the message gives: 5 s windows are 500 frames, drift 0.1 m/s → 0.5 m.
        let config = EvalConfig {
            rate_hz: estimate_rate_hz(&times).unwrap(),
            ..EvalConfig::default()
        };
        let out = evaluate_trajectory(&times, &est, &gt, &config).unwrap();
        assert!(
            (out.metrics.rte_5s_m - 0.5).abs() < 1e-9,
            "{}",
            out.metrics.rte_5s_m
        );
        // What the default config silently gave before: 1000-frame windows, 10 s at 100 Hz.
        let aligned = out.aligned;
        let wrong = trajectory_metrics(&aligned, &gt, &EvalConfig::default()).unwrap();
        assert!((wrong.rte_5s_m - 1.0).abs() < 1e-9, "{}", wrong.rte_5s_m);

        // Twice the configured rate is refused too (windows half as long).
        let (times, est, gt) = drifting_walk(4000, 400.0, 0.1);
        let err = evaluate_trajectory(&times, &est, &gt, &EvalConfig::default()).unwrap_err();
        assert!(err.to_string().contains("0.50 times"), "{err}");
    }

    #[test]
    fn rates_within_ten_percent_of_the_config_are_accepted() {
        let config = EvalConfig::default();
        for rate in [181.0, 195.0, 200.0, 205.3, 219.0] {
            let (times, est, gt) = drifting_walk(3000, rate, 0.0);
            assert!(approx(check_rate(&times, &config).unwrap(), rate), "{rate}");
            let out = evaluate_trajectory(&times, &est, &gt, &config).unwrap();
            assert!(out.metrics.rte_m < 1e-9, "{rate}");
        }
        for rate in [100.0, 179.0, 221.0, 400.0] {
            let (times, est, gt) = drifting_walk(3000, rate, 0.0);
            assert!(
                matches!(
                    check_rate(&times, &config),
                    Err(EvalError::RateMismatch { .. })
                ),
                "{rate}"
            );
            assert!(
                matches!(
                    evaluate_trajectory(&times, &est, &gt, &config),
                    Err(EvalError::RateMismatch { .. })
                ),
                "{rate}"
            );
        }
        // The tolerance is relative to the configured rate.
        let (times, est, gt) = drifting_walk(3000, 92.0, 0.0);
        let at_100 = EvalConfig {
            rate_hz: 100.0,
            ..config
        };
        assert!(evaluate_trajectory(&times, &est, &gt, &at_100).is_ok());
        assert_eq!(RATE_TOLERANCE, 0.1);
    }

    #[test]
    fn rate_check_reports_bad_configs_and_timelines_as_such() {
        let (times, est, gt) = drifting_walk(100, 200.0, 0.0);
        for bad in [0.0, -200.0, f64::NAN, f64::INFINITY] {
            let config = EvalConfig {
                rate_hz: bad,
                ..EvalConfig::default()
            };
            assert!(
                matches!(
                    evaluate_trajectory(&times, &est, &gt, &config),
                    Err(EvalError::InvalidParameter {
                        name: "rate_hz",
                        ..
                    })
                ),
                "{bad}"
            );
        }
        let config = EvalConfig::default();
        assert!(matches!(
            evaluate_trajectory(&[], &[], &[], &config),
            Err(EvalError::Empty { what: "times" })
        ));
        assert!(matches!(
            check_rate(&[0.0], &config),
            Err(EvalError::TooShort { .. })
        ));
        assert!(matches!(
            check_rate(&[0.0, 1.0, 0.5], &config),
            Err(EvalError::TimeDecreasing { index: 2 })
        ));
        // Mismatched lengths are still reported as such, after the rate check.
        assert!(matches!(
            evaluate_trajectory(&times, &est[..50], &gt, &config),
            Err(EvalError::LengthMismatch { .. })
        ));
    }

    #[test]
    fn evaluate_aligns_then_measures() {
        // The estimate is the ground truth seen from another frame, with a 1 m lateral drift
        // appearing after the 10 s alignment window.
        let times: Vec<f64> = (0..4000).map(|i| f64::from(i) / 200.0).collect();
        let gt: Vec<[f64; 2]> = times.iter().map(|&t| [t, 2.0 * (0.3 * t).sin()]).collect();
        let mut est = Rigid2::new(-1.0, [5.0, 7.0]).apply_all(&gt);
        let drift = Rigid2::new(-1.0, [0.0, 0.0]).apply([0.0, 1.0]);
        for p in est.iter_mut().skip(2000) {
            p[0] += drift[0];
            p[1] += drift[1];
        }
        let out = evaluate_trajectory(&times, &est, &gt, &EvalConfig::default()).unwrap();
        assert_eq!(out.alignment.frames_used, 2000);
        assert!((out.alignment.transform.angle - 1.0).abs() < 1e-9);
        // Half the frames are off by exactly 1 m.
        assert!((out.metrics.mpe_m - 0.5).abs() < 1e-9);
        assert!((out.metrics.ate_m - 0.5f64.sqrt()).abs() < 1e-9);
        assert!((out.metrics.ate_ronin_m - 0.5).abs() < 1e-9);
        // 4000 frames < 12000: single end-to-end drift of 1 m, scaled by 12000 / 4000.
        assert!((out.metrics.rte_m - 3.0).abs() < 1e-9);
        assert!((out.metrics.rte_ronin_m - 3.0 / SQRT_2).abs() < 1e-9);
        // 5 s windows (1000 frames) over 3000 starts; those spanning the step at 2000 are
        // i = 1000..=1999, each off by 1 m: sqrt(1000 / 3000).
        assert!((out.metrics.rte_5s_m - (1.0f64 / 3.0).sqrt()).abs() < 1e-9);
    }
}
