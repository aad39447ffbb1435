//! Cascade training and prediction, grid search, model file codec.

use ridi_features::FeatureMatrixRef;
use ridi_features::ridi_frames::StabHorizontal;
use ridi_features::{FeatureChannel, FeatureConfig, FeatureError};
use ridi_regress::{
    Cascade, CascadeParams, GridSpec, NoProgress, ProgressEvent, RegressError, RegressorChoice,
    Stage, Storage, StoredAs, Svc, SvcParams, TrainingSet,
};
use ridi_test_support::{SplitMix64, assert_names_file};

struct Data {
    x: Vec<f32>,
    y: Vec<StabHorizontal>,
    placement: Vec<usize>,
    group: Vec<u64>,
    names: Vec<String>,
    config: FeatureConfig,
}

impl Data {
    fn set(&self) -> TrainingSet<'_> {
        TrainingSet {
            features: FeatureMatrixRef::new(&self.x, self.config.feature_dim()).unwrap(),
            targets: &self.y,
            placements: &self.placement,
            placement_names: &self.names,
            groups: &self.group,
            feature_config: &self.config,
        }
    }
}

/// `placements` classes, `seqs` sequences each, `per_seq` samples per sequence; the
/// placement shifts a feature pattern, the velocity is a smooth function of a latent state.
fn make(placements: usize, seqs: usize, per_seq: usize, seed: u64) -> Data {
    make_window(placements, seqs, per_seq, seed, 4)
}

/// [`make`] with `window` frames per sample (`6 × window` values).
fn make_window(placements: usize, seqs: usize, per_seq: usize, seed: u64, window: usize) -> Data {
    let config = FeatureConfig {
        window,
        channels: vec![FeatureChannel::Gyro, FeatureChannel::LinearAcceleration],
        ..FeatureConfig::default()
    };
    let d = config.feature_dim();
    let mut rng = SplitMix64(seed);
    let mut data = Data {
        x: Vec::new(),
        y: Vec::new(),
        placement: Vec::new(),
        group: Vec::new(),
        names: (0..placements).map(|p| format!("placement{p}")).collect(),
        config,
    };
    for p in 0..placements {
        for s in 0..seqs {
            for _ in 0..per_seq {
                let a = rng.uniform();
                let b = rng.uniform();
                for j in 0..d {
                    let t = j as f64 / d as f64;
                    let shift = if j % placements == p { 1.5 } else { 0.0 };
                    data.x.push(
                        (shift + a * (4.0 * t).sin() + b * (3.0 * t).cos() + 0.05 * rng.uniform())
                            as f32,
                    );
                }
                let gain = 1.0 + p as f64 * 0.3;
                data.y
                    .push(StabHorizontal::new(gain * a, 0.5 * b * b - 0.3 * gain));
                data.placement.push(p);
                data.group.push((p * 100 + s) as u64);
            }
        }
    }
    data
}

fn small_grid() -> CascadeParams {
    CascadeParams {
        regressors: RegressorChoice::Grid(GridSpec {
            c: vec![1.0, 10.0],
            epsilon: vec![0.01, 0.1],
            folds: 3,
            seed: 7,
        }),
        ..CascadeParams::default()
    }
}

