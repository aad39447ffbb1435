//! Property tests of the frame algebra and gravity alignment.

use proptest::prelude::*;
use ridi_frames::nalgebra::{Matrix3, Vector3};
use ridi_frames::{
    Device, DeviceVec, QuatError, Rot, StabFromDevice, StabFromWorld, Stabilized, UP_S, UP_W,
    UpAxis, World, WorldFromDevice, align_gravity, gravity_in_device, stab_from_world,
};

fn vec3(range: f64) -> impl Strategy<Value = Vector3<f64>> {
    (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| Vector3::new(x, y, z))
}

fn rotation() -> impl Strategy<Value = WorldFromDevice> {
    // A scaled axis with norm up to about 5.4 rad covers every rotation (angles wrap at pi).
    vec3(3.2).prop_map(WorldFromDevice::from_scaled_axis)
}

/// Gravity readings of any direction and plausible magnitude, never zero.
fn gravity() -> impl Strategy<Value = DeviceVec> {
    (vec3(1.0), 0.5..20.0f64).prop_filter_map("zero direction", |(d, m)| {
        (d.norm() > 1e-3).then(|| DeviceVec::from_vector(d.normalize() * m))
    })
}

fn assert_orthonormal(m: &Matrix3<f64>) -> Result<(), TestCaseError> {
    prop_assert!(
        (m.determinant() - 1.0).abs() < 1e-12,
        "det {}",
        m.determinant()
    );
    let e = (m * m.transpose() - Matrix3::identity()).abs().max();
    prop_assert!(e < 1e-12, "R R^T - I = {e}");
    Ok(())
}

fn up_of(g: DeviceVec) -> DeviceVec {
    g / g.norm()
}

