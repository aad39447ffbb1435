//! Streaming speed of `LiveTracker` with a model: frames per second and the
//! latency of one `push`, those that ran a regression apart (on the calling thread, which runs
//! the regressions and corrections): the "Streaming" figures of
//! docs/benchmarks.md.
//!
//! ```text
//! cargo run --release -p ridi --example live_timing -- [MODEL] [--seq RECORDING] [--repeat N]
//! ```
//!
//! Without MODEL, the bundled model. The recording (default: a 24-s run of the bundled sample)
//! is streamed sample by sample N times (default 20), a fresh tracker each time, as
//! `ridi track --online` streams it.

use std::path::PathBuf;
use std::time::Instant;

use ridi::data::{ReadOptions, read_sequence};
use ridi::regress::Cascade;
use ridi::{LiveTracker, SensorReading, TrackOptions};

type Error = Box<dyn std::error::Error>;

fn percentile(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let seq_path = value("--seq").map_or_else(
        || root.join("datasets/sample/Thibaud_Nexus5_NoDist_Texting"),
        PathBuf::from,
    );
    let repeat: usize = value("--repeat").map_or(Ok(20), |v| v.parse())?;
    let model_path = args
        .first()
        .filter(|a| !a.starts_with("--"))
        .map(PathBuf::from);
    let model = match &model_path {
        Some(p) => Cascade::load(p)?,
        None => ridi::bundled_model()?,
    };
    // The recording as read: the live tracker estimates the orientation a model on the
    // estimated one needs, its heading corrected by the recorded one, as `ridi track
    // --online` of a streamed recording does.
    let seq = read_sequence(&seq_path, &ReadOptions::default())?;
    let readings: Vec<SensorReading> = (0..seq.len())
        .map(|i| SensorReading::of_frame(&seq, i))
        .collect();
    let opts = TrackOptions {
        online: true,
        ..TrackOptions::default()
    };
    // The tracker's regressions and corrections run on the calling thread.
    let (mut with, mut without, total) = (|| -> Result<_, Error> {
        let (mut with, mut without) = (Vec::new(), Vec::new());
        let mut updates = Vec::new();
        let started = Instant::now();
        for _ in 0..repeat {
            let mut live = LiveTracker::new(&model, &opts)?;
            for r in &readings {
                let before = live.regressions().0.len();
                updates.clear();
                let t = Instant::now();
                live.push(r, &mut updates)?;
                let dt = t.elapsed().as_secs_f64() * 1e3;
                if live.regressions().0.len() > before {
                    with.push(dt);
                } else {
                    without.push(dt);
                }
            }
            live.finish(&mut updates)?;
        }
        Ok((with, without, started.elapsed().as_secs_f64()))
    })()?;
    with.sort_by(f64::total_cmp);
    without.sort_by(f64::total_cmp);
    let frames = repeat * readings.len();
    println!(
        "{}: {} frames x {repeat} on the calling thread: {:.0} frames/s",
        model_path.map_or("the bundled model".into(), |p| p.display().to_string()),
        readings.len(),
        frames as f64 / total
    );
    println!(
        "push with a regression ({}): p50 {:.3} ms, p99 {:.3} ms; without ({}): p50 {:.4} ms, \
         p99 {:.4} ms",
        with.len(),
        percentile(&with, 0.5),
        percentile(&with, 0.99),
        without.len(),
        percentile(&without, 0.5),
        percentile(&without, 0.99)
    );
    Ok(())
}
