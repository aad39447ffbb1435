//! Velocity targets on synthetic walks with analytically known answers.

use ridi_features::{
    FeatureConfig, FeatureError, GroundTruthView, SampleSchedule, compute_targets,
    stabilized_velocity,
};
use ridi_frames::nalgebra::Vector3;
use ridi_frames::{
    DeviceVec, Rot, StabHorizontal, UpAxis, World, WorldFromDevice, WorldVec, gravity_in_device,
};
use ridi_test_support::naive_smooth;

struct Walk {
    time: Vec<f64>,
    position: Vec<WorldVec>,
    orientation: Vec<WorldFromDevice>,
    gravity: Vec<DeviceVec>,
}

impl Walk {
    fn view(&self) -> GroundTruthView<'_> {
        GroundTruthView {
            time: &self.time,
            position: &self.position,
            orientation: &self.orientation,
            gravity: &self.gravity,
        }
    }
}

/// Constant velocity `v` with a constant device orientation, irregular time steps.
fn constant_walk(n: usize, v: WorldVec, q: WorldFromDevice) -> Walk {
    let time: Vec<f64> = (0..n)
        .map(|i| i as f64 * 0.005 + 0.001 * ((i * 7919) % 13) as f64 / 13.0)
        .collect();
    let position = time
        .iter()
        .map(|&t| WorldVec::new(3.0, -2.0, 1.0) + v * t)
        .collect();
    Walk {
        time,
        position,
        orientation: vec![q; n],
        gravity: vec![gravity_in_device(q, 9.81); n],
    }
}

#[test]
fn constant_velocity_with_yawed_and_pitched_phone() {
    // q = yaw(psi) * pitch(theta) about the device x axis. Pitch is removed by S, and S's
    // heading is the phone's yaw, so W -> S is R_x(-90 deg) R_z(-psi):
    //   S-x = cos(psi) vx + sin(psi) vy,   S-z = sin(psi) vx - cos(psi) vy,   S-y = vz.
    let (vx, vy, vz) = (0.8, -1.1, 0.05);
    for (psi, theta) in [(0.0, 0.0), (0.7, 0.3), (-2.5, -0.9), (3.0, 1.2)] {
        let q = Rot::<World, World>::from_axis_angle(&Vector3::z_axis(), psi)
            * WorldFromDevice::from_axis_angle(&Vector3::x_axis(), theta);
        let walk = constant_walk(700, WorldVec::new(vx, vy, vz), q);
        let config = FeatureConfig::default();
        let frames = SampleSchedule::training(&config).unwrap().frames(700);
        let t = compute_targets(&walk.view(), &config, &frames).unwrap();
        let (c, s) = (psi.cos(), psi.sin());
        let expected = [c * vx + s * vy, s * vx - c * vy];
        assert_eq!(t.frames, frames);
        assert_eq!(t.values.len(), frames.len());
        for v in &t.values {
            assert!(
                (v[0] - expected[0]).abs() < 1e-9,
                "{psi} {theta}: {v:?} vs {expected:?}"
            );
            assert!(
                (v[1] - expected[1]).abs() < 1e-9,
                "{psi} {theta}: {v:?} vs {expected:?}"
            );
        }
        // Every frame, including both ends where the reflection is involved.
        assert_eq!(t.velocity.len(), 700);
        for v in &t.velocity {
            assert!((v.x() - expected[0]).abs() < 1e-9 && (v.z() - expected[1]).abs() < 1e-9);
            assert!((v.y() - vz).abs() < 1e-9);
        }
    }
}

#[test]
fn plus_or_minus_y_gives_a_top_down_phone_the_upright_targets() {
    // Upright phone pitched forward, and the same phone turned top down about its screen
    // normal (device x and y negated): with PlusOrMinusY both get the same S velocity.
    let pitch = WorldFromDevice::from_axis_angle(&Vector3::x_axis(), 1.2);
    let half_turn = Rot::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI);
    let v = WorldVec::new(0.9, -0.4, 0.0);
    let upright = constant_walk(500, v, pitch);
    let top_down = constant_walk(500, v, pitch * half_turn);
    let config = FeatureConfig {
        up_axis: UpAxis::PlusOrMinusY,
        ..FeatureConfig::default()
    };
    let frames = SampleSchedule::training(&config).unwrap().frames(500);
    let a = compute_targets(&upright.view(), &config, &frames).unwrap();
    let b = compute_targets(&top_down.view(), &config, &frames).unwrap();
    for (x, y) in a.values.iter().zip(&b.values) {
        assert!(
            (x[0] - y[0]).abs() < 1e-9 && (x[1] - y[1]).abs() < 1e-9,
            "{x:?} vs {y:?}"
        );
    }
    assert!((a.values[0].norm() - v.norm()).abs() < 1e-9);
}

#[test]
fn forward_walk_is_negative_s_z() {
    // Phone held upright in front, screen towards the walker (device y up, z back toward the
    // person), walking along the direction the back of the phone faces (-z_I).
    let q = WorldFromDevice::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2);
    let forward_w = q * DeviceVec::new(0.0, 0.0, -1.0);
    let walk = constant_walk(300, forward_w * 1.4, q);
    let t = compute_targets(&walk.view(), &FeatureConfig::default(), &[250]).unwrap();
    assert!(
        (t.values[0] - StabHorizontal::new(0.0, -1.4)).norm() < 1e-9,
        "{:?}",
        t.values
    );
}

