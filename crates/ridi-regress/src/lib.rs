//! Cascaded placement classification and velocity regression for RIDI.
//!
//! RIDI classifies the phone placement with an RBF C-SVC and regresses the two horizontal
//! velocity components in the stabilized frame S with one RBF epsilon-SVR per placement and
//! component. Optionally ([`CascadeParams::speed`], not in the paper) a third SVR per
//! placement regresses the speed and each velocity is scaled to it. This crate holds its own
//! SMO solver instead of using linfa-svm, whose solver
//! builds the full `n × n` kernel with a scalar loop and only handles binary classification.
//!
//! # Solver
//!
//! The solver is libsvm's: WSS3 second-order working-set selection, shrinking with
//! unshrinking and gradient reconstruction, epsilon-SVR as the 2l-variable dual, `rho` with
//! libsvm's sign (`f(x) = Σ coef K(sv, x) - rho`). Kernel values are `f32` and come from
//! blocked GEMM (faer) with precomputed squared norms, `K_ij = exp(-γ(|x_i|² + |x_j|² -
//! 2 x_i·x_j))`, either as a full matrix computed once in parallel (when it fits in
//! [`SolverConfig::kernel_memory`]) or as a bounded LRU row cache that computes missing rows in
//! batches. Gradients and dual variables are `f64`, and so are targets and predictions: the
//! velocities in S ([`StabHorizontal`](ridi_features::ridi_frames::StabHorizontal)) of
//! ridi-features' targets and ridi-correct's regressions, with
//! placements as `usize` indices into [`Cascade::placement_names`]. On x86-64 the hot loops (kernel
//! values, the solver's selection and gradient update, half-precision dot products) take AVX2
//! code paths when the running CPU has AVX2 and FMA, checked once per process.
//!
//! # Inputs
//!
//! Samples are the rows of a [`FeatureMatrixRef`](ridi_features::FeatureMatrixRef), the
//! borrowed view of ridi-features' row-major `f32` matrix; its checked constructors refuse a
//! NaN or infinite value, which the solver has no answer for
//! ([`RegressError::Features`]).
//!
//! # Reuse
//!
//! All fits of a placement index one kernel over its samples: the velocity (and speed)
//! channels, every grid point and every cross-validation fold of the grid search
//! ([`GridSpec`]). Fits along the `C` axis start from
//! the previous solution scaled by `C_new / C_old`. A trained [`Cascade`] stores each
//! placement's samples once in half precision, by default as coordinates on the few principal
//! directions that hold 99.99 % of the training features' variance (304 of 1200 on Tyrex
//! features), else as the features ([`Storage`]; ridi trains the Nyström solver with
//! [`Storage::NYSTROM_DEFAULT`], see [`Storage::projected_for`]): prediction is bound by the
//! bytes it streams, and
//! [`Cascade::rounding_effect`] measures what the compact storage costs. At prediction one
//! distance pass per placement feeds the classifier and is reused by the regressors
//! ([`Cascade::predict`] batches with GEMM, [`Cascade::predict_one`] streams the rows once).
//!
//! # Nyström solver
//!
//! [`CascadeParams::solver`] = [`Solver::Nystrom`] trains the same cascade approximately, in
//! time and memory linear in the rows, with a model whose size does not grow with them. Each
//! machine keeps `m` landmarks (default 2048) drawn uniformly with a fixed seed: the
//! classifier's from all training rows, each placement's regressors' from that placement's
//! rows. The RBF kernel (same widths) is projected on the span of the landmarks' feature maps,
//! `φ(x) = Λ^{-1/2} Uᵀ k(L, x)` with `K(L, L) = UΛUᵀ` (eigenvalues below `1e-6` of the largest
//! dropped), and every machine is linear on `φ`:
//!
//! - the one-vs-one classifier (same pairs, `C` and votes) by the dual coordinate descent of
//!   Hsieh et al. (2008) with LIBLINEAR's stopping rule ([`Nystrom::DEFAULT_TOL`]); its offset
//!   is a constant feature and so regularized;
//! - each regressor is kernel ridge regression, `½‖f‖² + (C/2) Σ (f(xᵢ) − yᵢ)²` with a free
//!   offset, solved in closed form (one `m × m` Cholesky factorization per placement and `C`):
//!   the squared loss replaces the exact path's epsilon-insensitive one (epsilon is unused,
//!   0 in the grid table), and the grid's cross-validation over `C` costs a factorization per
//!   fold and value from sums kept per fold, without another pass over the rows.
//!
//! What is approximated, then: the kernel beyond the landmarks' span, the classifier's offset,
//! and the regressors' loss; and, with projected storage, the distances, which training
//! computes from the stored principal coordinates (and each row's exact norm) as prediction
//! does, so a smaller share of the variance ([`Storage::NYSTROM_DEFAULT`]) changes the
//! kernel, not only its rounding. Training is `O(rows·m·(dim + m))` (the features and the sums,
//! GEMMs) plus `O(m³)` per placement; the model keeps the landmarks (in the same [`Storage`],
//! a placement's as its samples) with one weight per landmark and machine, `W^{-1/2}` folded
//! in; a query is one kernel row against the classifier's landmarks and one against its
//! placement's. With every row a landmark the regressors are exact kernel ridge regression
//! (tested against a dense solve) and the classifier gives the exact machine's placements
//! (tested against the SMO); with fewer landmarks the regressors approach kernel ridge
//! regression as they grow (tested bounds).
//!
//! Measured once on synthetic IMU-like features (`benches/synth.rs`, 1200 values, 4
//! placements, `C` = 10, epsilon = 0.01 for the exact solver, no grid; 2 cores of an Intel
//! Xeon, quiet), `cargo run --release -p ridi-regress --example svr_timing -- query N --solver
//! exact|nystrom --save F`, then `load-query N F`:
//!
//! | rows | solver | train | peak RSS | model | one query | held-out RMSE | placement |
//! | --- | --- | --- | --- | --- | --- | --- | --- |
//! | 20,000 | exact | 9.5 s | 552 MB | 15.0 MB | 0.30 ms | 0.180 m/s | 0.953 |
//! | 20,000 | Nyström 2048 | 14.2 s | 602 MB | 14.7 MB | 0.29 ms | 0.187 m/s | 0.936 |
//! | 40,000 | exact | 29.1 s | 1466 MB | 25.9 MB | 0.44 ms | 0.279 m/s | 0.962 |
//! | 40,000 | Nyström 2048 | 23.1 s | 1021 MB | 14.7 MB | 0.28 ms | 0.262 m/s | 0.954 |
//!
//! (one query: CPU time on one thread; held-out: 2000 windows of later sequences; these
//! features need 607 principal directions, so both models store half precision.) The model
//! and the query do not grow with the rows, and the held-out error stays the exact
//! solver's. On the real Tyrex features, whose exact models keep nearly every row as a support
//! vector, the difference in speed is larger: `docs/benchmarks.md` ("Training at scale") has
//! the figures on up to 430,000 rows, and the device protocol's accuracy.
//!
//! # Small or degenerate placements
//!
//! - A placement name without samples, or with fewer than
//!   [`CascadeParams::min_class_samples`] (default 10), fails with
//!   [`RegressError::NotEnoughData`] naming the placement.
//! - Grid search needs at least 2 sequences in a placement. A placement with fewer sequences
//!   than folds uses one fold per sequence. A placement with a single sequence fails with
//!   [`RegressError::TooFewSequences`].
//! - With one placement the classifier is skipped, and every query gets placement 0.
//!
//! # Model files
//!
//! [`Cascade::save`] and [`Cascade::load`] (or [`Cascade::to_bytes`] and
//! [`Cascade::from_bytes`]): the magic number [`MODEL_MAGIC`], the format version (7 for an
//! exact model, 8 = [`MODEL_FORMAT_VERSION`] for a Nyström one), a CRC32, and a bincode 2
//! payload including the [`ridi_features::FeatureConfig`]; atomic writes (a path that is not a
//! regular file, such as a link or a pipe, is refused), deterministic bytes; reading checks
//! every size and value a prediction uses. `Cascade`'s serde impls are that payload's codec,
//! not a format of their own: a model deserialized by serde alone is refused by prediction
//! (the [`Svr`] and [`Svc`] machines' serde forms are checked when read). That configuration is
//! how a model is used: its features must be computed with it, and its velocities are in the S
//! its `up_axis` defines (give the same `up_axis` to a correction of them, ridi-correct's
//! `CorrectionConfig::up_axis`).
//!
//! # Example
//!
//! ```
//! use ridi_features::ridi_frames::StabHorizontal;
//! use ridi_features::{FeatureConfig, FeatureMatrixRef};
//! use ridi_regress::{Cascade, CascadeParams, NoProgress, RegressorChoice, TrainingSet};
//!
//! // A tiny feature config: a 2-frame window of one channel gives 6 values per sample.
//! let config = FeatureConfig { window: 2, channels: vec![ridi_features::FeatureChannel::Gyro], ..FeatureConfig::default() };
//! // Two placements; the velocity depends on the features, the placement on their sign.
//! let mut x = Vec::new();
//! let (mut y, mut placement, mut group) = (Vec::new(), Vec::new(), Vec::new());
//! for i in 0..60 {
//!     let t = i as f32 / 60.0;
//!     let p = i % 2;
//!     let s = if p == 0 { 1.0 } else { -1.0 };
//!     x.extend([s + t, s - t, t, 0.5 * t, s, -t]);
//!     y.push(StabHorizontal::new(f64::from(t), f64::from(1.0 - t)));
//!     placement.push(p);
//!     group.push((i / 10) as u64);
//! }
//! let names = vec!["handheld".to_string(), "bag".to_string()];
//! let data = TrainingSet {
//!     features: FeatureMatrixRef::new(&x, 6)?,
//!     targets: &y,
//!     placements: &placement,
//!     placement_names: &names,
//!     groups: &group,
//!     feature_config: &config,
//! };
//! let params = CascadeParams {
//!     regressors: RegressorChoice::Fixed { c: 10.0, epsilon: 0.01 },
//!     ..CascadeParams::default()
//! };
//! let model = Cascade::train(&data, &params, &mut NoProgress)?;
//! let p = model.predict_one(&x[6..12])?;
//! assert_eq!(p.placement, 1);
//! assert!((p.velocity[0] - 1.0 / 60.0).abs() < 0.1);
//!
//! let bytes = model.to_bytes()?;
//! assert_eq!(Cascade::from_bytes(&bytes)?, model);
//! # Ok::<(), ridi_regress::RegressError>(())
//! ```
//!
//! # Features
//!
//! - `linfa` (off): linfa's `Fit` for [`SvrParams`] and [`SvcParams`] and `Predict` for
//!   [`Svr`] and [`Svc`] (on `f32` datasets), and the `linfa` and `ndarray` versions they are
//!   built against. Without it the crate depends on neither.
//! - `bench-internals` (off): kernel and cross-validation internals that the crate's benches
//!   and timing examples measure or reuse; not a supported API.
//!
//! # Public surface
//!
//! Every public item is at the crate root; the modules are private.

