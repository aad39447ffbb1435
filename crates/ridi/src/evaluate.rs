//! Evaluation: every method on every sequence with ground truth, metrics, and the report files.
//!
//! `report.json` has, per sequence, `name`, `placement`, `path_length_m`,
//! `alignment_extent_m` (how far the ground truth moved within the alignment window),
//! `placement_accuracy`, `velocity_mse` (`[S-x, S-z]`, (m/s)^2) and `methods.<key>` with the
//! metric keys of [`ridi_eval::TrajectoryMetrics`] (`mpe_m`, `mpe_pct`, `ate_m`, `rte_m`,
//! `ate_ronin_m`, `rte_ronin_m`, `rte_5s_m`, `path_length_ratio`); `summary.<key>` holds the
//! means over sequences; `warnings` what the numbers do not say (see [`placement_warnings`]).
//! Method keys are those of [`Method::key`]. [`Report::read`] reads a `report.json` back
//! (`null`, which JSON has for a `NaN`, as `NaN`); [`crate::EvalFolder`] writes an evaluation's
//! folder.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;
use ridi_data::{Sequence, write_atomically};
use ridi_eval::{
    ConfusionMatrix, EvalConfig, MethodMetrics, Metric, SequenceReport, TrajectoryMetrics,
    evaluate_trajectory, markdown_confusion, markdown_metric_table, summarize, velocity_mse,
};
use ridi_features::{FeatureConfig, compute_targets};
use ridi_regress::Cascade;
use serde::{Deserialize, Deserializer, Serialize};

use crate::baselines::{Method, baseline_trajectory};
use crate::error::{PipelineError, Result};
use crate::orientation::oriented;
use crate::track::{check_trackable, regressed};
use crate::track_options::TrackOptions;
use crate::train::ground_truth_view;

/// What to evaluate and how.
#[derive(Debug, Clone, PartialEq)]
pub struct EvalOptions {
    /// Methods, in report order.
    pub methods: Vec<Method>,
    /// Frames between regressions, and the correction, of the model-based methods.
    pub track: TrackOptions,
    /// Alignment and metric windows (a report's `config`).
    pub config: EvalConfig,
}

impl Default for EvalOptions {
    fn default() -> Self {
        Self {
            methods: Method::ALL.to_vec(),
            track: TrackOptions::default(),
            config: EvalConfig::default(),
        }
    }
}

/// Results of one sequence.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SequenceResult {
    /// Sequence name.
    pub name: String,
    /// The run it is part of, which the intervals draw whole ([`ridi_eval::run_of`]: the name
    /// without its `_part<N>` suffixes, as `ridi convert --split-at-gaps` and the Tyrex reader
    /// name the parts of a recording split at its gaps). Derived from the name, which the
    /// intervals and `ridi compare` take it from; written for a reader of `report.json`.
    #[serde(default)]
    pub run: String,
    /// Placement label.
    pub placement: Option<String>,
    /// The phone model it was recorded with ([`Sequence::device`]), when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub device: Option<String>,
    /// Horizontal ground-truth path length, metres.
    pub path_length_m: f64,
    /// How far the ground truth moved within the alignment window, metres
    /// ([`ridi_eval::AlignmentFit::target_extent_m`]); below
    /// [`ridi_eval::WEAK_ALIGNMENT_EXTENT_M`] the fitted heading is weakly determined and
    /// `report.md` says so.
    pub alignment_extent_m: f64,
    /// Fraction of regressions whose predicted placement is the sequence's label.
    pub placement_accuracy: Option<f64>,
    /// Velocity regression MSE `[S-x, S-z]`, (m/s)^2, against the smoothed ground truth
    /// (`NaN` without regressions, `null` in JSON).
    #[serde(deserialize_with = "nan_if_null")]
    pub velocity_mse: [f64; 2],
    /// Metrics per method key.
    pub methods: BTreeMap<String, TrajectoryMetrics>,
}

/// Everything needed to draw the plots of one sequence.
#[derive(Debug, Clone, PartialEq)]
pub struct Traces {
    /// Sequence name.
    pub name: String,
    /// Ground-truth horizontal positions.
    pub ground_truth: Vec<[f64; 2]>,
    /// Aligned horizontal trajectory of each method.
    pub methods: Vec<(Method, Vec<[f64; 2]>)>,
    /// Times of the regressions, seconds.
    pub regression_time: Vec<f64>,
    /// Regressed velocities `[S-x, S-z]`.
    pub regressed: Vec<[f64; 2]>,
    /// Ground-truth velocities at the same frames.
    pub true_velocity: Vec<[f64; 2]>,
    /// Predicted placement names at the same frames.
    pub placements: Vec<String>,
}

/// The whole evaluation: what `report.json` holds ([`Report::write`], [`Report::read`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// Per-sequence results.
    pub sequences: Vec<SequenceResult>,
    /// Mean of each metric over sequences, per method key.
    pub summary: BTreeMap<String, TrajectoryMetrics>,
    /// The 95 % interval of each mean of `summary`, per method and metric key: a bootstrap
    /// over the sequences, the parts of a run drawn together
    /// ([`ridi_eval::summary_intervals`]). Empty in reports written before it existed.
    #[serde(default)]
    pub intervals: BTreeMap<String, BTreeMap<String, ridi_eval::Interval>>,
    /// `ridi`'s paired difference from each other method, `ridi - method`, per metric key: its
    /// mean over the sequences and 95 % interval ([`ridi_eval::paired_differences`]); an
    /// interval that leaves out 0 tells the two apart on these runs. Empty without `ridi`.
    #[serde(default)]
    pub ridi_minus: BTreeMap<String, BTreeMap<String, ridi_eval::Interval>>,
    /// Velocity MSE over all regressions of all sequences, (m/s)^2 (`NaN` without
    /// regressions, `null` in JSON).
    #[serde(deserialize_with = "nan_if_null")]
    pub velocity_mse: [f64; 2],
    /// Placement accuracy over all regressions.
    pub placement_accuracy: Option<f64>,
    /// Confusion matrix of the placement classifier (rows: truth, columns: prediction).
    pub placement_confusion: Option<ConfusionMatrix>,
    /// Alignment and metric settings.
    pub config: EvalConfig,
    /// The heading correction tracking used with a model on the estimated orientation
    /// ([`TrackOptions::recorded_heading`](crate::TrackOptions::recorded_heading); `None`:
    /// the gyro's heading, as in reports written before the field existed).
    #[serde(default)]
    pub recorded_heading: Option<ridi_frames::HeadingConfig>,
    /// Methods in report order.
    pub methods: Vec<String>,
    /// Things to know before reading the numbers, one sentence each ([`placement_warnings`]);
    /// also in `report.md`.
    pub warnings: Vec<String>,
    /// What produced the numbers: the model and the tracking settings besides `config` and
    /// `recorded_heading` (`None` in reports written before the field existed).
    #[serde(default)]
    pub provenance: Option<Provenance>,
}

