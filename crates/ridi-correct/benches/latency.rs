//! Custom harness: latency distribution of streaming updates, one-hour stream throughput and
//! peak memory, banded vs dense solve.
//!
//! `cargo bench -p ridi-correct --bench latency`

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use ridi_correct::{
    CorrectionConfig, CorrectionOutcome, Corrector, FrameWindow, RegressorError, RegressorOutput,
    Tracker, TrackerConfig, VelocityRegressor, solve_dense,
};
use ridi_frames::{ImuSample, WorldVec};

/// Replays a lap's exact velocities (frame modulo lap length): a regression costs nothing,
/// so the measurements isolate integration and correction.
struct Replay {
    velocity: Vec<ridi_frames::StabHorizontal>,
}

impl VelocityRegressor for Replay {
    fn window_len(&self) -> usize {
        200
    }
    fn regress(
        &mut self,
        frames: &FrameWindow<'_>,
    ) -> Result<Option<RegressorOutput>, RegressorError> {
        let f = frames.last_frame() as usize % self.velocity.len();
        Ok(Some(RegressorOutput {
            velocity: self.velocity[f],
            placement: None,
        }))
    }
}

fn vm_hwm_kib() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// On-CPU time of this thread (user + system), seconds, at the kernel's tick resolution
/// (10 ms): only meaningful over batches of a second or more. The machine is shared, so
/// wall-clock figures include time spent waiting for a core; CPU time does not.
fn thread_cpu_seconds() -> f64 {
    let s = std::fs::read_to_string("/proc/thread-self/stat").unwrap_or_default();
    let after = s.rsplit_once(')').map_or("", |(_, r)| r);
    let fields: Vec<&str> = after.split_whitespace().collect();
    // Fields 14 and 15 of stat(5), counted from the state (field 3) at index 0.
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}

/// Mean wall and CPU seconds of `f` over `reps` runs.
fn timed(reps: usize, mut f: impl FnMut()) -> (f64, f64) {
    let c0 = thread_cpu_seconds();
    let t0 = Instant::now();
    for _ in 0..reps {
        f();
    }
    (
        t0.elapsed().as_secs_f64() / reps as f64,
        (thread_cpu_seconds() - c0) / reps as f64,
    )
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i]
}

