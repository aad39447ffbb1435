//! Criterion benchmarks on synthetic IMU-like data (`benches/synth.rs`). Long runs (17k-sample
//! fits, full grid, scikit-learn comparison) are in `examples/svr_timing.rs` and
//! `docs/benchmarks.md`.
//!
//! `gram_2000x1200` times the kernel internals `ridi_regress::{sq_norms, gram}`, which the
//! feature `bench-internals` exposes (turned on here by the crate's dev-dependency on itself).

mod synth;

use criterion::{Criterion, criterion_group, criterion_main};
use ridi_features::FeatureConfig;
use ridi_features::FeatureMatrixRef;
use ridi_regress::{
    Cascade, CascadeParams, NoProgress, Nystrom, RegressorChoice, Solver, Storage, Svc, SvcParams,
    Svr, SvrParams, TrainingSet,
};

fn benches(c: &mut Criterion) {
    let data = synth::generate(2000, 4, 150, 42);
    let x = FeatureMatrixRef::new(&data.x, data.dim).unwrap();
    let gamma = 1.0 / data.dim as f32;
    let mut g = c.benchmark_group("regress");
    g.sample_size(10);

    let norms = ridi_regress::sq_norms(x);
    g.bench_function("gram_2000x1200", |b| {
        b.iter(|| ridi_regress::gram(x, &norms, gamma))
    });

    let y: Vec<f64> = data.y.iter().map(|v| v[1]).collect();
    g.bench_function("svr_fit_2000_c10_eps0.01", |b| {
        b.iter(|| Svr::fit(x, &y, &SvrParams::new(10.0, 0.01, gamma)).unwrap())
    });
    g.bench_function("svc_fit_2000_4class_c10", |b| {
        b.iter(|| Svc::fit(x, &data.placement, &SvcParams::new(10.0, gamma)).unwrap())
    });

    let names: Vec<String> = (0..4).map(|p| format!("p{p}")).collect();
    let config = FeatureConfig::default();
    let set = TrainingSet {
        features: x,
        targets: &data.y,
        placements: &data.placement,
        placement_names: &names,
        groups: &data.group,
        feature_config: &config,
    };
    let params = CascadeParams {
        regressors: RegressorChoice::Fixed {
            c: 10.0,
            epsilon: 0.001,
        },
        ..CascadeParams::default()
    };
    let model = Cascade::train(&set, &params, &mut NoProgress).unwrap();
    // The synthetic features need 607 directions for the default 99.99 % of their variance,
    // so `model` falls back to half precision; 99.95 % takes 64 and exercises the projection.
    let projected = Cascade::train(
        &set,
        &CascadeParams {
            storage: Storage::Projected { energy: 0.9995 },
            ..params.clone()
        },
        &mut NoProgress,
    )
    .unwrap();
    for (id, m) in [
        ("cascade_predict_one", &model),
        ("cascade_predict_one_projected", &projected),
    ] {
        g.bench_function(id, |b| {
            let mut i = 0;
            b.iter(|| {
                i = (i + 1) % 2000;
                m.predict_one(x.row(i)).unwrap()
            })
        });
    }
    g.bench_function("cascade_predict_batch_2000", |b| {
        b.iter(|| model.predict(x).unwrap())
    });
    // The Nyström solver on the same rows: training (landmarks, features, the linear
    // classifier, the ridge regressors) and one query, on up to 1024 landmarks per machine,
    // with the projection its users get (`Storage::projected_for`: its kernel's distances
    // from the principal coordinates).
    let solver = Solver::Nystrom(Nystrom::new(1024, 0).unwrap());
    let nystrom = CascadeParams {
        storage: Storage::projected_for(&solver),
        solver,
        ..params.clone()
    };
    g.bench_function("cascade_train_nystrom_2000_1024", |b| {
        b.iter(|| Cascade::train(&set, &nystrom, &mut NoProgress).unwrap())
    });
    let nys = Cascade::train(&set, &nystrom, &mut NoProgress).unwrap();
    g.bench_function("cascade_predict_one_nystrom_1024", |b| {
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) % 2000;
            nys.predict_one(x.row(i)).unwrap()
        })
    });
    g.finish();
}

criterion_group!(regress, benches);
criterion_main!(regress);
