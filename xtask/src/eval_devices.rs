//! `cargo xtask eval tyrex`: how well RIDI tracks a person, and a phone, its model never saw.
//!
//! Every protocol leaves one person out (train on two people, test on the third, three folds);
//! they differ in which phones the model trains and is tested on:
//!
//! - both phones: train on every run of two people (Nexus 5 with and without magnetic
//!   disturbance, iPhone 4S), test on every run of the third;
//! - across devices: train on two people's Nexus 5 runs, test on the third person's iPhone 4S
//!   runs, beside the model trained on the same people's iPhone 4S runs (and the reverse); and
//!   as a control, the Nexus 5 model trained on as many runs as the iPhone 4S model has;
//! - the 24 undisturbed Nexus 5 runs, the protocol of `--variants`, for continuity.
//!
//! The runs are the committed list [`RUN_LIST`], so that a fuller copy of the dataset does not
//! change the protocol. Every figure is a mean over runs (a run split at a gap is first averaged
//! into its run, weighted by frames) with a 95 % bootstrap interval over runs; RIDI's difference
//! from PDR (step counting with the oracle step length) is paired run by run.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail, ensure};
use ridi::data::tyrex::{self, TyrexOptions};
use ridi::data::{Sequence, write_atomically};
use ridi::features::Orientation;
use ridi::regress::{NoProgress, Nystrom, Solver, Storage};
use ridi::{EvalOptions, GridChoice, PlacementMap, TrainOptions, apply_orientation};
use ridi::{SequenceResult, check_evaluable};

use crate::bootstrap::{self, FiniteMean, Interval};
use crate::eval_tyrex::{PEOPLE, interval_cell};
use crate::eval_tyrex::{Truth, oracle_rte, swapped_rte};

/// The protocol's runs, relative to the workspace root.
pub const RUN_LIST: &str = "datasets/protocols/tyrex-runs.txt";

/// The phone of a run (also `cargo xtask eval orientation --phone`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, clap::ValueEnum)]
pub(crate) enum Phone {
    /// The Nexus 5 (Android rotation vector).
    #[value(name = "nexus5")]
    Nexus5,
    /// The iPhone 4S (Core Motion attitude).
    #[value(name = "iphone4s")]
    IPhone4S,
}

impl Phone {
    /// What a run folder's name calls it: `<person>_<token>_<condition>_<motion>`.
    pub(crate) fn token(self) -> &'static str {
        match self {
            Phone::Nexus5 => "Nexus5",
            Phone::IPhone4S => "iPhone4S",
        }
    }

    pub(crate) fn name(self) -> &'static str {
        match self {
            Phone::Nexus5 => "Nexus 5",
            Phone::IPhone4S => "iPhone 4S",
        }
    }
}

/// One run of the list: `<layout>/<person>_<phone>_<condition>_<motion>`.
#[derive(Debug, Clone, PartialEq)]
struct Run {
    /// The folder under `<tyrex root>/datasets`.
    path: String,
    /// The folder's name (what the reader names the run's sequences after).
    name: String,
    person: String,
    phone: Phone,
    /// Recorded near magnetic disturbances (`Dist`).
    disturbed: bool,
}

impl Run {
    /// `Nexus 5`, `Nexus 5 near disturbance` or `iPhone 4S`.
    fn device_condition(&self) -> String {
        if self.disturbed {
            format!("{} near disturbance", self.phone.name())
        } else {
            self.phone.name().to_string()
        }
    }
}

/// Reads the run list; errors name the file and line.
fn read_run_list(path: &Path) -> Result<Vec<Run>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading the run list {}", path.display()))?;
    parse_run_list(&text).with_context(|| format!("in the run list {}", path.display()))
}

fn parse_run_list(text: &str) -> Result<Vec<Run>> {
    let mut runs: Vec<Run> = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let run = parse_run(line).with_context(|| format!("line {}: {line:?}", i + 1))?;
        ensure!(
            runs.iter().all(|r| r.name != run.name),
            "line {}: {} is listed twice",
            i + 1,
            run.name
        );
        runs.push(run);
    }
    ensure!(!runs.is_empty(), "no run listed");
    Ok(runs)
}

fn parse_run(line: &str) -> Result<Run> {
    let (layout, name) = line
        .split_once('/')
        .context("expected <android|ios>/<run folder>")?;
    let fields: Vec<&str> = name.split('_').collect();
    let [person, phone, condition, _motion] = fields[..] else {
        bail!("expected a folder named <person>_<phone>_<NoDist|Dist>_<motion>");
    };
    let phone = match (layout, phone) {
        ("android", t) if t == Phone::Nexus5.token() => Phone::Nexus5,
        ("ios", t) if t == Phone::IPhone4S.token() => Phone::IPhone4S,
        _ => bail!(
            "unknown phone {phone:?} under {layout:?} (Nexus5 under android, iPhone4S under ios)"
        ),
    };
    let disturbed = match condition {
        "NoDist" => false,
        "Dist" => true,
        _ => bail!("unknown condition {condition:?} (NoDist or Dist)"),
    };
    ensure!(
        PEOPLE.contains(&person),
        "unknown person {person:?} (the protocol's people: {})",
        PEOPLE.join(", ")
    );
    Ok(Run {
        path: line.to_string(),
        name: name.to_string(),
        person: person.to_string(),
        phone,
        disturbed,
    })
}

/// A set of runs a model trains on or is tested on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum RunSet {
    Every,
    Nexus5,
    IPhone4S,
    /// The Nexus 5 runs without magnetic disturbance: the 24-run protocol.
    Nexus5Undisturbed,
}

impl RunSet {
    fn holds(self, run: &Run) -> bool {
        match self {
            RunSet::Every => true,
            RunSet::Nexus5 => run.phone == Phone::Nexus5,
            RunSet::IPhone4S => run.phone == Phone::IPhone4S,
            RunSet::Nexus5Undisturbed => run.phone == Phone::Nexus5 && !run.disturbed,
        }
    }

    fn name(self) -> &'static str {
        match self {
            RunSet::Every => "both phones",
            RunSet::Nexus5 => "Nexus 5",
            RunSet::IPhone4S => "iPhone 4S",
            RunSet::Nexus5Undisturbed => "Nexus 5 without disturbance",
        }
    }
}

/// One row of the report: a model trained on `train`, tested on `test`, leaving one person out.
#[derive(Debug, Clone, Copy)]
struct Protocol {
    name: &'static str,
    train: RunSet,
    test: RunSet,
}

const BOTH_PHONES: Protocol = Protocol {
    name: "both phones",
    train: RunSet::Every,
    test: RunSet::Every,
};

