//! Feature and target extraction for RIDI.
//!
//! # Features
//!
//! The feature of sample frame `f` is the window of frames `[f - window, f)` (200 in the
//! paper) of gyro and linear acceleration, each frame rotated into its own stabilized frame S
//! with `up_axis.align(gravity[i])` ([`ridi_frames::UpAxis`]; the paper's is +y,
//! [`ridi_frames::align_gravity`]), each channel smoothed inside the window by a Gaussian
//! (sigma 2, 17 taps, scipy's `'reflect'` borders at the window ends), then flattened
//! time-major: row `t` of the window holds gyro x y z then linear acceleration x y z, so the
//! feature has `window * 3 * channels` = 1200 values.
//!
//! [`FeatureExtractor::stabilize`] rotates every frame of a sequence once into
//! [`StabilizedChannels`]; [`FeatureExtractor::features`] then smooths each window straight
//! into its row of a row-major [`FeatureMatrix`], rows in parallel with rayon and no
//! allocation per window ([`FeatureExtractor::features_into`] also reuses the matrix, and
//! [`FeatureExtractor::row_into`] computes one row for streaming use). [`compute_features`]
//! does both steps. [`FeatureMatrixRef`] is the matrix's borrowed view, checked for whole rows
//! of finite values: what ridi-regress's solvers take. Frames come from a
//! [`SampleSchedule`]: every `step` frames from the first full window (`FeatureConfig`'s
//! default step is 10; `ridi train` takes 20).
//!
//! # Configuration and standardization
//!
//! [`FeatureConfig`] (serde) holds everything that shapes a feature or target; [`Default`] is
//! the paper. Model files embed it so that tracking computes the features a model was trained
//! on. Its optional [`Standardization`] (per-dimension mean and std fitted on the training set
//! with [`Standardization::fit`] or [`StandardizationFit`]) is applied by every extraction with
//! that configuration; the original RIDI had none.
//!
//! # Targets
//!
//! [`compute_targets`]: forward-difference ground-truth velocity, rotated into the device
//! frame with the ground-truth orientation and into S with that frame's gravity, smoothed with
//! sigma 30 over the whole sequence; the target is `[S-x, S-z]` in `f64` (S-x right, S-z back,
//! so forward walking is negative S-z, as in the original).
//!
//! # Turned copies
//!
//! [`YawTurn`] turns a feature row and its target about S-up (+y), which is what the phone
//! would have measured carried turned by the opposite angle about the vertical;
//! [`turned_copies`] adds evenly spaced turned copies of every training row (the pipeline's
//! default training adds one), so that regressors do not tie the velocity to the headings at
//! which the training people happened to carry their phones.
//!
//! # Smoothing
//!
//! [`gaussian_filter1d`] reproduces `scipy.ndimage.gaussian_filter1d(x, sigma,
//! truncate=4.0, mode='reflect')`, including repeated reflection for signals shorter than the
//! kernel radius.
//!
//! # Example
//!
//! ```
//! use ridi_features::{
//!     FeatureConfig, FeatureExtractor, GroundTruthView, SampleSchedule, compute_targets,
//! };
//! use ridi_frames::{DeviceVec, ImuFrames, WorldFromDevice, WorldVec};
//!
//! // Ten seconds at 200 Hz of a flat phone walking along world +y at 1.2 m/s.
//! let n = 2000;
//! let time: Vec<f64> = (0..n).map(|i| i as f64 / 200.0).collect();
//! let gyro = vec![DeviceVec::new(0.0, 0.0, 0.1); n];
//! let linacce = vec![DeviceVec::new(0.2, 0.0, 0.0); n];
//! let gravity = vec![DeviceVec::new(0.0, 0.0, 9.81); n];
//! let position: Vec<WorldVec> = time.iter().map(|&t| WorldVec::new(0.0, 1.2 * t, 0.0)).collect();
//! let orientation = vec![WorldFromDevice::identity(); n];
//!
//! let config = FeatureConfig::default();
//! let frames = SampleSchedule::training(&config)?.frames(n);
//! assert_eq!(frames.len(), 180); // 200, 210, ..., 1990
//!
//! let fx = FeatureExtractor::new(config.clone())?;
//! let imu = ImuFrames::new(&time, &gyro, &linacce, &gravity, &orientation)?;
//! let stab = fx.stabilize(&imu)?;
//! let x = fx.features(&stab, &frames)?;
//! assert_eq!((x.rows(), x.cols()), (180, 1200));
//! // A flat phone's z axis is S-up (y): the gyro's z rate appears as S-y.
//! assert!((x.row(0)[1] - 0.1).abs() < 1e-6);
//!
//! let gt = GroundTruthView { time: &time, position: &position, orientation: &orientation, gravity: &gravity };
//! let y = compute_targets(&gt, &config, &frames)?;
//! // Walking along the phone's top (device y), i.e. forward: S-z = -1.2.
//! assert!(y.values.iter().all(|v| v[0].abs() < 1e-9 && (v[1] + 1.2).abs() < 1e-9));
//! # Ok::<(), ridi_features::FeatureError>(())
//! ```

mod config;
mod error;
mod features;
mod gaussian;
mod matrix;
mod targets;
mod turn;

pub use config::{FeatureChannel, FeatureConfig, Orientation, Standardization, StandardizationFit};
pub use error::FeatureError;
pub use features::{FeatureExtractor, SampleSchedule, StabilizedChannels, compute_features};
pub use gaussian::{gaussian_filter1d, gaussian_kernel};
pub use matrix::{FeatureMatrix, FeatureMatrixRef};
/// The frame types the inputs are built from.
pub use ridi_frames;
pub use targets::{GroundTruthView, Targets, compute_targets, stabilized_velocity};
pub use turn::{TurnedRows, YawTurn, turned_copies};

/// The README's example, compiled by `cargo test --doc` so that it cannot drift from the API.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