/// What produced a report, so that a figure can be traced to its model and settings. A field
/// a report lacks reads as empty (`""`, 0, `None`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct Provenance {
    /// The version of the `ridi` crate that evaluated.
    pub ridi_version: String,
    /// Where the model came from, as the caller names it (`ridi eval`: the model file's path,
    /// or `bundled`); `None` when the caller did not say.
    pub model_source: Option<String>,
    /// FNV-1a 64 of the model's bytes ([`Cascade::to_bytes`]), in hex: the same for the same
    /// model, whatever its file is called.
    pub model_fingerprint: String,
    /// The model's solver, placements, feature window and orientation.
    pub model: String,
    /// The orientation the model was trained on (`estimated` or `recorded` in JSON; the
    /// heading settings matter only with `estimated`).
    pub orientation: Option<ridi_features::Orientation>,
    /// Frames between regressions ([`TrackOptions::regress_every`]).
    pub regress_every: usize,
    /// The placement majority window, seconds (`None`: each regression's own placement).
    pub placement_window_s: Option<f64>,
    /// The placement map the labels were grouped by, as the caller names it (`ridi eval
    /// --placement-map`: `tyrex4` or a file); `None` without one, or when the caller did not
    /// say.
    pub placement_map: Option<String>,
    /// The correction of the model's regressions ([`TrackOptions::correction_for`]: lambda,
    /// knots, weights, initial velocity); `None` in a report that does not record it.
    pub correction: Option<ridi_correct::CorrectionConfig>,
}

impl Provenance {
    /// The provenance of an evaluation of `model` with `opts`.
    pub fn of(model: &Cascade, opts: &EvalOptions) -> Result<Self> {
        let config = model.feature_config();
        let orientation = match config.orientation {
            ridi_features::Orientation::Recorded => "the recorded orientation",
            ridi_features::Orientation::Estimated => "the estimated orientation",
        };
        Ok(Self {
            ridi_version: env!("CARGO_PKG_VERSION").to_string(),
            model_source: None,
            model_fingerprint: model_fingerprint(model)?,
            model: format!(
                "{} solver; placements {}; a feature window of {} frames; {}",
                match model.solver() {
                    ridi_regress::Solver::Exact => "exact".to_string(),
                    ridi_regress::Solver::Nystrom(n) =>
                        format!("Nyström ({} landmarks, seed {})", n.landmarks(), n.seed()),
                },
                model.placement_names().join(", "),
                config.window,
                orientation
            ),
            orientation: Some(config.orientation),
            regress_every: opts.track.regress_every,
            placement_window_s: opts.track.placement_smoothing.map(|p| p.window_s),
            placement_map: None,
            correction: Some(opts.track.correction_for(model)),
        })
    }
}

#[cfg(test)]
impl Report {
    /// A report of `sequences` of `ridi` alone and nothing else, for tests to change.
    pub(crate) fn of_sequences(sequences: Vec<SequenceResult>) -> Report {
        Report {
            sequences,
            summary: BTreeMap::new(),
            intervals: BTreeMap::new(),
            ridi_minus: BTreeMap::new(),
            velocity_mse: [f64::NAN; 2],
            placement_accuracy: None,
            placement_confusion: None,
            config: EvalConfig::default(),
            recorded_heading: None,
            methods: vec!["ridi".into()],
            warnings: Vec::new(),
            provenance: None,
        }
    }
}

/// The settings of a correction as report.md and `ridi compare` name them.
pub(crate) fn correction_text(c: &ridi_correct::CorrectionConfig) -> String {
    format!(
        "lambda {}, a knot every {} frames, weights {} / {} (horizontal / vertical), initial \
         velocity {}",
        c.lambda,
        c.knot_spacing,
        c.horizontal_weight,
        c.vertical_weight,
        initial_velocity_text(c.initial_velocity)
    )
}

/// A correction's initial velocity as report.md and `ridi compare` name it.
pub(crate) fn initial_velocity_text(v: ridi_correct::InitialVelocity) -> String {
    match v {
        ridi_correct::InitialVelocity::Estimate => "estimated".to_string(),
        ridi_correct::InitialVelocity::Fixed(v) if v == ridi_frames::WorldVec::ZERO => {
            "at rest".to_string()
        }
        ridi_correct::InitialVelocity::Fixed(v) => {
            format!("({}, {}, {}) m/s", v.x(), v.y(), v.z())
        }
    }
}

/// A mean as report tables print it ([`Metric::format`]) with its interval when known, `1.033
/// [0.90, 1.19]`; a difference (`signed`) with its sign, bold when the interval leaves out 0.
pub(crate) fn with_interval(
    metric: Metric,
    mean: Option<f64>,
    interval: Option<&ridi_eval::Interval>,
    signed: bool,
) -> String {
    interval_text(metric.format(mean), mean, interval, signed)
}

/// [`with_interval`] for a value already formatted as `value`.
pub(crate) fn interval_text(
    value: String,
    mean: Option<f64>,
    interval: Option<&ridi_eval::Interval>,
    signed: bool,
) -> String {
    let value = if signed && mean.is_some() && !value.starts_with('-') {
        format!("+{value}")
    } else {
        value
    };
    let (Some(i), Some(mean)) = (interval.filter(|i| i.is_bounded()), mean) else {
        return value;
    };
    let resolved = signed && (i.low > 0.0 || i.high < 0.0);
    // A resolved interval whose bound rounds to 0 would read as touching 0 (`[-0.02, -0.00]`,
    // or `+0.000 [0.00, 0.00]` for a tiny one): more decimals, up to 5, then scientific.
    let shows = |x: f64, d: usize| {
        format!("{:.d$}", x.abs())
            .bytes()
            .any(|b| (b'1'..=b'9').contains(&b))
    };
    let text = match (2..=5).find(|&d| !resolved || (shows(i.low, d) && shows(i.high, d))) {
        Some(2) => format!("{value} [{:.2}, {:.2}]", i.low, i.high),
        Some(d) => format!("{mean:+.d$} [{:.d$}, {:.d$}]", i.low, i.high),
        None => format!("{mean:+.1e} [{:.1e}, {:.1e}]", i.low, i.high),
    };
    if resolved {
        format!("**{text}**")
    } else {
        text
    }
}

/// Reads a pair of floats that JSON holds as `null` where they are `NaN` (serde_json writes
/// a non-finite float as `null`).
fn nan_if_null<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<[f64; 2], D::Error> {
    let pair = <[Option<f64>; 2]>::deserialize(d)?;
    Ok(pair.map(|v| v.unwrap_or(f64::NAN)))
}

struct Evaluated {
    result: SequenceResult,
    traces: Traces,
    truth_labels: Vec<String>,
    squared_errors: Vec<[f64; 2]>,
}

