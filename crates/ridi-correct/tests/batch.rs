//! Batch correction: agreement with the dense reference, recovery of a known bias, limits of
//! lambda, bad input.

mod common;

use common::{max_position_error, walk};
use proptest::prelude::*;
use ridi_correct::{
    BiasCurve, CorrectError, CorrectionConfig, Corrector, FrameVelocity, InitialVelocity,
    integrate, objective, solve_dense, world_acceleration,
};
use ridi_frames::{
    DeviceVec, ImuFrames, Rot, StabHorizontal, UpAxis, WorldFromDevice, WorldVec, nalgebra::Vector3,
};

fn max_bias_diff(a: &[DeviceVec], b: &[DeviceVec]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (*x - *y).norm())
        .fold(0.0, f64::max)
}

#[test]
fn banded_solve_matches_dense_reference() {
    let w = walk(1237, 50, WorldVec::new(0.3, -0.2, 0.0), true);
    let imu = w.imu();
    let cases: Vec<(CorrectionConfig, Vec<FrameVelocity>)> = vec![
        (CorrectionConfig::default(), w.targets(50, 50)),
        (CorrectionConfig::original_cpp(), w.targets(0, 30)),
        (
            CorrectionConfig {
                knot_spacing: 37,
                initial_velocity: InitialVelocity::Estimate,
                ..Default::default()
            },
            w.targets(13, 41),
        ),
        (
            CorrectionConfig {
                knot_spacing: 20,
                lambda: 1e-3,
                horizontal_weight: 3.0,
                vertical_weight: 0.5,
                initial_velocity: InitialVelocity::Fixed(WorldVec::new(0.1, 0.2, 0.0)),
                ..Default::default()
            },
            // Several targets per knot interval, and one on the very last frame.
            (0..1237)
                .step_by(7)
                .map(|f| w.target(f))
                .chain([w.target(1236)])
                .collect(),
        ),
        (
            CorrectionConfig {
                initial_velocity: InitialVelocity::Estimate,
                ..Default::default()
            },
            vec![w.target(600)],
        ),
    ];
    for (i, (config, targets)) in cases.iter().enumerate() {
        let sparse = Corrector::new(*config)
            .unwrap()
            .solve(&imu, targets)
            .unwrap();
        let dense = solve_dense(config, &imu, targets).unwrap();
        let scale = dense
            .bias
            .values()
            .iter()
            .map(|x| x.norm())
            .fold(1e-3, f64::max);
        let d = max_bias_diff(sparse.bias.values(), dense.bias.values());
        assert!(d < 1e-9 * scale.max(1.0), "case {i}: bias differs by {d}");
        let dv = (sparse.initial_velocity - dense.initial_velocity).norm();
        assert!(dv < 1e-9, "case {i}: v0 differs by {dv}");
        let e_sparse = objective(config, &imu, targets, &sparse).unwrap();
        let e_dense = objective(config, &imu, targets, &dense).unwrap();
        assert!(
            (e_sparse - e_dense).abs() <= 1e-9 * e_dense.max(1e-6),
            "case {i}: objective {e_sparse} vs {e_dense}"
        );
    }
}

#[test]
fn recovers_known_bias_and_trajectory() {
    // Exact targets more often than knots: the data alone determine the bias, and a tiny
    // lambda makes the estimate exact up to rounding.
    let w = walk(6001, 50, WorldVec::ZERO, true);
    let config = CorrectionConfig {
        lambda: 1e-9,
        ..Default::default()
    };
    let targets = w.targets(10, 10);
    let traj = Corrector::new(config)
        .unwrap()
        .correct(&w.imu(), &targets)
        .unwrap();
    let d = max_bias_diff(traj.correction.bias.values(), &w.bias_knots);
    assert!(d < 1e-5, "bias error {d}");
    let e = max_position_error(&traj.poses, &w.poses_true);
    assert!(e < 1e-5, "position error {e} m after 30 s");

    // Raw double integration drifts by metres over the same 30 s.
    let raw = integrate(
        &w.time,
        &world_acceleration(&w.imu()).unwrap(),
        WorldVec::ZERO,
        WorldVec::ZERO,
    )
    .unwrap();
    assert!(max_position_error(&raw, &w.poses_true) > 10.0);
}

