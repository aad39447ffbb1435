//! Coordinate frames for pedestrian inertial navigation.
//!
//! Three frames matter in RIDI, and mixing them up was the most common question about the
//! original code, so here each is a type:
//!
//! - [`World`] (W): gravity-aligned, z up.
//! - [`Device`] (I): the Android sensor frame (x right, y top of the device, z out of screen).
//! - [`Stabilized`] (S): the device frame with pitch and roll removed by the smallest rotation
//!   taking the measured gravity onto [`UP_S`] (+y, as in the original). Horizontal axes: S-x
//!   (right) and S-z (back; forward is -z).
//!
//! [`Vec3<F>`] is a vector in frame `F`; [`Rot<To, From>`] a rotation that maps `Vec3<From>` to
//! `Vec3<To>`. [`Horizontal<F>`] is the part of a vector perpendicular to `F`'s up axis:
//! [`StabHorizontal`] (`[S-x, S-z]`, what RIDI regresses) and [`WorldHorizontal`]
//! (`[W-x, W-y]`). Rotations are Hamilton unit quaternions with `v_To = q v_From q*`; the device
//! orientation is [`WorldFromDevice`]. Quaternion component order is never implicit: use
//! [`Rot::from_wxyz`] or [`Rot::from_xyzw`] at file edges.
//!
//! # Gravity alignment
//!
//! [`align_gravity`] is the S-from-device rotation of one frame. It is the *smallest* rotation
//! taking gravity onto S-up, so its axis is horizontal and heading is kept (no twist about the
//! vertical). It is accurate right up to gravity pointing exactly down the S-up axis, where it
//! is a proper half turn (the original C++ used a reflection there). Test-time world to S is
//! [`stab_from_world`]`(q, g) = align(g) * q*`.
//!
//! Accurate is not well-conditioned: near that pole a small change of gravity turns S's
//! heading by a large angle. [`UpAxis`] names the definition of S a computation uses:
//! [`UpAxis::PlusY`] is the original's, [`UpAxis::PlusOrMinusY`] builds S on device -y while
//! the phone is upside down.
//!
//! # Orientation without a magnetometer
//!
//! The orientation estimator is a Mahony complementary filter on gyroscope and accelerometer
//! ([`estimate_orientation`], gains in [`FilterConfig`]): `ridi` trains and tracks with it by
//! default (a recorded orientation's tilt may be lost while running, its heading jumps).
//! [`OrientationFilter`] is the same filter one sample at a time, for live streams. It starts
//! with heading 0 ([`initial_orientation`]). [`tilt_error`], [`heading_difference`] and
//! [`orientation_errors`] compare any orientation track with a
//! reference (e.g. motion capture): tilt error in the device frame, heading drift as the yaw of
//! the relative rotation. [`HeadingCorrector`] (and [`with_reference_heading`] over whole
//! tracks) takes the slow part of a recorded orientation's heading onto the estimate, whose
//! heading drifts with the gyro bias, and keeps the estimate's tilt.
//!
//! # A recording's streams
//!
//! [`ImuFrames`] is the one borrowed view of a recording's IMU streams (time, gyro, linear
//! acceleration, gravity, orientation), checked once for equal lengths, that features, the
//! correction and a streaming regressor's window take; [`ImuSample`] is one frame of it, owned,
//! what a live tracker is pushed.
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
//!
//! // A phone held top down: the paper's S is ill-conditioned there, so PlusOrMinusY builds S
//! // on device -y; gravity still lands on S-up.
//! use ridi_frames::UpAxis;
//! let top_down = DeviceVec::new(0.01, -9.8, 0.02);
//! let up = UpAxis::PlusOrMinusY.align(top_down) * (top_down / top_down.norm());
//! assert!((up - UP_S).norm() < 1e-12);
//! assert_ne!(UpAxis::PlusOrMinusY.align(top_down), align_gravity(top_down));
//!
//! // A still phone tilted by 0.3 rad: the filter's tilt matches, heading starts at 0.
//! use ridi_frames::{estimate_orientation, gravity_in_device, tilt_error, FilterConfig};
//! let truth = WorldFromDevice::from_scaled_axis([0.3, 0.0, 0.0].into());
//! let time: Vec<f64> = (0..400).map(|i| i as f64 / 200.0).collect();
//! let gyro = vec![DeviceVec::ZERO; time.len()];
//! let acce = vec![gravity_in_device(truth, 9.81); time.len()];
//! let est = estimate_orientation(&time, &gyro, &acce, &FilterConfig::default()).unwrap();
//! assert!(tilt_error(est[399], truth) < 1e-9);
//! ```

mod estimate;
mod frame;
mod gravity;
mod heading;
mod horizontal;
mod imu;
mod rotation;
mod vector;

pub use estimate::{
    EstimateError, FilterConfig, OrientationErrors, OrientationFilter, estimate_orientation,
    estimate_orientation_from, heading_difference, initial_orientation, orientation_errors,
    tilt_error,
};
pub use frame::{Device, Frame, Stabilized, World};
pub use gravity::{
    STANDARD_GRAVITY, UP_S, UP_W, UpAxis, align_gravity, gravity_and_linacce, gravity_in_device,
    stab_from_world,
};
pub use heading::{HeadingConfig, HeadingCorrector, with_reference_heading};
pub use horizontal::{Horizontal, StabHorizontal, WorldHorizontal};
pub use imu::{ImuError, ImuFrames, ImuSample, ImuStream};
pub use rotation::{QuatError, Rot, StabFromDevice, StabFromWorld, WorldFromDevice};
pub use vector::{DeviceVec, StabVec, Vec3, WorldVec};

/// nalgebra, re-exported so downstream crates use the same version.
pub use nalgebra;

/// The README's example, compiled by `cargo test --doc` so that it cannot drift from the API.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
