//! Gravity alignment: the stabilized-IMU frame S.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use crate::frame::Stabilized;
use crate::rotation::{StabFromDevice, StabFromWorld, WorldFromDevice};
use crate::vector::{DeviceVec, Vec3, WorldVec};

/// Up axis of the stabilized frame S (+y, as in the original RIDI code).
pub const UP_S: Vec3<Stabilized> = Vec3::new(0.0, 1.0, 0.0);

/// Up axis of the world frame W.
pub const UP_W: WorldVec = Vec3::new(0.0, 0.0, 1.0);

/// Standard gravity, m/s^2.
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// The smallest rotation taking the measured gravity direction (device frame, pointing up as
/// Android's gravity sensor reports it) onto [`UP_S`].
///
/// Heading is kept: the rotation axis is horizontal. It is computed from the half-angle
/// quaternion `[|g| + g.up, g x up]`, which is exact near the parallel case (it tends to the
/// identity) and stays a proper rotation near the opposite case (a half turn about the
/// horizontal axis `g x up`). Only exactly opposite gravity leaves the axis free; then the half
/// turn is about device x, a proper rotation (the original C++ used a reflection here).
/// A zero or non-finite gravity gives the identity.
pub fn align_gravity(gravity: DeviceVec) -> StabFromDevice {
    let g = *gravity.vector();
    let up = Vector3::new(0.0, 1.0, 0.0);
    let norm = g.norm();
    if !(norm.is_finite() && norm > 0.0) {
        return StabFromDevice::identity();
    }
    let axis = g.cross(&up);
    // w = |g| + g_y loses every digit to cancellation when g points nearly down; the
    // algebraically equal (g_x^2 + g_z^2) / (|g| - g_y) keeps full precision there, so the
    // near-opposite rotations stay accurate right up to the exactly opposite case.
    let w = if g.y >= 0.0 {
        norm + g.y
    } else {
        (g.x * g.x + g.z * g.z) / (norm - g.y)
    };
    let q = Quaternion::from_parts(w, axis);
    if q.norm() <= norm * 1e-12 {
        return StabFromDevice::from_unit_quaternion(UnitQuaternion::from_axis_angle(
            &Vector3::x_axis(),
            std::f64::consts::PI,
        ));
    }
    StabFromDevice::from_unit_quaternion(UnitQuaternion::new_normalize(q))
}

/// World-to-S rotation of one frame: `align(g) * q*`, with `q` the device orientation and `g`
/// the device-frame gravity of that frame.
pub fn stab_from_world(orientation: WorldFromDevice, gravity: DeviceVec) -> StabFromWorld {
    align_gravity(gravity) * orientation.inverse()
}

/// Gravity as Android's gravity sensor reports it (pointing up, `magnitude` long), expressed in
/// the device frame of orientation `q`.
pub fn gravity_in_device(orientation: WorldFromDevice, magnitude: f64) -> DeviceVec {
    orientation.inverse() * (UP_W * magnitude)
}
