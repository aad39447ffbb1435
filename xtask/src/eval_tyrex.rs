//! `cargo xtask eval tyrex --variants`: one variant per open choice of the paper, on the 24
//! Tyrex Nexus 5 runs without magnetic disturbance.
//!
//! Leave one subject out: train on two people, test on the third, three folds, so every run
//! is tested once by a model that never saw its person. Runs split at long mocap or sensor gaps
//! count as several test sequences; figures are means over all test sequences. Each variant
//! changes one thing against the paper's configuration (4 placement groups, standardized
//! features, gamma 1/1200, C = 10, epsilon = 0.01, the Android rotation vector as orientation,
//! each window's own placement label, start at rest). Variants that differ only at test time
//! share their trained models. RTE 5 s means come with 95 % intervals over the runs, and each
//! variant's difference from ridi's defaults with its own ([`crate::bootstrap`]).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::bootstrap::{self, FiniteMean, Interval};
use anyhow::{Context, Result};
use ridi::correct::{CorrectionConfig, FrameVelocity, InitialVelocity, PlacementSmoother};
use ridi::data::tyrex::{self, TyrexOptions};
use ridi::data::{Sequence, write_atomically};
use ridi::eval::{AlignWindow, EvalConfig, evaluate_trajectory};
use ridi::features::{FeatureConfig, Orientation, SampleSchedule, compute_targets};
use ridi::frames::UpAxis;
use ridi::ground_truth_view;
use ridi::regress::{Cascade, Gamma, NoProgress};
use ridi::{EvalOptions, GridChoice, PlacementMap, TrackOptions, TrainOptions, apply_orientation};
use ridi::{Method, baseline_trajectory};
use ridi::{SequenceResult, Traces};

pub(crate) const PEOPLE: [&str; 3] = ["Guillaume", "Jakob", "Thibaud"];

/// One configuration of the protocol.
#[derive(Debug, Clone)]
struct Variant {
    name: &'static str,
    groups: bool,
    standardize: bool,
    gamma: Gamma,
    orientation: Orientation,
    turned_copies: usize,
    speed: bool,
    /// Training sample step in frames (paper: 10).
    step: usize,
    /// Frames per feature window (paper: 200).
    window: usize,
    up_axis: UpAxis,
    /// Regressor hyper-parameters: the protocol's fixed C = 10, epsilon = 0.01, or a search.
    grid: GridChoice,
    // Test time only.
    estimate_v0: bool,
    smoothing: bool,
}

impl Variant {
    /// Variants with equal keys train the same models.
    fn train_key(&self) -> String {
        format!(
            "{} {} {:?} {:?} {} {} {} {} {:?} {:?}",
            self.groups,
            self.standardize,
            self.gamma,
            self.orientation,
            self.turned_copies,
            self.speed,
            self.step,
            self.window,
            self.up_axis,
            self.grid
        )
    }
}

const PAPER: Variant = Variant {
    name: "paper: 4 groups, each window's own placement",
    groups: true,
    standardize: true,
    gamma: Gamma::InverseDim,
    orientation: Orientation::Recorded,
    turned_copies: 0,
    speed: false,
    step: 10,
    window: 200,
    up_axis: UpAxis::PlusY,
    grid: GridChoice::None,
    estimate_v0: false,
    smoothing: false,
};

const SMOOTHED: Variant = Variant {
    name: "placement majority over 10 s (ridi's default)",
    smoothing: true,
    ..PAPER
};

const RECOMMENDED: Variant = Variant {
    name: "majority + orientation from gyro + accelerometer",
    smoothing: true,
    orientation: Orientation::Estimated,
    ..PAPER
};

/// What `ridi train` and `ridi track` do by default: a window every 20 frames and one turned
/// copy of each (the paper's number of rows), the speed regressor, S on device -y while the
/// phone is upside down.
const DEFAULTS: Variant = Variant {
    name: "turned copy + speed regressor + majority + S on -y upside down, step 20 (ridi's defaults)",
    turned_copies: 1,
    speed: true,
    step: ridi::default_step(1),
    up_axis: UpAxis::PlusOrMinusY,
    smoothing: true,
    ..PAPER
};

