//! Feature extraction against the naive reference, schedules, configuration and errors.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use ridi_features::{
    FeatureChannel, FeatureConfig, FeatureError, FeatureExtractor, FeatureMatrix, SampleSchedule,
    Standardization, StandardizationFit, compute_features,
};
use ridi_frames::{DeviceVec, ImuFrames, UpAxis, WorldFromDevice};
use ridi_test_support::naive_features;

struct Imu {
    time: Vec<f64>,
    gyro: Vec<DeviceVec>,
    linacce: Vec<DeviceVec>,
    gravity: Vec<DeviceVec>,
    orientation: Vec<WorldFromDevice>,
}

impl Imu {
    /// Features read gyro, linear acceleration and gravity; time and orientation fill the rest.
    fn new(gyro: Vec<DeviceVec>, linacce: Vec<DeviceVec>, gravity: Vec<DeviceVec>) -> Self {
        let n = gravity.len();
        Imu {
            time: (0..n).map(|i| i as f64 / 200.0).collect(),
            gyro,
            linacce,
            gravity,
            orientation: vec![WorldFromDevice::identity(); n],
        }
    }

    fn view(&self) -> ImuFrames<'_> {
        ImuFrames::new(
            &self.time,
            &self.gyro,
            &self.linacce,
            &self.gravity,
            &self.orientation,
        )
        .unwrap()
    }

    /// The same frames with other gravity or linear acceleration.
    fn with<'a>(&'a self, linacce: &'a [DeviceVec], gravity: &'a [DeviceVec]) -> ImuFrames<'a> {
        ImuFrames {
            linacce,
            gravity,
            ..self.view()
        }
    }
}

fn random_imu(n: usize, seed: u64) -> Imu {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut v = |s: f64| {
        DeviceVec::new(
            rng.random_range(-s..s),
            rng.random_range(-s..s),
            rng.random_range(-s..s),
        )
    };
    let gyro = (0..n).map(|_| v(3.0)).collect();
    let linacce = (0..n).map(|_| v(8.0)).collect();
    // Gravity in every direction, including nearly and exactly downward ones.
    let mut gravity: Vec<DeviceVec> = (0..n)
        .map(|_| {
            let d = v(1.0);
            d / d.norm() * 9.8
        })
        .collect();
    if n > 3 {
        gravity[1] = DeviceVec::new(0.0, -9.8, 0.0);
        gravity[2] = DeviceVec::new(1e-9, -9.8, 0.0);
        gravity[3] = DeviceVec::new(0.0, 9.8, 0.0);
    }
    Imu::new(gyro, linacce, gravity)
}

fn max_rel_diff(fast: &FeatureMatrix, slow: &[Vec<f32>]) -> f64 {
    assert_eq!(fast.rows(), slow.len());
    let mut worst = 0.0f64;
    for (i, r) in slow.iter().enumerate() {
        for (a, b) in fast.row(i).iter().zip(r) {
            let d = f64::from((a - b).abs()) / (1.0 + f64::from(b.abs()));
            worst = worst.max(d);
        }
    }
    worst
}

#[test]
fn matches_naive_reference_on_random_data() {
    let imu = random_imu(900, 1);
    let config = FeatureConfig::default();
    let frames = SampleSchedule::every(&config, 7).unwrap().frames(900);
    assert_eq!(*frames.last().unwrap(), 893);
    let fast = compute_features(&imu.view(), &config, &frames).unwrap();
    let slow = naive_features(
        &imu.gyro,
        &imu.linacce,
        &imu.gravity,
        &frames,
        200,
        2.0,
        4.0,
    );
    let worst = max_rel_diff(&fast, &slow);
    // f32 smoothing against f64 smoothing rounded once to f32: a few f32 ulps.
    assert!(worst < 1e-6, "max relative difference {worst}");
    // The last valid frame is the sequence length (window [n - 200, n)).
    let end = compute_features(&imu.view(), &config, &[900]).unwrap();
    let slow_end = naive_features(&imu.gyro, &imu.linacce, &imu.gravity, &[900], 200, 2.0, 4.0);
    assert!(max_rel_diff(&end, &slow_end) < 1e-6);
}