const PROTOCOLS: [Protocol; 7] = [
    BOTH_PHONES,
    Protocol {
        name: "Nexus 5 -> iPhone 4S",
        train: RunSet::Nexus5,
        test: RunSet::IPhone4S,
    },
    Protocol {
        name: "iPhone 4S -> iPhone 4S",
        train: RunSet::IPhone4S,
        test: RunSet::IPhone4S,
    },
    Protocol {
        name: "iPhone 4S -> Nexus 5",
        train: RunSet::IPhone4S,
        test: RunSet::Nexus5,
    },
    Protocol {
        name: "Nexus 5 -> Nexus 5",
        train: RunSet::Nexus5,
        test: RunSet::Nexus5,
    },
    Protocol {
        name: "Nexus 5 without disturbance -> Nexus 5",
        train: RunSet::Nexus5Undisturbed,
        test: RunSet::Nexus5,
    },
    Protocol {
        name: "24 Nexus 5 runs",
        train: RunSet::Nexus5Undisturbed,
        test: RunSet::Nexus5Undisturbed,
    },
];

/// Two protocols on the same test runs: a model that never saw the test phone (`cross`), and
/// a model of the same people trained on it (`same`).
struct Across {
    cross: &'static str,
    same: &'static str,
    /// One of the every-phone issue's goals (at most 15 % lost), else a control.
    goal: bool,
}

/// The goals' pairs, and two controls. The iPhone 4S model learns from two people's 16 runs, the
/// Nexus 5 model from their 28, 12 of them recorded near magnetic disturbance (a session of its
/// own that 18 of the 42 Nexus 5 test runs share, and no iPhone run). The controls set the iPhone
/// 4S model against a Nexus 5 model on the 16 undisturbed runs: on every Nexus 5 test run, and
/// on the undisturbed ones only, where training and test differ in nothing but the phone.
const ACROSS: [Across; 4] = [
    Across {
        cross: "Nexus 5 -> iPhone 4S",
        same: "iPhone 4S -> iPhone 4S",
        goal: true,
    },
    Across {
        cross: "iPhone 4S -> Nexus 5",
        same: "Nexus 5 -> Nexus 5",
        goal: true,
    },
    Across {
        cross: "iPhone 4S -> Nexus 5",
        same: "Nexus 5 without disturbance -> Nexus 5",
        goal: false,
    },
    Across {
        cross: "iPhone 4S -> Nexus 5",
        same: "24 Nexus 5 runs",
        goal: false,
    },
];

/// One figure of a run.
struct Metric {
    label: &'static str,
    of: fn(&SequenceResult) -> f64,
}

fn method(r: &SequenceResult, key: &str, f: fn(&ridi::eval::TrajectoryMetrics) -> f64) -> f64 {
    r.methods.get(key).map_or(f64::NAN, f)
}

const MSE_X: usize = 0;
const MSE_Z: usize = 1;
const RTE: usize = 2;
const PATH_RATIO: usize = 4;
const PLACEMENT: usize = 5;
const PDR_RTE: usize = 6;

const METRICS: [Metric; 9] = [
    Metric {
        label: "velocity MSE S-x (m/s)^2",
        of: |r| r.velocity_mse[0],
    },
    Metric {
        label: "velocity MSE S-z (m/s)^2",
        of: |r| r.velocity_mse[1],
    },
    Metric {
        label: "RTE 5 s (m)",
        of: |r| method(r, "ridi", |m| m.rte_5s_m),
    },
    Metric {
        label: "ATE (m)",
        of: |r| method(r, "ridi", |m| m.ate_m),
    },
    Metric {
        label: "path length ratio",
        of: |r| method(r, "ridi", |m| m.path_length_ratio.unwrap_or(f64::NAN)),
    },
    Metric {
        label: "placement accuracy",
        of: |r| r.placement_accuracy.unwrap_or(f64::NAN),
    },
    Metric {
        label: "PDR RTE 5 s (m)",
        of: |r| method(r, "pdr", |m| m.rte_5s_m),
    },
    Metric {
        label: "RIDI-MAG RTE 5 s (m)",
        of: |r| method(r, "ridi_mag", |m| m.rte_5s_m),
    },
    Metric {
        label: "STILL RTE 5 s (m)",
        of: |r| method(r, "still", |m| m.rte_5s_m),
    },
];

/// One tested sequence of one protocol.
#[derive(Debug, Clone)]
struct Tested {
    /// Index into the run list.
    run: usize,
    frames: usize,
    result: SequenceResult,
    /// RIDI's RTE 5 s with the OS orientation's jumps bridged by the gyro (the sequence's own
    /// where it has none).
    bridged_rte: f64,
    /// RIDI's RTE 5 s with each regressed velocity's speed, then its direction, then both from
    /// the ground truth ([`eval_tyrex::swapped_rte`], [`eval_tyrex::oracle_rte`]): which part of
    /// the error is speed, which heading, and the floor the correction and orientation leave.
    swapped_rte: [f64; 3],
}

/// A run's figures: its sequences averaged, weighted by frames ([`METRICS`] order).
#[derive(Debug, Clone)]
struct RunFigures {
    run: usize,
    placement: String,
    values: [f64; METRICS.len()],
    /// [`Tested::bridged_rte`], averaged the same way.
    bridged_rte: f64,
    /// [`Tested::swapped_rte`], averaged the same way.
    swapped_rte: [f64; 3],
    /// Whether a part of the run had orientation jumps.
    jumps: bool,
}

/// Averages each run's parts into the run, weighted by their frames. A figure a part lacks
/// (`NaN`, e.g. a path ratio without a path) leaves the part out of that figure's mean.
fn per_run(tested: &[Tested]) -> Vec<RunFigures> {
    // Weighted means of METRICS, then of the bridged RTE and the swapped ones.
    type Sums = ([FiniteMean; METRICS.len()], [FiniteMean; 4], bool);
    let mut runs: BTreeMap<usize, (String, Sums)> = BTreeMap::new();
    for t in tested {
        let e = runs.entry(t.run).or_insert_with(|| {
            let placement = t.result.placement.clone().unwrap_or_else(|| "-".into());
            (placement, Sums::default())
        });
        let w = t.frames as f64;
        for (acc, m) in e.1.0.iter_mut().zip(&METRICS) {
            acc.add(w, (m.of)(&t.result));
        }
        let [speed, direction, truth] = t.swapped_rte;
        for (acc, v) in
            e.1.1
                .iter_mut()
                .zip([t.bridged_rte, speed, direction, truth])
        {
            acc.add(w, v);
        }
        e.1.2 |= t.bridged_rte != (METRICS[RTE].of)(&t.result);
    }
    runs.into_iter()
        .map(
            |(run, (placement, (sums, [bridged, speed, direction, truth], jumps)))| RunFigures {
                run,
                placement,
                values: sums.map(|m| m.mean()),
                bridged_rte: bridged.mean(),
                swapped_rte: [speed, direction, truth].map(|m| m.mean()),
                jumps,
            },
        )
        .collect()
}