fn variants(quick: bool) -> Vec<Variant> {
    if quick {
        return vec![PAPER, SMOOTHED];
    }
    // Ordered so that variants sharing models are adjacent.
    vec![
        PAPER,
        SMOOTHED,
        Variant {
            name: "initial velocity estimated",
            estimate_v0: true,
            ..PAPER
        },
        RECOMMENDED,
        Variant {
            name: "orientation from gyro + accelerometer",
            orientation: Orientation::Estimated,
            ..PAPER
        },
        Variant {
            name: "8 motion names",
            groups: false,
            ..PAPER
        },
        Variant {
            name: "raw features (no standardization)",
            standardize: false,
            ..PAPER
        },
        Variant {
            name: "gamma 4/1200",
            gamma: Gamma::Value(4.0 / 1200.0),
            ..PAPER
        },
        Variant {
            name: "gamma 0.25/1200",
            gamma: Gamma::Value(0.25 / 1200.0),
            ..PAPER
        },
        Variant {
            name: "speed regressor",
            speed: true,
            ..PAPER
        },
        // Step 10 with a turned copy doubles the rows and takes 7.6x the training time for
        // the same accuracy (docs/benchmarks.md): these run at step 20.
        Variant {
            name: "one turned copy of each window, step 20",
            turned_copies: 1,
            step: 20,
            ..PAPER
        },
        Variant {
            name: "S on -y upside down",
            up_axis: UpAxis::PlusOrMinusY,
            ..PAPER
        },
        Variant {
            name: "turned copy + speed regressor, step 20",
            smoothing: false,
            up_axis: UpAxis::PlusY,
            ..DEFAULTS
        },
        Variant {
            name: "turned copy + speed regressor + majority, step 20",
            up_axis: UpAxis::PlusY,
            ..DEFAULTS
        },
        DEFAULTS,
        // What `ridi train` does without `--grid`: the same with the paper's search, the
        // longest to train.
        Variant {
            name: "the same with the paper grid search, C x epsilon 4 x 4, 3-fold CV (ridi train's default)",
            grid: GridChoice::Paper,
            ..DEFAULTS
        },
        // Shorter feature windows (`ridi train --window`): lower RTE 5 s, shorter paths.
        Variant {
            name: "ridi's defaults with a 150-frame feature window",
            window: 150,
            ..DEFAULTS
        },
        Variant {
            name: "ridi's defaults with a 100-frame feature window",
            window: 100,
            ..DEFAULTS
        },
    ]
}

/// One test sequence of one variant.
#[derive(Debug, Clone)]
struct SeqRow {
    result: SequenceResult,
    /// Mean regressed and mean true velocity `[S-x, S-z]`: the heading of the phone relative
    /// to the walk that the regressors learned, against this person's.
    mean_regressed: [f64; 2],
    mean_true: [f64; 2],
    /// RIDI's RTE 5 s with the alignment fitted on the whole run instead of the first 10 s:
    /// separates drift from a start where the person stood (the 10 s then fix no heading).
    rte_5s_whole: f64,
    /// RIDI's RTE 5 s with one half of each regressed velocity replaced by the ground truth's:
    /// `[true speed with the regressed direction, true direction with the regressed speed]`.
    rte_5s_swapped: [f64; 2],
    /// Frames of the sequence: a part's weight within its run.
    frames: usize,
}

impl SeqRow {
    fn new(
        result: SequenceResult,
        traces: &Traces,
        seq: &Sequence,
        correction: CorrectionConfig,
    ) -> Result<Self> {
        let time = seq.time();
        let mean = |v: &[[f64; 2]]| {
            let n = v.len().max(1) as f64;
            [
                v.iter().map(|x| x[0]).sum::<f64>() / n,
                v.iter().map(|x| x[1]).sum::<f64>() / n,
            ]
        };
        let ridi = traces
            .methods
            .iter()
            .find(|(m, _)| *m == Method::Ridi)
            .context("no RIDI trajectory")?;
        let whole = EvalConfig {
            align: AlignWindow::All,
            ..EvalConfig::default()
        };
        Ok(Self {
            mean_regressed: mean(&traces.regressed),
            mean_true: mean(&traces.true_velocity),
            rte_5s_whole: evaluate_trajectory(time, &ridi.1, &traces.ground_truth, &whole)?
                .metrics
                .rte_5s_m,
            rte_5s_swapped: [
                swapped_rte(seq, traces, correction, Truth::Speed)?,
                swapped_rte(seq, traces, correction, Truth::Direction)?,
            ],
            frames: time.len(),
            result,
        })
    }
}

/// Which half of each regressed velocity [`swapped_rte`] takes from the ground truth.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Truth {
    Speed,
    Direction,
}

/// RIDI's RTE 5 s on `seq` when each regressed velocity takes its speed or its direction from
/// the ground truth: which part of the error is heading, which is speed.
pub(crate) fn swapped_rte(
    seq: &Sequence,
    traces: &Traces,
    correction: CorrectionConfig,
    truth_of: Truth,
) -> Result<f64> {
    let regs: Vec<FrameVelocity> = traces
        .regression_time
        .iter()
        .zip(traces.regressed.iter().zip(&traces.true_velocity))
        .map(|(&t, (&reg, &truth))| {
            let (direction, size) = match truth_of {
                Truth::Speed => (reg, truth),
                Truth::Direction => (truth, reg),
            };
            let n = direction[0].hypot(direction[1]);
            let speed = size[0].hypot(size[1]);
            let scale = if n > 1e-9 { speed / n } else { 0.0 };
            FrameVelocity {
                frame: seq.time().partition_point(|&x| x < t),
                velocity: ridi::frames::StabHorizontal::from_array(direction) * scale,
            }
        })
        .collect();
    let est = baseline_trajectory(Method::Ridi, seq, &regs, correction)?;
    Ok(evaluate_trajectory(
        seq.time(),
        &est,
        &traces.ground_truth,
        &EvalConfig::default(),
    )?
    .metrics
    .rte_5s_m)
}

