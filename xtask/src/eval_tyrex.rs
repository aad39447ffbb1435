//! `cargo xtask eval-tyrex`: the accuracy protocol of ridi-rs on the 24 Tyrex Nexus 5 runs.
//!
//! Leave one subject out: train on two people, test on the third, three folds, so every run
//! is tested once by a model that never saw its person. Runs split at long mocap or sensor gaps
//! count as several test sequences; figures are means over all test sequences. Each variant
//! changes one thing against the reference (4 placement groups, standardized features, gamma
//! 1/1200, C = 10, epsilon = 0.01, the Android rotation vector as orientation, start at rest).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use ridi::baselines::{Method, trajectory};
use ridi::correct::InitialVelocity;
use ridi::data::tyrex::{self, TyrexOptions};
use ridi::data::{OrientationSource, Sequence, write_atomically};
use ridi::eval::{EvalConfig, evaluate_trajectory};
use ridi::features::{SampleSchedule, compute_targets};
use ridi::frames::{FilterConfig, STANDARD_GRAVITY, estimate_orientation, gravity_in_device};
use ridi::regress::{Gamma, NoProgress};
use ridi::track::Regressed;
use ridi::train::ground_truth_view;
use ridi::{EvalOptions, GridChoice, PlacementMap, TrackOptions, TrainOptions};

const PEOPLE: [&str; 3] = ["Guillaume", "Jakob", "Thibaud"];

/// One configuration of the protocol.
#[derive(Debug, Clone)]
struct Variant {
    name: &'static str,
    groups: bool,
    standardize: bool,
    gamma: Gamma,
    estimate_v0: bool,
    estimated_orientation: bool,
}

const REFERENCE: Variant = Variant {
    name: "reference: 4 groups",
    groups: true,
    standardize: true,
    gamma: Gamma::InverseDim,
    estimate_v0: false,
    estimated_orientation: false,
};

fn variants(quick: bool) -> Vec<Variant> {
    let mut v = vec![REFERENCE];
    if quick {
        return v;
    }
    v.extend([
        Variant {
            name: "8 motion names",
            groups: false,
            ..REFERENCE
        },
        Variant {
            name: "raw features (no standardization)",
            standardize: false,
            ..REFERENCE
        },
        Variant {
            name: "gamma 4/1200",
            gamma: Gamma::Value(4.0 / 1200.0),
            ..REFERENCE
        },
        Variant {
            name: "initial velocity estimated",
            estimate_v0: true,
            ..REFERENCE
        },
        Variant {
            name: "orientation from gyro + accelerometer",
            estimated_orientation: true,
            ..REFERENCE
        },
    ]);
    v
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
    train_s: f64,
}

fn with_estimated_orientation(seq: &Sequence) -> Result<Sequence> {
    let q = estimate_orientation(seq.time(), seq.gyro(), seq.acce(), &FilterConfig::default())?;
    let mut p = seq.clone().into_parts();
    p.gravity = q
        .iter()
        .map(|&q| gravity_in_device(q, STANDARD_GRAVITY))
        .collect();
    p.linacce = p
        .acce
        .iter()
        .zip(&p.gravity)
        .map(|(&a, &g)| a - g)
        .collect();
    p.orientation = q;
    p.orientation_source = Some(OrientationSource::Estimated);
    Ok(Sequence::new(p)?)
}