/// Mean and interval of one figure over runs (runs without the figure left out).
fn figure(runs: &[&RunFigures], k: usize) -> Option<Interval> {
    interval_of(runs, |r| r.values[k])
}

/// RIDI's RTE 5 s minus PDR's, run by run.
fn ridi_minus_pdr(runs: &[&RunFigures]) -> Option<Interval> {
    interval_of(runs, |r| r.values[RTE] - r.values[PDR_RTE])
}

/// Mean and interval over runs of `value` (runs without it left out).
fn interval_of(runs: &[&RunFigures], value: impl Fn(&RunFigures) -> f64) -> Option<Interval> {
    let values: Vec<f64> = runs
        .iter()
        .map(|r| value(r))
        .filter(|v| v.is_finite())
        .collect();
    bootstrap::runs_interval(&values)
}

/// The figures of `runs` as table cells, then RIDI - PDR.
fn cells(runs: &[&RunFigures]) -> String {
    let mut row = format!("{} |", runs.len());
    for k in 0..METRICS.len() {
        let _ = write!(row, " {} |", interval_cell(figure(runs, k), false));
    }
    let _ = write!(row, " {} |", interval_cell(ridi_minus_pdr(runs), true));
    row
}

fn table_header(first: &str) -> String {
    let mut h = format!("| {first} | runs |");
    for m in &METRICS {
        let _ = write!(h, " {} |", m.label);
    }
    h.push_str(" RIDI - PDR RTE 5 s (m) |\n|");
    h.push_str(&" --- |".repeat(METRICS.len() + 3));
    h
}

/// What the protocol was run with.
#[derive(Debug, Clone)]
pub struct Options {
    pub data: Option<PathBuf>,
    pub out: Option<PathBuf>,
    /// Protocols whose name contains this text.
    pub only: Option<String>,
    /// Training sample step in frames (`None`: ridi train's).
    pub step: Option<usize>,
    pub orientation: Orientation,
    /// With the estimated orientation, its heading corrected by the recorded one's (as
    /// `ridi track --heading`); `None` keeps the gyro's.
    pub recorded_heading: Option<ridi::frames::HeadingConfig>,
    /// Nyström landmarks instead of the exact solver.
    pub landmarks: Option<usize>,
    /// Search the paper's grid by cross-validation on the training people (`false`: C = 10,
    /// epsilon = 0.01 fixed).
    pub grid: bool,
    /// Seed of training's random draws ([`ridi::regress::CascadeParams::set_seed`]).
    pub seed: u64,
}

/// The protocol's training: `ridi train`'s defaults but C and epsilon fixed unless `grid` (the
/// paper grid's search multiplies exact training by 48), with this sample step (`None`: ridi
/// train's), orientation, and the Nyström solver on `landmarks` (`None`: exact) with its own
/// projection (`Storage::projected_for`), its random draws seeded with `seed`. `cargo xtask
/// model` trains the bundled model the same way.
pub fn train_options(
    step: Option<usize>,
    orientation: Orientation,
    landmarks: Option<usize>,
    grid: bool,
    seed: u64,
) -> Result<TrainOptions> {
    let mut train_opts = TrainOptions::default();
    if !grid {
        train_opts.cascade.regressors = GridChoice::None.regressors();
    }
    train_opts.features.orientation = orientation;
    if let Some(step) = step {
        train_opts.features.step = step;
    }
    if let Some(m) = landmarks {
        train_opts.cascade.solver = Solver::Nystrom(Nystrom::new(m, 0)?);
        train_opts.cascade.storage = Storage::projected_for(&train_opts.cascade.solver);
    }
    train_opts.cascade.set_seed(seed);
    Ok(train_opts)
}

/// The runs of the committed list, read from the Tyrex root `data` (each run's parts).
pub fn read_all_runs(data: &Path) -> Result<Vec<Sequence>> {
    let runs = read_run_list(&xtask::workspace_root().join(RUN_LIST))?;
    let mut seqs = Vec::new();
    for run in &runs {
        seqs.extend(read_folder(&run_folder(data, run)?)?.sequences);
    }
    Ok(seqs)
}

/// A run's folder, read as the protocols read it.
fn read_folder(dir: &Path) -> Result<tyrex::TyrexRead> {
    tyrex::read(dir, &TyrexOptions::default()).with_context(|| format!("reading {}", dir.display()))
}

/// The folder of `run` under the Tyrex root `data`; a run of the list must be there.
fn run_folder(data: &Path, run: &Run) -> Result<PathBuf> {
    let dir = data.join("datasets").join(&run.path);
    ensure!(
        dir.is_dir(),
        "{}: a run of {RUN_LIST} is missing from {}",
        run.path,
        data.display()
    );
    Ok(dir)
}