/// Means over the test sequences of one variant.
#[derive(Debug, Default, Clone)]
struct Row {
    sequences: usize,
    velocity_mse: [f64; 2],
    placement_accuracy: f64,
    rte_5s: Vec<(String, f64)>,
    ate: Vec<(String, f64)>,
    path_ratio: Vec<(String, f64)>,
    oracle_rte_5s: f64,
    rte_5s_whole: f64,
    rte_5s_swapped: [f64; 2],
    train_s: f64,
    per_sequence: Vec<SeqRow>,
}

fn load(data: &Path) -> Result<Vec<Sequence>> {
    let mut seqs = Vec::new();
    for dir in tyrex::list_sequences(data)?.runs {
        let name = dir.file_name().unwrap_or_default().to_string_lossy();
        if name.contains("_Nexus5_NoDist_") {
            seqs.extend(tyrex::read(&dir, &TyrexOptions::default())?.sequences);
        }
    }
    Ok(seqs)
}

fn person(seq: &Sequence) -> &str {
    seq.name().split('_').next().unwrap_or_default()
}

/// RTE 5 s of the correction driven by ground-truth velocities: the floor the orientation sets,
/// a model's targets (its `config`: window, smoothing, S) every `regress_every` frames through
/// its `correction` (`TrackOptions::correction_for`).
pub(crate) fn oracle_rte(
    seq: &Sequence,
    config: &FeatureConfig,
    regress_every: usize,
    correction: CorrectionConfig,
) -> Result<f64> {
    let frames = SampleSchedule::every(config, regress_every)?.frames(seq.len());
    let targets = compute_targets(&ground_truth_view(seq)?, config, &frames)?;
    let regs: Vec<FrameVelocity> = frames
        .iter()
        .zip(&targets.values)
        .map(|(&frame, v)| FrameVelocity {
            frame,
            velocity: *v,
        })
        .collect();
    let est = baseline_trajectory(Method::Ridi, seq, &regs, correction)?;
    let gt = seq.ground_truth().context("no ground truth")?.horizontal();
    Ok(
        evaluate_trajectory(seq.time(), &est, &gt, &EvalConfig::default())?
            .metrics
            .rte_5s_m,
    )
}

/// The sequences a variant trains and tests on.
fn prepare(all: &[Sequence], v: &Variant) -> Result<Vec<Sequence>> {
    let mut seqs = all.to_vec();
    // Once here rather than in every fold's training and evaluation (which then find it done).
    let heading = EvalOptions::default().track.recorded_heading;
    apply_orientation(v.orientation, heading.as_ref(), &mut seqs)?;
    if v.groups {
        PlacementMap::tyrex4().apply(&mut seqs);
    }
    Ok(seqs)
}

/// One model per test person, and the training time of all three.
fn train_folds(seqs: &[Sequence], v: &Variant) -> Result<(Vec<Cascade>, f64)> {
    let mut opts = TrainOptions {
        standardize: v.standardize,
        turned_copies: v.turned_copies,
        ..TrainOptions::default()
    };
    opts.cascade.regressors = v.grid.regressors();
    opts.cascade.classifier_gamma = v.gamma;
    opts.cascade.regressor_gamma = v.gamma;
    opts.cascade.speed = v.speed;
    opts.features.step = v.step;
    opts.features.window = v.window;
    opts.features.up_axis = v.up_axis;
    opts.features.orientation = v.orientation;
    let started = Instant::now();
    let models = PEOPLE
        .iter()
        .map(|&test_person| {
            let train: Vec<Sequence> = seqs
                .iter()
                .filter(|s| person(s) != test_person)
                .cloned()
                .collect();
            let model = ridi::train(&train, &opts, &mut NoProgress)?;
            eprintln!("  {}: trained without {test_person}", v.name);
            Ok(model)
        })
        .collect::<Result<_>>()?;
    Ok((models, started.elapsed().as_secs_f64()))
}