fn evaluate_one(seq: &Sequence, model: &Cascade, opts: &EvalOptions) -> Result<Evaluated> {
    // Baselines see the same orientation as the model.
    let seq = oriented(
        seq,
        model.feature_config().orientation,
        opts.track.recorded_heading.as_ref(),
    )?;
    let seq = seq.as_ref();
    let gt = seq
        .ground_truth()
        .ok_or_else(|| PipelineError::sequence(seq.name(), "has no ground truth to evaluate"))?;
    let gt2 = gt.horizontal();
    let (regressions, placements) = if opts.methods.iter().any(|m| m.needs_model()) {
        regressed(seq, model, &opts.track)?
    } else {
        Default::default()
    };
    let frames: Vec<usize> = regressions.iter().map(|r| r.frame).collect();
    let targets = compute_targets(&ground_truth_view(seq)?, model.feature_config(), &frames)?;
    let predicted: Vec<[f64; 2]> = regressions.iter().map(|r| r.velocity.to_array()).collect();
    let truth: Vec<[f64; 2]> = targets.values.iter().map(|v| v.to_array()).collect();
    let vel_mse = if predicted.is_empty() {
        [f64::NAN; 2]
    } else {
        velocity_mse(&predicted, &truth)?
    };
    let names: Vec<String> = placements
        .iter()
        .map(|&p| model.placement_names().get(p).cloned().unwrap_or_default())
        .collect();
    let placement_accuracy = match (seq.placement(), names.is_empty()) {
        (Some(p), false) => {
            Some(names.iter().filter(|n| n.as_str() == p).count() as f64 / names.len() as f64)
        }
        _ => None,
    };
    let mut methods = BTreeMap::new();
    let mut traced = Vec::new();
    for &m in &opts.methods {
        let est = baseline_trajectory(m, seq, &regressions, opts.track.correction_for(model))?;
        let e = evaluate_trajectory(seq.time(), &est, &gt2, &opts.config)?;
        methods.insert(m.key().to_string(), e.metrics);
        traced.push((m, e.aligned));
    }
    Ok(Evaluated {
        result: SequenceResult {
            name: seq.name().to_string(),
            run: ridi_eval::run_of(seq.name()).to_string(),
            placement: seq.placement().map(str::to_string),
            device: seq.device().map(|d| d.model().to_string()),
            path_length_m: ridi_eval::path_length(&gt2)?,
            alignment_extent_m: ridi_eval::target_extent(
                &gt2[..opts.config.align.frame_count(seq.time())?],
            ),
            placement_accuracy,
            velocity_mse: vel_mse,
            methods,
        },
        truth_labels: seq
            .placement()
            .map(|p| vec![p.to_string(); names.len()])
            .unwrap_or_default(),
        squared_errors: predicted
            .iter()
            .zip(&targets.values)
            .map(|(p, t)| [(p[0] - t[0]).powi(2), (p[1] - t[1]).powi(2)])
            .collect(),
        traces: Traces {
            name: seq.name().to_string(),
            ground_truth: gt2,
            methods: traced,
            regression_time: frames.iter().map(|&f| seq.time()[f]).collect(),
            regressed: predicted,
            true_velocity: truth,
            placements: names,
        },
    })
}