#[test]
fn matches_naive_reference_for_short_windows_and_other_sigmas() {
    // Windows shorter than the kernel radius exercise repeated reflection inside the window.
    let imu = random_imu(120, 2);
    for (window, sigma) in [
        (5, 2.0),
        (1, 2.0),
        (16, 2.0),
        (17, 2.0),
        (40, 0.0),
        (30, 3.3),
    ] {
        let config = FeatureConfig {
            window,
            feature_sigma: sigma,
            ..FeatureConfig::default()
        };
        let frames = SampleSchedule::every(&config, 3).unwrap().frames(120);
        let fast = compute_features(&imu.view(), &config, &frames).unwrap();
        assert_eq!(fast.cols(), window * 6);
        let slow = naive_features(
            &imu.gyro,
            &imu.linacce,
            &imu.gravity,
            &frames,
            window,
            sigma,
            4.0,
        );
        let worst = max_rel_diff(&fast, &slow);
        assert!(worst < 1e-6, "window {window} sigma {sigma}: {worst}");
    }
}

#[test]
fn layout_is_time_major_gyro_then_linacce() {
    // A flat phone (gravity along device z): S = R_x(-90 deg) I, so (x, y, z)_I -> (x, z, -y)_S.
    // Constant inputs survive smoothing, so every time row is the rotated pair.
    let n = 250;
    let gyro = vec![DeviceVec::new(1.0, 2.0, 3.0); n];
    let linacce = vec![DeviceVec::new(4.0, 5.0, 6.0); n];
    let gravity = vec![DeviceVec::new(0.0, 0.0, 9.81); n];
    let imu = Imu::new(gyro, linacce, gravity);
    let x = compute_features(&imu.view(), &FeatureConfig::default(), &[200, 250]).unwrap();
    let expected = [1.0, 3.0, -2.0, 4.0, 6.0, -5.0];
    for r in 0..2 {
        for t in 0..200 {
            for (c, e) in expected.iter().enumerate() {
                let v = x.row(r)[t * 6 + c];
                assert!((v - e).abs() < 2e-6, "row {r} t {t} c {c}: {v}");
            }
        }
    }
    // Channel order follows the configuration.
    let swapped = FeatureConfig {
        channels: vec![FeatureChannel::LinearAcceleration, FeatureChannel::Gyro],
        ..FeatureConfig::default()
    };
    let y = compute_features(&imu.view(), &swapped, &[200]).unwrap();
    assert!((y.row(0)[0] - 4.0).abs() < 2e-6 && (y.row(0)[3] - 1.0).abs() < 2e-6);
    let gyro_only = FeatureConfig {
        channels: vec![FeatureChannel::Gyro],
        ..FeatureConfig::default()
    };
    assert_eq!(gyro_only.feature_dim(), 600);
    let z = compute_features(&imu.view(), &gyro_only, &[200]).unwrap();
    assert!((z.row(0)[599] + 2.0).abs() < 2e-6);
}

#[test]
fn each_frame_uses_its_own_gravity() {
    // Gravity alternates between two tilts; the same device vector lands differently in S.
    let n = 210;
    let gyro = vec![DeviceVec::new(0.0, 1.0, 0.0); n];
    let linacce = vec![DeviceVec::ZERO; n];
    let gravity: Vec<DeviceVec> = (0..n)
        .map(|i| {
            if i < 205 {
                DeviceVec::new(0.0, 9.8, 0.0)
            } else {
                DeviceVec::new(0.0, 0.0, 9.8)
            }
        })
        .collect();
    let imu = Imu::new(gyro, linacce, gravity);
    let config = FeatureConfig {
        feature_sigma: 0.0,
        ..FeatureConfig::default()
    };
    let x = compute_features(&imu.view(), &config, &[210]).unwrap();
    // Frame 10 of the window (device frame 10, gravity along y): device y is S-up.
    assert_eq!(&x.row(0)[10 * 6..10 * 6 + 3], &[0.0, 1.0, 0.0]);
    // Last frame (gravity along z): device y is S-forward, -z.
    let last = &x.row(0)[199 * 6..199 * 6 + 3];
    assert!(last[0].abs() < 1e-7 && last[1].abs() < 1e-7 && (last[2] + 1.0).abs() < 1e-7);
}