fn load(data: &Path) -> Result<Vec<Sequence>> {
    let mut seqs = Vec::new();
    for dir in tyrex::list_sequences(data)? {
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

/// RTE 5 s of the correction driven by ground-truth velocities: the floor the orientation sets.
fn oracle_rte(seq: &Sequence, opts: &EvalOptions) -> Result<f64> {
    let config = ridi::features::FeatureConfig::default();
    let frames = SampleSchedule::every(&config, opts.track.regress_every)?.frames(seq.len());
    let targets = compute_targets(&ground_truth_view(seq)?, &config, &frames)?;
    let regs: Vec<Regressed> = frames
        .iter()
        .zip(&targets.values)
        .map(|(&frame, v)| Regressed {
            frame,
            placement: 0,
            velocity: *v,
        })
        .collect();
    let est = trajectory(Method::Ridi, seq, &regs, opts.track.correction)?;
    let gt = seq.ground_truth().context("no ground truth")?.horizontal();
    Ok(
        evaluate_trajectory(seq.time(), &est, &gt, &EvalConfig::default())?
            .metrics
            .rte_5s_m,
    )
}

fn run_variant(all: &[Sequence], v: &Variant) -> Result<Row> {
    let mut seqs: Vec<Sequence> = if v.estimated_orientation {
        all.iter()
            .map(with_estimated_orientation)
            .collect::<Result<_>>()?
    } else {
        all.to_vec()
    };
    if v.groups {
        PlacementMap::tyrex_groups().apply(&mut seqs);
    }
    let mut train_opts = TrainOptions {
        standardize: v.standardize,
        ..TrainOptions::default()
    };
    train_opts.cascade.regressors = GridChoice::None.regressors();
    train_opts.cascade.classifier_gamma = v.gamma;
    train_opts.cascade.regressor_gamma = v.gamma;
    let mut eval_opts = EvalOptions {
        track: TrackOptions::default(),
        ..EvalOptions::default()
    };
    if v.estimate_v0 {
        eval_opts.track.correction.initial_velocity = InitialVelocity::Estimate;
    }
    let mut results = Vec::new();
    let mut oracle = Vec::new();
    let mut train_s = 0.0;
    for test_person in PEOPLE {
        let (test, train): (Vec<Sequence>, Vec<Sequence>) =
            seqs.iter().cloned().partition(|s| person(s) == test_person);
        let t = Instant::now();
        let model = ridi::train(&train, &train_opts, &mut NoProgress)?;
        train_s += t.elapsed().as_secs_f64();
        let (report, _) = ridi::evaluate(&test, &model, &eval_opts)?;
        results.extend(report.sequences);
        for s in &test {
            oracle.push(oracle_rte(s, &eval_opts)?);
        }
        eprintln!("  {}: fold {test_person} done", v.name);
    }
    let n = results.len() as f64;
    let mean =
        |f: &dyn Fn(&ridi::evaluate::SequenceResult) -> f64| results.iter().map(f).sum::<f64>() / n;
    let per_method = |f: fn(&ridi::eval::TrajectoryMetrics) -> f64| {
        Method::ALL
            .iter()
            .map(|m| {
                let vals: Vec<f64> = results.iter().map(|r| f(&r.methods[m.key()])).collect();
                (
                    m.key().to_string(),
                    vals.iter().sum::<f64>() / vals.len() as f64,
                )
            })
            .collect::<Vec<_>>()
    };
    Ok(Row {
        sequences: results.len(),
        velocity_mse: [mean(&|r| r.velocity_mse[0]), mean(&|r| r.velocity_mse[1])],
        placement_accuracy: mean(&|r| r.placement_accuracy.unwrap_or(0.0)),
        rte_5s: per_method(|m| m.rte_5s_m),
        ate: per_method(|m| m.ate_m),
        path_ratio: per_method(|m| m.path_length_ratio.unwrap_or(f64::NAN)),
        oracle_rte_5s: oracle.iter().sum::<f64>() / oracle.len() as f64,
        train_s,
    })
}

fn get(v: &[(String, f64)], key: &str) -> f64 {
    v.iter()
        .find(|(k, _)| k == key)
        .map_or(f64::NAN, |(_, x)| *x)
}

/// Runs the protocol and writes the markdown report; returns its path.
pub fn run(data: Option<PathBuf>, out: Option<PathBuf>, quick: bool) -> Result<PathBuf> {
    let root = xtask::workspace_root();
    let data = data.unwrap_or_else(|| root.join("../shared/data/raw/tyrex-attitude-smartphones"));
    let out = out.unwrap_or_else(|| root.join("docs/bench-accuracy.md"));
    let started = Instant::now();
    let all = load(&data).with_context(|| format!("reading Tyrex data in {}", data.display()))?;
    let mut rows = Vec::new();
    for v in variants(quick) {
        let row = run_variant(&all, &v)?;
        rows.push((v, row));
    }
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Accuracy: leave-one-subject-out on the Tyrex Nexus 5 runs\n"
    );
    let _ = writeln!(
        md,
        "Command: `cargo xtask eval-tyrex{}` ({:.0} s in all on a 2-core machine shared with other work). \
         {} test sequences (24 runs; runs split at long mocap or sensor gaps count once per part). \
         Train on two people, test on the third, three folds; C = 10, epsilon = 0.01, no grid search; \
         trajectories aligned on the first 10 s; means over test sequences.\n",
        if quick { " --quick" } else { "" },
        started.elapsed().as_secs_f64(),
        rows.first().map_or(0, |r| r.1.sequences)
    );
    let _ = writeln!(md, "## RIDI per variant\n");
    let _ = writeln!(
        md,
        "| variant | velocity MSE S-x / S-z (m/s)^2 | RTE 5 s (m) | ATE (m) | path length ratio | placement accuracy | GT-velocity floor RTE 5 s (m) | training (s, 3 folds) |\n| --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    for (v, r) in &rows {
        let _ = writeln!(
            md,
            "| {} | {:.3} / {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.1} |",
            v.name,
            r.velocity_mse[0],
            r.velocity_mse[1],
            get(&r.rte_5s, "ridi"),
            get(&r.ate, "ridi"),
            get(&r.path_ratio, "ridi"),
            r.placement_accuracy,
            r.oracle_rte_5s,
            r.train_s
        );
    }
    if let Some((v, r)) = rows.first() {
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
    write_atomically(&out, |w| w.write_all(md.as_bytes()))?;
    print!("{md}");
    Ok(out)
}