/// One warning naming the placement labels of `seqs` that are not among the model's classes,
/// with their sequences: the classifier cannot predict them, so their placement accuracy is 0
/// (their trajectories are still worth evaluating). For example: "placement `swing` of 2
/// sequences (Thibaud_Nexus5_NoDist_Swinging, Jakob_Nexus5_NoDist_Swinging) is not one of the
/// model's classes (hand, pocket): their placement accuracy is 0"; several labels are listed in
/// one warning. Tyrex motion names under a model of the Tyrex groups get the placement map to
/// give.
pub fn placement_warnings(seqs: &[Sequence], model: &Cascade) -> Vec<String> {
    let classes = model.placement_names();
    let mut unknown: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for s in seqs {
        if let Some(label) = s.placement()
            && !classes.iter().any(|c| c == label)
        {
            unknown.entry(label).or_default().push(s.name());
        }
    }
    if unknown.is_empty() {
        return Vec::new();
    }
    // The map, where it takes every such label to one of the model's classes (with a label it
    // lacks, giving it would be an error).
    let tyrex = crate::PlacementMap::tyrex4();
    let mapped = unknown.keys().all(|l| {
        tyrex
            .class_of(l)
            .is_some_and(|class| classes.iter().any(|c| c == class))
    });
    let give = "give `--placement-map tyrex4`, in Python `placement_map=\"tyrex4\"`";
    let hint = match (mapped, unknown.len()) {
        (false, _) => String::new(),
        (true, 1) => format!(" (a Tyrex motion name: {give})"),
        (true, _) => format!(" (Tyrex motion names: {give})"),
    };
    let of = |names: &[&str]| {
        format!(
            "{} ({})",
            ridi_data::counted(names.len(), "sequence"),
            ridi_data::first_few(names.iter(), 3)
        )
    };
    let classes = classes.join(", ");
    let warning = match unknown.into_iter().collect::<Vec<_>>().as_slice() {
        [(label, names)] => format!(
            "placement `{label}` of {} is not one of the model's classes ({classes}): {} \
             placement accuracy is 0{hint}",
            of(names),
            if names.len() == 1 { "its" } else { "their" },
        ),
        labels => format!(
            "{} placement labels are not among the model's classes ({classes}), so their \
             sequences' placement accuracy is 0: {}{hint}",
            labels.len(),
            labels
                .iter()
                .map(|(label, names)| format!("`{label}` of {}", of(names)))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    vec![warning]
}

/// Refuses a sequence [`evaluate`] cannot evaluate with a model of feature configuration
/// `config`: as tracking does (a gap longer than the correction's `max_dt`, a median rate
/// outside 200 Hz ± 10 %, no whole feature window), and frames that do not average
/// `opts.config.rate_hz` ± 10 %, at which the RTE windows are counted (many dropped frames,
/// each gap short enough to track across). [`evaluate`] checks every sequence first; call it
/// to check test sequences before training their model.
pub fn check_evaluable(seq: &Sequence, config: &FeatureConfig, opts: &EvalOptions) -> Result<()> {
    check_trackable(seq, config, opts.track.correction.max_dt)?;
    match ridi_eval::check_rate(seq.time(), &opts.config) {
        Ok(_) => Ok(()),
        Err(ridi_eval::EvalError::RateMismatch {
            timeline_hz,
            config_hz,
        }) => {
            let cause = if timeline_hz < config_hz {
                "dropped frames?"
            } else {
                "extra frames?"
            };
            Err(PipelineError::sequence(
                seq.name(),
                format!(
                    "averages {timeline_hz:.1} Hz ({cause}), but the RTE windows are counted at \
                     {config_hz} Hz: resample it with `ridi convert --rate {config_hz}` (in \
                     Python `Sequence.resampled({config_hz})`)"
                ),
            ))
        }
        Err(e) => Err(PipelineError::sequence(seq.name(), e.to_string())),
    }
}

/// Evaluates every method of `opts` on every sequence (ground truth required), in parallel.
/// Returns the report (with [`placement_warnings`] in its `warnings` when a method uses the
/// model) and the traces for plots, in sequence order. No sequence is an error.
pub fn evaluate(
    seqs: &[Sequence],
    model: &Cascade,
    opts: &EvalOptions,
) -> Result<(Report, Vec<Traces>)> {
    evaluate_cancellable(seqs, model, opts, &AtomicBool::new(false))
}

/// [`evaluate`], which another thread cancels by setting `cancel`: the sequences being
/// evaluated then finish and no other starts; the result is [`PipelineError::Cancelled`] when
/// one was left out (an error of a sequence evaluated comes first), the whole report when the
/// flag came after the last had started. (Python's `ridi.evaluate` sets it on Ctrl-C; the
/// command line exits instead.)
pub fn evaluate_cancellable(
    seqs: &[Sequence],
    model: &Cascade,
    opts: &EvalOptions,
    cancel: &AtomicBool,
) -> Result<(Report, Vec<Traces>)> {
    if seqs.is_empty() {
        return Err(PipelineError::NoSequences("evaluate"));
    }
    crate::check_distinct_recordings(seqs)?;
    opts.track.validate()?;
    // Every sequence before any work: a bad one fails in a second, not after the others.
    for s in seqs {
        check_evaluable(s, model.feature_config(), opts)?;
    }
    let results: Vec<Result<Evaluated>> = seqs
        .par_iter()
        .map(|s| {
            // Relaxed: the flag carries no data, and a sequence more or less is no matter.
            if cancel.load(Ordering::Relaxed) {
                return Err(PipelineError::Cancelled("evaluation"));
            }
            evaluate_one(s, model, opts)
        })
        .collect();
    // The first error in the sequences' order, whatever the threads met first; a sequence
    // left out by a cancel is no fault of its own, so another's error comes before it.
    let mut done = Vec::with_capacity(results.len());
    let mut cancelled = None;
    for r in results {
        match r {
            Ok(e) => done.push(e),
            Err(e @ PipelineError::Cancelled(_)) => {
                cancelled.get_or_insert(e);
            }
            Err(e) => return Err(e),
        }
    }
    if let Some(e) = cancelled {
        return Err(e);
    }
    let order: Vec<String> = opts.methods.iter().map(|m| m.key().to_string()).collect();
    let reports = sequence_reports(done.iter().map(|e| &e.result), &order);
    let summary = summarize(&reports)
        .into_iter()
        .map(|s| (s.method, s.mean))
        .collect();
    let intervals = ridi_eval::summary_intervals(&reports);
    let ridi_minus = ridi_eval::paired_differences(&reports, Method::Ridi.key());
    let squared: Vec<[f64; 2]> = done
        .iter()
        .flat_map(|e| e.squared_errors.iter().copied())
        .collect();
    let velocity_mse = if squared.is_empty() {
        [f64::NAN; 2]
    } else {
        // Summed in an order that does not depend on the sequences'.
        let channel = |c: usize| squared.iter().map(|s| s[c]).collect::<Vec<f64>>();
        [
            ridi_eval::ordered_mean(&channel(0)),
            ridi_eval::ordered_mean(&channel(1)),
        ]
    };
    let truth: Vec<&str> = done
        .iter()
        .flat_map(|e| e.truth_labels.iter().map(String::as_str))
        .collect();
    let predicted: Vec<&str> = done
        .iter()
        .filter(|e| !e.truth_labels.is_empty())
        .flat_map(|e| e.traces.placements.iter().map(String::as_str))
        .collect();
    let (placement_accuracy, placement_confusion) = if truth.is_empty() {
        (None, None)
    } else {
        let classes: BTreeSet<&str> = model
            .placement_names()
            .iter()
            .map(String::as_str)
            .chain(truth.iter().copied())
            .collect();
        let classes: Vec<&str> = classes.into_iter().collect();
        let cm = ConfusionMatrix::from_names(&truth, &predicted, &classes)?;
        (cm.accuracy(), Some(cm))
    };
    let (results, traces): (Vec<SequenceResult>, _) =
        done.into_iter().map(|e| (e.result, e.traces)).unzip();
    // Without regressions there is no placement accuracy to warn about.
    let mut warnings = if opts.methods.iter().any(|m| m.needs_model()) {
        placement_warnings(seqs, model)
    } else {
        Vec::new()
    };
    warnings.extend(weak_alignment(&results, opts.config.align));
    warnings.extend(still_ahead(&summary));
    warnings.extend(pdr_without_steps(&results));
    warnings.extend(too_few_runs(&results));
    let provenance = Provenance::of(model, opts)?;
    #[cfg(feature = "bundled-model")]
    warnings.extend(crate::bundled::trained_on_warning(
        seqs,
        &provenance.model_fingerprint,
    ));
    Ok((
        Report {
            sequences: results,
            summary,
            intervals,
            ridi_minus,
            velocity_mse,
            placement_accuracy,
            placement_confusion,
            config: opts.config,
            recorded_heading: opts.track.recorded_heading,
            methods: order,
            warnings,
            provenance: Some(provenance),
        },
        traces,
    ))
}

/// The warning that the sequences hold fewer runs than an interval needs
/// ([`ridi_eval::MIN_INTERVAL_RUNS`]): the report gives means alone.
fn too_few_runs(sequences: &[SequenceResult]) -> Option<String> {
    let runs: BTreeSet<&str> = sequences
        .iter()
        .map(|s| ridi_eval::run_of(&s.name))
        .collect();
    (runs.len() < ridi_eval::MIN_INTERVAL_RUNS).then(|| {
        format!(
            "{} ({}, the parts of a recording split at its gaps counted as one): too few for \
             95 % intervals, which need {} runs; the means stand alone and no difference \
             between methods is resolved",
            ridi_data::counted(sequences.len(), "sequence"),
            ridi_data::counted(runs.len(), "run"),
            ridi_eval::MIN_INTERVAL_RUNS
        )
    })
}

/// The warning naming the sequences where PDR detected no step: its trajectory there stays
/// put (path length ratio 0), and its figures are standing still's, not a step counter's.
fn pdr_without_steps(sequences: &[SequenceResult]) -> Option<String> {
    let still: Vec<String> = sequences
        .iter()
        .filter(|s| {
            s.methods
                .get(Method::Pdr.key())
                .is_some_and(|m| m.path_length_ratio == Some(0.0))
        })
        .map(|s| ridi_data::shown(&s.name))
        .collect();
    (!still.is_empty()).then(|| {
        format!(
            "pdr detected no step in {} of {}, where it stands still and its figures are not a \
             step counter's: {}",
            still.len(),
            ridi_data::counted(sequences.len(), "sequence"),
            ridi_data::first_few(still.into_iter(), 5)
        )
    })
}

/// The warning that standing still (`still`) scores a lower mean ATE than RIDI: the walks stay
/// in an area small against RIDI's drift, where ATE rewards staying put and says little about
/// tracking.
fn still_ahead(summary: &BTreeMap<String, TrajectoryMetrics>) -> Option<String> {
    let ridi = summary.get(Method::Ridi.key())?;
    let still = summary.get(Method::Still.key())?;
    (still.ate_m < ridi.ate_m).then(|| {
        format!(
            "standing still (`still`) has a lower mean ATE than ridi ({:.3} m against {:.3} m): \
             the walks stay within an area small against ridi's error, where ATE rewards a \
             trajectory that stays put; RTE 5 s and the path length ratio say more",
            still.ate_m, ridi.ate_m
        )
    })
}

/// The warning about the sequences whose ground truth moves less than
/// [`ridi_eval::WEAK_ALIGNMENT_EXTENT_M`] within the alignment window `align`, naming the first
/// few with their travel: their fitted heading rests on little motion.
fn weak_alignment(sequences: &[SequenceResult], align: ridi_eval::AlignWindow) -> Option<String> {
    let weak: Vec<String> = sequences
        .iter()
        .filter(|s| s.alignment_extent_m < ridi_eval::WEAK_ALIGNMENT_EXTENT_M)
        .map(|s| {
            format!(
                "{} ({:.2} m)",
                ridi_data::shown(&s.name),
                s.alignment_extent_m
            )
        })
        .collect();
    (!weak.is_empty()).then(|| {
        format!(
            "weakly determined alignment in {} of {}: the ground truth moves less than {} m \
             within the alignment window, so the fitted heading rests on little motion and \
             every metric inherits its error: {}{}",
            weak.len(),
            ridi_data::counted(sequences.len(), "sequence"),
            ridi_eval::WEAK_ALIGNMENT_EXTENT_M,
            ridi_data::first_few(weak.into_iter(), 5),
            // Aligned on the whole trajectory already, there is no larger window to offer.
            match align {
                ridi_eval::AlignWindow::All => "",
                _ => " (`ridi eval --align all`, in Python `align=\"all\"`, shows them without it)",
            }
        )
    })
}

/// `results` as ridi-eval's tables take them, each sequence's methods in `order` (a report's
/// `methods`; a key not in it, as from a report of another version, last).
fn sequence_reports<'a>(
    results: impl Iterator<Item = &'a SequenceResult>,
    order: &[String],
) -> Vec<SequenceReport> {
    results
        .map(|r| SequenceReport {
            sequence: r.name.clone(),
            placement: r.placement.clone(),
            frames: 0,
            // In the report's order, as its other tables have them, not the map's alphabetical
            // one.
            methods: order
                .iter()
                .map(String::as_str)
                .chain(
                    r.methods
                        .keys()
                        .map(String::as_str)
                        .filter(|k| !order.iter().any(|o| o == k)),
                )
                .filter_map(|k| {
                    r.methods.get(k).map(|m| MethodMetrics {
                        method: k.to_string(),
                        metrics: *m,
                    })
                })
                .collect(),
        })
        .collect()
}

fn fmt_opt(v: Option<f64>) -> String {
    v.map_or("-".into(), |v| format!("{v:.3}"))
}

/// What a table of `report.md` groups sequences by (placement, device).
type GroupKey = fn(&SequenceResult) -> Option<&str>;

/// The mean of each method's metrics over the sequences of one group: one placement
/// ([`Report::per_placement`]) or one device ([`Report::per_device`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct GroupSummary {
    /// The placement label or device model the group's sequences share.
    pub group: String,
    /// How many sequences the group holds.
    pub sequences: usize,
    /// Mean of each metric over the group's sequences, per method key (as
    /// [`Report::summary`] over all of them).
    pub summary: BTreeMap<String, TrajectoryMetrics>,
}

