//! Gravity alignment: the stabilized-IMU frame S.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::frame::{Device, Stabilized};
use crate::rotation::{Rot, StabFromDevice, StabFromWorld, WorldFromDevice};
use crate::vector::{DeviceVec, StabVec, Vec3, WorldVec};

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

/// Which device axis the stabilized frame S is built on: the definition of S.
///
/// Every S rotation of a frame depends only on that frame's gravity, so features, targets,
/// corrections and baselines that share an `UpAxis` share one S. A model records the one it
/// was trained with. Its serde names are the command line's (`plus-y`, `plus-or-minus-y`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum UpAxis {
    /// [`align_gravity`] at every attitude: the smallest rotation onto device +y, as in the
    /// original RIDI code.
    #[default]
    PlusY,
    /// Device +y, or device -y while the phone is upside down (gravity's direction cosine
    /// with +y below [`UpAxis::FLIP_COSINE`]); see [`UpAxis::align`].
    ///
    /// Near gravity opposite to +y the smallest rotation is ill-conditioned: a small change of
    /// gravity's horizontal part turns S's heading by a large angle, so a phone carried top
    /// down (swung in a hanging hand, say) gets an S that spins with every swing and features
    /// unlike any upright training data. Flipping keeps S as steady as for an upright phone.
    PlusOrMinusY,
}

/// Half a turn about device z (`[w, x, y, z] = [0, 0, 0, 1]`, exactly): swaps +y and -y, and
/// +x and -x.
const HALF_TURN_Z: Rot<Device, Device> = Rot::from_unit_quaternion(UnitQuaternion::new_unchecked(
    Quaternion::new(0.0, 0.0, 0.0, 1.0),
));

impl UpAxis {
    /// Below this cosine between gravity and device +y (about 134 degrees), [`PlusOrMinusY`]
    /// uses -y. Far from both poles, so that neither choice is ill-conditioned at the switch,
    /// and far below 0, where a phone held flat (texting, reading) fluctuates.
    ///
    /// [`PlusOrMinusY`]: UpAxis::PlusOrMinusY
    pub const FLIP_COSINE: f64 = -0.7;

    /// The S-from-device rotation of a frame with device-frame gravity `gravity` (pointing up).
    ///
    /// For [`UpAxis::PlusOrMinusY`] and an upside-down phone: a half turn about device z,
    /// which swaps +y and -y (and +x and -x), then [`align_gravity`]. An upside-down phone
    /// thus gets the S it would have had upright with the same face towards the walker: S-x
    /// then follows device -x. The switch is a jump in S's heading; only a window in which the
    /// phone turns over sees it.
    pub fn align(self, gravity: DeviceVec) -> StabFromDevice {
        if self == UpAxis::PlusOrMinusY && Self::is_upside_down(gravity) {
            align_gravity(HALF_TURN_Z * gravity) * HALF_TURN_Z
        } else {
            align_gravity(gravity)
        }
    }

    /// `true` when gravity (device frame, pointing up) is further than the flip threshold from
    /// device +y ([`UpAxis::FLIP_COSINE`]): where [`UpAxis::PlusOrMinusY`] builds S on -y.
    /// `false` for a zero or non-finite gravity, which [`align_gravity`] maps to the identity.
    pub fn is_upside_down(gravity: DeviceVec) -> bool {
        let g = gravity.vector();
        g.y < Self::FLIP_COSINE * g.norm()
    }

    /// World-to-S rotation of one frame: `align(g) * q*` with this axis's [`UpAxis::align`].
    pub fn stab_from_world(
        self,
        orientation: WorldFromDevice,
        gravity: DeviceVec,
    ) -> StabFromWorld {
        self.align(gravity) * orientation.inverse()
    }

    /// Heading of S's forward direction (-z) in the world: radians counter-clockwise from W +x
    /// about W up, the walking direction of a phone carried facing forward. What a step-based
    /// baseline walks along (ridi-eval's `pdr_trajectory` takes one per frame).
    ///
    /// ```
    /// use ridi_frames::{DeviceVec, UpAxis, WorldFromDevice};
    ///
    /// // A phone lying flat, screen up, top towards W +y: it faces W +y (90 degrees).
    /// let up = DeviceVec::new(0.0, 0.0, 9.81);
    /// let h = UpAxis::PlusY.forward_heading(WorldFromDevice::identity(), up);
    /// assert!((h - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
    /// ```
    pub fn forward_heading(self, orientation: WorldFromDevice, gravity: DeviceVec) -> f64 {
        let forward = StabVec::new(0.0, 0.0, -1.0);
        let f: WorldVec = self.stab_from_world(orientation, gravity).inverse() * forward;
        f.y().atan2(f.x())
    }
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

/// Gravity (pointing up, [`STANDARD_GRAVITY`] long) and linear acceleration (accelerometer
/// minus that gravity) of one sample, from an orientation estimated without the OS's gravity
/// sensor ([`estimate_orientation`](crate::estimate_orientation)): what stands in for the
/// gravity and linear acceleration streams, so that the three stay consistent.
pub fn gravity_and_linacce(
    orientation: WorldFromDevice,
    acce: DeviceVec,
) -> (DeviceVec, DeviceVec) {
    let gravity = gravity_in_device(orientation, STANDARD_GRAVITY);
    (gravity, acce - gravity)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn estimated_gravity_and_linear_acceleration_add_up_to_the_accelerometer() {
        // Tilted 0.4 rad about world x, pushed 1 m/s² along world z (up).
        let q = WorldFromDevice::from_axis_angle(&Vector3::x_axis(), 0.4);
        let acce = q.inverse() * crate::WorldVec::new(0.0, 0.0, STANDARD_GRAVITY + 1.0);
        let (g, lin) = gravity_and_linacce(q, acce);
        assert!((q * g - crate::WorldVec::new(0.0, 0.0, STANDARD_GRAVITY)).norm() < 1e-12);
        assert!((q * lin - crate::WorldVec::new(0.0, 0.0, 1.0)).norm() < 1e-12);
        assert!((g + lin - acce).norm() < 1e-12);
    }
}