#[test]
fn targets_are_read_in_the_configured_s() {
    // The walk's phone turned top down about its screen normal (device x and y negated). A
    // PlusOrMinusY regressor sees it as the upright phone, so its targets are the upright
    // walk's; read in the same S they give back the trajectory, read in the paper's they
    // do not, and the dense reference agrees on both.
    let w = walk(3001, 50, WorldVec::ZERO, false);
    let half_turn = Rot::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI);
    let turn = |v: &DeviceVec| DeviceVec::new(-v.x(), -v.y(), v.z());
    let orientation: Vec<WorldFromDevice> = w.orientation.iter().map(|q| *q * half_turn).collect();
    let linacce: Vec<DeviceVec> = w.linacce.iter().map(turn).collect();
    let gravity: Vec<DeviceVec> = w.gravity.iter().map(turn).collect();
    assert!(
        gravity
            .iter()
            .all(|g| g.y() < UpAxis::FLIP_COSINE * g.norm())
    );
    let imu = ImuFrames {
        time: &w.time,
        gyro: &w.gyro,
        linacce: &linacce,
        gravity: &gravity,
        orientation: &orientation,
    };
    let targets = w.targets(10, 10);
    let error = |up_axis| {
        let config = CorrectionConfig {
            lambda: 1e-9,
            up_axis,
            ..Default::default()
        };
        let traj = Corrector::new(config)
            .unwrap()
            .correct(&imu, &targets)
            .unwrap();
        let dense = solve_dense(&config, &imu, &targets).unwrap();
        let d = max_bias_diff(traj.correction.bias.values(), dense.bias.values());
        assert!(d < 1e-6, "{up_axis:?}: banded vs dense bias {d}");
        max_position_error(&traj.poses, &w.poses_true)
    };
    let e = error(UpAxis::PlusOrMinusY);
    assert!(e < 1e-5, "position error {e} m");
    let e = error(UpAxis::PlusY);
    assert!(e > 1.0, "position error {e} m");
}

#[test]
fn paper_configuration_removes_the_drift() {
    // Paper setup: knots and targets every 50 frames, lambda = 0.1. The prior shrinks the
    // bias a little, so the recovery is close rather than exact.
    let w = walk(12_000, 50, WorldVec::ZERO, false);
    let traj = Corrector::new(CorrectionConfig::default())
        .unwrap()
        .correct(&w.imu(), &w.targets(50, 50))
        .unwrap();
    let e = max_position_error(&traj.poses, &w.poses_true);
    assert!(e < 0.5, "position error {e} m after 60 s");
    // The tail after the last target is covered by the final knot.
    let kn = traj.correction.bias.knots().frames();
    assert_eq!(*kn.last().unwrap(), 11_999);
}

#[test]
fn estimates_a_nonzero_initial_velocity() {
    let v0 = WorldVec::new(1.1, -0.4, 0.0);
    let w = walk(3001, 50, v0, false);
    let config = CorrectionConfig {
        lambda: 1e-9,
        initial_velocity: InitialVelocity::Estimate,
        ..Default::default()
    };
    let c = Corrector::new(config)
        .unwrap()
        .solve(&w.imu(), &w.targets(0, 10))
        .unwrap();
    assert!(
        (c.initial_velocity - v0).norm() < 1e-6,
        "{:?}",
        c.initial_velocity
    );
    assert!(max_bias_diff(c.bias.values(), &w.bias_knots) < 1e-5);
}

#[test]
fn huge_lambda_is_plain_double_integration() {
    let w = walk(2001, 50, WorldVec::ZERO, false);
    let config = CorrectionConfig {
        lambda: 1e12,
        ..Default::default()
    };
    let traj = Corrector::new(config)
        .unwrap()
        .correct(&w.imu(), &w.targets(50, 50))
        .unwrap();
    let raw = integrate(
        &w.time,
        &world_acceleration(&w.imu()).unwrap(),
        WorldVec::ZERO,
        WorldVec::ZERO,
    )
    .unwrap();
    let e = max_position_error(&traj.poses, &raw);
    assert!(e < 1e-9, "differs from plain integration by {e} m");
    assert!(
        traj.correction
            .bias
            .values()
            .iter()
            .all(|x| x.norm() < 1e-10)
    );
}