impl Report {
    /// Each placement's means, sorted by label. A sequence without a placement is in no group,
    /// so the groups may hold fewer sequences than the report.
    pub fn per_placement(&self) -> Vec<GroupSummary> {
        self.grouped(|s| s.placement.as_deref())
    }

    /// Each device's means, sorted by model name (byte order: `Nexus 5` before `iPhone 4S`). A
    /// sequence without a device is in no group, so the groups may hold fewer sequences than
    /// the report (none when no sequence names its device).
    pub fn per_device(&self) -> Vec<GroupSummary> {
        self.grouped(|s| s.device.as_deref())
    }

    fn grouped(&self, key_of: GroupKey) -> Vec<GroupSummary> {
        let keys: BTreeSet<&str> = self.sequences.iter().filter_map(key_of).collect();
        keys.into_iter()
            .map(|k| {
                let subset = sequence_reports(
                    self.sequences.iter().filter(|s| key_of(s) == Some(k)),
                    &self.methods,
                );
                GroupSummary {
                    group: k.to_string(),
                    sequences: subset.len(),
                    summary: summarize(&subset)
                        .into_iter()
                        .map(|s| (s.method, s.mean))
                        .collect(),
                }
            })
            .collect()
    }

    /// The section of `report.md` that says what each figure and method is.
    fn definitions(&self) -> String {
        let c = &self.config;
        let methods: Vec<String> = self
            .methods
            .iter()
            .filter_map(|key| {
                let method = Method::ALL.into_iter().find(|m| m.key() == key)?;
                Some(format!("`{key}`, {}", method.definition()))
            })
            .collect();
        let methods = methods.join("; ");
        format!(
            "\n## Definitions\n\n\
             Every trajectory is horizontal, aligned on the ground truth as the header says (one \
             turn and shift per sequence and method, no scale), and compared frame by frame.\n\n\
             - **ATE**: the RMS of the position error, m. **ATE RoNIN**: RoNIN's per-coordinate \
             RMS (ATE / sqrt 2).\n\
             - **RTE**: the RMS, over every window of {long} s, of the error in the displacement \
             across the window, m; a sequence shorter than the window gets its end-to-end drift \
             scaled to {long} s (RoNIN's rule). **RTE 5 s**: the same over {short} s. **RTE \
             RoNIN**: per coordinate (RTE / sqrt 2).\n\
             - **MPE**: the mean position error, m; **MPE (%)**: over the ground truth's path \
             length.\n\
             - **path length ratio**: the trajectory's path length over the ground truth's.\n\
             - **Means** are over sequences, each counting once; **intervals** are 95 % bootstrap \
             percentiles over runs (the parts `_part1`, `_part2`, ... of a recording split at \
             its gaps are one run), given for {min} runs or more. **Velocity MSE**: the \
             squared error of each regressed velocity against the ground truth's, both \
             horizontal in S (the phone's frame with its tilt taken out; the ground truth \
             smoothed as the training targets are), per channel; **placement accuracy**: the \
             share of regressions whose placement is the sequence's label; both pool every \
             regression of every sequence.\n\
             - **Methods**: {methods}.\n",
            long = c.rte_window_s,
            short = c.short_rte_window_s,
            min = ridi_eval::MIN_INTERVAL_RUNS,
        )
    }