#[test]
fn cascade_classifies_regresses_and_batches_consistently() {
    let data = make(3, 4, 15, 1);
    let mut events = Vec::new();
    let mut progress = |e: &ProgressEvent<'_>| {
        events.push((format!("{:?}", e.stage), e.done, e.total));
        true
    };
    let model = Cascade::train(&data.set(), &small_grid(), &mut progress).unwrap();
    assert_eq!(model.placements(), &data.names[..]);
    // Grid table: 3 placements × 2 channels × 4 points.
    assert_eq!(model.grid_results().len(), 24);
    for p in 0..3 {
        let chosen = model.regressor_params(p).unwrap();
        for (ch, &(c, e)) in chosen.iter().enumerate() {
            let best = model
                .grid_results()
                .iter()
                .filter(|r| r.placement == data.names[p] && r.channel as usize == ch)
                .min_by(|a, b| a.mse.total_cmp(&b.mse))
                .unwrap();
            assert_eq!((best.c, best.epsilon), (c, e));
        }
        assert!(model.stored_samples(p) <= 60);
    }
    assert!(
        events
            .iter()
            .any(|e| e.0 == "Classifier" && e.1 == 3 && e.2 == 3)
    );
    assert!(
        events
            .iter()
            .any(|e| e.0.starts_with("Grid") && e.1 == 24 && e.2 == 24)
    );

    // Held-out data from the same distribution.
    let test = make(3, 1, 20, 99);
    let xt = FeatureMatrixRef::new(&test.x, 24).unwrap();
    let batch = model.predict(xt).unwrap();
    let correct = batch
        .iter()
        .zip(&test.placement)
        .filter(|(p, t)| p.placement == **t)
        .count();
    assert!(correct >= 57, "placement accuracy {correct}/60");
    // The cascade's classifier (each placement keeping the coefficients of its own pairs) is
    // the stand-alone one-vs-one classifier on the same data.
    let train_x = FeatureMatrixRef::new(&data.x, 24).unwrap();
    let svc = Svc::fit(train_x, &data.placement, &SvcParams::new(10.0, 1.0 / 24.0)).unwrap();
    let labels = svc.predict(xt).unwrap();
    for (b, l) in batch.iter().zip(&labels) {
        assert_eq!(b.placement, *l);
    }
    let mse: f64 = batch
        .iter()
        .zip(&test.y)
        .map(|(p, t)| (p.velocity[0] - t[0]).powi(2) + (p.velocity[1] - t[1]).powi(2))
        .sum::<f64>()
        / 120.0;
    assert!(mse < 0.01, "velocity MSE {mse}");
    for (i, b) in batch.iter().enumerate() {
        let one = model.predict_one(xt.row(i)).unwrap();
        assert_eq!(one.placement, b.placement);
        for ch in 0..2 {
            let diff = (one.velocity[ch] - b.velocity[ch]).abs();
            // GEMM blocking differs between one query and a block: f32 rounding only.
            assert!(diff < 1e-4, "sample {i} channel {ch}: {diff}");
        }
        let forced = model
            .predict_with_placement(xt.rows_range(i, i + 1), one.placement)
            .unwrap();
        assert!((forced[0] - one.velocity).norm() < 1e-4);
    }
    assert_eq!(
        model.predict_one(&test.x[..23]).unwrap_err().to_string(),
        RegressError::LengthMismatch {
            what: "query row",
            expected: 24,
            found: 23
        }
        .to_string()
    );
    let mut nan = test.x[..24].to_vec();
    nan[5] = f32::NAN;
    assert!(matches!(
        model.predict_one(&nan),
        Err(RegressError::Features(FeatureError::NonFinite {
            index: 0,
            ..
        }))
    ));
}

/// The speed regressor: a third grid channel, velocities scaled to the regressed speed, the
/// same on every path and through the file.
#[test]
fn speed_regressor_scales_velocities_to_the_regressed_speed() {
    let data = make(2, 3, 15, 3);
    let params = CascadeParams {
        speed: true,
        ..small_grid()
    };
    let model = Cascade::train(&data.set(), &params, &mut NoProgress).unwrap();
    let plain = Cascade::train(&data.set(), &small_grid(), &mut NoProgress).unwrap();
    // Grid table: 2 placements × 3 channels × 4 points; the plain model has no speed channel.
    assert_eq!(model.grid_results().len(), 24);
    for p in 0..2 {
        let (c, e) = model.speed_params(p).unwrap();
        let best = model
            .grid_results()
            .iter()
            .filter(|r| r.placement == data.names[p] && r.channel == 2)
            .min_by(|a, b| a.mse.total_cmp(&b.mse))
            .unwrap();
        assert_eq!((best.c, best.epsilon), (c, e));
        assert_eq!(plain.speed_params(p), None);
        // The velocity regressors are the plain model's.
        assert_eq!(model.regressor_params(p), plain.regressor_params(p));
    }
    let test = make(2, 1, 20, 98);
    let xt = FeatureMatrixRef::new(&test.x, 24).unwrap();
    let scaled = model.predict(xt).unwrap();
    let unscaled = plain.predict(xt).unwrap();
    let (mut err_scaled, mut moved) = (0.0f64, 0.0f64);
    for (i, (s, u)) in scaled.iter().zip(&unscaled).enumerate() {
        assert_eq!(s.placement, u.placement);
        // Same direction as the plain model's velocity, only its size changes.
        let cross = s.velocity[0] * u.velocity[1] - s.velocity[1] * u.velocity[0];
        assert!(
            cross.abs() < 1e-3 * u.velocity.norm().max(1.0),
            "{s:?} {u:?}"
        );
        assert!(s.velocity[0] * u.velocity[0] + s.velocity[1] * u.velocity[1] >= 0.0);
        err_scaled = err_scaled.max((s.velocity.norm() - test.y[i].norm()).abs());
        moved = moved.max((s.velocity.norm() - u.velocity.norm()).abs());
        let one = model.predict_one(xt.row(i)).unwrap();
        for ch in 0..2 {
            assert!((one.velocity[ch] - s.velocity[ch]).abs() < 1e-4);
        }
    }
    assert!(moved > 0.0, "the speed channel changed nothing");
    assert!(err_scaled < 0.3, "largest speed error {err_scaled}");
    let back = Cascade::from_bytes(&model.to_bytes().unwrap()).unwrap();
    assert_eq!(back.predict(xt).unwrap(), scaled);
}

