//! Frame markers.
//!
//! A frame is a zero-sized type used as a type parameter of [`Vec3`](crate::Vec3) and
//! [`Rot`](crate::Rot) so that the compiler rejects, say, adding a device-frame acceleration to
//! a world-frame velocity.

use std::fmt::Debug;

/// A coordinate frame marker.
pub trait Frame: Copy + Clone + Debug + Default + PartialEq + Send + Sync + 'static {
    /// Short name used in `Debug` output and documentation ("W", "I", "S").
    const NAME: &'static str;
}

/// World frame W: gravity-aligned, z up; heading is whatever the orientation source uses
/// (game rotation vector start, Tango start of service, mocap room).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct World;

/// Device frame I: the Android sensor frame. x to the right of the screen, y to the top of the
/// device, z out of the screen.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct Device;

/// Stabilized-IMU frame S: the device frame with pitch and roll removed by the smallest rotation
/// that takes the measured gravity direction onto [`UP_S`](crate::UP_S) (+y, as in the original
/// RIDI code). Heading follows the device. Horizontal plane: S-x (right) and S-z (back; forward
/// is -z).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct Stabilized;

impl Frame for World {
    const NAME: &'static str = "W";
}
impl Frame for Device {
    const NAME: &'static str = "I";
}
impl Frame for Stabilized {
    const NAME: &'static str = "S";
}