    /// Where the trajectories were aligned, as report.md's header says it.
    pub(crate) fn alignment_text(&self) -> String {
        match self.config.align {
            ridi_eval::AlignWindow::Seconds(s) => format!("the first {s} s"),
            ridi_eval::AlignWindow::Frames(n) => format!("the first {n} frames"),
            ridi_eval::AlignWindow::All => "the whole trajectory".to_string(),
        }
    }

    /// The heading a model on the estimated orientation tracked with, as report.md says it.
    pub(crate) fn heading_text(&self) -> String {
        match self.recorded_heading {
            Some(h) => format!(
                "the gyro's, its drift corrected by the recorded orientation's slow heading \
                 (time constant {} s, changes clamped at {} rad/s)",
                h.time_constant, h.max_rate
            ),
            None => "the gyro's alone".to_string(),
        }
    }

    /// The markdown report: overall summary, per placement, per device (when the sequences
    /// name theirs), per sequence, velocity and placement results, and what each figure and
    /// method is. Control characters in names are escaped (`\u{1b}`), as in messages.
    pub fn to_markdown(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "# RIDI evaluation\n");
        let _ = writeln!(
            out,
            "{}; trajectories aligned on {} (2D rigid, no scale); RTE window {} s, short RTE {} s.\n",
            ridi_data::counted(self.sequences.len(), "sequence"),
            self.alignment_text(),
            self.config.rte_window_s,
            self.config.short_rte_window_s
        );
        let _ = writeln!(
            out,
            "Heading with a model on the estimated orientation: {}.\n",
            self.heading_text()
        );
        if let Some(p) = &self.provenance {
            let _ = writeln!(
                out,
                "Model: {} (fingerprint {}{}); regressions every {} frames, placement {}{}; \
                 ridi {}.\n",
                p.model,
                p.model_fingerprint,
                p.model_source
                    .as_deref()
                    .map_or(String::new(), |s| format!(", {s}")),
                p.regress_every,
                p.placement_window_s
                    .map_or("per regression".to_string(), |w| format!(
                        "by majority over {w} s"
                    )),
                p.correction.as_ref().map_or(String::new(), |c| format!(
                    "; correction {}",
                    correction_text(c)
                )),
                p.ridi_version
            );
        }
        let mse = match self.velocity_mse {
            [x, z] if x.is_finite() && z.is_finite() => format!("S-x {x:.4}, S-z {z:.4} (m/s)^2"),
            // Methods without a model regress nothing.
            _ => "- (no regressions)".to_owned(),
        };
        let _ = writeln!(
            out,
            "Velocity MSE (all regressions): {mse}; placement accuracy {}.\n",
            fmt_opt(self.placement_accuracy)
        );
        for w in &self.warnings {
            let _ = writeln!(out, "**Warning**: {w}.\n");
        }
        let has_intervals = self.has_intervals();
        if has_intervals {
            let _ = writeln!(
                out,
                "## Overall (mean over sequences [95 % interval])\n\nIntervals: a bootstrap \
                 over the sequences ({} resamples, the parts of a run drawn together); they say \
                 how well these runs pin a mean down, not how far it carries to other people \
                 or phones.\n",
                ridi_eval::DRAWS
            );
        } else {
            let _ = writeln!(
                out,
                "## Overall (mean over sequences; too few runs for intervals)\n"
            );
        }
        let mut head = "| method |".to_string();
        let mut rule = "| --- |".to_string();
        for m in Metric::ALL {
            let _ = write!(head, " {} |", m.label());
            rule.push_str(" --- |");
        }
        let _ = writeln!(out, "{head}\n{rule}");
        for key in &self.methods {
            if let Some(mean) = self.summary.get(key) {
                let _ = write!(out, "| {key} |");
                for m in Metric::ALL {
                    let interval = self.intervals.get(key).and_then(|i| i.get(m.key()));
                    let _ = write!(
                        out,
                        " {} |",
                        with_interval(m, m.value(mean), interval, false)
                    );
                }
                let _ = writeln!(out);
            }
        }
        let ridi = Method::Ridi.key();
        let others: Vec<&String> = self
            .methods
            .iter()
            .filter(|k| k.as_str() != ridi && self.summary.contains_key(*k))
            .collect();
        if self.summary.contains_key(ridi) && !others.is_empty() {
            let _ = writeln!(
                out,
                "\n## ridi minus each method (paired over sequences{})\n\n{head}\n{rule}",
                if has_intervals {
                    " [95 % interval]; bold: the interval leaves out 0"
                } else {
                    "; too few runs for intervals"
                }
            );
            for key in others {
                let _ = write!(out, "| {key} |");
                for m in Metric::ALL {
                    let d = self
                        .ridi_minus
                        .get(key.as_str())
                        .and_then(|d| d.get(m.key()));
                    // Under too few runs for bounds, the mean alone (`Interval::unbounded`).
                    let _ = write!(out, " {} |", with_interval(m, d.map(|d| d.mean), d, true));
                }
                let _ = writeln!(out);
            }
        }
        let groups = [
            ("placement", self.per_placement()),
            ("device", self.per_device()),
        ];
        for (what, groups) in groups {
            if groups.is_empty() {
                continue;
            }
            let _ = writeln!(out, "\n## Per {what} (mean RTE 5 s, m)\n");
            let _ = write!(out, "| {what} | sequences |");
            for key in &self.methods {
                let _ = write!(out, " {key} |");
            }
            let _ = writeln!(
                out,
                "\n| --- | --- |{}",
                " --- |".repeat(self.methods.len())
            );
            for g in groups {
                let _ = write!(out, "| {} | {} |", g.group, g.sequences);
                for key in &self.methods {
                    let v = g.summary.get(key).map(|m| m.rte_5s_m);
                    let _ = write!(out, " {} |", fmt_opt(v));
                }
                let _ = writeln!(out);
            }
        }
        let reports = sequence_reports(self.sequences.iter(), &self.methods);
        for metric in [
            Metric::Rte5sM,
            Metric::PathLengthRatio,
            Metric::AteM,
            Metric::MpeM,
        ] {
            let _ = writeln!(out, "\n## Per sequence: {}\n", metric.label());
            out.push_str(&markdown_metric_table(&reports, metric));
        }
        let _ = writeln!(out, "\n## Velocity regression and placement per sequence\n");
        let _ = writeln!(
            out,
            "| sequence | placement | path (m) | ground-truth travel in the alignment window (m) | velocity MSE S-x | velocity MSE S-z | placement accuracy |\n| --- | --- | --- | --- | --- | --- | --- |"
        );
        for s in &self.sequences {
            let _ = writeln!(
                out,
                "| {} | {} | {:.1} | {:.2} | {:.4} | {:.4} | {} |",
                s.name,
                s.placement.as_deref().unwrap_or("-"),
                s.path_length_m,
                s.alignment_extent_m,
                s.velocity_mse[0],
                s.velocity_mse[1],
                fmt_opt(s.placement_accuracy)
            );
        }
        if let Some(cm) = &self.placement_confusion {
            let _ = writeln!(out, "\n## Placement confusion (rows: truth)\n");
            out.push_str(&markdown_confusion(cm));
        }
        out.push_str(&self.definitions());
        // Names come from folders and list files: a control character in one (a terminal
        // escape) is written escaped, as every message shows it, so that `cat report.md` cannot
        // retitle or clear the terminal.
        out.split('\n')
            .map(ridi_data::shown)
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// Reads a `report.json` that [`Report::write`] wrote: `path` is the file, or the folder
    /// holding it (a `ridi eval --out`).
    pub fn read(path: &Path) -> Result<Report> {
        let joined;
        let path = if path.is_dir() {
            joined = path.join("report.json");
            joined.as_path()
        } else {
            path
        };
        let file = |message: String| PipelineError::File {
            path: path.to_path_buf(),
            message,
        };
        // Bounded: a report holds figures per sequence, far below this for any dataset.
        let text = ridi_data::read_text(path, 1 << 30)?;
        let report: Report = serde_json::from_str(&text)
            .map_err(|e| file(format!("not a report.json of `ridi eval`: {e}")))?;
        report.validate().map_err(file)?;
        Ok(report)
    }