#[test]
fn training_is_deterministic_and_model_files_round_trip() {
    let data = make(2, 3, 12, 5);
    let params = small_grid();
    let a = Cascade::train(&data.set(), &params, &mut NoProgress).unwrap();
    let b = Cascade::train(&data.set(), &params, &mut NoProgress).unwrap();
    let bytes = a.to_bytes().unwrap();
    assert_eq!(bytes, b.to_bytes().unwrap());
    assert_eq!(&bytes[..8], b"RIDIREG\0");
    let back = Cascade::from_bytes(&bytes).unwrap();
    assert_eq!(back, a);
    assert_eq!(back.feature_config(), &data.config);

    let dir = std::env::temp_dir().join(format!("ridi-regress-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("model.ridi");
    a.save(&path).unwrap();
    assert_eq!(Cascade::load(&path).unwrap(), a);
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        1,
        "temporary file left behind"
    );
    std::fs::remove_dir_all(&dir).unwrap();

    let mut corrupt = bytes.clone();
    let mid = bytes.len() / 2;
    corrupt[mid] ^= 0x40;
    assert!(matches!(
        Cascade::from_bytes(&corrupt),
        Err(RegressError::Checksum { .. })
    ));
    for cut in [0, 5, 20, bytes.len() - 1] {
        assert!(
            matches!(
                Cascade::from_bytes(&bytes[..cut]),
                Err(RegressError::Truncated { .. })
            ),
            "cut at {cut}"
        );
    }
    let mut newer = bytes.clone();
    newer[8..12].copy_from_slice(&8u32.to_le_bytes());
    assert!(matches!(
        Cascade::from_bytes(&newer),
        Err(RegressError::UnsupportedVersion {
            found: 8,
            supported: 7
        })
    ));
    // Versions 1 (f32 samples), 2 (half precision only), 3 (an f32 block of leading
    // coordinates), 4 (every pair's classifier coefficient), 5 (no speed regressor) and 6 (no
    // up axis): refused with advice.
    for v in [1u32, 2, 3, 4, 5, 6] {
        let mut older = bytes.clone();
        older[8..12].copy_from_slice(&v.to_le_bytes());
        let err = Cascade::from_bytes(&older).unwrap_err();
        assert!(
            matches!(err, RegressError::UnsupportedVersion { found, supported: 7 } if found == v)
        );
        assert!(err.to_string().contains("retrain"), "{err}");
    }
    let mut magic = bytes.clone();
    magic[0] = b'X';
    assert!(matches!(
        Cascade::from_bytes(&magic),
        Err(RegressError::BadMagic)
    ));
    // A file that cannot be read is named (decode errors have no file: `from_bytes` takes
    // bytes, and the `ridi` binary adds the file's name to them, as its tests check).
    let missing = std::path::Path::new("/nonexistent/model.ridi");
    assert_names_file(&Cascade::load(missing).unwrap_err(), missing);
}

#[test]
fn small_or_degenerate_placements_give_clear_errors_or_documented_fallbacks() {
    // Too few samples: placement0 keeps 5 of its 30.
    let fixed = CascadeParams {
        regressors: RegressorChoice::Fixed {
            c: 1.0,
            epsilon: 0.1,
        },
        ..CascadeParams::default()
    };
    let mut few = make(2, 3, 10, 3);
    for p in few.placement.iter_mut().take(25) {
        *p = 1;
    }
    match Cascade::train(&few.set(), &fixed, &mut NoProgress) {
        Err(RegressError::NotEnoughData(m)) => assert!(m.contains("placement0"), "{m}"),
        other => panic!("expected NotEnoughData, got {other:?}"),
    }
    // A name without samples.
    let mut empty = make(2, 3, 10, 3);
    empty.names.push("leg".into());
    assert!(matches!(
        Cascade::train(&empty.set(), &fixed, &mut NoProgress),
        Err(RegressError::NotEnoughData(m)) if m.contains("leg")
    ));
    // A placement recorded in a single sequence cannot be cross-validated by sequence.
    let mut one_seq = make(2, 3, 10, 3);
    for (g, p) in one_seq.group.iter_mut().zip(&one_seq.placement) {
        if *p == 0 {
            *g = 0;
        }
    }
    match Cascade::train(&one_seq.set(), &small_grid(), &mut NoProgress) {
        Err(e @ RegressError::TooFewSequences { found: 1, .. }) => {
            assert!(e.to_string().starts_with("placement 'placement0': "), "{e}")
        }
        other => panic!("expected TooFewSequences, got {other:?}"),
    }
    // A single placement: no classifier, every query gets placement 0.
    let single = make(1, 3, 10, 4);
    let model = Cascade::train(&single.set(), &fixed, &mut NoProgress).unwrap();
    assert_eq!(model.predict_one(&single.x[..24]).unwrap().placement, 0);
    let bytes = model.to_bytes().unwrap();
    assert_eq!(Cascade::from_bytes(&bytes).unwrap(), model);
    // Mismatched lengths and a feature config of another width.
    let mut short = make(2, 3, 10, 3);
    short.y.pop();
    assert!(matches!(
        Cascade::train(&short.set(), &fixed, &mut NoProgress),
        Err(RegressError::LengthMismatch {
            what: "targets (one per feature row)",
            ..
        })
    ));
    let mut wide = make(2, 3, 10, 3);
    wide.config.window = 5;
    let set = wide.set_unchecked();
    assert!(matches!(
        Cascade::train(&set, &fixed, &mut NoProgress),
        Err(RegressError::LengthMismatch { expected: 30, .. })
    ));
}

#[test]
fn half_precision_samples_stay_close_to_the_exact_model() {
    let data = make(3, 4, 15, 1);
    let params = CascadeParams {
        regressors: RegressorChoice::Fixed {
            c: 10.0,
            epsilon: 0.01,
        },
        ..CascadeParams::default()
    };
    let model = Cascade::train(&data.set(), &params, &mut NoProgress).unwrap();
    let test = make(3, 2, 20, 99);
    let xt = FeatureMatrixRef::new(&test.x, 24).unwrap();
    let r = model.rounding_effect(data.set().features, xt).unwrap();
    assert_eq!(r.queries, 120);
    assert_eq!(r.placement_agreement, 1.0);
    // Features of magnitude up to about 3 lose at most 2^-12 relative to rounding; targets
    // are of order 1 m/s: the stored model moves velocities by well under 1 cm/s.
    for ch in 0..2 {
        assert!(r.max_velocity_diff[ch] < 5e-3, "{r:?}");
        assert!(r.mean_velocity_diff[ch] <= r.max_velocity_diff[ch]);
    }
    assert!(
        r.max_velocity_diff.iter().any(|&d| d > 0.0),
        "rounding had no effect"
    );
    // Rows that are not the training rows cannot be matched.
    assert!(matches!(
        model.rounding_effect(xt, xt),
        Err(RegressError::NotTrainingRow { .. })
    ));
    // The single-query path (half-precision GEMV) agrees with the batched GEMM path up to the
    // summation order of the dot products (the distances cancel |q|² + |s|² - 2 q·s).
    let batch = model.predict(xt).unwrap();
    for (i, b) in batch.iter().enumerate() {
        let one = model.predict_one(xt.row(i)).unwrap();
        assert_eq!(one.placement, b.placement);
        for ch in 0..2 {
            assert!(
                (one.velocity[ch] - b.velocity[ch]).abs() < 1e-4,
                "query {i}"
            );
        }
    }
}

#[test]
fn projected_samples_stay_close_to_the_exact_model() {
    // 240 values per row with a handful of directions of variance plus faint noise.
    let data = make_window(3, 4, 15, 1, 40);
    let d = data.config.feature_dim();
    let params = |storage| CascadeParams {
        regressors: RegressorChoice::Fixed {
            c: 10.0,
            epsilon: 0.01,
        },
        storage,
        ..CascadeParams::default()
    };
    let model = Cascade::train(
        &data.set(),
        &params(Storage::Projected { energy: 0.999 }),
        &mut NoProgress,
    )
    .unwrap();
    let StoredAs::Projected { components, energy } = model.stored_as() else {
        panic!("not projected: {:?}", model.stored_as());
    };
    assert_eq!(components, 64, "a few directions, at least 64 kept");
    assert!((0.999..=1.0).contains(&energy), "{energy}");
    let half = Cascade::train(&data.set(), &params(Storage::Half), &mut NoProgress).unwrap();
    assert_eq!(half.stored_as(), StoredAs::Half);

    let test = make_window(3, 2, 20, 99, 40);
    let xt = FeatureMatrixRef::new(&test.x, d).unwrap();
    let r = model.rounding_effect(data.set().features, xt).unwrap();
    assert_eq!(r.queries, 120);
    assert_eq!(r.placement_agreement, 1.0);
    // Dropping the noise directions leaves `2 r_q·r_s` out of each squared distance (about
    // 3e-3 here, 1e-5 of a kernel value); with C = 10 on 60 samples a class's coefficients
    // are large and of both signs, so that adds up to a few mm/s (15x half precision's
    // rounding on these rows; about 3x on the Tyrex features, docs/benchmarks.md).
    for ch in 0..2 {
        assert!(r.max_velocity_diff[ch] < 1e-2, "{r:?}");
        assert!(
            r.max_velocity_diff[ch] > 0.0,
            "projection had no effect: {r:?}"
        );
    }
    // Both storages answer alike, and one query agrees with the batched path.
    let batch = model.predict(xt).unwrap();
    for ((b, h), i) in batch.iter().zip(half.predict(xt).unwrap()).zip(0..) {
        assert_eq!(b.placement, h.placement);
        let one = model.predict_one(xt.row(i)).unwrap();
        assert_eq!(one.placement, b.placement);
        for ch in 0..2 {
            assert!((b.velocity[ch] - h.velocity[ch]).abs() < 1e-2, "query {i}");
            assert!(
                (one.velocity[ch] - b.velocity[ch]).abs() < 1e-4,
                "query {i}"
            );
        }
    }
    let bytes = model.to_bytes().unwrap();
    assert_eq!(Cascade::from_bytes(&bytes).unwrap(), model);
    // Coordinates beyond the half-precision range are refused like features are.
    let mut big = make_window(2, 3, 10, 3, 40);
    big.x.iter_mut().for_each(|v| *v *= 1.0e4);
    match Cascade::train(
        &big.set(),
        &params(Storage::Projected { energy: 0.999 }),
        &mut NoProgress,
    ) {
        Err(
            e @ RegressError::BeyondHalfPrecision {
                what: "principal coordinate",
                ..
            },
        ) => assert!(e.to_string().contains("standardize"), "{e}"),
        other => panic!("expected BeyondHalfPrecision, got {other:?}"),
    }
}

#[test]
fn features_beyond_the_half_precision_range_are_refused() {
    let mut data = make(2, 3, 10, 3);
    data.x[30] = 1.0e5;
    let fixed = CascadeParams {
        regressors: RegressorChoice::Fixed {
            c: 1.0,
            epsilon: 0.1,
        },
        ..CascadeParams::default()
    };
    match Cascade::train(&data.set(), &fixed, &mut NoProgress) {
        Err(
            e @ RegressError::BeyondHalfPrecision {
                row: 1, column: 6, ..
            },
        ) => {
            assert!(e.to_string().contains("row 1, column 6"), "{e}")
        }
        other => panic!("expected BeyondHalfPrecision, got {other:?}"),
    }
}

#[test]
fn progress_callback_can_cancel() {
    let data = make(2, 3, 10, 8);
    let mut calls = 0;
    let mut progress = |e: &ProgressEvent<'_>| {
        calls += 1;
        !matches!(e.stage, Stage::Grid { .. }) || e.done < 2
    };
    assert!(matches!(
        Cascade::train(&data.set(), &small_grid(), &mut progress),
        Err(RegressError::Cancelled)
    ));
    assert!(calls > 2);
}

impl Data {
    /// Like `set` but without building the features view from the config width.
    fn set_unchecked(&self) -> TrainingSet<'_> {
        TrainingSet {
            features: FeatureMatrixRef::new(&self.x, 24).unwrap(),
            targets: &self.y,
            placements: &self.placement,
            placement_names: &self.names,
            groups: &self.group,
            feature_config: &self.config,
        }
    }
}
