//! Criterion benchmarks of the correction solve.
//!
//! `cargo bench -p ridi-correct --bench correct`
//!
//! - `global/10min`: batch solve over 120,000 frames (2,401 knots, 2,400 targets) with a
//!   warm corrector (symbolic factorization cached), and the full corrected trajectory;
//! - `window/1000`: one streaming update's solve (1,000 frames, 20 targets);
//! - `dense_vs_banded/1min`: the dense reference against the banded solve on 12,000 frames,
//!   the largest size the dense solve handles in reasonable time.

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use ridi_correct::{CorrectionConfig, Corrector, InitialVelocity, solve_dense};
use ridi_frames::WorldVec;

fn bench(c: &mut Criterion) {
    let config = CorrectionConfig::default();

    let w = common::walk(120_000, 50, WorldVec::ZERO, true);
    let targets = w.targets(50, 50);
    let mut corrector = Corrector::new(config).unwrap();
    corrector.solve(&w.imu(), &targets).unwrap();
    let mut g = c.benchmark_group("global");
    g.sample_size(20).measurement_time(Duration::from_secs(4));
    g.bench_function("10min/solve", |b| {
        b.iter(|| {
            corrector
                .solve(black_box(&w.imu()), black_box(&targets))
                .unwrap()
        })
    });
    g.bench_function("10min/solve+integrate", |b| {
        b.iter(|| {
            corrector
                .correct(black_box(&w.imu()), black_box(&targets))
                .unwrap()
        })
    });
    g.finish();

    let imu = w.imu().slice(0..1000);
    let window_targets: Vec<_> = targets.iter().copied().filter(|t| t.frame < 1000).collect();
    let mut g = c.benchmark_group("window");
    g.sample_size(50).measurement_time(Duration::from_secs(3));
    g.bench_function("1000/solve", |b| {
        b.iter(|| {
            corrector
                .solve_from(
                    black_box(&imu),
                    black_box(&window_targets),
                    InitialVelocity::Fixed(WorldVec::new(0.5, 0.1, 0.0)),
                )
                .unwrap()
        })
    });
    g.finish();

    let n = 12_000;
    let imu = w.imu().slice(0..n);
    let t1: Vec<_> = targets.iter().copied().filter(|t| t.frame < n).collect();
    let mut g = c.benchmark_group("dense_vs_banded");
    g.sample_size(10).measurement_time(Duration::from_secs(4));
    g.bench_function("1min/banded", |b| {
        b.iter(|| corrector.solve(black_box(&imu), black_box(&t1)).unwrap())
    });
    g.bench_function("1min/dense", |b| {
        b.iter(|| solve_dense(&config, black_box(&imu), black_box(&t1)).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