/// Runs the protocols and writes the report; returns its path.
pub fn run(opts: Options) -> Result<PathBuf> {
    let root = xtask::workspace_root();
    let out = opts
        .out
        .clone()
        .unwrap_or_else(|| root.join("docs/bench-devices.md"));
    let protocols: Vec<Protocol> = PROTOCOLS
        .into_iter()
        .filter(|p| opts.only.as_deref().is_none_or(|o| p.name.contains(o)))
        .collect();
    if protocols.is_empty() {
        let names: Vec<&str> = PROTOCOLS.iter().map(|p| p.name).collect();
        bail!(
            "no protocol's name contains {:?}; the protocols: {}",
            opts.only.unwrap_or_default(),
            names.join("; ")
        );
    }
    let runs = read_run_list(&root.join(RUN_LIST))?;
    let data = xtask::tyrex_root(opts.data.clone())?;
    let started = Instant::now();
    let needed = |r: &Run| {
        protocols
            .iter()
            .any(|p| p.train.holds(r) || p.test.holds(r))
    };
    // Each run also read with its OS orientation jumps bridged by the gyro: the same models
    // track both, which measures what bridging would gain (`bridged`, where a sequence has
    // jumps; the reader's default keeps them).
    let compare_jumps = opts.orientation == Orientation::Recorded;
    let bridging = TyrexOptions {
        bridge_orientation_jumps: true,
        ..TyrexOptions::default()
    };
    let (mut seqs, mut run_of_seq, mut bridged) = (Vec::new(), Vec::new(), Vec::new());
    for (i, run) in runs.iter().enumerate().filter(|(_, r)| needed(r)) {
        let dir = run_folder(&data, run)?;
        let read = read_folder(&dir)?;
        let other = if compare_jumps {
            tyrex::read(&dir, &bridging)?.sequences
        } else {
            Vec::new()
        };
        ensure!(
            other.is_empty() || other.len() == read.sequences.len(),
            "{}: bridging the orientation's jumps changed the parts",
            run.path
        );
        for (k, s) in read.sequences.into_iter().enumerate() {
            let b = other.get(k).filter(|b| b.orientation() != s.orientation());
            bridged.push(b.cloned());
            run_of_seq.push(i);
            seqs.push(s);
        }
    }
    let read_s = started.elapsed().as_secs_f64();
    eprintln!(
        "{} sequences of {} runs read in {read_s:.0} s",
        seqs.len(),
        runs.len()
    );
    apply_orientation(opts.orientation, opts.recorded_heading.as_ref(), &mut seqs)?;
    PlacementMap::tyrex4().apply(&mut seqs);
    for s in bridged.iter_mut().flatten() {
        PlacementMap::tyrex4().apply(std::slice::from_mut(s));
    }

    let train_opts = train_options(
        opts.step,
        opts.orientation,
        opts.landmarks,
        opts.grid,
        opts.seed,
    )?;
    let mut eval_opts = EvalOptions::default();
    eval_opts.track.recorded_heading = opts.recorded_heading;

    let mut tested: Vec<Vec<Tested>> = vec![Vec::new(); protocols.len()];
    let mut skipped: Vec<String> = Vec::new();
    let mut trainings: Vec<(RunSet, &str, usize, f64)> = Vec::new();
    let mut sets: Vec<RunSet> = protocols.iter().map(|p| p.train).collect();
    sets.sort_unstable();
    sets.dedup();
    for set in sets {
        for person in PEOPLE {
            let train: Vec<Sequence> = seqs
                .iter()
                .zip(&run_of_seq)
                .filter(|&(_, &r)| set.holds(&runs[r]) && runs[r].person != person)
                .map(|(s, _)| s.clone())
                .collect();
            let t0 = Instant::now();
            let model = ridi::train(&train, &train_opts, &mut NoProgress)
                .with_context(|| format!("training on {} without {person}", set.name()))?;
            let secs = t0.elapsed().as_secs_f64();
            eprintln!("  {}: trained without {person} in {secs:.0} s", set.name());
            trainings.push((set, person, train.len(), secs));
            for (p, rows) in protocols.iter().zip(&mut tested) {
                if p.train != set {
                    continue;
                }
                let (mut test, mut test_runs, mut with_bridges) =
                    (Vec::new(), Vec::new(), Vec::new());
                for ((s, &r), u) in seqs.iter().zip(&run_of_seq).zip(&bridged) {
                    if !(p.test.holds(&runs[r]) && runs[r].person == person) {
                        continue;
                    }
                    match check_evaluable(s, model.feature_config(), &eval_opts) {
                        Ok(()) => {
                            test.push(s.clone());
                            test_runs.push(r);
                            with_bridges.extend(u.clone());
                        }
                        Err(e) => skipped.push(format!("{}: {e}", p.name)),
                    }
                }
                if test.is_empty() {
                    continue;
                }
                let (report, traces) = ridi::evaluate(&test, &model, &eval_opts)?;
                let correction = eval_opts.track.correction_for(&model);
                let bridged_rte: BTreeMap<String, f64> = if with_bridges.is_empty() {
                    BTreeMap::new()
                } else {
                    let (r, _) = ridi::evaluate(&with_bridges, &model, &eval_opts)?;
                    r.sequences
                        .iter()
                        .map(|q| (q.name.clone(), (METRICS[RTE].of)(q)))
                        .collect()
                };
                let tracked = report.sequences.into_iter().zip(&traces).zip(&test);
                for (((result, trace), s), run) in tracked.zip(test_runs) {
                    let bridged_rte = bridged_rte
                        .get(&result.name)
                        .copied()
                        .unwrap_or_else(|| (METRICS[RTE].of)(&result));
                    // Reported for both phones only: the other protocols skip the work.
                    let swapped = |truth| swapped_rte(s, trace, correction, truth);
                    let swapped_rte = if p.name == BOTH_PHONES.name {
                        [
                            swapped(Truth::Speed)?,
                            swapped(Truth::Direction)?,
                            oracle_rte(
                                s,
                                model.feature_config(),
                                eval_opts.track.regress_every,
                                correction,
                            )?,
                        ]
                    } else {
                        [f64::NAN; 3]
                    };
                    rows.push(Tested {
                        run,
                        frames: s.len(),
                        result,
                        bridged_rte,
                        swapped_rte,
                    });
                }
            }
        }
    }
    skipped.sort();
    skipped.dedup();
    let figures: Vec<Vec<RunFigures>> = tested.iter().map(|t| per_run(t)).collect();
    let md = report(
        &Report {
            runs: &runs,
            protocols: &protocols,
            figures: &figures,
            trainings: &trainings,
            skipped: &skipped,
            opts: &opts,
            train_opts: &train_opts,
        },
        started.elapsed().as_secs_f64(),
    );
    write_atomically(&out, |w| w.write_all(md.as_bytes()))?;
    print!("{md}");
    Ok(out)
}

/// Everything the markdown report shows.
struct Report<'a> {
    runs: &'a [Run],
    protocols: &'a [Protocol],
    /// Per protocol, per run.
    figures: &'a [Vec<RunFigures>],
    /// Model set, test person, training sequences, seconds.
    trainings: &'a [(RunSet, &'a str, usize, f64)],
    skipped: &'a [String],
    opts: &'a Options,
    train_opts: &'a TrainOptions,
}