fn run_variant(seqs: &[Sequence], models: &[Cascade], train_s: f64, v: &Variant) -> Result<Row> {
    let mut eval_opts = EvalOptions {
        track: TrackOptions {
            placement_smoothing: v.smoothing.then(PlacementSmoother::default),
            ..TrackOptions::default()
        },
        ..EvalOptions::default()
    };
    if v.estimate_v0 {
        eval_opts.track.correction.initial_velocity = InitialVelocity::Estimate;
    }
    let mut per_sequence = Vec::new();
    let mut oracle = Vec::new();
    for (test_person, model) in PEOPLE.iter().zip(models) {
        let test: Vec<Sequence> = seqs
            .iter()
            .filter(|s| person(s) == *test_person)
            .cloned()
            .collect();
        let (report, traces) = ridi::evaluate(&test, model, &eval_opts)?;
        let correction = eval_opts.track.correction_for(model);
        let (config, every) = (model.feature_config(), eval_opts.track.regress_every);
        for ((r, t), s) in report.sequences.into_iter().zip(&traces).zip(&test) {
            per_sequence.push(SeqRow::new(r, t, s, correction)?);
            oracle.push(oracle_rte(s, config, every, correction)?);
        }
    }
    eprintln!("  {}: evaluated", v.name);
    let results: Vec<&SequenceResult> = per_sequence.iter().map(|r| &r.result).collect();
    let mean = |f: &dyn Fn(&SequenceResult) -> f64| FiniteMean::of(results.iter().map(|r| f(r)));
    let per_method = |f: fn(&ridi::eval::TrajectoryMetrics) -> f64| {
        Method::ALL
            .iter()
            .map(|m| {
                let mean = FiniteMean::of(results.iter().map(|r| f(&r.methods[m.key()])));
                (m.key().to_string(), mean)
            })
            .collect::<Vec<_>>()
    };
    Ok(Row {
        sequences: results.len(),
        velocity_mse: [mean(&|r| r.velocity_mse[0]), mean(&|r| r.velocity_mse[1])],
        placement_accuracy: mean(&|r| r.placement_accuracy.unwrap_or(f64::NAN)),
        rte_5s: per_method(|m| m.rte_5s_m),
        ate: per_method(|m| m.ate_m),
        path_ratio: per_method(|m| m.path_length_ratio.unwrap_or(f64::NAN)),
        oracle_rte_5s: FiniteMean::of(oracle),
        rte_5s_whole: FiniteMean::of(per_sequence.iter().map(|s| s.rte_5s_whole)),
        rte_5s_swapped: [0, 1]
            .map(|k| FiniteMean::of(per_sequence.iter().map(|s| s.rte_5s_swapped[k]))),
        train_s,
        per_sequence,
    })
}

/// RIDI's means over whole runs, as the issue averages: the parts of a run split at a gap
/// (`<run>_part<k>`) are first averaged into their run, weighted by their frames. Returns the
/// number of runs, velocity MSE, RTE 5 s, ATE, path length ratio and placement accuracy.
fn per_run_means(r: &Row) -> (usize, [f64; 6]) {
    let mut runs: BTreeMap<&str, [FiniteMean; 6]> = BTreeMap::new();
    for s in &r.per_sequence {
        let q = &s.result;
        let run = run_of(&q.name);
        let ridi = &q.methods["ridi"];
        let values = [
            q.velocity_mse[0],
            q.velocity_mse[1],
            ridi.rte_5s_m,
            ridi.ate_m,
            ridi.path_length_ratio.unwrap_or(f64::NAN),
            q.placement_accuracy.unwrap_or(f64::NAN),
        ];
        let w = s.frames as f64;
        let e = runs.entry(run).or_default();
        for (acc, v) in e.iter_mut().zip(values) {
            acc.add(w, v);
        }
    }
    let means = std::array::from_fn(|k| FiniteMean::of(runs.values().map(|m| m[k].mean())));
    (runs.len(), means)
}

/// The run a test sequence belongs to: its name without the `_part<k>` of a run split at a gap.
fn run_of(name: &str) -> &str {
    name.rsplit_once("_part")
        .filter(|(_, k)| k.parse::<u32>().is_ok())
        .map_or(name, |(run, _)| run)
}

/// `mean [low, high]`, or a dash without an interval; a difference (`signed`) whose interval
/// leaves out 0 is bold.
pub(crate) fn interval_cell(i: Option<Interval>, signed: bool) -> String {
    match (i, signed) {
        (Some(i), false) => format!("{:.3} [{:.2}, {:.2}]", i.mean, i.low, i.high),
        (Some(i), true) if i.contains(0.0) => {
            format!("{:+.3} [{:+.3}, {:+.3}]", i.mean, i.low, i.high)
        }
        (Some(i), true) => format!("**{:+.3} [{:+.3}, {:+.3}]**", i.mean, i.low, i.high),
        (None, _) => "-".into(),
    }
}