#[test]
fn tiny_lambda_follows_the_targets() {
    // Targets that no real walk would produce (a step in speed): with lambda -> 0 the
    // corrected velocity still passes through every one of them, and stays level.
    let w = walk(2001, 50, WorldVec::ZERO, false);
    let targets: Vec<FrameVelocity> = (50..2001)
        .step_by(50)
        .map(|f| FrameVelocity {
            frame: f,
            velocity: StabHorizontal::new(
                if f < 1000 { 0.2 } else { -0.5 },
                if f < 1000 { -1.4 } else { 0.3 },
            ),
        })
        .collect();
    let config = CorrectionConfig {
        lambda: 1e-10,
        ..Default::default()
    };
    let traj = Corrector::new(config)
        .unwrap()
        .correct(&w.imu(), &targets)
        .unwrap();
    for t in &targets {
        let v = traj.poses[t.frame].velocity;
        let vs = ridi_frames::stab_from_world(w.orientation[t.frame], w.gravity[t.frame]) * v;
        assert!((vs.x() - t.velocity[0]).abs() < 1e-6, "frame {}", t.frame);
        assert!((vs.z() - t.velocity[1]).abs() < 1e-6, "frame {}", t.frame);
        assert!(v.z().abs() < 1e-6);
    }
}

#[test]
fn symbolic_factorization_is_reused_for_the_same_shape() {
    let w = walk(1001, 50, WorldVec::ZERO, false);
    let mut c = Corrector::new(CorrectionConfig::default()).unwrap();
    let t1 = w.targets(50, 50);
    let a = c.solve(&w.imu(), &t1).unwrap();
    let mut t2 = t1.clone();
    for t in &mut t2 {
        t.velocity += StabHorizontal::new(0.1, 0.0);
    }
    let b = c.solve(&w.imu(), &t2).unwrap();
    assert_eq!(c.symbolic_factorizations(), 1);
    assert_ne!(a, b);
    c.solve(&w.imu(), &w.targets(30, 50)).unwrap();
    assert_eq!(c.symbolic_factorizations(), 2);
    // Back to the first shape: same answer as a fresh corrector.
    let again = c.solve(&w.imu(), &t1).unwrap();
    let fresh = Corrector::new(CorrectionConfig::default())
        .unwrap()
        .solve(&w.imu(), &t1)
        .unwrap();
    assert_eq!(again, fresh);
}

#[test]
fn no_targets_means_no_correction() {
    let w = walk(300, 50, WorldVec::ZERO, false);
    let mut c = Corrector::new(CorrectionConfig::default()).unwrap();
    let r = c.solve(&w.imu(), &[]).unwrap();
    assert!(r.bias.values().iter().all(|x| *x == DeviceVec::ZERO));
    let mut est = Corrector::new(CorrectionConfig {
        initial_velocity: InitialVelocity::Estimate,
        ..Default::default()
    })
    .unwrap();
    assert_eq!(est.solve(&w.imu(), &[]), Err(CorrectError::NoTargets));
}