fn report(r: &Report<'_>, total_s: f64) -> String {
    let mut md = String::new();
    let o = r.opts;
    let mut command = "cargo xtask eval tyrex".to_string();
    if let Some(only) = &o.only {
        let _ = write!(command, " --only '{only}'");
    }
    if let Some(step) = o.step {
        let _ = write!(command, " --step {step}");
    }
    if o.orientation == Orientation::Estimated {
        command.push_str(" --orientation estimated");
        if o.recorded_heading.is_none() {
            command.push_str(" --heading gyro");
        }
    }
    if let Some(m) = o.landmarks {
        let _ = write!(command, " --landmarks {m}");
    }
    if o.grid {
        command.push_str(" --grid paper");
    }
    if o.seed != 0 {
        let _ = write!(command, " --seed {}", o.seed);
    }
    let _ = writeln!(
        md,
        "# Accuracy on unseen people and phones: the Tyrex runs\n"
    );
    let _ = writeln!(
        md,
        "Command: `{command}` ({:.0} min in all on a 2-core machine). The {} runs of `{RUN_LIST}` \
         ({} Nexus 5, {} of them near magnetic disturbance, and {} iPhone 4S; three people). \
         Every protocol leaves one person out: a model trained on two people's runs is tested on \
         the third person's, three folds. Training as `ridi train` does by default (one turned \
         copy of each window, the speed regressor, standardized features, 4 placement groups), \
         except: {}; sample step {} frames{}; orientation {}; {}. Tracking and evaluation as `ridi eval` does \
         by default (trajectories aligned on the first 10 s).\n",
        total_s / 60.0,
        r.runs.len(),
        r.runs.iter().filter(|x| x.phone == Phone::Nexus5).count(),
        r.runs.iter().filter(|x| x.disturbed).count(),
        r.runs.iter().filter(|x| x.phone == Phone::IPhone4S).count(),
        if o.grid {
            "C (and for the exact solver epsilon) chosen by the paper grid's cross-validation \
             over the training people's sequences"
        } else {
            "C = 10 and epsilon = 0.01 fixed instead of the paper grid's search"
        },
        r.train_opts.features.step,
        if o.step.is_some() {
            " (coarser than ridi train's 20: exact training on this many runs takes too long)"
        } else {
            ""
        },
        match o.orientation {
            Orientation::Recorded => "as recorded (Android rotation vector, Core Motion attitude)",
            Orientation::Estimated if o.recorded_heading.is_some() => {
                "estimated from gyro and accelerometer, its heading drift corrected by the \
                 recorded orientation's slow heading (`ridi track`'s default)"
            }
            Orientation::Estimated => {
                "estimated from gyro and accelerometer, its heading the gyro's alone \
                 (`ridi track --heading gyro`)"
            }
        },
        o.landmarks.map_or("the exact SMO solver".to_string(), |m| {
            // The projection the training used (`train_options`), as it was set.
            let kernel = match r.train_opts.cascade.storage {
                Storage::Projected { energy } => format!(
                    ", its kernel's distances from the principal coordinates holding {:.0} % of \
                     the variance",
                    energy * 100.0
                ),
                Storage::Half => String::new(),
            };
            format!("the Nyström solver on {m} landmarks{kernel}")
        }),
    );
    let _ = writeln!(
        md,
        "Each figure is a mean over runs (the parts of a run split at a gap are first averaged \
         into it, weighted by frames) with its 95 % bootstrap interval over runs ({} resamples). \
         PDR counts steps with the oracle step length (the true path length over the steps \
         counted); STILL stands still. RIDI - PDR is paired run by run: bold when its interval \
         leaves out 0.\n",
        bootstrap::DRAWS
    );
    let _ = writeln!(md, "## Per protocol\n\n{}", table_header("protocol"));
    let all = |k: usize| r.figures[k].iter().collect::<Vec<_>>();
    for (k, p) in r.protocols.iter().enumerate() {
        let _ = writeln!(md, "| {} | {}", p.name, cells(&all(k)));
    }
    goals(&mut md, r);
    across(&mut md, r);
    error_sources(&mut md, r);
    if let Some(k) = r.protocols.iter().position(|p| p.name == BOTH_PHONES.name) {
        let runs = all(k);
        let _ = writeln!(
            md,
            "\n## Both phones, per device and condition\n\n{}",
            table_header("device")
        );
        for (name, g) in &by_device_condition(r.runs, runs.iter().copied()) {
            let _ = writeln!(md, "| {name} | {}", cells(g));
        }
        let _ = writeln!(
            md,
            "\n## Both phones, per placement\n\n{}",
            table_header("placement")
        );
        let mut groups: BTreeMap<&str, Vec<&RunFigures>> = BTreeMap::new();
        for f in &runs {
            groups.entry(f.placement.as_str()).or_default().push(f);
        }
        for (name, g) in &groups {
            let _ = writeln!(md, "| {name} | {}", cells(g));
        }
        let _ = writeln!(
            md,
            "\n## Both phones, per run\n\n| run | placement | RTE 5 s (m) | PDR RTE 5 s (m) | \
             velocity MSE S-x / S-z | path length ratio | placement accuracy |\n| --- | --- | --- \
             | --- | --- | --- | --- |"
        );
        for f in &runs {
            let v = &f.values;
            let _ = writeln!(
                md,
                "| {} | {} | {:.3} | {:.3} | {:.3} / {:.3} | {:.3} | {:.3} |",
                r.runs[f.run].name,
                f.placement,
                v[RTE],
                v[PDR_RTE],
                v[MSE_X],
                v[MSE_Z],
                v[PATH_RATIO],
                v[PLACEMENT]
            );
        }
    }
    jumps(&mut md, r);
    let _ = writeln!(
        md,
        "\n## Training\n\n| model | without | sequences | seconds |\n| --- | --- | --- | --- |"
    );
    for (set, person, n, secs) in r.trainings {
        let _ = writeln!(md, "| {} | {person} | {n} | {secs:.0} |", set.name());
    }
    if !r.skipped.is_empty() {
        let _ = writeln!(md, "\n## Test sequences left out\n");
        for s in r.skipped {
            let _ = writeln!(md, "- {s}");
        }
    }
    md
}

/// `figures` by their run's device and condition ([`Run::device_condition`]), in name order.
fn by_device_condition<'f>(
    runs: &[Run],
    figures: impl IntoIterator<Item = &'f RunFigures>,
) -> BTreeMap<String, Vec<&'f RunFigures>> {
    let mut groups: BTreeMap<String, Vec<&RunFigures>> = BTreeMap::new();
    for f in figures {
        groups
            .entry(runs[f.run].device_condition())
            .or_default()
            .push(f);
    }
    groups
}

/// Both phones' RTE 5 s with each regressed velocity's speed, then its direction, then both
/// taken from the ground truth: which of the two the remaining error is, and the floor, over all
/// runs and per device.
fn error_sources(md: &mut String, r: &Report<'_>) {
    let Some(k) = r.protocols.iter().position(|p| p.name == BOTH_PHONES.name) else {
        return;
    };
    let _ = writeln!(
        md,
        "\n## Where RIDI's RTE 5 s comes from (both phones)\n\nThe same tracks with one half of \
         each regressed velocity replaced by the ground truth's (in S; the correction and the \
         evaluation unchanged): the true speed with the regressed direction, and the true \
         direction with the regressed speed, and the ground-truth velocity itself (the floor \
         the correction and the orientation leave). RTE 5 s (m), means over runs.\n\n| device \
         | runs | RIDI | true speed, regressed direction | true direction, regressed speed | \
         ground-truth velocity |\n| --- | --- | --- | --- | --- | --- |"
    );
    let all: Vec<&RunFigures> = r.figures[k].iter().collect();
    let groups = by_device_condition(r.runs, all.iter().copied());
    for (name, g) in std::iter::once(("all runs".to_string(), all)).chain(groups) {
        let _ = writeln!(
            md,
            "| {name} | {} | {} | {} | {} | {} |",
            g.len(),
            interval_cell(figure(&g, RTE), false),
            interval_cell(interval_of(&g, |f| f.swapped_rte[0]), false),
            interval_cell(interval_of(&g, |f| f.swapped_rte[1]), false),
            interval_cell(interval_of(&g, |f| f.swapped_rte[2]), false),
        );
    }
}