/// Each variant's RTE 5 s under both alignments with its 95 % interval over runs, and its
/// difference from ridi's defaults on the same sequences (paired: a resample draws the same
/// runs for both), so that a reader sees which differences the 24 runs resolve.
fn resolution(md: &mut String, rows: &[(Variant, Row)]) {
    let _ = writeln!(
        md,
        "\n## How much the protocol resolves\n\nRTE 5 s differs widely from one test sequence \
         to the next (one 10-s alignment that fixes a wrong heading adds metres), so a mean over \
         the sequences of three people is uncertain. 95 % intervals from a bootstrap over the \
         runs ({} resamples of whole runs, a run's parts together, fixed seed): of each \
         variant's mean, and of its difference from ridi's defaults on the same runs. A \
         difference whose interval holds 0 is one the protocol cannot tell from none; bold: one it resolves. \
         The runs are drawn as if independent, though a person's runs share that person and one \
         model: the intervals hold for these three people, not for others; and with two \
         differences per variant, about one in twenty would leave out 0 by chance alone.\n",
        bootstrap::DRAWS
    );
    let _ = writeln!(
        md,
        "| variant | RTE 5 s (m) [95 %] | difference from the defaults [95 %] | aligned on the whole run (m) [95 %] | difference from the defaults [95 %] |\n| --- | --- | --- | --- | --- |"
    );
    let defaults = rows
        .iter()
        .find(|(v, _)| v.name == DEFAULTS.name)
        .map(|(_, r)| r);
    let ten = |s: &SeqRow| s.result.methods["ridi"].rte_5s_m;
    let whole = |s: &SeqRow| s.rte_5s_whole;
    for (v, r) in rows {
        let cluster: Vec<&str> = r
            .per_sequence
            .iter()
            .map(|s| run_of(&s.result.name))
            .collect();
        let of = |f: &dyn Fn(&SeqRow) -> f64| {
            let values: Vec<f64> = r.per_sequence.iter().map(f).collect();
            bootstrap::mean_interval(&values, &cluster)
        };
        // The same sequences in the same order, or no paired difference.
        let paired = defaults.filter(|d| {
            v.name != DEFAULTS.name
                && d.per_sequence.len() == r.per_sequence.len()
                && d.per_sequence
                    .iter()
                    .zip(&r.per_sequence)
                    .all(|(a, b)| a.result.name == b.result.name)
        });
        let difference = |f: &dyn Fn(&SeqRow) -> f64| {
            let d = paired?;
            let values: Vec<f64> = r
                .per_sequence
                .iter()
                .zip(&d.per_sequence)
                .map(|(mine, theirs)| f(mine) - f(theirs))
                .collect();
            bootstrap::mean_interval(&values, &cluster)
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} |",
            v.name,
            interval_cell(of(&ten), false),
            interval_cell(difference(&ten), true),
            interval_cell(of(&whole), false),
            interval_cell(difference(&whole), true),
        );
    }
}

/// Means per placement label of one variant's sequences.
fn per_placement(md: &mut String, v: &Variant, r: &Row) {
    let _ = writeln!(md, "\n## Per placement, {}\n", v.name);
    let _ = writeln!(
        md,
        "| placement | sequences | velocity MSE S-x / S-z | placement accuracy | RTE 5 s (m) | ATE (m) | path length ratio |\n| --- | --- | --- | --- | --- | --- | --- |"
    );
    let mut labels: Vec<&str> = r
        .per_sequence
        .iter()
        .filter_map(|s| s.result.placement.as_deref())
        .collect();
    labels.sort_unstable();
    labels.dedup();
    for label in labels {
        let rows: Vec<&SequenceResult> = r
            .per_sequence
            .iter()
            .map(|s| &s.result)
            .filter(|s| s.placement.as_deref() == Some(label))
            .collect();
        let m = |f: &dyn Fn(&SequenceResult) -> f64| FiniteMean::of(rows.iter().map(|r| f(r)));
        let _ = writeln!(
            md,
            "| {label} | {} | {:.3} / {:.3} | {:.3} | {:.3} | {:.3} | {:.3} |",
            rows.len(),
            m(&|r| r.velocity_mse[0]),
            m(&|r| r.velocity_mse[1]),
            m(&|r| r.placement_accuracy.unwrap_or(f64::NAN)),
            m(&|r| r.methods["ridi"].rte_5s_m),
            m(&|r| r.methods["ridi"].ate_m),
            m(&|r| r.methods["ridi"].path_length_ratio.unwrap_or(f64::NAN)),
        );
    }
}

