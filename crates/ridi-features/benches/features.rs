//! Feature extraction speed on a 10-minute 200 Hz sequence (120,000 frames) at step 10
//! (11,980 windows x 1200 values).
//!
//! `cargo bench -p ridi-features --bench features`
//!
//! Two groups: `wall` is ordinary wall-clock time on rayon pools of 1 and 2 threads;
//! `cpu_1t` is process CPU time (summed over threads from `/proc/self/task/*/schedstat`) on a
//! 1-thread pool, which stays meaningful when other jobs share the cores. On systems without
//! `/proc` the `cpu_1t` group is skipped.

use criterion::{Criterion, criterion_group, criterion_main};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ridi_features::{
    FeatureConfig, FeatureExtractor, FeatureMatrix, GroundTruthView, SampleSchedule,
    compute_targets,
};
use ridi_frames::{DeviceVec, ImuFrames, WorldFromDevice, WorldVec};
use ridi_test_support::naive_features;
use std::hint::black_box;
use std::time::Duration;

const N: usize = 120_000;

struct Data {
    time: Vec<f64>,
    gyro: Vec<DeviceVec>,
    linacce: Vec<DeviceVec>,
    gravity: Vec<DeviceVec>,
    position: Vec<WorldVec>,
    orientation: Vec<WorldFromDevice>,
}

fn data() -> Data {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut v = |s: f64| {
        DeviceVec::new(
            rng.random_range(-s..s),
            rng.random_range(-s..s),
            rng.random_range(-s..s),
        )
    };
    let gyro = (0..N).map(|_| v(2.0)).collect();
    let linacce = (0..N).map(|_| v(3.0)).collect();
    let gravity = (0..N)
        .map(|_| {
            let d = v(1.0) + DeviceVec::new(0.0, 0.5, 0.5);
            d / d.norm() * 9.81
        })
        .collect();
    let time: Vec<f64> = (0..N).map(|i| i as f64 / 200.0).collect();
    let position = time
        .iter()
        .map(|&t| WorldVec::new(t.sin(), 1.2 * t, 0.0))
        .collect();
    let orientation = vec![WorldFromDevice::identity(); N];
    Data {
        time,
        gyro,
        linacce,
        gravity,
        position,
        orientation,
    }
}

/// CPU time of the whole process, ns, or `None` without `/proc`.
fn cpu_ns() -> Option<u64> {
    let mut total = 0;
    for e in std::fs::read_dir("/proc/self/task").ok()? {
        let p = e.ok()?.path().join("schedstat");
        // A thread may exit between listing and reading: skip it.
        if let Ok(s) = std::fs::read_to_string(p) {
            total += s.split_whitespace().next()?.parse::<u64>().ok()?;
        }
    }
    Some(total)
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("rayon pool")
}

fn bench(c: &mut Criterion) {
    let d = data();
    let config = FeatureConfig::default();
    let frames = SampleSchedule::training(&config)
        .expect("schedule")
        .frames(N);
    let fx = FeatureExtractor::new(config.clone()).expect("config");
    let imu =
        ImuFrames::new(&d.time, &d.gyro, &d.linacce, &d.gravity, &d.orientation).expect("imu");
    let gt = GroundTruthView {
        time: &d.time,
        position: &d.position,
        orientation: &d.orientation,
        gravity: &d.gravity,
    };
    let stab = fx.stabilize(&imu).expect("stabilize");
    // The naive reference on a tenth of the windows (it is slow): scale by 10 for the ratio.
    let tenth: Vec<usize> = frames.iter().copied().step_by(10).collect();

    let mut g = c.benchmark_group("wall");
    g.sample_size(10).measurement_time(Duration::from_secs(3));
    for threads in [1, 2] {
        let p = pool(threads);
        g.bench_function(format!("total/{threads}t"), |b| {
            b.iter(|| {
                p.install(|| {
                    let stab = fx.stabilize(&imu).expect("stabilize");
                    black_box(fx.features(&stab, &frames).expect("features"))
                })
            })
        });
        let mut m = FeatureMatrix::default();
        g.bench_function(format!("windows_reuse/{threads}t"), |b| {
            b.iter(|| p.install(|| fx.features_into(&stab, &frames, &mut m).expect("features")))
        });
    }
    g.bench_function("naive_tenth/1t", |b| {
        b.iter(|| {
            black_box(naive_features(
                &d.gyro, &d.linacce, &d.gravity, &tenth, 200, 2.0, 4.0,
            ))
        })
    });
    g.finish();

    if cpu_ns().is_none() {
        return;
    }
    let p = pool(1);
    let mut g = c.benchmark_group("cpu_1t");
    g.sample_size(10).measurement_time(Duration::from_secs(3));
    let mut cpu = |name: &str, f: &mut dyn FnMut()| {
        g.bench_function(name, |b| {
            b.iter_custom(|iters| {
                let c0 = cpu_ns().unwrap_or(0);
                for _ in 0..iters {
                    f();
                }
                Duration::from_nanos(cpu_ns().unwrap_or(0).saturating_sub(c0))
            })
        });
    };
    cpu("stabilize", &mut || {
        p.install(|| black_box(fx.stabilize(&imu).expect("stabilize")));
    });
    cpu("windows_fresh", &mut || {
        p.install(|| black_box(fx.features(&stab, &frames).expect("features")));
    });
    let mut m = FeatureMatrix::default();
    cpu("windows_reuse", &mut || {
        p.install(|| fx.features_into(&stab, &frames, &mut m).expect("features"));
    });
    cpu("targets", &mut || {
        p.install(|| black_box(compute_targets(&gt, &config, &frames).expect("targets")));
    });
    cpu("naive_tenth", &mut || {
        black_box(naive_features(
            &d.gyro, &d.linacce, &d.gravity, &tenth, 200, 2.0, 4.0,
        ));
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