/// RTE 5 s of a model that never saw the test phone against the same people's model trained on
/// it, on the same runs: the loss `cross / same - 1` with its paired interval.
fn across(md: &mut String, r: &Report<'_>) {
    let pairs = cross_device(r);
    if pairs.is_empty() {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Across devices\n\nThe same test runs tracked by a model that never saw their \
         phone and by the same people's model trained on it. Loss: the ratio of the mean RTE \
         5 s minus 1, its interval from the same bootstrap over runs (paired), on the runs both \
         tested.{}\n\n| test runs | model | RTE 5 s (m) | same-device model | its RTE 5 s (m) | \
         loss [95 %] |\n| --- | --- | --- | --- | --- | --- |",
        if pairs.iter().any(|p| !p.goal) {
            " The controls (not goals) set a model that never saw the phone against one \
             trained on as many of that phone's runs, none recorded near magnetic disturbance: \
             the Nexus 5 model without disturbance on every Nexus 5 test run, and the 24-run \
             protocol's model on the undisturbed ones only, where the two models differ in the \
             phone alone."
        } else {
            ""
        }
    );
    for p in pairs {
        let loss = p.ratio.map(|i| Interval {
            mean: i.mean - 1.0,
            low: i.low - 1.0,
            high: i.high - 1.0,
        });
        let _ = writeln!(
            md,
            "| {} ({}) | {} | {} | {} | {} | {} |",
            r.protocols[p.same].test.name(),
            p.cross_rte.len(),
            r.protocols[p.cross].name,
            interval_cell(bootstrap::runs_interval(&p.cross_rte), false),
            r.protocols[p.same].name,
            interval_cell(bootstrap::runs_interval(&p.same_rte), false),
            interval_cell(loss, true),
        );
    }
}

/// One pair of [`ACROSS`] that the report ran: RIDI's RTE 5 s on the runs both protocols
/// tested, and the ratio of their means (cross / same) with its paired interval.
struct CrossDevice {
    cross: usize,
    same: usize,
    goal: bool,
    cross_rte: Vec<f64>,
    same_rte: Vec<f64>,
    ratio: Option<Interval>,
}

fn cross_device(r: &Report<'_>) -> Vec<CrossDevice> {
    let at = |name: &str| r.protocols.iter().position(|p| p.name == name);
    ACROSS
        .iter()
        .filter_map(|a| {
            let (cross, same) = (at(a.cross)?, at(a.same)?);
            let (cross_rte, same_rte) = paired(&r.figures[cross], &r.figures[same], RTE);
            let ratio = bootstrap::ratio_interval(&cross_rte, &same_rte);
            Some(CrossDevice {
                cross,
                same,
                goal: a.goal,
                cross_rte,
                same_rte,
                ratio,
            })
        })
        .collect()
}

/// Figure `k` of the runs two protocols both tested, in the same order.
fn paired(a: &[RunFigures], b: &[RunFigures], k: usize) -> (Vec<f64>, Vec<f64>) {
    a.iter()
        .filter_map(|x| {
            let y = b.iter().find(|y| y.run == x.run)?;
            (x.values[k].is_finite() && y.values[k].is_finite())
                .then_some((x.values[k], y.values[k]))
        })
        .unzip()
}

/// What bridging the OS orientation's jumps by the gyro would gain: RIDI's RTE 5 s on the runs
/// with jumps, as recorded (the reader's default) and bridged, tracked by the same models.
fn jumps(md: &mut String, r: &Report<'_>) {
    let Some(k) = r.protocols.iter().position(|p| p.name == BOTH_PHONES.name) else {
        return;
    };
    if r.opts.orientation != Orientation::Recorded {
        return;
    }
    let _ = writeln!(
        md,
        "\n## Orientation jumps: as recorded or bridged by the gyro\n\nBoth phones' protocol, \
         the runs where the OS orientation jumps (heading corrections and resets), tracked by the \
         same models from the orientation as recorded (the reader's default) and with its jumps \
         bridged by the gyro (`TyrexOptions::bridge_orientation_jumps`). RTE 5 s (m); the \
         difference is paired run by run.\n\n| runs | count | bridged | as recorded | bridged - \
         as recorded |\n| --- | --- | --- | --- | --- |"
    );
    let with_jumps: Vec<&RunFigures> = r.figures[k].iter().filter(|f| f.jumps).collect();
    let mut groups = by_device_condition(r.runs, with_jumps.iter().copied());
    if !with_jumps.is_empty() {
        groups.insert("all".into(), with_jumps);
    }
    for (name, g) in &groups {
        let raw: Vec<f64> = g.iter().map(|f| f.values[RTE]).collect();
        let bridged: Vec<f64> = g.iter().map(|f| f.bridged_rte).collect();
        let diff: Vec<f64> = bridged.iter().zip(&raw).map(|(a, b)| a - b).collect();
        let _ = writeln!(
            md,
            "| {name} | {} | {} | {} | {} |",
            g.len(),
            interval_cell(bootstrap::runs_interval(&bridged), false),
            interval_cell(bootstrap::runs_interval(&raw), false),
            interval_cell(bootstrap::runs_interval(&diff), true),
        );
    }
}

/// The every-phone issue's goals for ridi train's defaults, each with whether the figures meet it.
fn goals(md: &mut String, r: &Report<'_>) {
    let Some(k) = r.protocols.iter().position(|p| p.name == BOTH_PHONES.name) else {
        return;
    };
    let runs: Vec<&RunFigures> = r.figures[k].iter().collect();
    let mut lines = Vec::new();
    let verdict = |met: Option<bool>| match met {
        Some(true) => "met",
        Some(false) => "not met",
        None => "no figure",
    };
    let rte = figure(&runs, RTE);
    lines.push(format!(
        "RTE 5 s under 1.0 m: {} ({})",
        interval_cell(rte, false),
        verdict(rte.map(|i| i.mean < 1.0))
    ));
    let diff = ridi_minus_pdr(&runs);
    lines.push(format!(
        "better than PDR, the paired interval excluding 0: {} ({})",
        interval_cell(diff, true),
        verdict(diff.map(|i| i.high < 0.0))
    ));
    let ratio = figure(&runs, PATH_RATIO);
    lines.push(format!(
        "path length ratio 0.9-1.1: {} ({})",
        interval_cell(ratio, false),
        verdict(ratio.map(|i| (0.9..=1.1).contains(&i.mean)))
    ));
    for (label, k) in [("S-x", MSE_X), ("S-z", MSE_Z)] {
        let mse = figure(&runs, k);
        lines.push(format!(
            "velocity MSE {label} under 0.15: {} ({})",
            interval_cell(mse, false),
            verdict(mse.map(|i| i.mean < 0.15))
        ));
    }
    let acc = figure(&runs, PLACEMENT);
    lines.push(format!(
        "placement accuracy at least 0.95: {} ({})",
        interval_cell(acc, false),
        verdict(acc.map(|i| i.mean >= 0.95))
    ));
    let _ = writeln!(
        md,
        "\n## Goals (both phones; point estimates against the goal, intervals beside)\n"
    );
    for l in lines {
        let _ = writeln!(md, "- {l}");
    }
    for p in cross_device(r).into_iter().filter(|p| p.goal) {
        let loss = p.ratio;
        let _ = writeln!(
            md,
            "- {} loses at most 15 % RTE 5 s against {}: {} ({})",
            r.protocols[p.cross].name,
            r.protocols[p.same].name,
            loss.map_or("-".into(), |i| format!(
                "{:+.1} % [{:+.1}, {:+.1}]",
                100.0 * (i.mean - 1.0),
                100.0 * (i.low - 1.0),
                100.0 * (i.high - 1.0)
            )),
            verdict(loss.map(|i| i.mean <= 1.15))
        );
    }
}