#[test]
fn plus_or_minus_y_gives_an_upside_down_phone_the_upright_features() {
    // The same motion measured by the phone turned top down about its screen normal: every
    // device vector has x and y negated. Gravity stays within 45 degrees of +y upright.
    let mut upright = random_imu(600, 11);
    for g in &mut upright.gravity {
        *g = DeviceVec::new(0.5 * g.x(), 9.8, 0.5 * g.z());
    }
    let turn = |v: &DeviceVec| DeviceVec::new(-v.x(), -v.y(), v.z());
    let top_down = Imu::new(
        upright.gyro.iter().map(turn).collect(),
        upright.linacce.iter().map(turn).collect(),
        upright.gravity.iter().map(turn).collect(),
    );
    let frames = [200, 377, 599];
    let with = |axis| FeatureConfig {
        up_axis: axis,
        ..FeatureConfig::default()
    };
    let reference = compute_features(&upright.view(), &with(UpAxis::PlusY), &frames).unwrap();
    let flipped = compute_features(&top_down.view(), &with(UpAxis::PlusOrMinusY), &frames).unwrap();
    for r in 0..frames.len() {
        for (a, b) in reference.row(r).iter().zip(flipped.row(r)) {
            assert!((a - b).abs() < 1e-4, "row {r}: {a} vs {b}");
        }
    }
    // The paper's S sees the top-down phone differently.
    let plain = compute_features(&top_down.view(), &with(UpAxis::PlusY), &frames).unwrap();
    let differs = plain
        .row(0)
        .iter()
        .zip(reference.row(0))
        .any(|(a, b)| (a - b).abs() > 0.1);
    assert!(differs);
}

#[test]
fn schedules() {
    let config = FeatureConfig::default();
    let train = SampleSchedule::training(&config).unwrap();
    assert_eq!((train.start(), train.step()), (200, 10));
    assert_eq!(train.frames(200), Vec::<usize>::new());
    assert_eq!(train.frames(201), vec![200]);
    assert_eq!(train.frames(221), vec![200, 210, 220]);
    assert_eq!(train.frames(0), Vec::<usize>::new());
    assert_eq!(
        SampleSchedule::every(&config, 1).unwrap().frames(203),
        vec![200, 201, 202]
    );
    assert_eq!(
        SampleSchedule::new(250, 25).unwrap().frames(300),
        vec![250, 275]
    );
    assert!(SampleSchedule::new(0, 0).is_err());
    let bad = FeatureConfig {
        step: 0,
        ..FeatureConfig::default()
    };
    assert!(SampleSchedule::training(&bad).is_err());
}