mod cache;
mod cascade;
mod config;
mod error;
mod expansion;
mod f16mat;
mod grid;
#[cfg(feature = "bench-internals")]
mod internals;
mod kernel;
mod linear;
#[cfg(feature = "linfa")]
mod linfa_impl;
mod matrix;
mod model_file;
mod nystrom;
mod progress;
mod projection;
mod ridge;
#[cfg(target_arch = "x86_64")]
mod simd;
mod smo;
mod store;
mod svc;
mod svr;

pub use crate::cascade::{
    Cascade, CascadeParams, Gamma, Prediction, RegressorChoice, RoundingEffect, Storage, StoredAs,
    TrainingSet,
};
pub use crate::config::{Precompute, SolverConfig};
pub use crate::error::RegressError;
pub use crate::grid::{GridRow, GridSpec};
#[cfg(feature = "bench-internals")]
#[doc(hidden)]
pub use crate::internals::{assign_folds, gram, sq_norms};
pub use crate::model_file::{MODEL_FORMAT_VERSION, MODEL_MAGIC};
pub use crate::nystrom::{Nystrom, Solver};
pub use crate::progress::{NoProgress, Progress, ProgressEvent, Stage};
pub use crate::smo::SmoSettings;
pub use crate::svc::{Svc, SvcParams};
pub use crate::svr::{FitInfo, Svr, SvrParams};
/// The feature configuration a model stores ([`Cascade::feature_config`]).
pub use ridi_features;
/// The versions the linfa adapters (feature `linfa`) are built against.
#[cfg(feature = "linfa")]
pub use {linfa, ndarray};

/// The README's example, compiled by `cargo test --doc` so that it cannot drift from the API.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
