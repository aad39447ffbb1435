//! Reading and writing a 10-minute 200 Hz RIDI processed file (120 000 rows x 28 columns).
//!
//! `cargo bench -p ridi-data --bench read -- --warm-up-time 1 --measurement-time 3`
//!
//! Each case is measured twice: wall time (criterion's default) and the CPU time of the
//! benchmark thread (group `..._cpu`). The machines this runs on are shared with other builds,
//! where wall time mostly measures the load; thread CPU time stays close to the unloaded cost.

use std::hint::black_box;
use std::sync::LazyLock;
use std::time::Instant;

use criterion::measurement::{Measurement, ValueFormatter};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use ridi_data::ridi_frames::nalgebra::Vector3;
use ridi_data::ridi_frames::{DeviceVec, WorldFromDevice, WorldVec, gravity_in_device};
use ridi_data::{
    GroundTruth, OrientationSource, ReadOptions, Sequence, SequenceParts, ridi_csv, ridi_plain,
    write_ridi_csv, write_ridi_plain,
};

const ROWS: usize = 120_000;

/// A sequence with full-precision values in every channel, like a real recording.
fn sequence() -> Sequence {
    let t0_ns: i64 = 172_364_832_413_231;
    let time: Vec<f64> = (0..ROWS)
        .map(|i| (t0_ns + 4_943_000 * i as i64) as f64 / 1e9)
        .collect();
    let orientation: Vec<WorldFromDevice> = (0..ROWS)
        .map(|i| {
            let t = i as f64 / 200.0;
            WorldFromDevice::from_scaled_axis(Vector3::new(0.2 * t.sin(), 0.1 * t.cos(), 0.3 * t))
        })
        .collect();
    let gravity: Vec<DeviceVec> = orientation
        .iter()
        .map(|q| gravity_in_device(*q, 9.80665))
        .collect();
    let wave = |k: f64| -> Vec<DeviceVec> {
        (0..ROWS)
            .map(|i| {
                let a = k * i as f64;
                DeviceVec::new(a.sin(), a.cos() * 0.5, (a * 0.3).sin() * 2.0)
            })
            .collect()
    };
    let linacce = wave(0.013);
    Sequence::new(SequenceParts {
        name: "bench".into(),
        placement: None,
        // The orientation's own rotation rate (the readers check the gyro against it, per axis
        // too), with a wave on top so that no two channels are alike.
        gyro: (0..ROWS)
            .map(|i| {
                let (a, b) = if i + 1 < ROWS { (i, i + 1) } else { (i - 1, i) };
                let rate = (orientation[a].inverse() * orientation[b])
                    .quaternion()
                    .scaled_axis()
                    * 200.0;
                let w = 0.071 * i as f64;
                DeviceVec::new(rate.x, rate.y, rate.z)
                    + DeviceVec::new(w.sin(), w.cos() * 0.5, (w * 0.3).sin() * 2.0) * 0.02
            })
            .collect(),
        acce: linacce.iter().zip(&gravity).map(|(a, g)| *a + *g).collect(),
        linacce,
        gravity,
        magnet: Some(wave(0.0007).into_iter().map(|m| m * 40.0).collect()),
        ground_truth: Some(GroundTruth {
            position: (0..ROWS)
                .map(|i| {
                    let t = i as f64 / 200.0;
                    WorldVec::new(1.3 * t.cos(), 1.3 * t.sin(), 0.01 * t)
                })
                .collect(),
            orientation: orientation.clone(),
        }),
        orientation,
        orientation_source: Some(OrientationSource::GameRotationVector),
        steps: None,
        device: None,
        time,
    })
    .expect("benchmark sequence is valid")
}

/// CPU time of the calling thread, ns: Linux's `/proc/thread-self/schedstat`, or wall time
/// elsewhere.
fn thread_cpu_ns() -> u64 {
    static EPOCH: LazyLock<Instant> = LazyLock::new(Instant::now);
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or_else(|| EPOCH.elapsed().as_nanos() as u64)
}

/// Criterion measurement of thread CPU time.
struct ThreadCpuTime;

impl Measurement for ThreadCpuTime {
    type Intermediate = u64;
    type Value = u64;
    fn start(&self) -> u64 {
        thread_cpu_ns()
    }
    fn end(&self, start: u64) -> u64 {
        thread_cpu_ns().saturating_sub(start)
    }
    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }
    fn zero(&self) -> u64 {
        0
    }
    fn to_f64(&self, v: &u64) -> f64 {
        *v as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        &CpuFormatter
    }
}

/// Shows CPU time in ms and byte throughputs in MiB per CPU second.
struct CpuFormatter;

impl ValueFormatter for CpuFormatter {
    fn scale_values(&self, _typical: f64, values: &mut [f64]) -> &'static str {
        values.iter_mut().for_each(|v| *v /= 1e6);
        "ms (cpu)"
    }
    fn scale_throughputs(&self, _typical: f64, t: &Throughput, values: &mut [f64]) -> &'static str {
        let (per_iter, unit) = match *t {
            Throughput::Bytes(b) | Throughput::BytesDecimal(b) => {
                (b as f64 / 1048576.0, "MiB/s (cpu)")
            }
            Throughput::Bits(b) => (b as f64, "bit/s (cpu)"),
            Throughput::Elements(e) | Throughput::ElementsAndBytes { elements: e, .. } => {
                (e as f64, "elem/s (cpu)")
            }
        };
        values.iter_mut().for_each(|v| *v = per_iter * 1e9 / *v);
        unit
    }
    fn scale_for_machines(&self, _values: &mut [f64]) -> &'static str {
        "ns"
    }
}

fn bench<M: Measurement>(c: &mut Criterion<M>, group: &str) {
    let seq = sequence();
    let dir = tempfile::tempdir().expect("temp dir");
    let csv = dir.path().join("data.csv");
    let plain = dir.path().join("data_plain.txt");
    write_ridi_csv(&seq, &csv).expect("write csv");
    write_ridi_plain(&seq, &plain).expect("write plain");
    let bytes = std::fs::metadata(&csv).expect("csv size").len();
    let opts = ReadOptions::default();

    let mut g = c.benchmark_group(group);
    g.sample_size(10);
    g.throughput(Throughput::Bytes(bytes));
    g.bench_function("read_csv", |b| {
        b.iter(|| black_box(ridi_csv::read(&csv, &opts).expect("read csv")))
    });
    g.bench_function("read_plain", |b| {
        b.iter(|| black_box(ridi_plain::read(&plain, &opts).expect("read plain")))
    });
    g.bench_function("write_csv", |b| {
        b.iter(|| write_ridi_csv(black_box(&seq), &csv).expect("write csv"))
    });
    g.finish();
}

fn wall(c: &mut Criterion) {
    bench(c, "ridi_data_120k_rows");
}

fn cpu(c: &mut Criterion<ThreadCpuTime>) {
    bench(c, "ridi_data_120k_rows_cpu");
}

criterion_group!(wall_time, wall);
criterion_group! {
    name = cpu_time;
    config = Criterion::default().with_measurement(ThreadCpuTime);
    targets = cpu
}
criterion_main!(wall_time, cpu_time);