#[test]
fn short_sequences_give_zero_samples() {
    for n in [0, 1, 150, 200] {
        let imu = random_imu(n, 3);
        let config = FeatureConfig::default();
        let frames = SampleSchedule::training(&config).unwrap().frames(n);
        assert!(frames.is_empty());
        let x = compute_features(&imu.view(), &config, &frames).unwrap();
        assert_eq!((x.rows(), x.cols()), (0, 1200));
        assert_eq!(x.iter_rows().count(), 0);
    }
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let imu = random_imu(300, 4);
    let config = FeatureConfig::default();
    let short = ImuFrames {
        gyro: &imu.gyro[..299],
        ..imu.view()
    };
    assert!(matches!(
        compute_features(&short, &config, &[200]),
        Err(FeatureError::LengthMismatch { what: "gyro", .. })
    ));
    let unchecked = imu.with(&imu.linacce[..10], &imu.gravity);
    assert!(matches!(
        compute_features(&unchecked, &config, &[200]),
        Err(FeatureError::LengthMismatch {
            what: "linacce",
            ..
        })
    ));
    for (frame, ok) in [(199, false), (200, true), (300, true), (301, false)] {
        let r = compute_features(&imu.view(), &config, &[frame]);
        assert_eq!(r.is_ok(), ok, "frame {frame}: {r:?}");
    }
    let mut g = imu.gravity.clone();
    g[123] = DeviceVec::new(f64::NAN, 0.0, 9.8);
    let v = imu.with(&imu.linacce, &g);
    assert_eq!(
        compute_features(&v, &config, &[200]).unwrap_err(),
        FeatureError::NonFinite {
            what: "gravity",
            index: 123
        }
    );
    let mut a = imu.linacce.clone();
    a[7] = DeviceVec::new(0.0, f64::INFINITY, 0.0);
    let v = imu.with(&a, &imu.gravity);
    assert!(matches!(
        compute_features(&v, &config, &[200]),
        Err(FeatureError::NonFinite {
            what: "linacce",
            index: 7
        })
    ));
    let fx = FeatureExtractor::new(config.clone()).unwrap();
    let stab = fx.stabilize(&imu.view()).unwrap();
    let mut short = vec![0.0; 10];
    assert!(matches!(
        fx.row_into(&stab, 250, &mut short),
        Err(FeatureError::LengthMismatch { .. })
    ));
    let gyro_only = FeatureExtractor::new(FeatureConfig {
        channels: vec![FeatureChannel::Gyro],
        ..config.clone()
    })
    .unwrap();
    assert!(matches!(
        gyro_only.features(&stab, &[250]),
        Err(FeatureError::LengthMismatch { .. })
    ));
}

#[test]
fn invalid_configurations_are_rejected() {
    let base = FeatureConfig::default();
    let cases = [
        FeatureConfig {
            window: 0,
            ..base.clone()
        },
        FeatureConfig {
            step: 0,
            ..base.clone()
        },
        FeatureConfig {
            channels: vec![],
            ..base.clone()
        },
        FeatureConfig {
            channels: vec![FeatureChannel::Gyro, FeatureChannel::Gyro],
            ..base.clone()
        },
        FeatureConfig {
            feature_sigma: f64::NAN,
            ..base.clone()
        },
        FeatureConfig {
            target_sigma: -1.0,
            ..base.clone()
        },
        FeatureConfig {
            truncate: 0.0,
            ..base.clone()
        },
        FeatureConfig {
            standardization: Some(Standardization {
                mean: vec![0.0; 5],
                std: vec![1.0; 5],
            }),
            ..base.clone()
        },
        FeatureConfig {
            standardization: Some(Standardization {
                mean: vec![0.0; 1200],
                std: vec![0.0; 1200],
            }),
            ..base.clone()
        },
    ];
    for c in cases {
        assert!(c.validate().is_err(), "{c:?}");
        assert!(FeatureExtractor::new(c).is_err());
    }
    assert!(base.validate().is_ok());
}

#[test]
fn config_default_is_the_paper_and_round_trips_through_json() {
    let c = FeatureConfig::default();
    assert_eq!(
        (c.window, c.step, c.feature_dim(), c.row_width()),
        (200, 10, 1200, 6)
    );
    assert_eq!(
        (c.feature_sigma, c.target_sigma, c.truncate),
        (2.0, 30.0, 4.0)
    );
    assert_eq!(
        c.channels,
        vec![FeatureChannel::Gyro, FeatureChannel::LinearAcceleration]
    );
    assert_eq!(c.standardization, None);
    let with_std = FeatureConfig {
        standardization: Some(Standardization {
            mean: (0..1200).map(|i| i as f32 * 0.5).collect(),
            std: vec![2.0; 1200],
        }),
        ..c
    };
    let json = serde_json::to_string(&with_std).unwrap();
    assert!(json.contains("\"linear_acceleration\""));
    let back: FeatureConfig = serde_json::from_str(&json).unwrap();
    assert_eq!(back, with_std);
}

