//! Coordinate frames for pedestrian inertial navigation.
//!
//! Three frames matter in RIDI, and mixing them up was the most common question about the
//! original code, so here each is a type:
//!
//! - [`World`] (W): gravity-aligned, z up.
//! - [`Device`] (I): the Android sensor frame (x right, y top of the device, z out of screen).
//! - [`Stabilized`] (S): the device frame with pitch and roll removed by the smallest rotation
//!   taking the measured gravity onto [`UP_S`] (+y, as in the original). Horizontal axes: S-x
//!   and S-z (forward is -z).
//!
//! [`Vec3<F>`] is a vector in frame `F`; [`Rot<To, From>`] a rotation that maps `Vec3<From>` to
//! `Vec3<To>`. Rotations are Hamilton unit quaternions with `v_To = q v_From q*`; the device
//! orientation is [`WorldFromDevice`]. Quaternion component order is never implicit: use
//! [`Rot::from_wxyz`] or [`Rot::from_xyzw`] at file edges.
//!
//! # Example
//!
//! ```
//! use ridi_frames::{align_gravity, stab_from_world, DeviceVec, WorldFromDevice, UP_S};
//!
//! // A phone lying flat, screen up: gravity reads +9.8 along device z.
//! let g = DeviceVec::new(0.0, 0.0, 9.81);
//! let s_from_i = align_gravity(g);
//! let up = s_from_i * (g / g.norm());
//! assert!((up - UP_S).norm() < 1e-12);
//!
//! // A world-frame velocity seen in S needs the orientation and that frame's gravity.
//! let q = WorldFromDevice::identity();
//! let v_w = ridi_frames::WorldVec::new(1.0, 0.0, 0.0);
//! let v_s = stab_from_world(q, g) * v_w;
//! assert!((v_s.norm() - 1.0).abs() < 1e-12);
//! ```

mod frame;
mod gravity;
mod rotation;
mod vector;

pub use frame::{Device, Frame, Stabilized, World};
pub use gravity::{
    STANDARD_GRAVITY, UP_S, UP_W, align_gravity, gravity_in_device, stab_from_world,
};
pub use rotation::{QuatError, Rot, StabFromDevice, StabFromWorld, WorldFromDevice};
pub use vector::{DeviceVec, StabVec, Vec3, WorldVec};

/// nalgebra, re-exported so downstream crates use the same version.
pub use nalgebra;
