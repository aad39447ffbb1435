//! Trajectory evaluation for pedestrian inertial navigation.
//!
//! Everything here takes plain arrays (`[x, y]` positions in metres, times in seconds, labels
//! as indices or names), so any pipeline can be evaluated without depending on its types.
//!
//! - Alignment ([`align_trajectory`], [`fit_alignment`]): 2D rigid alignment (rotation + translation, no scale) fitted on an initial
//!   stretch, RIDI's 10 s by default.
//! - Metrics ([`evaluate_trajectory`], [`TrajectoryEval`]): MPE (m and % of path length), ATE and RTE in Euclidean and RoNIN
//!   per-coordinate forms, short-window RTE, path length ratio, velocity MSE, placement accuracy
//!   and confusion matrix. RTE windows are set in seconds ([`EvalConfig`]) and counted in
//!   frames at [`EvalConfig::rate_hz`], 200 Hz by default: [`evaluate_trajectory`] refuses a
//!   timeline whose mean rate is more than 10 % from it ([`EvalError::RateMismatch`]); set
//!   `rate_hz` to [`estimate_rate_hz`]`(times)` for data at another rate.
//! - Report building blocks ([`SequenceReport`], [`summarize`], [`markdown_table`]): serde
//!   per-sequence results (`report.json`), per-method means, markdown tables
//!   (`report.md`).
//! - PDR ([`pdr_trajectory`], [`detect_steps`]): the step-counting baseline: step detection and step-and-heading integration.
//! - Intervals ([`mean_interval`], [`runs_interval`], [`ratio_interval`]): how far a mean over
//!   runs can be trusted, by a bootstrap over whole runs (a run's parts drawn together), given
//!   from [`MIN_INTERVAL_RUNS`] runs on; means summed in an order that does not depend on the
//!   runs' ([`ordered_mean`]), so that a report reproduces to the last bit.
//!
//! Inputs are validated: empty, mismatched or non-finite inputs give an [`EvalError`], never a
//! panic.
//!
//! # Example
//!
//! ```
//! use ridi_eval::{EvalConfig, Rigid2, evaluate_trajectory};
//!
//! // 30 s walking a circle of radius 10 m, sampled at 200 Hz.
//! let times: Vec<f64> = (0..6000).map(|i| i as f64 / 200.0).collect();
//! let gt: Vec<[f64; 2]> = times
//!     .iter()
//!     .map(|&t| [10.0 * (0.1 * t).cos(), 10.0 * (0.1 * t).sin()])
//!     .collect();
//!
//! // An estimate in its own frame (unknown heading and origin) that drifts 2 cm/s along x.
//! let mut est = Rigid2::new(0.8, [-3.0, 5.0]).inverse().apply_all(&gt);
//! let drift_dir = Rigid2::new(-0.8, [0.0, 0.0]).apply([1.0, 0.0]);
//! for (p, &t) in est.iter_mut().zip(&times) {
//!     p[0] += 0.02 * t * drift_dir[0];
//!     p[1] += 0.02 * t * drift_dir[1];
//! }
//!
//! let out = evaluate_trajectory(&times, &est, &gt, &EvalConfig::default())?;
//! assert_eq!(out.alignment.frames_used, 2000); // the first 10 s
//! assert!((out.alignment.transform.angle - 0.8).abs() < 0.05);
//! let m = out.metrics;
//! assert!(m.mpe_m > 0.0 && m.mpe_m < 0.6);
//! assert!((m.ate_ronin_m - m.ate_m / 2f64.sqrt()).abs() < 1e-12);
//!
//! // One row per (sequence, method) for report.md.
//! use ridi_eval::{MethodMetrics, SequenceReport, markdown_table};
//! let seq = SequenceReport {
//!     sequence: "circle".into(),
//!     placement: None,
//!     frames: times.len(),
//!     methods: vec![MethodMetrics { method: "drifty".into(), metrics: m }],
//! };
//! assert!(markdown_table(&[seq]).contains("| circle | drifty |"));
//! # Ok::<(), ridi_eval::EvalError>(())
//! ```

mod align;
mod bootstrap;
mod error;
mod metrics;
mod pdr;
mod report;

pub use align::{
    AlignWindow, AlignmentFit, Rigid2, WEAK_ALIGNMENT_EXTENT_M, align_trajectory, fit_alignment,
    fit_rigid_2d, target_extent,
};
pub use bootstrap::{
    DRAWS, Interval, MIN_INTERVAL_RUNS, mean_interval, ordered_mean, ratio_interval, runs_interval,
};
pub use error::{EvalError, Result};
pub use metrics::{
    ConfusionMatrix, EvalConfig, RATE_TOLERANCE, TrajectoryEval, TrajectoryMetrics, accuracy, ate,
    ate_ronin, check_rate, estimate_rate_hz, evaluate_trajectory, mean_position_error,
    mean_position_error_percent, path_length, path_length_ratio, rte, rte_ronin, seconds_to_frames,
    trajectory_metrics, velocity_mse,
};
pub use pdr::{StepDetectorConfig, detect_steps, detect_steps_in_magnitude, pdr_trajectory};
pub use report::{
    MethodMetrics, MethodSummary, Metric, SequenceReport, markdown_confusion,
    markdown_metric_table, markdown_table, paired_differences, run_of, summarize,
    summary_intervals,
};

/// The README's example, compiled by `cargo test --doc` so that it cannot drift from the API.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
