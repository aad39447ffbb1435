//! `cargo xtask model`: rebuilds the model bundled in the `ridi` crate
//! (`crates/ridi/model/ridi-tyrex.ridi`, [`ridi::bundled_model`]) from every run of the
//! committed Tyrex list: both phones, all three people, trained as the device protocols train
//! (`cargo xtask eval tyrex`, whose leave-one-person-out figures are the model card's) with
//! the Nyström solver. A test in the `ridi` crate loads the file, so a change of the model
//! format cannot leave it stale: rerun this task.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use ridi::features::Orientation;
use ridi::regress::ProgressEvent;
use ridi::{PlacementMap, apply_orientation};

use crate::eval_devices::{read_all_runs, train_options};

/// Where the bundled model lives, relative to the workspace root.
pub const MODEL_PATH: &str = "crates/ridi/model/ridi-tyrex.ridi";

/// Landmarks per machine of the bundled model: the solver's default.
pub const LANDMARKS: usize = ridi::regress::Nystrom::DEFAULT_LANDMARKS;

/// Sample step of the bundled model's training windows: `ridi train`'s.
const STEP: Option<usize> = None;

/// Trains and writes the bundled model (or to `out`); returns its path.
pub fn run(data: Option<PathBuf>, out: Option<PathBuf>) -> Result<PathBuf> {
    let out = out.unwrap_or_else(|| xtask::workspace_root().join(MODEL_PATH));
    let data = xtask::tyrex_root(data)?;
    let started = Instant::now();
    let mut seqs = read_all_runs(&data)?;
    let orientation = Orientation::Estimated;
    // Training does not see the heading (features and targets live in S).
    apply_orientation(orientation, None, &mut seqs)?;
    PlacementMap::tyrex4().apply(&mut seqs);
    eprintln!(
        "{} sequences read in {:.0} s",
        seqs.len(),
        started.elapsed().as_secs_f64()
    );
    // C fixed as the protocol fixes it: its search did not change a figure beyond its
    // interval there (docs/benchmarks.md).
    let opts = train_options(STEP, orientation, Some(LANDMARKS), false, 0)?;
    let t0 = Instant::now();
    let mut progress = |e: &ProgressEvent<'_>| {
        if e.done == e.total {
            eprintln!("  {:?}: {} of {}", e.stage, e.done, e.total);
        }
        true
    };
    let model = ridi::train(&seqs, &opts, &mut progress).context("training the bundled model")?;
    let train_s = t0.elapsed().as_secs_f64();
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    model
        .save(&out)
        .with_context(|| format!("writing {}", out.display()))?;
    let bytes = std::fs::metadata(&out)?.len();
    eprintln!(
        "trained on {} sequences in {train_s:.0} s; {} bytes",
        seqs.len(),
        bytes
    );
    Ok(out)
}