/// One of RIDI's figures of a [`RunRow`].
type RunFigure = fn(&RunRow) -> f64;
/// Whether a run, by name, belongs to a group of runs.
type RunGroup = fn(&str) -> bool;

/// RIDI's figures of one run in a report's per-run table.
#[derive(Debug, Clone, Copy, PartialEq)]
struct RunRow {
    rte: f64,
    pdr: f64,
    mse: [f64; 2],
    ratio: f64,
    accuracy: f64,
}

/// The per-run table of both phones' protocol in a report [`report`] wrote, by run name.
fn per_run_table(md: &str) -> Result<BTreeMap<String, RunRow>> {
    let mut rows = BTreeMap::new();
    let mut inside = false;
    for (i, line) in md.lines().enumerate() {
        if line.starts_with("## ") {
            inside = line == "## Both phones, per run";
            continue;
        }
        if !inside
            || !line.starts_with("| ")
            || line.starts_with("| run ")
            || line.starts_with("| ---")
        {
            continue;
        }
        let cells: Vec<&str> = line.trim_matches('|').split('|').map(str::trim).collect();
        let number = |s: &str| {
            s.parse::<f64>()
                .with_context(|| format!("line {}: `{s}` is not a number", i + 1))
        };
        let [name, _, rte, pdr, mse, ratio, accuracy] = cells[..] else {
            bail!("line {}: expected 7 cells, found {}", i + 1, cells.len());
        };
        let (x, z) = mse
            .split_once('/')
            .with_context(|| format!("line {}: velocity MSE `{mse}`", i + 1))?;
        rows.insert(
            name.to_string(),
            RunRow {
                rte: number(rte)?,
                pdr: number(pdr)?,
                mse: [number(x.trim())?, number(z.trim())?],
                ratio: number(ratio)?,
                accuracy: number(accuracy)?,
            },
        );
    }
    ensure!(!rows.is_empty(), "no `## Both phones, per run` table");
    Ok(rows)
}

