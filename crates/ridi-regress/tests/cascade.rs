//! Cascade training and prediction, grid search, model file codec.

use ridi_features::FeatureMatrixRef;
use ridi_features::ridi_frames::StabHorizontal;
use ridi_features::{FeatureChannel, FeatureConfig, FeatureError};
use ridi_regress::{
    Cascade, CascadeParams, GridSpec, NoProgress, Nystrom, ProgressEvent, RegressError,
    RegressorChoice, Solver, Stage, Storage, StoredAs, Svc, SvcParams, TrainingSet,
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
    assert_eq!(model.placement_names(), &data.names[..]);
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

/// An exact model of two placements with fixed hyper-parameters, and its data.
fn small_exact_model() -> (Data, Cascade) {
    let data = make(2, 3, 8, 11);
    let params = fixed(CascadeParams::default().storage, Solver::Exact);
    let model = Cascade::train(&data.set(), &params, &mut NoProgress).unwrap();
    (data, model)
}

#[test]
fn a_nan_anywhere_in_an_exact_model_file_is_refused_or_harmless() {
    // Every 8 bytes of the payload made a NaN f64, the checksum fixed: the file is refused,
    // or (the bytes of no f64, such as counts) the model still predicts finite velocities.
    let (data, model) = small_exact_model();
    let bytes = model.to_bytes().unwrap();
    let x = data.set().features;
    let mut refused = 0;
    for at in 24..=bytes.len() - 8 {
        let mut b = bytes.clone();
        b[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
        let crc = crc32fast::hash(&b[24..]);
        b[20..24].copy_from_slice(&crc.to_le_bytes());
        match Cascade::from_bytes(&b) {
            Err(_) => refused += 1,
            Ok(m) => {
                for p in m.predict(x).unwrap() {
                    assert!(p.velocity.is_finite(), "a NaN at byte {at} predicts {p:?}");
                }
            }
        }
    }
    assert!(refused > 0);
}

#[test]
fn a_cascade_deserialized_by_serde_alone_predicts_nothing() {
    // Its serde form is the model file's payload, without what the file adds and checks.
    let (data, model) = small_exact_model();
    let cfg = bincode::config::standard();
    let bytes = bincode::serde::encode_to_vec(&model, cfg).unwrap();
    let (back, _): (Cascade, _) = bincode::serde::decode_from_slice(&bytes, cfg).unwrap();
    let x = data.set().features;
    for e in [
        back.predict(x).unwrap_err(),
        back.predict_one(x.row(0)).unwrap_err(),
        back.predict_with_placement(x, 0).unwrap_err(),
    ] {
        assert!(e.to_string().contains("Cascade::from_bytes"), "{e}");
    }
    // The model file's codec gives it back whole.
    let whole = Cascade::from_bytes(&model.to_bytes().unwrap()).unwrap();
    assert_eq!(whole.predict(x).unwrap(), model.predict(x).unwrap());
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
    // The mode every file of the project gets, 0644, whatever the umask allows beyond it:
    // saved under umask 0 (process-wide for a moment; no other test checks a mode).
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        // SAFETY: umask only sets the process's file creation mask.
        let old = unsafe { libc::umask(0) };
        let saved = a.save(&path);
        unsafe { libc::umask(old) };
        saved.unwrap();
        let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o644, "mode {mode:o}");
    }
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        1,
        "temporary file left behind"
    );
    // What the rename would replace is refused and left as it was: a link, a pipe, a folder.
    #[cfg(unix)]
    {
        let link = dir.join("link.ridi");
        std::os::unix::fs::symlink(&path, &link).unwrap();
        let fifo = dir.join("fifo.ridi");
        ridi_test_support::make_fifo(&fifo);
        for kept in [&link, &fifo, &dir] {
            let e = a.save(kept).unwrap_err().to_string();
            assert!(e.contains("not a regular file"), "{e}");
        }
        assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
        assert!(ridi_test_support::is_fifo(&fifo));
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 3);
    }
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
    // Exact models are version 7 (8 is a Nyström model, whose payload this is not).
    assert_eq!(&bytes[8..12], &7u32.to_le_bytes());
    assert_eq!(a.format_version(), 7);
    let mut newer = bytes.clone();
    newer[8..12].copy_from_slice(&9u32.to_le_bytes());
    assert!(matches!(
        Cascade::from_bytes(&newer),
        Err(RegressError::UnsupportedVersion {
            found: 9,
            supported: 8
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
            matches!(err, RegressError::UnsupportedVersion { found, supported: 8 } if found == v)
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

    // `load` reads the header first: a device, a folder, a huge file that is no model, one
    // whose header declares another size, are refused without reading the rest.
    let dir = std::env::temp_dir().join(format!("ridi-regress-load-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let zero = std::path::Path::new("/dev/zero");
    if zero.exists() {
        let e = Cascade::load(zero).unwrap_err();
        assert_names_file(&e, zero);
        assert!(e.to_string().contains("not a regular file"), "{e}");
    }
    let e = Cascade::load(&dir).unwrap_err();
    assert!(
        e.to_string()
            .ends_with("is a folder: it is not a regular file"),
        "{e}"
    );
    let huge = dir.join("huge.ridi");
    std::fs::File::create(&huge)
        .unwrap()
        .set_len(3 << 30)
        .unwrap();
    assert!(matches!(Cascade::load(&huge), Err(RegressError::BadMagic)));
    let padded = dir.join("padded.ridi");
    let mut f = std::fs::File::create(&padded).unwrap();
    std::io::Write::write_all(&mut f, &bytes).unwrap();
    f.set_len(3 << 30).unwrap();
    let e = Cascade::load(&padded).unwrap_err();
    assert!(e.to_string().contains("trailing bytes"), "{e}");
    let one_more = dir.join("one-more.ridi");
    std::fs::write(&one_more, [&bytes[..], b"\n"].concat()).unwrap();
    let e = Cascade::load(&one_more).unwrap_err();
    assert!(
        e.to_string()
            .ends_with(": 1 trailing byte after the payload"),
        "{e}"
    );
    let cut = dir.join("cut.ridi");
    std::fs::write(&cut, &bytes[..bytes.len() - 1]).unwrap();
    assert!(matches!(
        Cascade::load(&cut),
        Err(RegressError::Truncated { .. })
    ));
    let newer_file = dir.join("newer.ridi");
    std::fs::write(&newer_file, &newer[..30]).unwrap();
    assert!(matches!(
        Cascade::load(&newer_file),
        Err(RegressError::UnsupportedVersion { found: 9, .. })
    ));
    let whole = dir.join("whole.ridi");
    std::fs::write(&whole, &bytes).unwrap();
    assert_eq!(Cascade::load(&whole).unwrap(), a);
    std::fs::remove_dir_all(&dir).unwrap();
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
    // A placement recorded in a single sequence cannot be cross-validated by sequence: refused
    // before any stage starts, also when it is the last placement the search would reach.
    let mut one_seq = make(2, 3, 10, 3);
    for (g, p) in one_seq.group.iter_mut().zip(&one_seq.placement) {
        if *p == 1 {
            *g = 0;
        }
    }
    let mut stages = 0;
    let mut count = |_: &ProgressEvent<'_>| {
        stages += 1;
        true
    };
    match Cascade::train(&one_seq.set(), &small_grid(), &mut count) {
        Err(e @ RegressError::TooFewSequences { found: 1, .. }) => {
            assert!(e.to_string().starts_with("placement 'placement1': "), "{e}")
        }
        other => panic!("expected TooFewSequences, got {other:?}"),
    }
    assert_eq!(stages, 0);
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
    // A feature configuration a model file would not load with is refused before training.
    let mut stepless = make(2, 3, 10, 3);
    stepless.config.step = 0;
    assert!(matches!(
        Cascade::train(&stepless.set(), &fixed, &mut NoProgress),
        Err(RegressError::Features(FeatureError::InvalidConfig(_)))
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
    assert_one_query_agrees(&model, xt, &batch);
}

/// One query at a time ([`Cascade::predict_one`]) agrees with the batched path `batch`:
/// the same placements, velocities within 1e-4 m/s per channel.
fn assert_one_query_agrees(
    model: &Cascade,
    xt: FeatureMatrixRef<'_>,
    batch: &[ridi_regress::Prediction],
) {
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

/// The stored coordinates of a projected model and their share of the variance.
fn projected(model: &Cascade) -> (usize, f64) {
    match model.stored_as() {
        StoredAs::Projected { components, energy } => (components, energy),
        other => panic!("not projected: {other:?}"),
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
    let (components, energy) = projected(&model);
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

// ---- The Nyström solver ----

fn fixed(storage: Storage, solver: Solver) -> CascadeParams {
    CascadeParams {
        regressors: RegressorChoice::Fixed {
            c: 10.0,
            epsilon: 0.01,
        },
        storage,
        solver,
        ..CascadeParams::default()
    }
}

/// Largest velocity difference per channel between two sets of predictions, and the share
/// of queries given the same placement.
fn compare(a: &[ridi_regress::Prediction], b: &[ridi_regress::Prediction]) -> (f64, [f64; 2]) {
    let mut max = [0.0f64; 2];
    let mut same = 0;
    for (p, q) in a.iter().zip(b) {
        if p.placement != q.placement {
            continue;
        }
        same += 1;
        for (ch, m) in max.iter_mut().enumerate() {
            *m = m.max((p.velocity[ch] - q.velocity[ch]).abs());
        }
    }
    (same as f64 / a.len() as f64, max)
}

/// `A x = b` by Gaussian elimination with partial pivoting (`A` row-major, `n × n`).
fn dense_solve(mut a: Vec<f64>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs()))
            .unwrap();
        for k in 0..n {
            a.swap(c * n + k, p * n + k);
        }
        b.swap(c, p);
        for r in c + 1..n {
            let f = a[r * n + c] / a[c * n + c];
            for k in c..n {
                a[r * n + k] -= f * a[c * n + k];
            }
            b[r] -= f * b[c];
        }
    }
    for c in (0..n).rev() {
        let s: f64 = (c + 1..n).map(|k| a[c * n + k] * b[k]).sum();
        b[c] = (b[c] - s) / a[c * n + c];
    }
    b
}

/// Kernel ridge regression by a dense solve, the oracle of the Nyström regressors: `f(x) =
/// Σ αᵢ k(xᵢ, x) + b` minimizing `½‖f‖² + (C/2) Σ (f(xᵢ) − yᵢ)²`, i.e.
/// `[K + I/C, 1; 1ᵀ, 0] [α; b] = [y; 0]`.
fn kernel_ridge(x: &[Vec<f32>], y: &[f64], gamma: f64, c: f64) -> impl Fn(&[f32]) -> f64 + use<> {
    let k = move |a: &[f32], b: &[f32]| {
        let d: f64 = a
            .iter()
            .zip(b)
            .map(|(p, q)| (*p as f64 - *q as f64).powi(2))
            .sum();
        (-gamma * d).exp()
    };
    let n = x.len();
    let mut a = vec![0.0; (n + 1) * (n + 1)];
    for i in 0..n {
        for j in 0..n {
            a[i * (n + 1) + j] = k(&x[i], &x[j]) + if i == j { 1.0 / c } else { 0.0 };
        }
        a[i * (n + 1) + n] = 1.0;
        a[n * (n + 1) + i] = 1.0;
    }
    let mut rhs = y.to_vec();
    rhs.push(0.0);
    let sol = dense_solve(a, rhs);
    let x = x.to_vec();
    move |q: &[f32]| x.iter().zip(&sol).map(|(xi, a)| a * k(xi, q)).sum::<f64>() + sol[n]
}

#[test]
fn nystrom_with_every_row_a_landmark_is_the_exact_classifier_and_kernel_ridge() {
    // 480 rows, 160 per placement, all of them landmarks: φ(a)·φ(b) is then the kernel
    // itself on the training rows. The classifier is the exact one's machine but for the
    // offset, which the linear one regularizes, and the stopping rules (tight on both
    // sides); each placement's regressors are kernel ridge regressions, against a dense
    // solve.
    let data = make(3, 4, 40, 1);
    let test = make(3, 2, 20, 99);
    let dim = 24;
    let xt = FeatureMatrixRef::new(&test.x, dim).unwrap();
    let mut exact = fixed(Storage::Half, Solver::Exact);
    exact.solver_config.smo.tol = 1e-5;
    let exact = Cascade::train(&data.set(), &exact, &mut NoProgress).unwrap();
    let cfg = Nystrom::new(480, 0).unwrap().with_tol(1e-4).unwrap();
    let mut params = fixed(Storage::Half, Solver::Nystrom(cfg));
    params.solver_config.smo.max_iter = Some(20_000);
    let nys = Cascade::train(&data.set(), &params, &mut NoProgress).unwrap();
    assert_eq!(nys.solver(), Solver::Nystrom(cfg));
    assert_eq!(nys.stored_samples(0), 160);
    let (pe, pn) = (exact.predict(xt).unwrap(), nys.predict(xt).unwrap());
    assert_eq!(compare(&pe, &pn).0, 1.0, "placements");
    let oracles = ridge_oracles(&data, dim);
    let mut worst = 0.0f64;
    for (i, p) in pn.iter().enumerate() {
        for (ch, f) in oracles[p.placement].iter().enumerate() {
            let f = f(&test.x[i * dim..(i + 1) * dim]);
            worst = worst.max((p.velocity[ch] - f).abs());
        }
    }
    // Half-precision landmarks against f32 rows in the oracle: measured 1.3e-4 m/s.
    assert!(worst < 1e-3, "{worst}");
    // The single-query path agrees with the batched one (summation order only).
    for (i, b) in pn.iter().enumerate() {
        let one = nys.predict_one(xt.row(i)).unwrap();
        assert_eq!(one.placement, b.placement);
        assert!((one.velocity - b.velocity).norm() < 1e-4, "query {i}");
    }
}

/// One channel's oracle: a query row in, the velocity out.
type Oracle = Box<dyn Fn(&[f32]) -> f64>;

/// Per placement of `data`, the kernel ridge oracle of each channel ([`kernel_ridge`] at
/// `C` = 10, the width `1 / dim`).
fn ridge_oracles(data: &Data, dim: usize) -> Vec<Vec<Oracle>> {
    (0..data.names.len())
        .map(|p| {
            let rows: Vec<usize> = (0..data.placement.len())
                .filter(|&i| data.placement[i] == p)
                .collect();
            let xs: Vec<Vec<f32>> = rows
                .iter()
                .map(|&i| data.x[i * dim..(i + 1) * dim].to_vec())
                .collect();
            (0..2)
                .map(|ch| {
                    let y: Vec<f64> = rows.iter().map(|&i| data.y[i][ch]).collect();
                    Box::new(kernel_ridge(&xs, &y, 1.0 / dim as f64, 10.0)) as Oracle
                })
                .collect()
        })
        .collect()
}

#[test]
fn nystrom_with_few_landmarks_stays_within_a_measured_bound_of_kernel_ridge() {
    // What the regressors approximate is kernel ridge regression on all of a placement's
    // rows (160 here); fewer landmarks per placement move them further from it.
    let data = make(3, 4, 40, 1);
    let test = make(3, 2, 20, 99);
    let dim = 24;
    let xt = FeatureMatrixRef::new(&test.x, dim).unwrap();
    let exact = Cascade::train(
        &data.set(),
        &fixed(Storage::DEFAULT, Solver::Exact),
        &mut NoProgress,
    )
    .unwrap();
    let pe = exact.predict(xt).unwrap();
    let oracles = ridge_oracles(&data, dim);
    // Measured (largest |dv| from kernel ridge over both channels, m/s): 80 landmarks
    // 0.0011, 40 0.0060, 20 0.027. Bounds 1.5x that.
    for (m, bound) in [(80, 0.0016), (40, 0.0091), (20, 0.040)] {
        let cfg = Nystrom::new(m, 3).unwrap();
        let model = Cascade::train(
            &data.set(),
            &fixed(Storage::DEFAULT, Solver::Nystrom(cfg)),
            &mut NoProgress,
        )
        .unwrap();
        let pn = model.predict(xt).unwrap();
        assert_eq!(compare(&pe, &pn).0, 1.0, "{m} landmarks: placements");
        let mut worst = 0.0f64;
        for (i, p) in pn.iter().enumerate() {
            for (ch, f) in oracles[p.placement].iter().enumerate() {
                let f = f(&test.x[i * dim..(i + 1) * dim]);
                worst = worst.max((p.velocity[ch] - f).abs());
            }
        }
        assert!(worst < bound, "{m} landmarks: {worst}");
    }
}

#[test]
fn nystrom_classifier_separates_separable_placements_and_the_grid_runs() {
    // Four placements, each shifting its own quarter of the features: separable.
    let data = make(4, 3, 20, 11);
    let test = make(4, 1, 25, 12);
    let xt = FeatureMatrixRef::new(&test.x, 24).unwrap();
    let params = CascadeParams {
        solver: Solver::Nystrom(Nystrom::new(64, 5).unwrap()),
        ..small_grid()
    };
    let mut events = Vec::new();
    let mut progress = |e: &ProgressEvent<'_>| {
        events.push((format!("{:?}", e.stage), e.done, e.total));
        true
    };
    let model = Cascade::train(&data.set(), &params, &mut progress).unwrap();
    let pred = model.predict(xt).unwrap();
    let correct = pred
        .iter()
        .zip(&test.placement)
        .filter(|(p, t)| p.placement == **t)
        .count();
    assert_eq!(correct, 100, "placement accuracy {correct}/100");
    // The grid: 4 placements × 2 channels × 2 values of C (ridge regression has no
    // epsilon: 0 in the table), the best point chosen per channel.
    assert_eq!(model.grid_results().len(), 16);
    for p in 0..4 {
        for (ch, &(c, e)) in model.regressor_params(p).unwrap().iter().enumerate() {
            let best = model
                .grid_results()
                .iter()
                .filter(|r| r.placement == data.names[p] && r.channel as usize == ch)
                .min_by(|a, b| a.mse.total_cmp(&b.mse))
                .unwrap();
            assert_eq!((best.c, best.epsilon), (c, e));
            assert_eq!(e, 0.0);
            assert!(best.mse.is_finite() && best.fold_mse.len() == 3);
        }
    }
    assert!(
        events
            .iter()
            .any(|e| e.0 == "Classifier" && e.1 == 6 && e.2 == 6)
    );
    assert!(
        events
            .iter()
            .any(|e| e.0.starts_with("Grid") && e.1 == 6 && e.2 == 6)
    );
    // Known placements skip the classifier.
    let forced = model.predict_with_placement(xt, 2).unwrap();
    assert_eq!(forced.len(), 100);
}

#[test]
fn a_nystrom_model_of_one_placement_has_no_classifier_and_round_trips() {
    let data = make(1, 4, 30, 21);
    let cfg = Nystrom::new(32, 1).unwrap();
    let params = fixed(Storage::DEFAULT, Solver::Nystrom(cfg));
    let model = Cascade::train(&data.set(), &params, &mut NoProgress).unwrap();
    assert_eq!(model.stored_samples(0), 32);
    let back = Cascade::from_bytes(&model.to_bytes().unwrap()).unwrap();
    assert_eq!(back, model);
    let x = data.set().features;
    for (i, b) in back.predict(x).unwrap().iter().enumerate() {
        let one = back.predict_one(x.row(i)).unwrap();
        assert_eq!((one.placement, b.placement), (0, 0));
        assert!((one.velocity - b.velocity).norm() < 1e-4, "row {i}");
    }
}

#[test]
fn nystrom_models_are_deterministic_compact_and_round_trip() {
    let data = make(2, 3, 30, 5);
    let cfg = Nystrom::new(32, 9).unwrap();
    let params = CascadeParams {
        speed: true,
        ..fixed(Storage::DEFAULT, Solver::Nystrom(cfg))
    };
    let a = Cascade::train(&data.set(), &params, &mut NoProgress).unwrap();
    let b = Cascade::train(&data.set(), &params, &mut NoProgress).unwrap();
    let bytes = a.to_bytes().unwrap();
    assert_eq!(
        bytes,
        b.to_bytes().unwrap(),
        "same data and seed, same bytes"
    );
    assert_eq!(&bytes[8..12], &8u32.to_le_bytes());
    assert_eq!(a.format_version(), 8);
    let other = CascadeParams {
        solver: Solver::Nystrom(Nystrom::new(32, 10).unwrap()),
        ..params.clone()
    };
    let c = Cascade::train(&data.set(), &other, &mut NoProgress).unwrap();
    assert_ne!(
        c.to_bytes().unwrap(),
        bytes,
        "another seed, other landmarks"
    );
    let back = Cascade::from_bytes(&bytes).unwrap();
    assert_eq!(back, a);
    let xt = data.set().features;
    assert_eq!(back.predict(xt).unwrap(), a.predict(xt).unwrap());
    assert!(back.speed_params(0).is_some());

    // Both kinds load from files side by side.
    let exact = Cascade::train(
        &data.set(),
        &fixed(Storage::DEFAULT, Solver::Exact),
        &mut NoProgress,
    )
    .unwrap();
    let dir = std::env::temp_dir().join(format!("ridi-regress-nystrom-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (pa, pe) = (dir.join("nystrom.ridi"), dir.join("exact.ridi"));
    a.save(&pa).unwrap();
    exact.save(&pe).unwrap();
    assert_eq!(Cascade::load(&pa).unwrap(), a);
    assert_eq!(Cascade::load(&pe).unwrap(), exact);
    assert_eq!(Cascade::load(&pe).unwrap().solver(), Solver::Exact);

    // An unknown kind tag (the payload's first byte) is refused, by name.
    let mut kind = bytes.clone();
    kind[24] = 7;
    let crc = crc32fast::hash(&kind[24..]);
    kind[20..24].copy_from_slice(&crc.to_le_bytes());
    match Cascade::from_bytes(&kind) {
        Err(RegressError::Decode(m)) => assert!(m.contains("unknown model kind 7"), "{m}"),
        other => panic!("expected a decode error, got {other:?}"),
    }
    // Kind 1, the first Nyström models' layout, is refused with what to do.
    let mut old = bytes.clone();
    old[24] = 1;
    let crc = crc32fast::hash(&old[24..]);
    old[20..24].copy_from_slice(&crc.to_le_bytes());
    match Cascade::from_bytes(&old) {
        Err(RegressError::Decode(m)) => assert!(m.contains("retrain it"), "{m}"),
        other => panic!("expected a decode error, got {other:?}"),
    }
    // A corrupt Nyström part (a weight made NaN, checksum fixed) is refused.
    let mut nan = bytes.clone();
    let at = nan.len() - 8;
    nan[at..].copy_from_slice(&f64::NAN.to_le_bytes());
    let crc = crc32fast::hash(&nan[24..]);
    nan[20..24].copy_from_slice(&crc.to_le_bytes());
    assert!(matches!(
        Cascade::from_bytes(&nan),
        Err(RegressError::Decode(_))
    ));
    // A payload cut short, or holding a value of no model, under a consistent header and
    // checksum (a file edited, or written by a broken build): said in words, not in bincode's
    // debug text (`UnexpectedEnd { additional: 1 }`, `InvalidIntegerType { .. }`).
    let reheader = |mut b: Vec<u8>| {
        let len = (b.len() - 24) as u64;
        b[12..20].copy_from_slice(&len.to_le_bytes());
        let crc = crc32fast::hash(&b[24..]);
        b[20..24].copy_from_slice(&crc.to_le_bytes());
        b
    };
    let mut cut = bytes.clone();
    cut.pop();
    let mut odd = bytes.clone();
    odd[25] = 0xff;
    for (b, words) in [
        (reheader(cut), "ends 1 byte before the model does"),
        (reheader(odd), "holds a value no model has"),
    ] {
        match Cascade::from_bytes(&b) {
            Err(e @ RegressError::Decode(_)) => {
                let m = e.to_string();
                assert!(m.contains(words) && !m.contains('{'), "{m}");
            }
            other => panic!("expected a decode error, got {other:?}"),
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();

    // The model is the landmarks and a weight per landmark and machine, not the rows.
    assert!(
        bytes.len() < exact.to_bytes().unwrap().len(),
        "{} bytes",
        bytes.len()
    );
    assert!(matches!(
        a.rounding_effect(xt, xt),
        Err(RegressError::InvalidParam(_))
    ));
}

#[test]
fn nystrom_settings_are_checked() {
    for bad in [0, 1, Nystrom::MAX_LANDMARKS + 1] {
        assert!(
            matches!(Nystrom::new(bad, 0), Err(RegressError::InvalidParam(_))),
            "{bad}"
        );
    }
    let ok = Nystrom::new(2, 0).unwrap();
    assert_eq!(
        (ok.landmarks(), ok.seed(), ok.tol()),
        (2, 0, Nystrom::DEFAULT_TOL)
    );
    for tol in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(ok.with_tol(tol).is_err(), "{tol}");
    }
    // The training set's own checks still come first.
    let data = make(2, 2, 10, 1);
    let params = CascadeParams {
        classifier_c: -1.0,
        ..fixed(Storage::DEFAULT, Solver::Nystrom(ok))
    };
    assert!(matches!(
        Cascade::train(&data.set(), &params, &mut NoProgress),
        Err(RegressError::InvalidParam(_))
    ));
}

#[test]
fn a_projected_nystrom_model_answers_as_it_was_trained() {
    // 240 values per row, so the projection applies (24-value rows fall back to half
    // precision). The Nyström machines compute their distances from the stored coordinates
    // in training as at prediction: one query equals the batched path, the model round-trips,
    // and it answers close to the same training on half-precision rows.
    let data = make_window(3, 4, 15, 1, 40);
    let d = data.config.feature_dim();
    let solver = Solver::Nystrom(Nystrom::new(32, 5).unwrap());
    assert_eq!(Storage::projected_for(&solver), Storage::NYSTROM_DEFAULT);
    assert_eq!(Storage::projected_for(&Solver::Exact), Storage::DEFAULT);
    let model = Cascade::train(
        &data.set(),
        &fixed(Storage::projected_for(&solver), solver),
        &mut NoProgress,
    )
    .unwrap();
    let (components, energy) = projected(&model);
    assert_eq!(components, 64, "the floor");
    assert!((0.9..=1.0).contains(&energy), "{energy}");
    let half = Cascade::train(&data.set(), &fixed(Storage::Half, solver), &mut NoProgress).unwrap();
    let test = make_window(3, 2, 20, 99, 40);
    let xt = FeatureMatrixRef::new(&test.x, d).unwrap();
    let batch = model.predict(xt).unwrap();
    let (same, dv) = compare(&batch, &half.predict(xt).unwrap());
    assert_eq!(same, 1.0);
    assert!(dv.iter().all(|v| *v < 2e-2), "{dv:?}");
    assert_one_query_agrees(&model, xt, &batch);
    assert_eq!(
        Cascade::from_bytes(&model.to_bytes().unwrap()).unwrap(),
        model
    );
}

/// A model file whose header declares more than the machine can allocate (a sparse file of
/// half a tebibyte, its size matching) is an error naming the file, not an abort in the
/// allocator.
#[cfg(target_os = "linux")]
#[test]
fn a_model_too_large_to_allocate_is_an_error() {
    let dir = std::env::temp_dir().join(format!("ridi-regress-huge-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("huge.ridi");
    let len: u64 = 1 << 39;
    let mut header = ridi_regress::MODEL_MAGIC.to_vec();
    header.extend_from_slice(&ridi_regress::MODEL_FORMAT_VERSION.to_le_bytes());
    header.extend_from_slice(&len.to_le_bytes());
    header.extend_from_slice(&0u32.to_le_bytes());
    std::fs::write(&path, &header).unwrap();
    std::fs::OpenOptions::new()
        .write(true)
        .open(&path)
        .unwrap()
        .set_len(24 + len)
        .unwrap();
    let e = Cascade::load(&path).unwrap_err();
    assert_names_file(&e, &path);
    assert!(
        e.to_string()
            .contains("more than this machine can allocate"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