proptest! {
    #[test]
    fn rotations_are_orthonormal(q in rotation(), g in gravity()) {
        assert_orthonormal(&q.matrix())?;
        assert_orthonormal(&align_gravity(g).matrix())?;
        assert_orthonormal(&stab_from_world(q, g).matrix())?;
    }

    #[test]
    fn gravity_maps_onto_up(g in gravity()) {
        let up = align_gravity(g) * up_of(g);
        prop_assert!((up - UP_S).norm() < 1e-12, "{up:?}");
    }

    #[test]
    fn stab_from_world_maps_world_up_to_s_up(q in rotation(), m in 1.0..12.0f64) {
        // With gravity consistent with the orientation, S differs from W only by a yaw and the
        // fixed axis swap: world up lands on S-up.
        let g = gravity_in_device(q, m);
        let up = stab_from_world(q, g) * UP_W;
        prop_assert!((up - UP_S).norm() < 1e-12, "{up:?}");
    }

    #[test]
    fn align_gravity_keeps_heading(g in gravity()) {
        let r = align_gravity(g);
        // No twist about the vertical: the rotation axis is horizontal in S (quaternion y part
        // zero) and perpendicular to gravity, and the angle is exactly the tilt angle.
        let [w, x, y, z] = r.to_wxyz();
        prop_assert!(y.abs() < 1e-12, "twist component {y}");
        let axis = Vector3::new(x, y, z);
        prop_assert!(axis.dot(up_of(g).vector()).abs() < 1e-12);
        let angle = 2.0 * axis.norm().atan2(w.abs());
        let tilt = up_of(g).vector().cross(UP_S.vector()).norm().atan2(up_of(g).y());
        prop_assert!((angle - tilt).abs() < 1e-9, "angle {angle} tilt {tilt}");
        // The device's horizontal axis g x up is left where it is: its azimuth is kept.
        let h = g.vector().cross(UP_S.vector());
        if h.norm() > 1e-6 {
            let hd = DeviceVec::from_vector(h.normalize());
            let hs = r * hd;
            prop_assert!((hs.vector() - hd.vector()).norm() < 1e-12);
        }
    }

    #[test]
    fn pitched_phone_keeps_world_heading(yaw in -3.1..3.1f64, pitch in -1.5..1.5f64) {
        // A phone yawed by `yaw` and pitched about its own x axis: S is the world yawed by the
        // same angle (plus the fixed y-up axis swap), whatever the pitch.
        let q = Rot::<World, World>::from_axis_angle(&Vector3::z_axis(), yaw)
            * WorldFromDevice::from_axis_angle(&Vector3::x_axis(), pitch);
        let s_w = stab_from_world(q, gravity_in_device(q, 9.8));
        let expected: StabFromWorld =
            Rot::<Stabilized, World>::from_axis_angle(&Vector3::x_axis(), -std::f64::consts::FRAC_PI_2)
                * Rot::<World, World>::from_axis_angle(&Vector3::z_axis(), -yaw);
        prop_assert!(s_w.angle_to(&expected) < 1e-9, "{s_w:?} vs {expected:?}");
    }

    #[test]
    fn round_trips_are_identities(q in rotation(), v in vec3(100.0)) {
        let v = DeviceVec::from_vector(v);
        prop_assert!(((q.inverse() * (q * v)) - v).norm() < 1e-12 * (1.0 + v.norm()));
        prop_assert!((q * q.inverse()).angle_to(&Rot::identity()) < 1e-12);
        prop_assert!((q.inverse() * q).angle_to(&Rot::identity()) < 1e-12);
        let a = WorldFromDevice::from_wxyz(q.to_wxyz()).unwrap();
        let b = WorldFromDevice::from_xyzw(q.to_xyzw()).unwrap();
        prop_assert!(a.angle_to(&q) < 1e-15 && b.angle_to(&q) < 1e-15);
        // xyzw and wxyz are permutations of one another, not the same array.
        let [w, x, y, z] = q.to_wxyz();
        prop_assert_eq!(q.to_xyzw(), [x, y, z, w]);
        let m = WorldFromDevice::from_matrix(&q.matrix()).unwrap();
        prop_assert!(m.angle_to(&q) < 1e-12);
    }

    #[test]
    fn nearly_orthonormal_matrices_give_the_nearest_rotation(
        q in rotation(),
        noise in prop::array::uniform9(-1.0..1.0f64),
        size in 1e-9..1e-4f64,
    ) {
        // Within the tolerance: each entry of MᵀM − I is at most 2·√3·size + 3·size², < 1e-3.
        let mut m = q.matrix();
        for (v, n) in m.iter_mut().zip(noise) {
            *v += size * n;
        }
        let r = WorldFromDevice::from_matrix(&m).unwrap();
        prop_assert!((r.quaternion().norm() - 1.0).abs() < 1e-14);
        assert_orthonormal(&r.matrix())?;
        // Nearest rotation in the Frobenius norm: at least as near as the unperturbed one.
        prop_assert!((r.matrix() - m).norm() <= (q.matrix() - m).norm() + 1e-14);
        prop_assert!(r.angle_to(&q) < 6.0 * size, "{} vs {size}", r.angle_to(&q));
    }

    #[test]
    fn reflections_and_scaled_rotations_are_refused(q in rotation(), scale in 0.0..3.0f64) {
        let reflected = WorldFromDevice::from_matrix(&-q.matrix());
        let refused = matches!(
            reflected,
            Err(QuatError::NotRotation { determinant, .. }) if determinant < -0.99
        );
        prop_assert!(refused, "{reflected:?}");
        let m = Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0)) * q.matrix();
        prop_assert!(WorldFromDevice::from_matrix(&m).is_err());
        // s R: |MᵀM − I| = |s² − 1| on the diagonal.
        let err = (scale * scale - 1.0).abs();
        let result = WorldFromDevice::from_matrix(&(q.matrix() * scale));
        if err > 1.01 * WorldFromDevice::ORTHONORMALITY_TOLERANCE {
            let refused = matches!(
                result,
                Err(QuatError::NotRotation { orthonormality_error, .. })
                    if (orthonormality_error - err).abs() < 1e-9
            );
            prop_assert!(refused, "{scale}: {result:?}");
        } else if err < 0.99 * WorldFromDevice::ORTHONORMALITY_TOLERANCE {
            prop_assert!(result.unwrap().angle_to(&q) < 1e-9);
        }
    }

    #[test]
    fn near_parallel_tends_to_identity(dir in vec3(1.0), eps in 1e-12..1e-3f64, m in 0.5..20.0f64) {
        // Gravity within eps of S-up: the rotation angle is the tilt (about eps), so the map is
        // continuous into the identity at exactly parallel gravity.
        let h = Vector3::new(dir.x, 0.0, dir.z);
        prop_assume!(h.norm() > 1e-3);
        let g = DeviceVec::from_vector((Vector3::y() + h.normalize() * eps).normalize() * m);
        let r = align_gravity(g);
        let angle = r.angle_to(&StabFromDevice::identity());
        prop_assert!((angle - eps.atan()).abs() <= 1e-12 + 1e-9 * eps, "{angle} vs {eps}");
        prop_assert!((r * up_of(g) - UP_S).norm() < 1e-12);
    }

    #[test]
    fn near_opposite_is_proper_and_continuous(
        dir in vec3(1.0), eps in 1e-10..1e-2f64, m in 0.5..20.0f64, delta in 1e-12..1e-9f64
    ) {
        let h = Vector3::new(dir.x, 0.0, dir.z);
        prop_assume!(h.norm() > 1e-3);
        let h = h.normalize();
        let down = -Vector3::y();
        let g = DeviceVec::from_vector((down + h * eps).normalize() * m);
        let r = align_gravity(g);
        assert_orthonormal(&r.matrix())?;
        prop_assert!((r * up_of(g) - UP_S).norm() < 1e-12, "{:?}", r * up_of(g));
        // A half turn, give or take the tilt from straight down...
        let angle = r.angle_to(&StabFromDevice::identity());
        prop_assert!((angle - (std::f64::consts::PI - eps.atan())).abs() < 1e-9);
        // ...about the horizontal axis perpendicular to the tilt direction.
        let [_, x, y, z] = r.to_wxyz();
        let axis = Vector3::new(x, y, z).normalize();
        prop_assert!(axis.dot(&h).abs() < 1e-9 && y.abs() < 1e-12);
        // Continuity: a slightly different gravity gives a slightly different rotation.
        let g2 = DeviceVec::from_vector((down + h * (eps * (1.0 + delta))).normalize() * m);
        let d = r.angle_to(&align_gravity(g2));
        prop_assert!(d < 1e-6, "jump {d}");
    }
}

