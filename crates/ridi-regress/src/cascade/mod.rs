//! The RIDI cascade: a placement classifier, then two epsilon-SVRs per placement for the two
//! horizontal velocity components in the stabilized frame S.
//!
//! Storage: each placement keeps its samples once in half precision, as coordinates on the
//! leading principal directions of the training features or as the features themselves
//! ([`Storage`]: a query is bound by the bytes it streams), ordered so that the classifier's
//! support vectors of that placement come first, followed by the other samples that either
//! regressor uses.
//! Prediction computes the squared distances of a query to the classifier part of every
//! placement, classifies, and then reuses those distances for the regressors of the predicted
//! placement, so every stored row is read once. A query is projected first when the samples
//! are. Batches go through GEMM (half-precision rows widened to `f32` a tile at a time); a
//! single query streams the rows once (a fused half-precision GEMV for half-precision rows)
//! and reuses thread-local buffers.
//!
//! One module per job: `params` (what to train with), `train` (the training set, its checks and
//! the fits), `approx` (the fits by the Nyström solver), `predict` (the batched and the single-query path), `rounding` (what the compact
//! storage changes) and `validate` (the consistency checks of a decoded model file). This
//! module holds the trained model and what it reports about itself.

mod approx;
mod params;
mod predict;
mod rounding;
mod train;
mod validate;

use ridi_features::FeatureConfig;
use serde::{Deserialize, Serialize};

use crate::grid::GridRow;
use crate::nystrom::{Nystrom, Solver};
use crate::projection::Projection;
use crate::store::SampleRows;
use crate::svr::FitInfo;

pub use self::params::{CascadeParams, Gamma, RegressorChoice, Storage};
pub use self::predict::Prediction;
pub use self::rounding::RoundingEffect;
pub use self::train::TrainingSet;

/// A trained cascade (what the model file holds).
///
/// Its serde impls are the model file's payload codec, not a storage format of their own: a
/// `Cascade` deserialized by serde alone lacks what [`Cascade::from_bytes`] recomputes, adds
/// and checks (the Nyström part, the samples' norms, the consistency checks), and its
/// predictions are refused. Store a model with [`Cascade::to_bytes`] or [`Cascade::save`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Cascade {
    feature_config: FeatureConfig,
    dim: usize,
    placements: Vec<String>,
    classifier: Option<ClassifierHead>,
    regressor_gamma: f32,
    classes: Vec<ClassModel>,
    grid: Vec<GridRow>,
    /// Principal directions the samples are stored on (`None`: half-precision features).
    projection: Option<Projection>,
    /// The Nyström solver's landmarks and weights ([`Solver::Nystrom`]); its placements then
    /// store no samples. Not in the exact model's payload (whose bytes stay those of format
    /// 7): the model file writes it after the cascade, as format 8.
    #[serde(skip)]
    nystrom: Option<Box<NystromParts>>,
    /// Trained, or decoded and checked ([`Cascade::finish_decode`]): `false` only for one
    /// deserialized by serde alone, which prediction refuses.
    #[serde(skip)]
    checked: bool,
}

/// What a Nyström model adds to the cascade: the classifier's landmarks, drawn from all
/// rows, and one weight per landmark and classifier pair (`W^{-1/2}` folded in). Each
/// placement keeps its regressors' own landmarks as its samples and their folded weights as
/// its coefficients, as an exact model keeps support vectors; the offsets stay where the
/// exact model keeps them (`ClassifierHead::rho`, `ClassModel::reg_rho`, `SpeedRegressor::rho`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct NystromParts {
    /// Landmark draw (the landmarks asked for and the seed).
    config: Nystrom,
    /// The classifier's landmarks (none without a classifier).
    landmarks: SampleRows,
    /// Squared norms of the stored landmarks: recomputed on load, not stored.
    #[serde(skip)]
    norms: Vec<f32>,
    /// `landmarks × pairs` row-major: classifier weights.
    clf_weights: Vec<f64>,
}

/// How a trained model stores its samples ([`Cascade::stored_as`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StoredAs {
    /// Every feature value in half precision.
    Half,
    /// Principal-component coordinates.
    Projected {
        /// Coordinates per sample.
        components: usize,
        /// Share of the training variance they hold.
        energy: f64,
    },
}

/// The one-vs-one placement classifier: its width, `C`, class pairs `(a, b)` (`a < b`), their
/// offsets and fit reports; the coefficients are stored with each placement's samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct ClassifierHead {
    gamma: f32,
    c: f64,
    pairs: Vec<(u32, u32)>,
    rho: Vec<f64>,
    info: Vec<FitInfo>,
}