#[test]
fn standardization_fit_apply_and_fused_extraction() {
    let imu = random_imu(1500, 5);
    let config = FeatureConfig::default();
    let frames = SampleSchedule::every(&config, 3).unwrap().frames(1500);
    let raw = compute_features(&imu.view(), &config, &frames).unwrap();
    let (first, second) = raw.as_slice().split_at(200 * 1200);
    let a = FeatureMatrix::from_vec(200, 1200, first.to_vec()).unwrap();
    let b = FeatureMatrix::from_vec(raw.rows() - 200, 1200, second.to_vec()).unwrap();
    // Fitting over two matrices equals fitting over their concatenation.
    let s = Standardization::fit([&a, &b]).unwrap();
    let s_all = Standardization::fit([&raw]).unwrap();
    for i in 0..1200 {
        assert!((s.mean[i] - s_all.mean[i]).abs() <= 1e-6 * (1.0 + s.mean[i].abs()));
        assert!((s.std[i] - s_all.std[i]).abs() <= 1e-5 * s.std[i]);
    }
    // Column 0 by a direct two-pass computation.
    let col: Vec<f64> = raw.iter_rows().map(|r| f64::from(r[0])).collect();
    let m = col.iter().sum::<f64>() / col.len() as f64;
    let sd = (col.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / col.len() as f64).sqrt();
    assert!((f64::from(s.mean[0]) - m).abs() < 1e-6 && (f64::from(s.std[0]) - sd).abs() < 1e-5);

    let mut z = raw.clone();
    s.apply(&mut z).unwrap();
    let refit = Standardization::fit([&z]).unwrap();
    assert!(refit.mean.iter().all(|m| m.abs() < 1e-4));
    assert!(refit.std.iter().all(|s| (s - 1.0).abs() < 1e-4));

    // A configuration carrying the standardization applies it during extraction, bit for bit.
    let fused = compute_features(
        &imu.view(),
        &FeatureConfig {
            standardization: Some(s.clone()),
            ..config
        },
        &frames,
    )
    .unwrap();
    assert_eq!(fused, z);

    let mut wrong = FeatureMatrix::zeros(3, 10);
    assert!(s.apply(&mut wrong).is_err());
    assert!(s.apply_row(&mut [0.0; 3]).is_err());
    assert!(Standardization::fit(std::iter::empty()).is_err());
    let mut fit = StandardizationFit::new(2);
    assert!(fit.add_row(&[1.0, f32::NAN]).is_err());
    fit.add_row(&[1.0, 5.0]).unwrap();
    fit.add_row(&[3.0, 5.0]).unwrap();
    let s2 = fit.finish().unwrap();
    // Constant dimension: std 1 instead of a division by zero.
    assert_eq!(
        s2,
        Standardization {
            mean: vec![2.0, 5.0],
            std: vec![1.0, 1.0]
        }
    );
    // Built through its public fields, a zero or missing deviation is refused, not divided by.
    for bad in [
        Standardization {
            mean: vec![2.0, 5.0],
            std: vec![1.0, 0.0],
        },
        Standardization {
            mean: vec![2.0, 5.0],
            std: vec![1.0],
        },
    ] {
        assert!(bad.apply_row(&mut [1.0, 2.0]).is_err());
        assert!(bad.apply(&mut FeatureMatrix::zeros(3, 2)).is_err());
    }
}

#[test]
fn row_into_matches_matrix_rows() {
    let imu = random_imu(400, 6);
    let fx = FeatureExtractor::new(FeatureConfig::default()).unwrap();
    let stab = fx.stabilize(&imu.view()).unwrap();
    assert_eq!((stab.len(), stab.width()), (400, 6));
    let frames = [200, 333, 400];
    let m = fx.features(&stab, &frames).unwrap();
    let mut row = vec![0.0; fx.dim()];
    for (i, &f) in frames.iter().enumerate() {
        fx.row_into(&stab, f, &mut row).unwrap();
        assert_eq!(row, m.row(i));
    }
}