fn half_turn_about_device_z() -> Rot<Device, Device> {
    Rot::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI)
}

proptest! {
    #[test]
    fn every_up_axis_maps_gravity_onto_up(g in gravity(), q in rotation(), m in 1.0..12.0f64) {
        for axis in [UpAxis::PlusY, UpAxis::PlusOrMinusY] {
            assert_orthonormal(&axis.align(g).matrix())?;
            let up = axis.align(g) * up_of(g);
            prop_assert!((up - UP_S).norm() < 1e-12, "{axis:?}: {up:?}");
            let up = axis.stab_from_world(q, gravity_in_device(q, m)) * UP_W;
            prop_assert!((up - UP_S).norm() < 1e-12, "{axis:?}: {up:?}");
        }
    }

    #[test]
    fn plus_or_minus_y_differs_only_upside_down(g in gravity()) {
        prop_assert_eq!(UpAxis::PlusY.align(g), align_gravity(g));
        let cosine = g.y() / g.norm();
        let same = UpAxis::PlusOrMinusY.align(g) == align_gravity(g);
        prop_assert_eq!(same, cosine >= UpAxis::FLIP_COSINE, "cosine {}", cosine);
    }

    #[test]
    fn upside_down_phone_gets_the_upright_s(
        yaw in -3.2..3.2f64,
        tilt_x in -0.5..0.5f64,
        tilt_z in -0.5..0.5f64,
        m in 1.0..12.0f64,
    ) {
        // An upright phone (device y within 0.71 rad of up) at any heading, and the same
        // phone turned top down about its screen normal: PlusOrMinusY gives both one S.
        let q = Rot::<World, World>::from_axis_angle(&Vector3::z_axis(), yaw)
            * WorldFromDevice::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2)
            * Rot::<Device, Device>::from_scaled_axis(Vector3::new(tilt_x, 0.0, tilt_z));
        let g = gravity_in_device(q, m);
        prop_assert!(g.y() / g.norm() > -UpAxis::FLIP_COSINE);
        let turned = q * half_turn_about_device_z();
        let s_upright = UpAxis::PlusOrMinusY.stab_from_world(q, g);
        let s_turned = UpAxis::PlusOrMinusY.stab_from_world(turned, gravity_in_device(turned, m));
        prop_assert!(s_upright.angle_to(&s_turned) < 1e-9, "{s_upright:?} vs {s_turned:?}");
    }
}

#[test]
fn plus_or_minus_y_is_steady_for_a_phone_top_down() {
    // Gravity a hundredth of a radian off device -y, once towards x and once towards z: the
    // original S turns by a quarter turn between the two, the flipped one by about 0.01 rad.
    let eps = 0.01;
    let a = DeviceVec::new(eps, -1.0, 0.0);
    let b = DeviceVec::new(0.0, -1.0, eps);
    let plus_y = UpAxis::PlusY.align(a).angle_to(&UpAxis::PlusY.align(b));
    let flipped = UpAxis::PlusOrMinusY
        .align(a)
        .angle_to(&UpAxis::PlusOrMinusY.align(b));
    assert!(plus_y > 1.0, "{plus_y}");
    assert!(flipped < 2.0 * eps, "{flipped}");
}

#[test]
fn exactly_opposite_is_a_proper_half_turn() {
    for m in [0.1, 1.0, 9.81, 1e6] {
        let g = DeviceVec::new(0.0, -m, 0.0);
        let r = align_gravity(g);
        assert!((r.matrix().determinant() - 1.0).abs() < 1e-12);
        assert!((r * DeviceVec::new(0.0, -1.0, 0.0) - UP_S).norm() < 1e-12);
        assert!((r.angle_to(&StabFromDevice::identity()) - std::f64::consts::PI).abs() < 1e-12);
    }
}

#[test]
fn degenerate_gravity_gives_identity() {
    for g in [
        DeviceVec::ZERO,
        DeviceVec::new(f64::NAN, 1.0, 0.0),
        DeviceVec::new(0.0, f64::INFINITY, 0.0),
    ] {
        assert_eq!(align_gravity(g), StabFromDevice::identity());
    }
}
