//! Reading the Tyrex benchmark from `../shared` (beside the checkout): one QTM `.mat`, one run
//! (phone text files + `.mat` -> resampled 200 Hz sequence) and all 24 runs. Without the shared
//! data it prints a note and measures nothing. Numbers: docs/benchmarks.md.
//!
//! `cargo bench -p ridi-data --bench tyrex -- --warm-up-time 1 --measurement-time 5`

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{Criterion, criterion_group, criterion_main};
use ridi_data::MatFile;
use ridi_data::tyrex::{self, TyrexOptions};

fn root() -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/raw/tyrex-attitude-smartphones");
    p.join("datasets/android").is_dir().then_some(p)
}

fn bench(c: &mut Criterion) {
    let Some(root) = root() else {
        eprintln!("note: Tyrex shared data not found beside the checkout: nothing to measure");
        return;
    };
    let name = "Guillaume_Nexus5_NoDist_Texting";
    let dir = root.join("datasets/android").join(name);
    let mat = root.join("datasets/qualisys").join(format!("{name}.mat"));
    let opts = TyrexOptions::default();
    let mut g = c.benchmark_group("tyrex");
    g.bench_function("mat_read_one", |b| {
        b.iter(|| black_box(MatFile::read(&mat).unwrap()))
    });
    g.bench_function("ground_truth_one", |b| {
        b.iter(|| black_box(tyrex::read_ground_truth(&mat).unwrap()))
    });
    g.bench_function("read_one", |b| {
        b.iter(|| black_box(tyrex::read(&dir, &opts).unwrap()))
    });
    let dirs: Vec<_> = tyrex::list_sequences(&root)
        .unwrap()
        .runs
        .into_iter()
        .filter(|d| d.to_string_lossy().contains("_Nexus5_NoDist_"))
        .collect();
    g.sample_size(10);
    g.bench_function("read_all_24", |b| {
        b.iter(|| {
            for d in &dirs {
                black_box(tyrex::read(d, &opts).unwrap());
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