#[test]
fn bad_input_is_a_clear_error() {
    let w = walk(400, 50, WorldVec::ZERO, false);
    let targets = w.targets(50, 50);
    let mut c = Corrector::new(CorrectionConfig::default()).unwrap();

    let mut lin = w.linacce.clone();
    lin[123] = DeviceVec::new(f64::NAN, 0.0, 0.0);
    let imu = ImuFrames {
        linacce: &lin,
        ..w.imu()
    };
    assert_eq!(
        c.solve(&imu, &targets),
        Err(CorrectError::NonFinite {
            what: "linacce",
            index: 123
        })
    );

    let mut time = w.time.clone();
    time[200] = time[198];
    let imu = ImuFrames {
        time: &time,
        ..w.imu()
    };
    assert_eq!(
        c.solve(&imu, &targets),
        Err(CorrectError::TimeNotIncreasing { frame: 200 })
    );

    let mut time = w.time.clone();
    for t in &mut time[300..] {
        *t += 4.4;
    }
    let imu = ImuFrames {
        time: &time,
        ..w.imu()
    };
    assert!(matches!(
        c.solve(&imu, &targets),
        Err(CorrectError::Gap { frame: 300, .. })
    ));

    let imu = ImuFrames {
        gravity: &w.gravity[..399],
        ..w.imu()
    };
    assert!(matches!(
        c.solve(&imu, &targets),
        Err(CorrectError::LengthMismatch {
            what: "gravity",
            ..
        })
    ));

    let out_of_range = [FrameVelocity {
        frame: 400,
        velocity: StabHorizontal::ZERO,
    }];
    assert!(matches!(
        c.solve(&w.imu(), &out_of_range),
        Err(CorrectError::TargetOutOfRange { .. })
    ));
    let unsorted = [w.target(100), w.target(50)];
    assert_eq!(
        c.solve(&w.imu(), &unsorted),
        Err(CorrectError::TargetsNotIncreasing { index: 1 })
    );
    let nan_target = [FrameVelocity {
        frame: 10,
        velocity: StabHorizontal::new(f64::NAN, 0.0),
    }];
    let e = c.solve(&w.imu(), &nan_target).unwrap_err();
    assert_eq!(
        e,
        CorrectError::NonFiniteTarget {
            index: 0,
            frame: 10
        }
    );
    assert_eq!(e.to_string(), "velocity target 0 (frame 10) is not finite");

    // Gravity perpendicular to the orientation's vertical: S is undefined.
    let mut grav = w.gravity.clone();
    grav[100] = w.orientation[100].inverse() * WorldVec::new(9.81, 0.0, 0.0);
    let imu = ImuFrames {
        gravity: &grav,
        ..w.imu()
    };
    assert_eq!(
        c.solve(&imu, &targets),
        Err(CorrectError::DegenerateFrame { frame: 100 })
    );

    for bad in [
        CorrectionConfig {
            lambda: 0.0,
            ..Default::default()
        },
        CorrectionConfig {
            lambda: f64::INFINITY,
            ..Default::default()
        },
        CorrectionConfig {
            knot_spacing: 0,
            ..Default::default()
        },
        CorrectionConfig {
            vertical_weight: 0.0,
            ..Default::default()
        },
        CorrectionConfig {
            horizontal_weight: f64::NAN,
            ..Default::default()
        },
    ] {
        assert!(matches!(
            Corrector::new(bad),
            Err(CorrectError::InvalidConfig(_))
        ));
    }
    let empty = ImuFrames {
        time: &[],
        gyro: &[],
        linacce: &[],
        gravity: &[],
        orientation: &[],
    };
    assert_eq!(c.solve(&empty, &[]), Err(CorrectError::Empty));
}

#[test]
fn extreme_weights_never_panic_or_return_non_finite_values() {
    let w = walk(500, 50, WorldVec::ZERO, false);
    let targets = w.targets(50, 50);
    for lambda in [1e-300, 1e-30, 1e30, 1e300] {
        for weight in [1e-150, 1.0, 1e150] {
            let config = CorrectionConfig {
                lambda,
                horizontal_weight: weight,
                ..Default::default()
            };
            match Corrector::new(config).unwrap().correct(&w.imu(), &targets) {
                Ok(t) => assert!(
                    t.poses.iter().all(|p| p.position.is_finite()),
                    "lambda {lambda}, weight {weight}"
                ),
                Err(e) => assert!(matches!(
                    e,
                    CorrectError::NotPositiveDefinite | CorrectError::DegenerateFrame { .. }
                )),
            }
        }
    }
}

#[test]
fn single_frame_and_target_at_start() {
    let time = [0.0];
    let lin = [DeviceVec::new(1.0, 0.0, 0.0)];
    let ori = [WorldFromDevice::identity()];
    let grav = [DeviceVec::new(0.0, 0.0, 9.8)];
    let imu = ImuFrames::new(&time, &[DeviceVec::ZERO], &lin, &grav, &ori).unwrap();
    let targets = [FrameVelocity {
        frame: 0,
        velocity: StabHorizontal::new(1.0, 0.0),
    }];
    let mut c = Corrector::new(CorrectionConfig {
        initial_velocity: InitialVelocity::Estimate,
        ..Default::default()
    })
    .unwrap();
    let r = c.solve(&imu, &targets).unwrap();
    // S-x is device x, which is world x here.
    assert!((r.initial_velocity - WorldVec::new(1.0, 0.0, 0.0)).norm() < 1e-12);
    let traj = Corrector::new(CorrectionConfig::default())
        .unwrap()
        .correct(&imu, &targets)
        .unwrap();
    assert_eq!(traj.poses.len(), 1);
    assert_eq!(traj.horizontal(), vec![[0.0, 0.0]]);
}