fn main() {
    // One-minute lap, replayed on a continuous clock.
    let lap = common::walk(12_000, 50, WorldVec::ZERO, true);
    let imu = lap.imu();
    let lap_samples: Vec<ImuSample> = (0..imu.len()).map(|f| imu.sample(f)).collect();
    let regressor = || Replay {
        velocity: (0..lap.time.len())
            .map(|f| lap.target(f).velocity)
            .collect(),
    };
    let lap_len = lap.time.len();
    let sample_at = |k: usize| {
        let mut s = lap_samples[k % lap_len];
        s.time = k as f64 * 0.005;
        s
    };

    // Latency of updates: plain frames and frames that solve and apply a window.
    for background in [false, true] {
        let config = TrackerConfig {
            background,
            apply_delay: if background { 50 } else { 0 },
            ..Default::default()
        };
        let mut tracker = Tracker::new(config, regressor()).unwrap();
        let mut correcting = Vec::new();
        let mut plain = Vec::new();
        for k in 0..120_000 {
            let s = sample_at(k);
            let t0 = Instant::now();
            let u = tracker.push(&s).unwrap();
            let dt = t0.elapsed().as_secs_f64() * 1e3;
            // Steady state only: the first windows are shorter (new shapes, new symbolic
            // factorizations).
            if k < 1200 {
                continue;
            }
            match u.correction {
                Some(CorrectionOutcome::Applied(_)) | Some(CorrectionOutcome::Submitted) => {
                    correcting.push(dt)
                }
                _ => plain.push(dt),
            }
        }
        correcting.sort_by(f64::total_cmp);
        plain.sort_by(f64::total_cmp);
        let mode = if background {
            "background, delay 50"
        } else {
            "inline"
        };
        println!(
            "update latency ({mode}), 10 min stream: correcting frames n={} p50={:.4} ms p99={:.4} ms max={:.4} ms; other frames p50={:.5} ms p99={:.5} ms",
            correcting.len(),
            percentile(&correcting, 0.5),
            percentile(&correcting, 0.99),
            correcting.last().unwrap(),
            percentile(&plain, 0.5),
            percentile(&plain, 0.99),
        );
    }

    // One-hour stream: throughput and peak memory (VmHWM after 10 and after 60 minutes).
    for background in [false, true] {
        let config = TrackerConfig {
            background,
            apply_delay: if background { 50 } else { 0 },
            ..Default::default()
        };
        let mut tracker = Tracker::new(config, regressor()).unwrap();
        let n = 200 * 3600;
        let c0 = thread_cpu_seconds();
        let t0 = Instant::now();
        let mut hwm_10min = None;
        let mut last = None;
        for k in 0..n {
            last = Some(tracker.push(&sample_at(k)).unwrap().pose);
            if k == 120_000 {
                hwm_10min = vm_hwm_kib();
            }
        }
        let secs = t0.elapsed().as_secs_f64();
        let cpu = thread_cpu_seconds() - c0;
        let st = tracker.stats();
        println!(
            "one-hour stream ({}): {n} frames in {secs:.3} s wall = {:.2} M frames/s (calling thread CPU {cpu:.2} s = {:.2} M frames/s); corrections {}, regressions {}; VmHWM after 10 min {:?} KiB, after 60 min {:?} KiB; buffered frames {}; final position {:?}",
            if background { "background" } else { "inline" },
            n as f64 / secs / 1e6,
            n as f64 / cpu / 1e6,
            st.corrections,
            st.regressions,
            hwm_10min,
            vm_hwm_kib(),
            tracker.buffered_frames(),
            last.map(|p| p.position),
        );
    }

    // Global pass over ten minutes (120,000 frames, 2,401 knots, 2,399 targets), warm.
    let ten = common::walk(120_000, 50, WorldVec::ZERO, true);
    let config = CorrectionConfig::default();
    let targets = ten.targets(50, 50);
    let mut corrector = Corrector::new(config).unwrap();
    corrector.solve(&ten.imu(), &targets).unwrap();
    let (wall, cpu) = timed(300, || {
        std::hint::black_box(corrector.solve(&ten.imu(), &targets).unwrap());
    });
    println!(
        "10-minute global solve: wall {:.3} ms, CPU {:.3} ms (mean of 300)",
        wall * 1e3,
        cpu * 1e3
    );
    let (wall, cpu) = timed(100, || {
        std::hint::black_box(corrector.correct(&ten.imu(), &targets).unwrap());
    });
    println!(
        "10-minute global solve + integration: wall {:.3} ms, CPU {:.3} ms (mean of 100)",
        wall * 1e3,
        cpu * 1e3
    );

    // One streaming window (1,000 frames, 20 targets), warm.
    let imu = ten.imu().slice(0..1000);
    let wt: Vec<_> = targets.iter().copied().filter(|t| t.frame < 1000).collect();
    corrector.solve(&imu, &wt).unwrap();
    let (wall, cpu) = timed(20_000, || {
        std::hint::black_box(corrector.solve(&imu, &wt).unwrap());
    });
    println!(
        "1000-frame window solve: wall {:.4} ms, CPU {:.4} ms (mean of 20,000)",
        wall * 1e3,
        cpu * 1e3
    );
    let mut per = Vec::with_capacity(20_000);
    for _ in 0..20_000 {
        let t0 = Instant::now();
        std::hint::black_box(corrector.solve(&imu, &wt).unwrap());
        per.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    per.sort_by(f64::total_cmp);
    println!(
        "1000-frame window solve, wall per call: p50 {:.4} ms, p99 {:.4} ms, p99.9 {:.4} ms",
        percentile(&per, 0.5),
        percentile(&per, 0.99),
        percentile(&per, 0.999)
    );

    // Banded vs dense on one minute (the dense solve's practical limit).
    let config = CorrectionConfig::default();
    let targets = lap.targets(50, 50);
    let mut corrector = Corrector::new(config).unwrap();
    corrector.solve(&lap.imu(), &targets).unwrap();
    let (bw, bc) = timed(1000, || {
        std::hint::black_box(corrector.solve(&lap.imu(), &targets).unwrap());
    });
    let (dw, dc) = timed(10, || {
        std::hint::black_box(solve_dense(&config, &lap.imu(), &targets).unwrap());
    });
    println!(
        "1-minute solve (241 knots, 239 targets): banded wall {:.3} ms / CPU {:.3} ms, dense wall {:.1} ms / CPU {:.1} ms, ratio (CPU) {:.0}x",
        bw * 1e3,
        bc * 1e3,
        dw * 1e3,
        dc * 1e3,
        dc / bc
    );
}