/// `cargo xtask eval compare`: RIDI's figures of two reports on the runs both tested, paired
/// run by run (`after - before`), per device and condition.
pub fn compare(before: &Path, after: &Path) -> Result<String> {
    let read = |p: &Path| -> Result<BTreeMap<String, RunRow>> {
        let text =
            std::fs::read_to_string(p).with_context(|| format!("reading {}", p.display()))?;
        per_run_table(&text).with_context(|| format!("in {}", p.display()))
    };
    let (a, b) = (read(before)?, read(after)?);
    let runs: Vec<(&String, &RunRow, &RunRow)> = a
        .iter()
        .filter_map(|(k, x)| Some((k, x, b.get(k)?)))
        .collect();
    ensure!(!runs.is_empty(), "the two reports share no run");
    let mut md = format!(
        "RIDI on the {} runs both reports tested: `{}` (before) and `{}` (after); means over \
         runs, the difference after - before paired run by run with its 95 % bootstrap \
         interval.\n\n| runs | count | figure | before | after | after - before |\n| --- | --- | \
         --- | --- | --- | --- |\n",
        runs.len(),
        before.display(),
        after.display()
    );
    let figures: [(&str, RunFigure); 6] = [
        ("RTE 5 s (m)", |r| r.rte),
        ("RIDI - PDR RTE 5 s (m)", |r| r.rte - r.pdr),
        ("path length ratio", |r| r.ratio),
        ("velocity MSE S-x", |r| r.mse[0]),
        ("velocity MSE S-z", |r| r.mse[1]),
        ("placement accuracy", |r| r.accuracy),
    ];
    let groups: [(&str, RunGroup); 4] = [
        ("all", |_| true),
        ("Nexus 5", |n| n.contains("_Nexus5_NoDist_")),
        ("Nexus 5 near disturbance", |n| n.contains("_Nexus5_Dist_")),
        ("iPhone 4S", |n| n.contains("_iPhone4S_")),
    ];
    for (group, holds) in groups {
        let g: Vec<_> = runs.iter().filter(|(n, _, _)| holds(n)).collect();
        if g.is_empty() {
            continue;
        }
        for (label, f) in figures {
            let x: Vec<f64> = g.iter().map(|(_, r, _)| f(r)).collect();
            let y: Vec<f64> = g.iter().map(|(_, _, r)| f(r)).collect();
            let d: Vec<f64> = x.iter().zip(&y).map(|(x, y)| y - x).collect();
            let _ = writeln!(
                md,
                "| {group} | {} | {label} | {} | {} | {} |",
                g.len(),
                interval_cell(bootstrap::runs_interval(&x), false),
                interval_cell(bootstrap::runs_interval(&y), false),
                interval_cell(bootstrap::runs_interval(&d), true),
            );
        }
    }
    Ok(md)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval_tyrex::tests::metrics_with_rte;

    /// A pair names its protocols: a typo would drop its row, and a goal's line, silently.
    #[test]
    fn every_pair_across_devices_names_two_protocols() {
        let names: Vec<&str> = PROTOCOLS.iter().map(|p| p.name).collect();
        let distinct: std::collections::BTreeSet<&str> = names.iter().copied().collect();
        assert_eq!(distinct.len(), names.len());
        for a in &ACROSS {
            assert!(
                names.contains(&a.cross) && names.contains(&a.same),
                "{}",
                a.cross
            );
        }
        assert_eq!(ACROSS.iter().filter(|a| a.goal).count(), 2);
    }

    #[test]
    fn the_committed_run_list_parses_and_spans_both_phones() {
        let runs = read_run_list(&xtask::workspace_root().join(RUN_LIST)).unwrap();
        assert_eq!(runs.len(), 66);
        let count = |set: RunSet| runs.iter().filter(|r| set.holds(r)).count();
        assert_eq!(count(RunSet::Nexus5), 42);
        assert_eq!(count(RunSet::IPhone4S), 24);
        assert_eq!(count(RunSet::Nexus5Undisturbed), 24);
        for person in PEOPLE {
            assert_eq!(runs.iter().filter(|r| r.person == person).count(), 22);
        }
    }

    #[test]
    fn run_list_errors_name_the_line() {
        let err = |text: &str| format!("{:#}", parse_run_list(text).unwrap_err());
        assert!(
            err("# c\nandroid/Jakob_Nexus5_NoDist_AR\nios/Jakob_Nexus5_NoDist_AR\n")
                .contains("line 3")
        );
        assert!(err("android/Jakob_Nexus5_Maybe_AR").contains("unknown condition"));
        assert!(err("android/Anna_Nexus5_NoDist_AR").contains("unknown person"));
        assert!(err("Jakob_Nexus5_NoDist_AR").contains("line 1"));
        assert!(
            err("android/Jakob_Nexus5_NoDist_AR\nandroid/Jakob_Nexus5_NoDist_AR").contains("twice")
        );
        assert!(err("# only a comment\n").contains("no run"));
    }

    fn result(name: &str, rte: f64, pdr: f64) -> SequenceResult {
        let metrics = metrics_with_rte;
        SequenceResult {
            name: name.into(),
            run: name.into(),
            placement: Some("hand".into()),
            device: None,
            path_length_m: 1.0,
            alignment_extent_m: 2.0,
            placement_accuracy: Some(1.0),
            velocity_mse: [0.1, 0.2],
            methods: [
                ("ridi".to_string(), metrics(rte)),
                ("pdr".to_string(), metrics(pdr)),
            ]
            .into_iter()
            .collect(),
        }
    }

    #[test]
    fn parts_are_averaged_into_their_run_by_frames() {
        let tested = vec![
            Tested {
                run: 3,
                frames: 100,
                result: result("A_part1", 1.0, 2.0),
                bridged_rte: 3.0,
                swapped_rte: [0.5, f64::NAN, 0.1],
            },
            Tested {
                run: 3,
                frames: 300,
                result: result("A_part2", 3.0, 2.0),
                bridged_rte: 3.0,
                swapped_rte: [1.5, 0.25, 0.1],
            },
            Tested {
                run: 1,
                frames: 50,
                result: result("B", 4.0, 1.0),
                bridged_rte: 4.0,
                swapped_rte: [2.0, 1.0, 0.3],
            },
        ];
        let runs = per_run(&tested);
        assert_eq!(runs.iter().map(|r| r.run).collect::<Vec<_>>(), [1, 3]);
        assert_eq!(runs[1].values[RTE], 2.5);
        assert_eq!(runs[1].values[PDR_RTE], 2.0);
        // A part tracked differently when bridged marks its run; (100 * 3 + 300 * 3) / 400.
        assert!(runs[1].jumps && !runs[0].jumps);
        assert_eq!((runs[1].bridged_rte, runs[0].bridged_rte), (3.0, 4.0));
        // The swapped figures average alike, (100 * 0.5 + 300 * 1.5) / 400; a part without one
        // leaves it to the others.
        assert_eq!(runs[1].swapped_rte, [1.25, 0.25, 0.1]);
        assert_eq!(runs[0].swapped_rte, [2.0, 1.0, 0.3]);
        // No RIDI-MAG in these results: the figure is missing, not zero.
        assert!(runs[0].values[7].is_nan());
        // Three copies of the two runs: enough runs for an interval (ridi_eval's
        // MIN_INTERVAL_RUNS), the same means.
        let all: Vec<&RunFigures> = runs.iter().cycle().take(6).collect();
        // Each run counts once: (4 + 2.5) / 2, and RIDI - PDR (3 + 0.5) / 2.
        assert_eq!(figure(&all, RTE).unwrap().mean, 3.25);
        assert_eq!(ridi_minus_pdr(&all).unwrap().mean, 1.75);
        assert_eq!(figure(&all, 7), None);
    }

    #[test]
    fn two_reports_compare_run_by_run() {
        let table = |rte: [f64; 5]| {
            format!(
                "# x\n\n## Both phones, per run\n\n| run | placement | RTE 5 s (m) | PDR RTE 5 s (m) | \
                 velocity MSE S-x / S-z | path length ratio | placement accuracy |\n| --- | --- | \
                 --- | --- | --- | --- | --- |\n\
                 | A_Nexus5_NoDist_AR | hand | {} | 2.0 | 0.1 / 0.2 | 0.9 | 1.0 |\n\
                 | B_iPhone4S_NoDist_AR | hand | {} | 2.0 | 0.1 / 0.2 | 0.9 | 1.0 |\n\
                 | C_Nexus5_Dist_AR | hand | {} | 2.0 | 0.1 / 0.2 | 0.9 | 1.0 |\n\
                 | D_Nexus5_NoDist_Texting | hand | {} | 2.0 | 0.1 / 0.2 | 0.9 | 1.0 |\n\
                 | E_iPhone4S_NoDist_Texting | hand | {} | 2.0 | 0.1 / 0.2 | 0.9 | 1.0 |\n\n\
                 ## Training\n\n| model | without |\n",
                rte[0], rte[1], rte[2], rte[3], rte[4]
            )
        };
        let rows = per_run_table(&table([1.0, 2.0, 3.0, 4.0, 5.0])).unwrap();
        assert_eq!(rows.len(), 5);
        assert_eq!(rows["B_iPhone4S_NoDist_AR"].mse, [0.1, 0.2]);
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.md"), dir.path().join("b.md"));
        std::fs::write(&a, table([1.0, 2.0, 3.0, 4.0, 5.0])).unwrap();
        std::fs::write(&b, table([1.5, 2.5, 3.5, 4.5, 5.5])).unwrap();
        let md = compare(&a, &b).unwrap();
        // Every run 0.5 m worse: resolved, whatever the resample.
        assert!(
            md.contains("| all | 5 | RTE 5 s (m) | 3.000 [")
                && md.contains("| **+0.500 [+0.500, +0.500]** |"),
            "{md}"
        );
        assert!(md.contains("| iPhone 4S | 2 | RTE 5 s (m) |"), "{md}");
        // A report without the table names the file.
        std::fs::write(&b, "# nothing\n").unwrap();
        let e = format!("{:#}", compare(&a, &b).unwrap_err());
        assert!(
            e.contains("b.md") && e.contains("no `## Both phones, per run` table"),
            "{e}"
        );
    }

    #[test]
    fn paired_figures_keep_only_runs_both_tested() {
        let f = |run, rte| RunFigures {
            run,
            placement: "hand".into(),
            bridged_rte: rte,
            swapped_rte: [rte; 3],
            jumps: false,
            values: {
                let mut v = [0.0; METRICS.len()];
                v[RTE] = rte;
                v
            },
        };
        let (a, b) = paired(&[f(1, 2.0), f(2, 3.0)], &[f(2, 1.5), f(5, 9.0)], RTE);
        assert_eq!((a, b), (vec![3.0], vec![1.5]));
    }
}