/// A random problem: irregular clock, random accelerations and orientations, random targets.
struct Problem {
    time: Vec<f64>,
    /// Zeros: the correction does not read the gyro.
    gyro: Vec<DeviceVec>,
    lin: Vec<DeviceVec>,
    ori: Vec<WorldFromDevice>,
    grav: Vec<DeviceVec>,
    targets: Vec<FrameVelocity>,
}

impl Problem {
    fn imu(&self) -> ImuFrames<'_> {
        ImuFrames {
            time: &self.time,
            gyro: &self.gyro,
            linacce: &self.lin,
            gravity: &self.grav,
            orientation: &self.ori,
        }
    }
}

fn random_problem(seed: u64, n: usize, every: usize, first: usize) -> Problem {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut t = 0.0;
    let mut time = Vec::with_capacity(n);
    for _ in 0..n {
        time.push(t);
        t += rng.random_range(0.003..0.008);
    }
    let lin = (0..n)
        .map(|_| {
            DeviceVec::new(
                rng.random_range(-2.0..2.0),
                rng.random_range(-2.0..2.0),
                rng.random_range(-2.0..2.0),
            )
        })
        .collect();
    let ori: Vec<WorldFromDevice> = (0..n)
        .map(|_| {
            WorldFromDevice::from_scaled_axis(Vector3::new(
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
            ))
        })
        .collect();
    let grav = ori
        .iter()
        .map(|q| ridi_frames::gravity_in_device(*q, 9.8))
        .collect();
    let targets = (first..n)
        .step_by(every)
        .map(|f| FrameVelocity {
            frame: f,
            velocity: StabHorizontal::new(rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0)),
        })
        .collect();
    Problem {
        gyro: vec![DeviceVec::ZERO; time.len()],
        time,
        lin,
        ori,
        grav,
        targets,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn banded_equals_dense_on_random_problems(
        seed in any::<u64>(),
        n in 1usize..400,
        spacing in 1usize..80,
        every in 1usize..90,
        first in 0usize..60,
        estimate in any::<bool>(),
        log_lambda in -4.0f64..3.0,
    ) {
        let p = random_problem(seed, n, every, first);
        let (imu, targets) = (p.imu(), &p.targets);
        let config = CorrectionConfig {
            knot_spacing: spacing,
            lambda: 10f64.powf(log_lambda),
            initial_velocity: if estimate { InitialVelocity::Estimate } else { InitialVelocity::Fixed(WorldVec::new(0.5, 0.0, 0.1)) },
            ..Default::default()
        };
        let sparse = Corrector::new(config).unwrap().solve(&imu, targets);
        let dense = solve_dense(&config, &imu, targets);
        match (sparse, dense) {
            (Ok(s), Ok(d)) => {
                let e_s = objective(&config, &imu, targets, &s).unwrap();
                let e_d = objective(&config, &imu, targets, &d).unwrap();
                // The exact minimiser can only be matched, never beaten, by the other.
                prop_assert!((e_s - e_d).abs() <= 1e-8 * e_d.max(1.0), "{} vs {}", e_s, e_d);
                let scale = d.bias.values().iter().map(|x| x.norm()).fold(1.0, f64::max);
                prop_assert!(max_bias_diff(s.bias.values(), d.bias.values()) < 1e-7 * scale);
            }
            (Err(a), Err(b)) => prop_assert_eq!(a, b),
            (a, b) => prop_assert!(false, "sparse {:?} vs dense {:?}", a.err(), b.err()),
        }
    }

    #[test]
    fn solution_is_a_minimum(seed in any::<u64>(), k in 0usize..5, axis in 0usize..3, h in -0.5f64..0.5) {
        let p = random_problem(seed, 250, 25, 25);
        let (imu, targets) = (p.imu(), &p.targets);
        let config = CorrectionConfig::default();
        let best = Corrector::new(config).unwrap().solve(&imu, targets).unwrap();
        let e0 = objective(&config, &imu, targets, &best).unwrap();
        let mut d = [0.0; 3];
        d[axis] = h;
        let mut values = best.bias.values().to_vec();
        values[k] += DeviceVec::from_array(d);
        let mut other = best.clone();
        other.bias = BiasCurve::new(best.bias.knots().clone(), values).unwrap();
        let e1 = objective(&config, &imu, targets, &other).unwrap();
        prop_assert!(e1 >= e0 - 1e-9 * e0.max(1.0));
    }
}