    /// Whether any mean has a 95 % interval (there are none from fewer than
    /// [`ridi_eval::MIN_INTERVAL_RUNS`] runs).
    pub fn has_intervals(&self) -> bool {
        self.intervals
            .values()
            .flat_map(BTreeMap::values)
            .any(ridi_eval::Interval::is_bounded)
    }

    /// Refuses what no evaluation writes (a hand-edited report): a negative figure, RTE
    /// windows, an alignment or a rate that are not positive. [`Report::read`] checks every
    /// file with it; a report deserialized otherwise (Python's `ridi.compare` of a dict) is
    /// checked the same way.
    pub fn validate(&self) -> std::result::Result<(), String> {
        let c = &self.config;
        let window = match c.align {
            ridi_eval::AlignWindow::Seconds(s) => s,
            ridi_eval::AlignWindow::Frames(n) => n as f64,
            ridi_eval::AlignWindow::All => 1.0,
        };
        for (name, v) in [
            ("config.rte_window_s", c.rte_window_s),
            ("config.short_rte_window_s", c.short_rte_window_s),
            ("config.rate_hz", c.rate_hz),
            ("config.align", window),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!(
                    "`{name}` is {v}; an evaluation's is a positive number"
                ));
            }
        }
        for s in &self.sequences {
            for (method, m) in &s.methods {
                for metric in Metric::ALL {
                    if let Some(v) = metric.value(m).filter(|v| *v < 0.0) {
                        return Err(format!(
                            "sequence `{}`, method `{method}`: `{}` is {v}, a figure that \
                             cannot be negative",
                            ridi_data::shown(&s.name),
                            metric.key()
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// Writes `report.json` and `report.md` into `dir` (created if needed), atomically.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        std::fs::create_dir_all(dir).map_err(|e| PipelineError::File {
            path: dir.to_path_buf(),
            message: e.to_string(),
        })?;
        let json = serde_json::to_string_pretty(self).map_err(|e| PipelineError::File {
            path: dir.join("report.json"),
            message: e.to_string(),
        })?;
        let md = self.to_markdown();
        let mut written = Vec::new();
        for (name, text) in [("report.json", json), ("report.md", md)] {
            let path = dir.join(name);
            write_atomically(&path, |w| w.write_all(text.as_bytes()))?;
            written.push(path);
        }
        Ok(written)
    }
}

impl Traces {
    /// Draws the trajectory plot (ground truth and every method, aligned) and the velocity plot
    /// (regressed vs true, with predicted placements) of this sequence into `dir` as
    /// `<name>.trajectory.<ext>` and `<name>.velocity.<ext>` (`ext`: `svg` or `png`).
    #[cfg(feature = "plot")]
    pub fn plot(&self, dir: &Path, ext: &str) -> Result<Vec<PathBuf>> {
        use crate::plot::{
            Placements, Trajectory, TrajectoryOptions, TrajectoryPlot, VelocityOptions,
            VelocityPlot, VelocityTrack, plot_trajectories, plot_velocity,
        };
        let traj_path = dir.join(format!("{}.trajectory.{ext}", self.name));
        let estimates: Vec<Trajectory<'_>> = self
            .methods
            .iter()
            .map(|(m, points)| Trajectory {
                name: m.key(),
                points,
            })
            .collect();
        plot_trajectories(
            &traj_path,
            &TrajectoryPlot {
                title: &self.name,
                ground_truth: Some(Trajectory {
                    name: "ground truth",
                    points: &self.ground_truth,
                }),
                estimates: &estimates,
            },
            &TrajectoryOptions::default(),
        )?;
        let mut written = vec![traj_path];
        if !self.regressed.is_empty() {
            let col = |v: &[[f64; 2]], i: usize| v.iter().map(|p| p[i]).collect::<Vec<f64>>();
            let (rx, rz) = (col(&self.regressed, 0), col(&self.regressed, 1));
            let (tx, tz) = (col(&self.true_velocity, 0), col(&self.true_velocity, 1));
            let labels: Vec<&str> = self.placements.iter().map(String::as_str).collect();
            let vel_path = dir.join(format!("{}.velocity.{ext}", self.name));
            plot_velocity(
                &vel_path,
                &VelocityPlot {
                    title: &self.name,
                    regressed: VelocityTrack {
                        name: "regressed",
                        t: &self.regression_time,
                        x: &rx,
                        z: &rz,
                    },
                    truth: Some(VelocityTrack {
                        name: "ground truth",
                        t: &self.regression_time,
                        x: &tx,
                        z: &tz,
                    }),
                    placements: Some(Placements {
                        t: &self.regression_time,
                        labels: &labels,
                    }),
                },
                &VelocityOptions::default(),
            )?;
            written.push(vel_path);
        }
        Ok(written)
    }
}

/// The fingerprint of `model`'s file ([`Provenance::model_fingerprint`]).
pub(crate) fn model_fingerprint(model: &Cascade) -> Result<String> {
    Ok(fingerprint(&model.to_bytes()?))
}

/// FNV-1a 64 of `bytes` in hex ([`Provenance::model_fingerprint`]): a stable,
/// dependency-free fingerprint (not a cryptographic one).
pub(crate) fn fingerprint(bytes: &[u8]) -> String {
    let hash = bytes.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    });
    format!("{hash:016x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pdr_without_a_step_is_a_warning() {
        let with_pdr = |name: &str, ratio: f64| {
            let mut r = result(name, None, 1.0);
            let ridi = r.methods["ridi"];
            r.methods.insert(
                "pdr".into(),
                TrajectoryMetrics {
                    path_length_ratio: Some(ratio),
                    ..ridi
                },
            );
            r
        };
        let results = [with_pdr("walk", 0.9), with_pdr("ar", 0.0)];
        assert_eq!(
            pdr_without_steps(&results).unwrap(),
            "pdr detected no step in 1 of 2 sequences, where it stands still and its figures \
             are not a step counter's: ar"
        );
        assert_eq!(pdr_without_steps(&results[..1]), None);
    }

    #[test]
    fn standing_still_ahead_of_ridi_on_ate_is_a_warning() {
        let metrics = |ate_m| TrajectoryMetrics {
            mpe_m: 0.0,
            mpe_pct: None,
            ate_m,
            rte_m: 0.0,
            ate_ronin_m: 0.0,
            rte_ronin_m: 0.0,
            rte_5s_m: 0.0,
            path_length_ratio: None,
        };
        let summary = |ridi, still| {
            BTreeMap::from([
                ("ridi".to_string(), metrics(ridi)),
                ("still".to_string(), metrics(still)),
            ])
        };
        let w = still_ahead(&summary(2.0, 1.5)).unwrap();
        assert!(
            w.starts_with(
                "standing still (`still`) has a lower mean ATE than ridi (1.500 m against 2.000 m)"
            ),
            "{w}"
        );
        assert_eq!(still_ahead(&summary(1.0, 1.5)), None);
        // Without either method there is nothing to compare.
        assert_eq!(
            still_ahead(&BTreeMap::from([("ridi".into(), metrics(2.0))])),
            None
        );
    }

    fn result(name: &str, device: Option<&str>, rte: f64) -> SequenceResult {
        let metrics = TrajectoryMetrics {
            mpe_m: 0.0,
            mpe_pct: None,
            ate_m: 0.0,
            rte_m: 0.0,
            ate_ronin_m: 0.0,
            rte_ronin_m: 0.0,
            rte_5s_m: rte,
            path_length_ratio: Some(1.0),
        };
        SequenceResult {
            name: name.into(),
            run: name.into(),
            placement: Some("hand".into()),
            device: device.map(str::to_string),
            path_length_m: 10.0,
            alignment_extent_m: 5.0,
            placement_accuracy: Some(1.0),
            velocity_mse: [0.1, 0.1],
            methods: [("ridi".to_string(), metrics)].into_iter().collect(),
        }
    }

    fn report(sequences: Vec<SequenceResult>) -> Report {
        Report {
            velocity_mse: [0.1, 0.1],
            placement_accuracy: Some(1.0),
            ..Report::of_sequences(sequences)
        }
    }

    #[test]
    fn results_are_grouped_by_device_when_the_sequences_name_theirs() {
        let r = report(vec![
            result("a", Some("Nexus 5"), 1.0),
            result("b", Some("iPhone 4S"), 5.0),
            result("c", Some("Nexus 5"), 3.0),
            result("d", None, 9.0),
        ]);
        let md = r.to_markdown();
        assert!(md.contains("## Per device (mean RTE 5 s, m)"), "{md}");
        assert!(md.contains("| Nexus 5 | 2 | 2.000 |"), "{md}");
        assert!(md.contains("| iPhone 4S | 1 | 5.000 |"), "{md}");
        // The placement table still holds every sequence.
        assert!(md.contains("| hand | 4 | 4.500 |"), "{md}");
        // The same groups for a caller, sorted by name; a sequence without a device is in none.
        let groups = |g: Vec<GroupSummary>| -> Vec<(String, usize, Option<f64>)> {
            g.into_iter()
                .map(|g| {
                    (
                        g.group,
                        g.sequences,
                        g.summary.get("ridi").map(|m| m.rte_5s_m),
                    )
                })
                .collect()
        };
        assert_eq!(
            groups(r.per_device()),
            [
                ("Nexus 5".to_string(), 2, Some(2.0)),
                ("iPhone 4S".to_string(), 1, Some(5.0))
            ]
        );
        assert!(!r.per_device()[0].summary.contains_key("pdr"));
        assert_eq!(
            groups(r.per_placement()),
            [("hand".to_string(), 4, Some(4.5))]
        );
        // Without devices, no device table; JSON without the key reads as no device.
        let none = report(vec![result("a", None, 1.0)]);
        assert!(!none.to_markdown().contains("Per device"));
        assert!(none.per_device().is_empty());
        let json = serde_json::to_string(&none).unwrap();
        assert!(!json.contains("\"device\""), "{json}");
        let back: Report = serde_json::from_str(&json).unwrap();
        assert_eq!(back.sequences[0].device, None);
        let json = serde_json::to_string(&r).unwrap();
        let back: Report = serde_json::from_str(&json).unwrap();
        assert_eq!(back.sequences[1].device.as_deref(), Some("iPhone 4S"));
    }

    #[test]
    fn a_weak_alignment_is_flagged_and_the_whole_run_offered_unless_already_used() {
        let mut weak = result("still", None, 1.0);
        weak.alignment_extent_m = 0.4;
        let sequences = vec![weak, result("walk", None, 1.0)];
        let w = weak_alignment(&sequences, ridi_eval::AlignWindow::default()).unwrap();
        assert!(
            w.starts_with("weakly determined alignment in 1 of 2 sequences")
                && w.ends_with("still (0.40 m) (`ridi eval --align all`, in Python `align=\"all\"`, shows them without it)"),
            "{w}"
        );
        let w = weak_alignment(&sequences, ridi_eval::AlignWindow::All).unwrap();
        assert!(w.ends_with("still (0.40 m)"), "{w}");
        assert_eq!(
            weak_alignment(&sequences[1..], ridi_eval::AlignWindow::All),
            None
        );
        let mut r = report(sequences);
        r.warnings.push(w);
        assert!(
            r.to_markdown()
                .contains("**Warning**: weakly determined alignment in 1 of 2")
        );
    }

    #[test]
    fn control_characters_of_names_are_escaped_in_the_markdown() {
        let mut r = report(vec![result(
            "esc\x1b]0;title\x07",
            Some("dev\u{9b}2J"),
            1.0,
        )]);
        r.warnings.push("placement of esc\x1b[2J".into());
        let md = r.to_markdown();
        assert!(!md.chars().any(|c| c.is_control() && c != '\n'), "{md:?}");
        assert!(md.contains("esc\\u{1b}]0;title\\u{7}"), "{md}");
        assert!(md.contains("dev\\u{9b}2J"), "{md}");
        assert!(md.contains("esc\\u{1b}[2J"), "{md}");
    }
}