#[test]
fn smoothing_and_rotation_match_a_naive_computation() {
    // Varying speed, turning phone, per-frame gravity: compare with a direct computation.
    let n = 900;
    let time: Vec<f64> = (0..n).map(|i| i as f64 / 200.0).collect();
    let position: Vec<WorldVec> = time
        .iter()
        .map(|&t| {
            WorldVec::new(
                (1.3 * t).sin() * 2.0,
                1.1 * t + 0.3 * (5.0 * t).cos(),
                0.02 * t,
            )
        })
        .collect();
    let orientation: Vec<WorldFromDevice> = time
        .iter()
        .map(|&t| WorldFromDevice::from_scaled_axis(Vector3::new(0.3 * t.sin(), 0.2, 0.5 * t)))
        .collect();
    // Gravity sensor slightly off the true orientation, as on a real phone.
    let gravity: Vec<DeviceVec> = orientation
        .iter()
        .zip(&time)
        .map(|(q, &t)| gravity_in_device(*q, 9.8) + DeviceVec::new(0.1 * t.cos(), 0.0, 0.05))
        .collect();
    let walk = Walk {
        time,
        position,
        orientation,
        gravity,
    };
    let v = stabilized_velocity(&walk.view(), UpAxis::PlusY, 30.0, 4.0).unwrap();
    let mut comps = [vec![], vec![], vec![]];
    for i in 0..n {
        let j = if i + 1 < n { i } else { i - 1 };
        let vw = (walk.position[j + 1] - walk.position[j]) / (walk.time[j + 1] - walk.time[j]);
        let vs = ridi_frames::align_gravity(walk.gravity[i]) * (walk.orientation[i].inverse() * vw);
        for (c, x) in comps.iter_mut().zip(vs.to_array()) {
            c.push(x);
        }
    }
    let smoothed: Vec<Vec<f64>> = comps.iter().map(|c| naive_smooth(c, 30.0, 4.0)).collect();
    for i in 0..n {
        let got = v[i].to_array();
        for c in 0..3 {
            assert!((got[c] - smoothed[c][i]).abs() < 1e-12, "{i} {c}");
        }
    }
}

#[test]
fn long_sequences_are_smoothed_in_blocks_identically() {
    // Longer than the parallel block size: block seams must not show.
    let n = 20_000;
    let time: Vec<f64> = (0..n).map(|i| i as f64 / 200.0).collect();
    let position: Vec<WorldVec> = time
        .iter()
        .map(|&t| WorldVec::new((0.7 * t).sin(), (1.9 * t).cos(), 0.0))
        .collect();
    let walk = Walk {
        time,
        position,
        orientation: vec![WorldFromDevice::identity(); n],
        gravity: vec![DeviceVec::new(0.0, 0.0, 9.8); n],
    };
    let v = stabilized_velocity(&walk.view(), UpAxis::PlusY, 30.0, 4.0).unwrap();
    let sx: Vec<f64> = (0..n)
        .map(|i| {
            let j = if i + 1 < n { i } else { i - 1 };
            (walk.position[j + 1].x() - walk.position[j].x()) / 0.005
        })
        .collect();
    let expected = naive_smooth(&sx, 30.0, 4.0);
    for i in 0..n {
        assert!(
            (v[i].x() - expected[i]).abs() < 1e-11,
            "{i}: {} vs {}",
            v[i].x(),
            expected[i]
        );
    }
}

#[test]
fn edge_cases_and_errors() {
    let q = WorldFromDevice::identity();
    let config = FeatureConfig::default();
    let empty = constant_walk(0, WorldVec::ZERO, q);
    let t = compute_targets(&empty.view(), &config, &[]).unwrap();
    assert!(t.values.is_empty() && t.velocity.is_empty());
    let one = constant_walk(1, WorldVec::new(1.0, 0.0, 0.0), q);
    let t = compute_targets(&one.view(), &config, &[0]).unwrap();
    assert_eq!(t.values, vec![StabHorizontal::ZERO]);
    let walk = constant_walk(50, WorldVec::new(1.0, 0.0, 0.0), q);
    assert_eq!(
        compute_targets(&walk.view(), &config, &[50]).unwrap_err(),
        FeatureError::FrameOutOfRange {
            frame: 50,
            min: 0,
            max: 49
        }
    );
    let mut bad = constant_walk(50, WorldVec::new(1.0, 0.0, 0.0), q);
    bad.time[20] = bad.time[19];
    assert_eq!(
        compute_targets(&bad.view(), &config, &[]).unwrap_err(),
        FeatureError::TimeNotIncreasing { index: 20 }
    );
    let mut bad = constant_walk(50, WorldVec::new(1.0, 0.0, 0.0), q);
    bad.position[3] = WorldVec::new(f64::NAN, 0.0, 0.0);
    assert!(matches!(
        compute_targets(&bad.view(), &config, &[]),
        Err(FeatureError::NonFinite {
            what: "position",
            index: 3
        })
    ));
    let mut bad = constant_walk(50, WorldVec::new(1.0, 0.0, 0.0), q);
    bad.orientation[9] = WorldFromDevice::from_unit_quaternion(
        ridi_frames::nalgebra::UnitQuaternion::new_unchecked(
            ridi_frames::nalgebra::Quaternion::new(f64::NAN, 0.0, 0.0, 0.0),
        ),
    );
    assert!(matches!(
        compute_targets(&bad.view(), &config, &[]),
        Err(FeatureError::NonFinite {
            what: "orientation",
            index: 9
        })
    ));
    let short = GroundTruthView {
        gravity: &walk.gravity[..10],
        ..walk.view()
    };
    assert!(matches!(
        compute_targets(&short, &config, &[]),
        Err(FeatureError::LengthMismatch {
            what: "gravity",
            ..
        })
    ));
}
