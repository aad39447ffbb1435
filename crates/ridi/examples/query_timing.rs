//! Prediction speed of a trained model on real recordings, and what its sample storage
//! changes: the "Prediction" figures of docs/benchmarks.md.
//!
//! ```text
//! cargo run --release -p ridi --example query_timing -- MODEL --train LIST... --test LIST...
//! ```
//!
//! `--train` lists the recordings the model was trained on (their windows are matched against
//! the stored samples by [`Cascade::rounding_effect`]); the windows of the `--test` recordings
//! are the queries, at the training schedule. One-query times are per call of
//! [`Cascade::predict_one`] on one thread, over the queries in recording order (consecutive
//! queries share a placement, as when tracking) and shuffled (the placement changes at
//! random, so the stored samples of every placement compete for the caches).

use std::path::PathBuf;
use std::time::Instant;

use ridi::data::{Listed, ReadOptions};
use ridi::features::FeatureMatrixRef;
use ridi::regress::Cascade;

#[path = "../../ridi-regress/examples/common/timing.rs"]
mod timing;

use timing::time_one;

type Error = Box<dyn std::error::Error>;

/// Standardized features of the recordings in `lists`, as the model computes them.
fn features(model: &Cascade, lists: &[PathBuf]) -> Result<Vec<f32>, Error> {
    let mut seqs = Vec::new();
    for l in lists {
        seqs.extend(Listed::read(&[l], &ReadOptions::default())?.into_sequences());
    }
    let config = model.feature_config();
    let mut data = ridi::training_data(&seqs, config)?;
    if let Some(s) = &config.standardization {
        s.apply(&mut data.features)?;
    }
    Ok(data.features.as_slice().to_vec())
}

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let model_path = args
        .first()
        .ok_or("usage: query_timing MODEL --train LIST... --test LIST...")?;
    let mut lists: [Vec<PathBuf>; 2] = [Vec::new(), Vec::new()];
    let mut which = None;
    for a in &args[1..] {
        match a.as_str() {
            "--train" => which = Some(0),
            "--test" => which = Some(1),
            _ => lists[which.ok_or("lists follow --train or --test")?].push(a.into()),
        }
    }
    let model = Cascade::load(model_path)?;
    let bytes = std::fs::metadata(model_path)?.len();
    println!(
        "{model_path}: {:.1} MB, {:?}, stored samples {:?}",
        bytes as f64 / 1e6,
        model.stored_as(),
        (0..model.placement_names().len())
            .map(|p| model.stored_samples(p))
            .collect::<Vec<_>>()
    );
    let dim = model.dim();
    let test = features(&model, &lists[1])?;
    let q = FeatureMatrixRef::new(&test, dim)?;
    let n = q.rows();
    let stream: Vec<usize> = (0..n).collect();
    let shuffled = timing::shuffled(n);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let (warm, cold, batch1) = one.install(|| -> Result<_, String> {
        let ms = |(wall, cpu): (f64, f64)| (wall * 1e3, cpu * 1e3);
        time_one(&model, q, &stream[..n.min(500)])?;
        let warm = ms(time_one(&model, q, &stream)?);
        let cold = ms(time_one(&model, q, &shuffled)?);
        let t = Instant::now();
        model.predict(q).map_err(|e| e.to_string())?;
        Ok((warm, cold, t.elapsed().as_secs_f64()))
    })?;
    let t = Instant::now();
    model.predict(q)?;
    let batch = t.elapsed().as_secs_f64();
    println!(
        "{n} queries, predict_one on one thread: recording order {:.3} ms wall / {:.3} ms CPU, \
         shuffled {:.3} ms wall / {:.3} ms CPU",
        warm.0, warm.1, cold.0, cold.1
    );
    println!(
        "predict (batched): one thread {:.0} queries/s, {} threads {:.0} queries/s",
        n as f64 / batch1,
        rayon::current_num_threads(),
        n as f64 / batch
    );
    println!(
        "peak RSS {:.0} MB (model, the {n} queries' features and the recordings they came from)",
        timing::peak_mb()
    );
    if !lists[0].is_empty() {
        let train = features(&model, &lists[0])?;
        let r = model.rounding_effect(FeatureMatrixRef::new(&train, dim)?, q)?;
        println!("storage vs exact f32 samples: {r}");
    }
    Ok(())
}
