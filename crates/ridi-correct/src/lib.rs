//! Acceleration-bias correction, double integration and a streaming tracker for RIDI.
//!
//! RIDI regresses the horizontal velocity of a phone in its stabilized frame S every few
//! frames, then corrects the linear acceleration so that its integral agrees with those
//! velocities, and integrates the corrected acceleration into a trajectory. This crate holds
//! the second half: the correction (a linear least-squares problem solved exactly as one
//! banded sparse system), the integration, and a bounded-memory [`Tracker`] for live streams.
//! Inputs are plain slices of [`ridi_frames`] types.
//!
//! # The objective
//!
//! Unknowns: a device-frame bias `x_k` at knots every `knot_spacing` frames (plus a final knot
//! on the last frame, so the tail is covered), linearly interpolated in time; optionally the
//! initial world velocity `v0` ([`InitialVelocity::Estimate`]). With `a_I(f)` the linear
//! acceleration, `R_WI(f)` the orientation and the [trapezoidal rule](integrate()),
//!
//! ```text
//! v_W(f) = v0 + Σ_{1≤s≤f} ½ (A(s-1) + A(s)) (t_s - t_{s-1}),   A(f) = R_WI(f) (a_I(f) + x(f))
//!
//! E(x, v0) = Σ_j  w_h [ (e_xᵀ R_SW(r_j) v_W(r_j) - u_j,x)² + (e_zᵀ R_SW(r_j) v_W(r_j) - u_j,z)² ]
//!          + Σ_j  w_v (e_zᵀ v_W(r_j))²
//!          + λ Σ_k ||x_k||²
//! ```
//!
//! where `r_j` are the target frames, `u_j` the regressed S-frame velocities `[S-x, S-z]`,
//! `R_SW(f) = up_axis.stab_from_world(q_f, g_f)` (S as the regressor defined it,
//! [`CorrectionConfig::up_axis`]), and `e_zᵀ v_W` the world vertical velocity. Defaults
//! follow the paper: `w_h = w_v = 1`, `λ = 0.1`, knots every 50 frames, `v0 = 0`.
//! [`CorrectionConfig::original_cpp`] gives the original code's weighting (100, 1, 1 on the
//! squared terms). `E` is minimised exactly (no iteration, no approximation): see
//! [`Corrector`] for the banded reformulation and [`solve_dense`] for the textbook dense
//! solve it is tested against.
//!
//! # Example
//!
//! ```
//! use ridi_correct::{CorrectionConfig, Corrector, FrameVelocity};
//! use ridi_frames::{DeviceVec, ImuFrames, StabHorizontal, WorldFromDevice};
//!
//! // Two seconds at 200 Hz of a phone lying flat, its accelerometer biased by 0.05 m/s² along
//! // device x, while the walker stands still (regressed velocity zero every 10 frames).
//! let n = 401;
//! let time: Vec<f64> = (0..n).map(|i| i as f64 * 0.005).collect();
//! let linacce = vec![DeviceVec::new(0.05, 0.0, 0.0); n];
//! let orientation = vec![WorldFromDevice::identity(); n];
//! let gravity = vec![DeviceVec::new(0.0, 0.0, 9.81); n];
//! let gyro = vec![DeviceVec::ZERO; n];
//! let imu = ImuFrames::new(&time, &gyro, &linacce, &gravity, &orientation)?;
//! let targets: Vec<FrameVelocity> =
//!     (10..n).step_by(10).map(|frame| FrameVelocity { frame, velocity: StabHorizontal::ZERO }).collect();
//!
//! let config = CorrectionConfig { lambda: 1e-6, ..CorrectionConfig::default() };
//! let trajectory = Corrector::new(config)?.correct(&imu, &targets)?;
//! // Plain double integration would drift by 0.05 * 2² / 2 = 10 cm; corrected, it stays put.
//! let end = trajectory.horizontal()[n - 1];
//! assert!(end[0].abs() < 1e-3 && end[1].abs() < 1e-3);
//! // The bias is what the correction adds to the measurement: -0.05 along x.
//! assert!((trajectory.correction.bias.at(200, 1.0).x() + 0.05).abs() < 1e-3);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! For a live stream, feed [`ImuSample`](ridi_frames::ImuSample)s to a [`Tracker`] with a [`VelocityRegressor`]; see the
//! [`Tracker`] docs for the exact semantics of its windowed corrections.

mod config;
mod dense;
mod error;
mod input;
mod integrate;
mod knots;
mod placement;
mod regressor;
mod ring;
mod solve;
mod tracker;

pub use config::{CorrectionConfig, InitialVelocity};
pub use dense::{objective, solve_dense};
pub use error::CorrectError;
pub use input::FrameVelocity;
pub use integrate::{Integrator, Pose, corrected_acceleration, integrate, world_acceleration};
pub use knots::{BiasCurve, Knots};
pub use placement::{PlacementFilter, PlacementSmoother, TrailingMajority};
pub use regressor::{FrameWindow, RegressorError, RegressorOutput, VelocityRegressor};
/// The frame types the inputs are built from.
pub use ridi_frames;
pub use solve::{Correction, Corrector, Trajectory, correct};
pub use tracker::{
    CorrectionOutcome, GapPolicy, MAX_BUFFER, RegressionOutcome, Revision, Segment, TrackError,
    Tracker, TrackerConfig, TrackerStats, Update,
};

/// The README's example, compiled by `cargo test --doc` so that it cannot drift from the API.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