/// One placement: samples stored once, shared by the classifier (first `n_classifier` rows)
/// and both regressors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct ClassModel {
    samples: SampleRows,
    /// Squared norms as the distances need them ([`SampleRows::norms`]): recomputed on load,
    /// not stored.
    #[serde(skip)]
    norms: Vec<f32>,
    n_classifier: usize,
    /// The classifier pairs (one-vs-one) this placement takes part in, ascending: its samples
    /// have coefficients in those only.
    clf_pairs: Vec<u32>,
    /// `n_classifier × clf_pairs` row-major.
    clf_coef: Vec<f64>,
    /// `samples × 2` row-major.
    reg_coef: Vec<f64>,
    reg_rho: [f64; 2],
    /// `(C, epsilon)` per channel.
    reg_params: [(f64, f64); 2],
    reg_info: [FitInfo; 2],
    /// The speed regressor ([`CascadeParams::speed`]); its coefficients are the third column
    /// of `reg_coef`.
    speed: Option<SpeedRegressor>,
    n_train: usize,
}

/// Offset, `(C, epsilon)` and fit report of a placement's speed regressor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct SpeedRegressor {
    rho: f64,
    params: (f64, f64),
    info: FitInfo,
}

impl ClassModel {
    /// Columns of `reg_coef`: S-x, S-z and, with a speed regressor, the speed.
    fn channels(&self) -> usize {
        2 + usize::from(self.speed.is_some())
    }
}

impl Cascade {
    /// Placement names, in class-index order.
    pub fn placement_names(&self) -> &[String] {
        &self.placements
    }

    /// Feature configuration the model was trained with.
    pub fn feature_config(&self) -> &FeatureConfig {
        &self.feature_config
    }

    /// Feature dimension.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Grid-search results table (empty when the regressor parameters were fixed).
    pub fn grid_results(&self) -> &[GridRow] {
        &self.grid
    }

    /// Chosen `(C, epsilon)` of the two regressors of placement `p`.
    pub fn regressor_params(&self, p: usize) -> Option<[(f64, f64); 2]> {
        self.classes.get(p).map(|c| c.reg_params)
    }

    /// Chosen `(C, epsilon)` of the speed regressor of placement `p`, if the model has one
    /// ([`CascadeParams::speed`]).
    pub fn speed_params(&self, p: usize) -> Option<(f64, f64)> {
        self.classes.get(p)?.speed.as_ref().map(|s| s.params)
    }

    /// How the samples are stored.
    pub fn stored_as(&self) -> StoredAs {
        match &self.projection {
            None => StoredAs::Half,
            Some(p) => StoredAs::Projected {
                components: p.dim(),
                energy: p.energy(),
            },
        }
    }

    /// Stored samples of placement `p` (shared by its classifier part and its regressors);
    /// for a Nyström model, its regressors' landmarks.
    pub fn stored_samples(&self, p: usize) -> usize {
        self.classes.get(p).map_or(0, |c| c.samples.rows())
    }

    /// Training windows of placement `p` (turned copies included).
    pub fn training_windows(&self, p: usize) -> usize {
        self.classes.get(p).map_or(0, |c| c.n_train)
    }

    /// How the model was trained: [`Solver::Exact`], or [`Solver::Nystrom`] with the most
    /// landmarks one machine holds (fewer than asked for when the training set had fewer
    /// rows) and their seed.
    pub fn solver(&self) -> Solver {
        match &self.nystrom {
            None => Solver::Exact,
            Some(n) => {
                let held = (0..self.classes.len())
                    .map(|p| self.stored_samples(p))
                    .chain([n.landmarks.rows()])
                    .max()
                    .unwrap_or(0);
                Solver::Nystrom(
                    Nystrom::new(held.max(2), n.config.seed())
                        .and_then(|c| c.with_tol(n.config.tol()))
                        .unwrap_or(n.config),
                )
            }
        }
    }

    /// The Nyström part the model file writes after the cascade (format 8).
    pub(crate) fn nystrom_parts(&self) -> Option<&NystromParts> {
        self.nystrom.as_deref()
    }

    /// Attaches a decoded Nyström part (before [`Self::finish_decode`]).
    pub(crate) fn set_nystrom_parts(&mut self, parts: NystromParts) {
        self.nystrom = Some(Box::new(parts));
    }

    /// Format version of this model's file: 7 for an exact model, 8 for a Nyström one.
    pub fn format_version(&self) -> u32 {
        if self.nystrom.is_some() {
            crate::model_file::NYSTROM_VERSION
        } else {
            crate::model_file::EXACT_VERSION
        }
    }
}