/// Every test sequence of one variant, with the mean velocity directions.
fn per_sequence(md: &mut String, v: &Variant, r: &Row) {
    let _ = writeln!(md, "\n## Per sequence, {}\n", v.name);
    let _ = writeln!(
        md,
        "Mean true and mean regressed velocity in S show how the phone was held relative to the \
         walk: a person who carries it turned against the training people gets velocities \
         turned by the same angle. Ground-truth travel is how far the walker moved within the \
         10 s the alignment is fitted on: below 1 m the fitted heading rests on little motion, \
         and the whole-run alignment shows what that cost.\n"
    );
    let _ = writeln!(
        md,
        "| sequence | placement | velocity MSE S-x / S-z | placement accuracy | mean true v (S-x, S-z) | mean regressed v | ground-truth travel in the alignment window (m) | RTE 5 s (m) | RTE 5 s, whole-run alignment (m) | path length ratio |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    let mut rows: Vec<&SeqRow> = r.per_sequence.iter().collect();
    rows.sort_by(|a, b| a.result.name.cmp(&b.result.name));
    for s in rows {
        let q = &s.result;
        let _ = writeln!(
            md,
            "| {} | {} | {:.3} / {:.3} | {:.3} | ({:+.2}, {:+.2}) | ({:+.2}, {:+.2}) | {:.2} | {:.3} | {:.3} | {:.3} |",
            q.name,
            q.placement.as_deref().unwrap_or("-"),
            q.velocity_mse[0],
            q.velocity_mse[1],
            q.placement_accuracy.unwrap_or(f64::NAN),
            s.mean_true[0],
            s.mean_true[1],
            s.mean_regressed[0],
            s.mean_regressed[1],
            q.alignment_extent_m,
            q.methods["ridi"].rte_5s_m,
            s.rte_5s_whole,
            q.methods["ridi"].path_length_ratio.unwrap_or(f64::NAN),
        );
    }
}

fn get(v: &[(String, f64)], key: &str) -> f64 {
    v.iter()
        .find(|(k, _)| k == key)
        .map_or(f64::NAN, |(_, x)| *x)
}

/// Runs the protocol and writes the markdown report; returns its path.
pub fn run(
    data: Option<PathBuf>,
    out: Option<PathBuf>,
    quick: bool,
    only: Option<String>,
) -> Result<PathBuf> {
    let root = xtask::workspace_root();
    let out = out.unwrap_or_else(|| root.join("docs/bench-accuracy.md"));
    let chosen: Vec<Variant> = variants(quick)
        .into_iter()
        .filter(|v| only.as_deref().is_none_or(|o| v.name.contains(o)))
        .collect();
    if chosen.is_empty() {
        let names: Vec<&str> = variants(quick).iter().map(|v| v.name).collect();
        anyhow::bail!(
            "no variant's name contains {:?}; the variants: {}",
            only.unwrap_or_default(),
            names.join("; ")
        );
    }
    let data = xtask::tyrex_root(data)?;
    let started = Instant::now();
    let all = load(&data).with_context(|| format!("reading Tyrex data in {}", data.display()))?;
    let mut rows = Vec::new();
    // Sequences and models of the previous variant, kept while the next one shares them
    // (`prepare` depends only on what the training key holds).
    let mut shared: Option<(String, Vec<Sequence>, Vec<Cascade>, f64)> = None;
    for v in chosen {
        if shared.as_ref().is_none_or(|s| s.0 != v.train_key()) {
            drop(shared.take()); // free the previous models first
            let seqs = prepare(&all, &v)?;
            let (models, secs) = train_folds(&seqs, &v)?;
            shared = Some((v.train_key(), seqs, models, secs));
        }
        let (_, seqs, models, secs) = shared.as_ref().context("models")?;
        let row = run_variant(seqs, models, *secs, &v)?;
        rows.push((v, row));
    }
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Accuracy: leave-one-subject-out on the Tyrex Nexus 5 runs\n"
    );
    let _ = writeln!(
        md,
        "Command: `cargo xtask eval tyrex --variants{}{}` ({:.0} s in all on a 2-core machine shared with other work). \
         {} test sequences (24 runs; runs split at long mocap or sensor gaps count once per part). \
         Train on two people, test on the third, three folds; C = 10, epsilon = 0.01 without grid \
         search unless a variant searches; \
         trajectories aligned on the first 10 s; means over test sequences. Variants that differ \
         only at test time share their models (and their training time).\n",
        if quick { " --quick" } else { "" },
        only.as_deref()
            .map_or(String::new(), |o| format!(" --only '{o}'")),
        started.elapsed().as_secs_f64(),
        rows.first().map_or(0, |r| r.1.sequences)
    );
    let _ = writeln!(md, "## RIDI per variant\n");
    let _ = writeln!(
        md,
        "| variant | velocity MSE S-x / S-z (m/s)^2 | RTE 5 s (m) | ATE (m) | path length ratio | placement accuracy | GT-velocity floor RTE 5 s (m) | RTE 5 s aligned on the whole run (m) | training (s, 3 folds) |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    for (v, r) in &rows {
        let _ = writeln!(
            md,
            "| {} | {:.3} / {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.1} |",
            v.name,
            r.velocity_mse[0],
            r.velocity_mse[1],
            get(&r.rte_5s, "ridi"),
            get(&r.ate, "ridi"),
            get(&r.path_ratio, "ridi"),
            r.placement_accuracy,
            r.oracle_rte_5s,
            r.rte_5s_whole,
            r.train_s
        );
    }
    let _ = writeln!(
        md,
        "\n## RIDI per variant, means over runs\n\nThe issue averages over its 24 test runs: here \
         the parts of a run split at a gap are first averaged into their run (weighted by their \
         frames), so every run counts once.\n"
    );
    let _ = writeln!(
        md,
        "| variant | runs | velocity MSE S-x / S-z (m/s)^2 | RTE 5 s (m) | ATE (m) | path length ratio | placement accuracy |\n| --- | --- | --- | --- | --- | --- | --- |"
    );
    for (v, r) in &rows {
        let (n, m) = per_run_means(r);
        let _ = writeln!(
            md,
            "| {} | {n} | {:.3} / {:.3} | {:.3} | {:.3} | {:.3} | {:.3} |",
            v.name, m[0], m[1], m[2], m[3], m[4], m[5]
        );
    }
    resolution(&mut md, &rows);
    let _ = writeln!(
        md,
        "\n## Where RIDI's RTE 5 s comes from\n\nThe same correction and evaluation with one \
         part of each regressed velocity replaced by the ground truth's (means over test \
         sequences): the regressed direction with the true speed, the true direction (in S) with \
         the regressed speed, and the whole ground-truth velocity (the floor the correction and \
         the phone's orientation leave). The alignment on the whole run removes the heading \
         error the first 10 s leave.\n"
    );
    let _ = writeln!(
        md,
        "| variant | RTE 5 s (m) | true speed, regressed direction | true direction, regressed speed | ground-truth velocity | aligned on the whole run |\n| --- | --- | --- | --- | --- | --- |"
    );
    for (v, r) in &rows {
        let _ = writeln!(
            md,
            "| {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} |",
            v.name,
            get(&r.rte_5s, "ridi"),
            r.rte_5s_swapped[0],
            r.rte_5s_swapped[1],
            r.oracle_rte_5s,
            r.rte_5s_whole,
        );
    }
    for (v, r) in rows
        .iter()
        .filter(|(v, _)| [PAPER.name, DEFAULTS.name].contains(&v.name))
    {
        let _ = writeln!(md, "\n## Every method, {}\n", v.name);
        let _ = writeln!(
            md,
            "| method | RTE 5 s (m) | ATE (m) | path length ratio |\n| --- | --- | --- | --- |"
        );
        for m in Method::ALL {
            let _ = writeln!(
                md,
                "| {} | {:.3} | {:.3} | {:.3} |",
                m.key(),
                get(&r.rte_5s, m.key()),
                get(&r.ate, m.key()),
                get(&r.path_ratio, m.key())
            );
        }
    }
    for (v, r) in rows
        .iter()
        .filter(|(v, _)| [PAPER.name, RECOMMENDED.name, DEFAULTS.name].contains(&v.name))
    {
        per_placement(&mut md, v, r);
    }
    for (v, r) in rows
        .iter()
        .filter(|(v, _)| [PAPER.name, DEFAULTS.name].contains(&v.name))
    {
        per_sequence(&mut md, v, r);
    }
    write_atomically(&out, |w| w.write_all(md.as_bytes()))?;
    print!("{md}");
    Ok(out)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use ridi::eval::TrajectoryMetrics;

    /// Metrics of a trajectory with RTE 5 s `rte` and ATE twice that, a path of the right
    /// length (the test fixture of both protocols' tables).
    pub(crate) fn metrics_with_rte(rte: f64) -> TrajectoryMetrics {
        TrajectoryMetrics {
            mpe_m: 0.0,
            mpe_pct: None,
            ate_m: 2.0 * rte,
            rte_m: 0.0,
            ate_ronin_m: 0.0,
            rte_ronin_m: 0.0,
            rte_5s_m: rte,
            path_length_ratio: Some(1.0),
        }
    }

    fn seq(name: &str, frames: usize, rte: f64) -> SeqRow {
        let metrics = metrics_with_rte(rte);
        SeqRow {
            result: SequenceResult {
                name: name.into(),
                run: name.into(),
                placement: None,
                device: None,
                path_length_m: 1.0,
                alignment_extent_m: 2.0,
                placement_accuracy: Some(1.0),
                velocity_mse: [rte, 0.0],
                methods: [("ridi".to_string(), metrics)].into_iter().collect(),
            },
            mean_regressed: [0.0; 2],
            mean_true: [0.0; 2],
            rte_5s_whole: 0.0,
            rte_5s_swapped: [0.0; 2],
            frames,
        }
    }

    #[test]
    fn swapping_in_the_true_half_of_a_velocity() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../datasets/sample/Thibaud_Nexus5_NoDist_Texting");
        let seq = ridi::data::read_sequence(&dir, &Default::default()).unwrap();
        let opts = EvalOptions::default();
        let config = FeatureConfig::default();
        let frames = SampleSchedule::every(&config, opts.track.regress_every)
            .unwrap()
            .frames(seq.len());
        let truth = compute_targets(&ground_truth_view(&seq).unwrap(), &config, &frames)
            .unwrap()
            .values
            .iter()
            .map(|v| v.to_array())
            .collect::<Vec<_>>();
        // Regressions turned by 30 degrees one way, then the other, every 5 s (a constant turn
        // would vanish in the alignment; the speed right), and then also 20 % short.
        let turned: Vec<[f64; 2]> = truth
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let sign = if (i / 20) % 2 == 0 { 1.0 } else { -1.0 };
                let (s, c) = (sign * 30f64.to_radians()).sin_cos();
                [c * v[0] - s * v[1], s * v[0] + c * v[1]]
            })
            .collect();
        let traces = |regressed: Vec<[f64; 2]>| Traces {
            name: seq.name().to_string(),
            ground_truth: seq.ground_truth().unwrap().horizontal(),
            methods: Vec::new(),
            regression_time: frames.iter().map(|&f| seq.time()[f]).collect(),
            regressed,
            true_velocity: truth.clone(),
            placements: Vec::new(),
        };
        let correction = opts.track.correction;
        let rte = |t: &Traces, which| swapped_rte(&seq, t, correction, which).unwrap();
        let oracle = oracle_rte(&seq, &config, opts.track.regress_every, correction).unwrap();
        // The true direction restores the ground truth exactly; the true speed changes nothing
        // while only the direction is wrong, and mends the shortening.
        let only_turned = traces(turned.clone());
        assert!((rte(&only_turned, Truth::Direction) - oracle).abs() < 1e-9);
        let turned_rte = rte(&only_turned, Truth::Speed);
        assert!(turned_rte > oracle + 0.2, "{turned_rte} vs {oracle}");
        let short = traces(turned.iter().map(|v| [0.8 * v[0], 0.8 * v[1]]).collect());
        assert!((rte(&short, Truth::Speed) - turned_rte).abs() < 1e-9);
        assert!(rte(&short, Truth::Direction) > oracle);
    }

    #[test]
    fn parts_are_averaged_into_their_run_by_frames() {
        let row = Row {
            per_sequence: vec![
                seq("A_Phoning_part1", 100, 1.0),
                seq("A_Phoning_part2", 300, 3.0),
                seq("B_Swinging", 50, 4.0),
                seq("C_partial", 10, 2.0),
            ],
            ..Row::default()
        };
        let (runs, m) = per_run_means(&row);
        // A: (100 * 1 + 300 * 3) / 400 = 2.5; B: 4; "C_partial" is a run of its own: 2.
        assert_eq!(runs, 3);
        assert!((m[2] - (2.5 + 4.0 + 2.0) / 3.0).abs() < 1e-12, "{m:?}");
        assert!((m[0] - m[2]).abs() < 1e-12 && (m[3] - 2.0 * m[2]).abs() < 1e-12);
        assert_eq!((m[4], m[5]), (1.0, 1.0));
    }

    #[test]
    fn a_figure_a_sequence_lacks_is_left_out_of_its_mean() {
        let mut a = seq("A_Phoning", 100, 1.0);
        let mut b = seq("B_Swinging", 100, 3.0);
        // A path without length has no ratio; a model of one placement, no accuracy.
        a.result.methods.get_mut("ridi").unwrap().path_length_ratio = None;
        b.result.placement_accuracy = None;
        let row = Row {
            per_sequence: vec![a, b],
            ..Row::default()
        };
        let (_, m) = per_run_means(&row);
        assert_eq!((m[4], m[5]), (1.0, 1.0), "{m:?}");
        assert!(FiniteMean::of([f64::NAN]).is_nan());
        assert_eq!(FiniteMean::of([2.0, f64::NAN, 4.0]), 3.0);
    }

    #[test]
    fn resolution_pairs_each_variant_with_the_defaults() {
        // Six runs of two parts each.
        let names: Vec<String> = (0..12)
            .map(|i| format!("P{}_Run{}_part{}", i / 4, i / 2, 1 + i % 2))
            .collect();
        let rows_of = |shift: f64| -> Vec<SeqRow> {
            names
                .iter()
                .enumerate()
                .map(|(i, name)| {
                    let mut s = seq(name, 100, 1.0 + 0.3 * (i % 4) as f64 + shift);
                    s.rte_5s_whole = 0.8 + 0.3 * (i % 4) as f64;
                    s
                })
                .collect()
        };
        let row = |per_sequence| Row {
            per_sequence,
            ..Row::default()
        };
        let renamed = {
            let mut r = rows_of(0.0);
            r[5].result.name = "P1_Other".into();
            r
        };
        let variant = |name| Variant { name, ..DEFAULTS };
        let rows = vec![
            (PAPER, row(rows_of(0.25))),
            (DEFAULTS, row(rows_of(0.0))),
            (variant("fewer sequences"), row(rows_of(0.0)[1..].to_vec())),
            (variant("one renamed"), row(renamed)),
        ];
        let mut md = String::new();
        resolution(&mut md, &rows);
        let line = |name: &str| {
            md.lines()
                .find(|l| l.starts_with(&format!("| {name} |")))
                .unwrap()
                .to_string()
        };
        // The paper row is 0.25 m above the defaults on every sequence: a resolved difference
        // under the 10-s alignment, none on the whole run.
        let paper = line(PAPER.name);
        assert!(paper.contains("**+0.250 [+0.250, +0.250]**"), "{paper}");
        assert!(paper.ends_with("| +0.000 [+0.000, +0.000] |"), "{paper}");
        // A mean's interval resamples runs, the parts of a run together.
        let runs: Vec<&str> = names.iter().map(|n| run_of(n)).collect();
        assert_eq!(runs[2], "P0_Run1");
        let values: Vec<f64> = (0..12).map(|i| 1.0 + 0.3 * (i % 4) as f64).collect();
        let by_run = bootstrap::mean_interval(&values, &runs).unwrap();
        let by_part = bootstrap::mean_interval(
            &values,
            &names.iter().map(String::as_str).collect::<Vec<_>>(),
        )
        .unwrap();
        assert_ne!(by_run, by_part);
        let defaults = line(DEFAULTS.name);
        assert!(
            defaults.starts_with(&format!(
                "| {} | {} |",
                DEFAULTS.name,
                interval_cell(Some(by_run), false)
            )),
            "{defaults}"
        );
        // The defaults are the reference; variants on other sequences are not paired.
        assert_eq!(defaults.matches("| - ").count(), 2, "{defaults}");
        assert_eq!(line("fewer sequences").matches("| - ").count(), 2);
        assert_eq!(line("one renamed").matches("| - ").count(), 2);
        assert_eq!(run_of("C_partial"), "C_partial");
    }
}
