//! The RIDI cascade: a placement classifier, then two epsilon-SVRs per placement for the two
//! horizontal velocity components in the stabilized frame S.
//!
//! Storage: each placement keeps its samples once in half precision, as coordinates on the
//! leading principal directions of the training features or as the features themselves
//! ([`Storage`]: a query is bound by the bytes it streams), ordered so that the classifier's support vectors of
//! that placement come first, followed by the other samples that either regressor uses.
//! Prediction computes the squared distances of a query to the classifier part of every
//! placement, classifies, and then reuses those distances for the regressors of the predicted
//! placement, so every stored row is read once. A query is projected first when the samples
//! are. Batches go through GEMM (half-precision rows widened to `f32` a tile at a time); a
//! single query streams the rows once (a fused half-precision GEMV for half-precision rows)
//! and reuses thread-local buffers.

use std::cell::RefCell;
use std::collections::HashMap;
use std::hash::{DefaultHasher, Hash, Hasher};

use rayon::prelude::*;
use ridi_features::FeatureConfig;
use ridi_features::ridi_frames::StabHorizontal;
use serde::{Deserialize, Serialize};

use crate::config::{self, SolverConfig};
use crate::error::RegressError;
use crate::expansion::weighted_sums;
use crate::f16mat::F16_MAX;
use crate::grid::{self, GridRow, GridSpec};
use crate::kernel;
use crate::matrix::{Matrix, MatrixRef};
use crate::progress::{Progress, ProgressEvent, Stage};
use crate::projection::Projection;
use crate::store::SampleRows;
use crate::svc::{self, PairDual, SvcParams};
use crate::svr::{self, FitInfo};

/// Queries per block in batched prediction (bounds temporaries to a few MB).
const QUERY_BLOCK: usize = 256;

/// Stored rows widened to `f32` per GEMM call in batched prediction (a 9.8 MB temporary at
/// dim 1200; two column tiles of `cross_kernel`, so both cores get work on a small batch).
const WIDEN_ROWS: usize = 2048;

/// How the RBF width is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Gamma {
    /// `1 / dim` (the paper's 1/1200).
    InverseDim,
    /// `1 / (dim · var(X))` over all training feature values (scikit-learn's `"scale"`;
    /// equals `1 / dim` on standardized features).
    Scale,
    /// A fixed value.
    Value(f32),
}

impl Gamma {
    fn resolve(self, x: MatrixRef<'_>) -> Result<f32, RegressError> {
        let d = x.dim() as f64;
        let g = match self {
            Gamma::InverseDim => 1.0 / d,
            Gamma::Value(g) => g as f64,
            Gamma::Scale => {
                let v = x.as_slice();
                let n = v.len() as f64;
                let mean = v.iter().map(|&a| a as f64).sum::<f64>() / n;
                let var = v.iter().map(|&a| (a as f64 - mean).powi(2)).sum::<f64>() / n;
                if var > 0.0 { 1.0 / (d * var) } else { 1.0 / d }
            }
        };
        let g = g as f32;
        if !(g.is_finite() && g > 0.0) {
            return Err(RegressError::InvalidParam(format!("gamma {g}")));
        }
        Ok(g)
    }
}

/// How a trained model stores its samples for prediction.
///
/// A query streams every stored sample it needs, so its time is set by their bytes. RIDI's
/// features are Gaussian-smoothed windows whose variance lies almost entirely in a few hundred
/// of the 1200 directions. Writing a sample as `μ + Uᵀz + r` (`U`: the leading principal
/// directions of the training features, `r`: the residual),
/// `|a − b|² = |a − μ|² + |b − μ|² − 2 z_a·z_b − 2 r_a·r_b`; a projected model keeps `z` and
/// the exact `|s − μ|²` of each sample, so every distance is right except for the product of
/// two small residuals. [`Cascade::rounding_effect`] measures what either storage changes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Storage {
    /// Every feature value in half precision.
    Half,
    /// Coordinates on the leading principal directions of the training features that hold at
    /// least `energy` of their variance (at least 64, in half precision; the 32 largest as two
    /// half-precision values, `hi + lo`), plus each sample's exact residual norm. Falls back
    /// to [`Storage::Half`] when that would not halve the bytes (features without
    /// low-dimensional structure, or fewer than 192 values per row).
    Projected {
        /// Share of the variance to keep, in `(0, 1]`.
        energy: f64,
    },
}

impl Storage {
    /// The default: [`Storage::Projected`] keeping 99.99 % of the variance (304 of 1200
    /// directions on standardized Tyrex features; the velocity moves by about as much as
    /// half-precision rounding moves it, measured in docs/benchmarks.md). At 99.95 % (256
    /// directions) the largest change was 3-6x that of half precision.
    pub const DEFAULT: Self = Self::Projected { energy: 0.9999 };
}

impl Default for Storage {
    fn default() -> Self {
        Self::DEFAULT
    }
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

/// Hyper-parameters of the regressors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum RegressorChoice {
    /// The same `C` and epsilon for every placement and channel.
    Fixed {
        /// Box constraint.
        c: f64,
        /// Tube width.
        epsilon: f64,
    },
    /// Cross-validated grid search per placement and channel (lowest mean fold MSE).
    Grid(GridSpec),
}

/// Training settings of the cascade. [`Default`] is the paper with its regressor grid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CascadeParams {
    /// Classifier `C` (paper: 10).
    pub classifier_c: f64,
    /// Classifier RBF width.
    pub classifier_gamma: Gamma,
    /// Regressor RBF width.
    pub regressor_gamma: Gamma,
    /// Regressor `C` / epsilon selection.
    pub regressors: RegressorChoice,
    /// Solver, memory and kernel strategy.
    pub solver: SolverConfig,
    /// Placements with fewer training samples are rejected with
    /// [`RegressError::NotEnoughData`] (default 10).
    pub min_class_samples: usize,
    /// Sample storage of the trained model (prediction speed against a small, measured
    /// change of the predictions).
    pub storage: Storage,
    /// Also regress the speed `|v|` per placement (a third epsilon-SVR on the same kernel)
    /// and scale each regressed velocity to it ([`Prediction::velocity`]). Not in the paper:
    /// where the heading of the phone relative to the walk is uncertain (training on turned
    /// windows), the two velocity components shrink towards zero while the speed, which does
    /// not depend on the heading, does not.
    pub speed: bool,
}

impl Default for CascadeParams {
    fn default() -> Self {
        Self {
            classifier_c: 10.0,
            classifier_gamma: Gamma::InverseDim,
            regressor_gamma: Gamma::InverseDim,
            regressors: RegressorChoice::Grid(GridSpec::default()),
            solver: SolverConfig::default(),
            min_class_samples: 10,
            storage: Storage::DEFAULT,
            speed: false,
        }
    }
}

/// Training data: one row per sample.
#[derive(Debug, Clone, Copy)]
pub struct TrainingSet<'a> {
    /// Feature matrix (`n × dim`).
    pub features: MatrixRef<'a>,
    /// Velocity targets in S (two horizontal components).
    pub targets: &'a [StabHorizontal],
    /// Placement of each sample, an index into `placement_names`.
    pub placements: &'a [usize],
    /// Placement names; every name needs samples.
    pub placement_names: &'a [String],
    /// Sequence id of each sample: cross-validation folds never split a sequence.
    pub groups: &'a [u64],
    /// Feature configuration the rows were computed with (stored in the model).
    pub feature_config: &'a FeatureConfig,
}

/// Output for one query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// Placement index (into [`Cascade::placements`]).
    pub placement: usize,
    /// Velocity in S (same components as the targets). With a speed regressor
    /// ([`CascadeParams::speed`]) the regressed components `v` scaled by
    /// `max(s, 0) / max(|v|, 0.1 m/s)`, `s` the regressed speed: the floor keeps a direction
    /// that is barely known from being blown up.
    pub velocity: StabHorizontal,
}

/// Below this regressed velocity (m/s) the speed channel scales by `s / SPEED_FLOOR` at most.
const SPEED_FLOOR: f64 = 0.1;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct ClassifierHead {
    pub gamma: f32,
    pub c: f64,
    pub pairs: Vec<(u32, u32)>,
    pub rho: Vec<f64>,
    pub info: Vec<FitInfo>,
}

/// One placement: samples stored once, shared by the classifier (first `n_classifier` rows)
/// and both regressors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct ClassModel {
    pub samples: SampleRows,
    /// Squared norms as the distances need them ([`SampleRows::norms`]): recomputed on load,
    /// not stored.
    #[serde(skip)]
    pub norms: Vec<f32>,
    pub n_classifier: usize,
    /// The classifier pairs (one-vs-one) this placement takes part in, ascending: its samples
    /// have coefficients in those only.
    pub clf_pairs: Vec<u32>,
    /// `n_classifier × clf_pairs` row-major.
    pub clf_coef: Vec<f64>,
    /// `samples × 2` row-major.
    pub reg_coef: Vec<f64>,
    pub reg_rho: [f64; 2],
    /// `(C, epsilon)` per channel.
    pub reg_params: [(f64, f64); 2],
    pub reg_info: [FitInfo; 2],
    /// The speed regressor ([`CascadeParams::speed`]); its coefficients are the third column
    /// of `reg_coef`.
    pub speed: Option<SpeedRegressor>,
    pub n_train: usize,
}

/// Offset, `(C, epsilon)` and fit report of a placement's speed regressor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct SpeedRegressor {
    pub rho: f64,
    pub params: (f64, f64),
    pub info: FitInfo,
}

impl ClassModel {
    /// Columns of `reg_coef`: S-x, S-z and, with a speed regressor, the speed.
    fn channels(&self) -> usize {
        2 + usize::from(self.speed.is_some())
    }

    /// The velocity from the kernel-weighted sums of the channels (before their offsets).
    fn velocity(&self, sums: &[f64]) -> StabHorizontal {
        let v = StabHorizontal::new(sums[0] - self.reg_rho[0], sums[1] - self.reg_rho[1]);
        match &self.speed {
            None => v,
            Some(sp) => v * ((sums[2] - sp.rho).max(0.0) / v.norm().max(SPEED_FLOOR)),
        }
    }
}

/// How far the compact sample storage (half precision or projection, [`Storage`]) moves
/// predictions: the stored model against the same model evaluated with the exact `f32`
/// training rows ([`Cascade::rounding_effect`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoundingEffect {
    /// Queries compared.
    pub queries: usize,
    /// Share of the queries given the same placement by both.
    pub placement_agreement: f64,
    /// Largest absolute velocity difference per channel (queries with the same placement).
    pub max_velocity_diff: [f64; 2],
    /// Mean absolute velocity difference per channel (queries with the same placement).
    pub mean_velocity_diff: [f64; 2],
}

impl std::fmt::Display for RoundingEffect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} queries: same placement {:.4}, max |dv| {:.2e} / {:.2e} m/s, mean |dv| {:.2e} / \
             {:.2e} m/s",
            self.queries,
            self.placement_agreement,
            self.max_velocity_diff[0],
            self.max_velocity_diff[1],
            self.mean_velocity_diff[0],
            self.mean_velocity_diff[1]
        )
    }
}

/// Where the batched path reads a placement's sample rows as `f32`.
#[derive(Clone, Copy)]
enum Rows<'a> {
    /// The stored half-precision rows, widened a tile at a time.
    Stored,
    /// Exact rows in the stored order with their squared norms (reference evaluation).
    Exact(&'a [(Matrix, Vec<f32>)]),
}

/// Buffers of the single-query path, kept per thread so that a query allocates nothing.
#[derive(Default)]
struct Scratch {
    /// Projected query and centring buffer (projected models).
    z: Vec<f32>,
    centred: Vec<f32>,
    /// Squared distances to the classifier rows of every placement, one after the other.
    dist: Vec<f32>,
    kv: Vec<f32>,
    dec: Vec<f64>,
    tmp: Vec<f64>,
    votes: Vec<u32>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::default();
}

/// A trained cascade (what the model file holds).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Cascade {
    pub(crate) feature_config: FeatureConfig,
    pub(crate) dim: usize,
    pub(crate) placements: Vec<String>,
    pub(crate) classifier: Option<ClassifierHead>,
    pub(crate) regressor_gamma: f32,
    pub(crate) classes: Vec<ClassModel>,
    pub(crate) grid: Vec<GridRow>,
    /// Principal directions the samples are stored on (`None`: half-precision features).
    pub(crate) projection: Option<Projection>,
}

fn report(
    progress: &mut dyn Progress,
    stage: Stage<'_>,
    done: usize,
    total: usize,
) -> Result<(), RegressError> {
    if progress.report(&ProgressEvent { stage, done, total }) {
        Ok(())
    } else {
        Err(RegressError::Cancelled)
    }
}

/// Half-precision storage cannot hold feature values beyond ±65504.
fn check_f16_range(x: MatrixRef<'_>) -> Result<(), RegressError> {
    match x.as_slice().iter().position(|v| v.abs() > F16_MAX) {
        None => Ok(()),
        Some(pos) => Err(RegressError::NonFinite(format!(
            "feature value {} at row {}, column {} exceeds the half-precision range of the \
             model (±{F16_MAX}); standardize the features",
            x.as_slice()[pos],
            pos / x.dim(),
            pos % x.dim()
        ))),
    }
}

fn check_training_set(
    data: &TrainingSet<'_>,
    params: &CascadeParams,
) -> Result<Vec<Vec<usize>>, RegressError> {
    let n = data.features.rows();
    if data.targets.len() != n || data.placements.len() != n || data.groups.len() != n {
        return Err(RegressError::Shape(format!(
            "{n} feature rows, {} targets, {} placements, {} group ids",
            data.targets.len(),
            data.placements.len(),
            data.groups.len()
        )));
    }
    if data.placement_names.is_empty() {
        return Err(RegressError::NotEnoughData("no placements".into()));
    }
    let fd = data.feature_config.feature_dim();
    if fd != data.features.dim() {
        return Err(RegressError::Shape(format!(
            "feature config describes {fd} values per row, features have {}",
            data.features.dim()
        )));
    }
    if let Some(i) = data.targets.iter().position(|t| !t.is_finite()) {
        return Err(RegressError::NonFinite(format!("target of sample {i}")));
    }
    let k = data.placement_names.len();
    let mut members = vec![Vec::new(); k];
    for (i, &p) in data.placements.iter().enumerate() {
        if p >= k {
            return Err(RegressError::Shape(format!(
                "sample {i} has placement {p}, only {k} names"
            )));
        }
        members[p].push(i);
    }
    for (c, m) in members.iter().enumerate() {
        if m.len() < params.min_class_samples.max(1) {
            return Err(RegressError::NotEnoughData(format!(
                "placement '{}' has {} training samples, at least {} are required",
                data.placement_names[c],
                m.len(),
                params.min_class_samples.max(1)
            )));
        }
    }
    svr::check_c_gamma(params.classifier_c, 1.0)?;
    svr::check_smo(&params.solver.smo)?;
    match &params.regressors {
        RegressorChoice::Fixed { c, epsilon } => {
            svr::SvrParams::new(*c, *epsilon, 1.0).validate()?;
        }
        RegressorChoice::Grid(g) => g.validate()?,
    }
    Ok(members)
}

impl Cascade {
    /// Trains the classifier (skipped when there is a single placement) and the regressors.
    pub fn train(
        data: &TrainingSet<'_>,
        params: &CascadeParams,
        progress: &mut dyn Progress,
    ) -> Result<Self, RegressError> {
        let members = check_training_set(data, params)?;
        let k = members.len();
        let x = data.features;
        let gamma_c = params.classifier_gamma.resolve(x)?;
        let gamma_r = params.regressor_gamma.resolve(x)?;
        let projection = match params.storage {
            Storage::Half => None,
            Storage::Projected { energy } => Projection::fit(x, energy)?,
        };
        if projection.is_none() {
            check_f16_range(x)?;
        }

        let (classifier, pair_duals) = if k >= 2 {
            let total = k * (k - 1) / 2;
            report(progress, Stage::Classifier, 0, total)?;
            let svc_params = SvcParams {
                c: params.classifier_c,
                gamma: gamma_c,
                solver: params.solver,
            };
            let mut on_pair = |done, total| {
                progress.report(&ProgressEvent {
                    stage: Stage::Classifier,
                    done,
                    total,
                })
            };
            let duals = svc::fit_ovo(x, data.placements, k, &svc_params, &mut on_pair)?;
            let head = ClassifierHead {
                gamma: gamma_c,
                c: params.classifier_c,
                pairs: duals.iter().map(|d| (d.a as u32, d.b as u32)).collect(),
                rho: duals.iter().map(|d| d.rho).collect(),
                info: duals.iter().map(|d| d.info).collect(),
            };
            (Some(head), duals)
        } else {
            (None, Vec::new())
        };

        let mut classes = Vec::with_capacity(k);
        let mut grid_rows = Vec::new();
        for (c, idx) in members.iter().enumerate() {
            let name = data.placement_names[c].as_str();
            let xc = x.select(idx);
            let rows = config::kernel_rows(
                xc.view(),
                gamma_r,
                params.solver.kernel_memory,
                params.solver.regressor_kernel,
            );
            let channels = 2 + usize::from(params.speed);
            let target = |i: usize, ch: usize| {
                let t = data.targets[i];
                if ch < 2 { t[ch] } else { t.norm() }
            };
            let targets: Vec<Vec<f64>> = (0..channels)
                .map(|ch| idx.iter().map(|&i| target(i, ch)).collect())
                .collect();
            let chosen: Vec<(f64, f64)> = match &params.regressors {
                RegressorChoice::Fixed { c, epsilon } => vec![(*c, *epsilon); channels],
                RegressorChoice::Grid(spec) => {
                    let groups: Vec<u64> = idx.iter().map(|&i| data.groups[i]).collect();
                    let table = grid::search(
                        rows.as_ref(),
                        &targets,
                        &groups,
                        spec,
                        &params.solver,
                        name,
                        progress,
                    )
                    .map_err(|e| match e {
                        RegressError::NotEnoughData(m) => {
                            RegressError::NotEnoughData(format!("placement '{name}': {m}"))
                        }
                        other => other,
                    })?;
                    let best = grid::best(&table, channels);
                    grid_rows.extend(table);
                    best
                }
            };
            report(progress, Stage::Regressors { placement: name }, 0, channels)?;
            let local: Vec<usize> = (0..idx.len()).collect();
            let smo = &params.solver.smo;
            let rows_ref = rows.as_ref();
            let fit = |ch: usize| {
                svr::solve_svr(
                    rows_ref,
                    &local,
                    &targets[ch],
                    chosen[ch].0,
                    chosen[ch].1,
                    None,
                    smo,
                )
            };
            // In parallel only over a precomputed kernel (see `grid::search` on determinism).
            let duals: Vec<svr::SvrDual> = if rows_ref.batch_size() == 0 {
                (0..channels).into_par_iter().map(fit).collect()
            } else {
                (0..channels).map(fit).collect()
            };
            drop(rows);
            report(
                progress,
                Stage::Regressors { placement: name },
                channels,
                channels,
            )?;
            classes.push(build_class(
                c,
                idx,
                xc.view(),
                &pair_duals,
                &duals,
                &chosen,
                projection.as_ref(),
            )?);
        }
        Ok(Self {
            feature_config: data.feature_config.clone(),
            dim: x.dim(),
            placements: data.placement_names.to_vec(),
            classifier,
            regressor_gamma: gamma_r,
            classes,
            grid: grid_rows,
            projection,
        })
    }

    /// Placement names, in class-index order.
    pub fn placements(&self) -> &[String] {
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

    /// Stored samples of placement `p` (shared by its classifier part and both regressors).
    pub fn stored_samples(&self, p: usize) -> usize {
        self.classes.get(p).map_or(0, |c| c.samples.rows())
    }

    /// Classifies and regresses one query (the online path).
    pub fn predict_one(&self, q: &[f32]) -> Result<Prediction, RegressError> {
        if q.len() != self.dim {
            return Err(RegressError::Shape(format!(
                "query has {} values, model expects {}",
                q.len(),
                self.dim
            )));
        }
        // Non-finite values are refused here.
        MatrixRef::new(q, self.dim.max(1))?;
        Ok(SCRATCH.with(|s| {
            let s = &mut *s.borrow_mut();
            let Some(p) = &self.projection else {
                return self.predict_single(q, kernel::dot(q, q), s);
            };
            let mut z = std::mem::take(&mut s.z);
            z.resize(p.stored_dim(), 0.0);
            let qn = p.project_one(q, &mut s.centred, &mut z);
            let out = self.predict_single(&z, qn, s);
            s.z = z;
            out
        }))
    }

    /// The single-query path: one streaming pass over the classifier rows of every placement
    /// and the remaining rows of the chosen one. Same arithmetic as [`Self::predict_block`]
    /// except for the summation order inside the dot products. `q` is in the stored form
    /// (projected when the samples are) and `qn` its squared norm as the distances need it.
    fn predict_single(&self, q: &[f32], qn: f32, s: &mut Scratch) -> Prediction {
        let k = self.classes.len();
        // Where each placement's classifier distances start in `s.dist`.
        let offset = |p: usize| -> usize { self.classes[..p].iter().map(|c| c.n_classifier).sum() };
        let total: usize = self.classes.iter().map(|cl| cl.n_classifier).sum();
        s.dist.resize(total, 0.0);
        let placement = match &self.classifier {
            None => 0,
            Some(head) => {
                let np = head.pairs.len();
                s.dec.clear();
                s.dec.resize(np, 0.0);
                for (p, cl) in self.classes.iter().enumerate() {
                    let off = offset(p);
                    let nc = cl.n_classifier;
                    let d = &mut s.dist[off..off + nc];
                    cl.samples.dots(q, 0, d);
                    kernel::dist_from_dots(d, qn, &cl.norms[..nc]);
                    s.kv.resize(nc, 0.0);
                    kernel::exp_neg_scaled(d, head.gamma, &mut s.kv);
                    s.tmp.resize(cl.clf_pairs.len(), 0.0);
                    weighted_sum(&s.kv, &cl.clf_coef, &mut s.tmp);
                    for (&p, &v) in cl.clf_pairs.iter().zip(&s.tmp) {
                        s.dec[p as usize] += v;
                    }
                }
                s.dec.iter_mut().zip(&head.rho).for_each(|(v, r)| *v -= r);
                s.votes.resize(k, 0);
                svc::vote(&s.dec, &head.pairs, k, &mut s.votes)
            }
        };
        let cl = &self.classes[placement];
        let ns = cl.samples.rows();
        // Without a classifier no distance was computed yet.
        let reuse = if self.classifier.is_some() {
            cl.n_classifier
        } else {
            0
        };
        let off = offset(placement);
        s.kv.resize(ns, 0.0);
        let (head, rest) = s.kv.split_at_mut(reuse);
        kernel::exp_neg_scaled(&s.dist[off..off + reuse], self.regressor_gamma, head);
        cl.samples.dots(q, reuse, rest);
        kernel::rbf_from_dots(rest, qn, &cl.norms[reuse..], self.regressor_gamma);
        let mut v = [0.0f64; 3];
        let v = &mut v[..cl.channels()];
        weighted_sum(&s.kv, &cl.reg_coef, v);
        Prediction {
            placement,
            velocity: cl.velocity(v),
        }
    }

    /// Classifies and regresses every row of `x` (batched GEMM path).
    pub fn predict(&self, x: MatrixRef<'_>) -> Result<Vec<Prediction>, RegressError> {
        self.check_dim(x)?;
        Ok(self.predict_blocks(Rows::Stored, x, None))
    }

    /// Predictions of every row, `QUERY_BLOCK` rows per GEMM, blocks in parallel; `placement`
    /// skips the classifier.
    fn predict_blocks(
        &self,
        rows: Rows<'_>,
        x: MatrixRef<'_>,
        placement: Option<usize>,
    ) -> Vec<Prediction> {
        let mut out = vec![
            Prediction {
                placement: placement.unwrap_or(0),
                velocity: StabHorizontal::ZERO
            };
            x.rows()
        ];
        out.par_chunks_mut(QUERY_BLOCK)
            .enumerate()
            .for_each(|(b, o)| {
                let r0 = b * QUERY_BLOCK;
                self.predict_block(rows, x.rows_range(r0, r0 + o.len()), placement, o);
            });
        out
    }

    /// Regresses every row of `x` with the regressors of a known placement (skips the
    /// classifier), e.g. to evaluate regressors on ground-truth placements.
    pub fn predict_with_placement(
        &self,
        x: MatrixRef<'_>,
        placement: usize,
    ) -> Result<Vec<StabHorizontal>, RegressError> {
        self.check_dim(x)?;
        if placement >= self.classes.len() {
            return Err(RegressError::Shape(format!(
                "placement {placement} of {}",
                self.classes.len()
            )));
        }
        Ok(self
            .predict_blocks(Rows::Stored, x, Some(placement))
            .into_iter()
            .map(|p| p.velocity)
            .collect())
    }

    fn check_dim(&self, x: MatrixRef<'_>) -> Result<(), RegressError> {
        if x.dim() != self.dim {
            return Err(RegressError::Shape(format!(
                "queries have {} features, model expects {}",
                x.dim(),
                self.dim
            )));
        }
        Ok(())
    }

    /// Compares [`Self::predict`] with the same model evaluated with the exact `f32` training
    /// rows in full dimension: each stored row is matched to the row of `training` (the rows
    /// the model was trained on) whose stored form (rounded, or projected) it is. Measures
    /// what the [`Storage`] changes. Fails when a stored row has no match.
    pub fn rounding_effect(
        &self,
        training: MatrixRef<'_>,
        queries: MatrixRef<'_>,
    ) -> Result<RoundingEffect, RegressError> {
        self.check_dim(training)?;
        self.check_dim(queries)?;
        let key = |bytes: &[u8]| {
            let mut h = DefaultHasher::new();
            bytes.hash(&mut h);
            h.finish()
        };
        let stored = |i: usize| {
            SampleRows::from_rows(training, &[i], self.projection.as_ref()).map(|s| s.row_bytes(0))
        };
        let forms: Vec<Vec<u8>> = (0..training.rows())
            .into_par_iter()
            .map(stored)
            .collect::<Result<_, _>>()?;
        let mut by_key: HashMap<u64, Vec<usize>> = HashMap::new();
        for (i, f) in forms.iter().enumerate() {
            by_key.entry(key(f)).or_default().push(i);
        }
        let mut exact = Vec::with_capacity(self.classes.len());
        for (p, cl) in self.classes.iter().enumerate() {
            let idx = (0..cl.samples.rows())
                .map(|j| {
                    let bytes = cl.samples.row_bytes(j);
                    by_key
                        .get(&key(&bytes))
                        .and_then(|c| c.iter().find(|&&i| forms[i] == bytes))
                        .copied()
                        .ok_or_else(|| {
                            RegressError::Shape(format!(
                                "stored sample {j} of placement {p} is not a training row"
                            ))
                        })
                })
                .collect::<Result<Vec<usize>, _>>()?;
            let m = training.select(&idx);
            let norms = kernel::sq_norms(m.view());
            exact.push((m, norms));
        }
        let stored = self.predict_blocks(Rows::Stored, queries, None);
        let reference = self.predict_blocks(Rows::Exact(&exact), queries, None);
        let mut same = 0usize;
        let mut max = [0.0f64; 2];
        let mut sum = [0.0f64; 2];
        for (a, b) in stored.iter().zip(&reference) {
            if a.placement != b.placement {
                continue;
            }
            same += 1;
            for ch in 0..2 {
                let d = (a.velocity[ch] - b.velocity[ch]).abs();
                max[ch] = max[ch].max(d);
                sum[ch] += d;
            }
        }
        let n = stored.len();
        Ok(RoundingEffect {
            queries: n,
            placement_agreement: same as f64 / n.max(1) as f64,
            max_velocity_diff: max,
            mean_velocity_diff: sum.map(|s| s / same.max(1) as f64),
        })
    }

    /// `out (q.rows() × (r1 - r0))`: squared distances (`gamma` `None`) or kernel values from
    /// the queries to sample rows `r0..r1` of placement `p`.
    #[allow(clippy::too_many_arguments)]
    fn class_block(
        &self,
        rows: Rows<'_>,
        p: usize,
        q: MatrixRef<'_>,
        qn: &[f32],
        (r0, r1): (usize, usize),
        gamma: Option<f32>,
        out: &mut [f32],
    ) {
        let run = |b: MatrixRef<'_>, nb: &[f32], o: &mut [f32]| match gamma {
            Some(g) => kernel::cross_kernel(q, qn, b, nb, g, o),
            None => kernel::cross_sq_dist(q, qn, b, nb, o),
        };
        let cl = &self.classes[p];
        let (m, w) = (q.rows(), r1 - r0);
        match rows {
            Rows::Exact(ex) => run(ex[p].0.view().rows_range(r0, r1), &ex[p].1[r0..r1], out),
            Rows::Stored => {
                let mut wide = Vec::new();
                let mut tile = Vec::new();
                for t0 in (r0..r1).step_by(WIDEN_ROWS) {
                    let t1 = (t0 + WIDEN_ROWS).min(r1);
                    cl.samples.rows_f32(t0, t1, &mut wide);
                    let b = MatrixRef::trusted(&wide, cl.samples.dim());
                    if t1 - t0 == w {
                        run(b, &cl.norms[t0..t1], out);
                        continue;
                    }
                    tile.resize(m * (t1 - t0), 0.0);
                    run(b, &cl.norms[t0..t1], &mut tile);
                    for (o, t) in out.chunks_exact_mut(w).zip(tile.chunks_exact(t1 - t0)) {
                        o[t0 - r0..t1 - r0].copy_from_slice(t);
                    }
                }
            }
        }
    }

    fn predict_block(
        &self,
        rows: Rows<'_>,
        q: MatrixRef<'_>,
        forced: Option<usize>,
        out: &mut [Prediction],
    ) {
        let m = q.rows();
        let (projected, qn) = match (rows, &self.projection) {
            (Rows::Stored, Some(p)) => {
                let (z, n) = p.project(q);
                (Some(z), n)
            }
            _ => (None, kernel::sq_norms(q)),
        };
        let q = projected.as_ref().map_or(q, Matrix::view);
        // Squared distances to the classifier part of each placement.
        let dists: Vec<Vec<f32>> = (0..self.classes.len())
            .map(|p| {
                let nc = self.classes[p].n_classifier;
                let mut d = vec![0.0f32; m * nc];
                if forced.is_none() && nc > 0 {
                    self.class_block(rows, p, q, &qn, (0, nc), None, &mut d);
                }
                d
            })
            .collect();
        match (forced, &self.classifier) {
            (Some(p), _) => out.iter_mut().for_each(|o| o.placement = p),
            (None, None) => out.iter_mut().for_each(|o| o.placement = 0),
            (None, Some(head)) => {
                let np = head.pairs.len();
                let mut dec = vec![0.0f64; m * np];
                for (cl, d) in self.classes.iter().zip(&dists) {
                    let mp = cl.clf_pairs.len();
                    if cl.n_classifier == 0 || mp == 0 {
                        continue;
                    }
                    let mut kv = vec![0.0f32; d.len()];
                    kernel::exp_neg_scaled(d, head.gamma, &mut kv);
                    let mut tmp = vec![0.0f64; m * mp];
                    weighted_sums(&kv, &cl.clf_coef, mp, &mut tmp);
                    for (row, t) in dec.chunks_exact_mut(np).zip(tmp.chunks_exact(mp)) {
                        for (&p, &v) in cl.clf_pairs.iter().zip(t) {
                            row[p as usize] += v;
                        }
                    }
                }
                let mut votes = vec![0u32; self.classes.len()];
                for (i, o) in out.iter_mut().enumerate() {
                    let row = &mut dec[i * np..(i + 1) * np];
                    row.iter_mut().zip(&head.rho).for_each(|(v, r)| *v -= r);
                    o.placement = svc::vote(row, &head.pairs, self.classes.len(), &mut votes);
                }
            }
        }
        for (p, cl) in self.classes.iter().enumerate() {
            let sel: Vec<usize> = (0..m).filter(|&i| out[i].placement == p).collect();
            if sel.is_empty() {
                continue;
            }
            let ns = cl.samples.rows();
            let nc = cl.n_classifier;
            let mut kv = vec![0.0f32; sel.len() * ns];
            // Classifier rows: reuse the distances.
            if nc > 0 && forced.is_none() {
                for (r, &i) in sel.iter().enumerate() {
                    kernel::exp_neg_scaled(
                        &dists[p][i * nc..(i + 1) * nc],
                        self.regressor_gamma,
                        &mut kv[r * ns..r * ns + nc],
                    );
                }
            }
            let start = if forced.is_none() { nc } else { 0 };
            if start < ns {
                let qs = if sel.len() == m {
                    None
                } else {
                    Some(q.select(&sel))
                };
                let qv = qs.as_ref().map_or(q, |s| s.view());
                let qsn: Vec<f32> = sel.iter().map(|&i| qn[i]).collect();
                let mut block = vec![0.0f32; sel.len() * (ns - start)];
                self.class_block(
                    rows,
                    p,
                    qv,
                    &qsn,
                    (start, ns),
                    Some(self.regressor_gamma),
                    &mut block,
                );
                for r in 0..sel.len() {
                    kv[r * ns + start..(r + 1) * ns]
                        .copy_from_slice(&block[r * (ns - start)..(r + 1) * (ns - start)]);
                }
            }
            let w = cl.channels();
            let mut v = vec![0.0f64; sel.len() * w];
            weighted_sums(&kv, &cl.reg_coef, w, &mut v);
            for (&i, sums) in sel.iter().zip(v.chunks_exact(w)) {
                out[i].velocity = cl.velocity(sums);
            }
        }
    }

    /// Recomputes what the model file does not store (the norms of the rounded samples),
    /// then checks consistency.
    pub(crate) fn finish_decode(&mut self) -> Result<(), RegressError> {
        for cl in &mut self.classes {
            cl.norms = cl.samples.norms();
        }
        self.check()
    }

    /// Consistency checks after decoding (the checksum only guards against corruption, not
    /// against a well-formed but inconsistent payload).
    pub(crate) fn check(&self) -> Result<(), RegressError> {
        let bad = |m: &str| Err(RegressError::Decode(m.to_string()));
        self.feature_config
            .validate()
            .map_err(|e| RegressError::Decode(format!("feature config: {e}")))?;
        if self.feature_config.feature_dim() != self.dim {
            return bad("feature config and model dimension disagree");
        }
        let k = self.placements.len();
        if k == 0 || self.classes.len() != k {
            return bad("placement count");
        }
        if !(self.regressor_gamma.is_finite() && self.regressor_gamma > 0.0) {
            return bad("regressor gamma");
        }
        let np = match &self.classifier {
            None if k == 1 => 0,
            None => return bad("missing classifier"),
            Some(h) => {
                if h.pairs.len() != k * (k - 1) / 2
                    || h.rho.len() != h.pairs.len()
                    || h.pairs
                        .iter()
                        .any(|&(a, b)| a as usize >= k || b as usize >= k)
                    || !(h.gamma.is_finite() && h.gamma > 0.0)
                {
                    return bad("classifier pairs");
                }
                h.pairs.len()
            }
        };
        let stored_dim = match &self.projection {
            None => self.dim,
            Some(p) => {
                p.check()?;
                if p.input_dim() != self.dim {
                    return bad("projection dimension");
                }
                p.stored_dim()
            }
        };
        for cl in &self.classes {
            cl.samples.check()?;
            let ns = cl.samples.rows();
            if cl.samples.is_projected() != self.projection.is_some()
                || cl.samples.dim() != stored_dim
                || cl.norms.len() != ns
                || cl.n_classifier > ns
                || cl.clf_coef.len() != cl.n_classifier * cl.clf_pairs.len()
                || cl.clf_pairs.windows(2).any(|w| w[0] >= w[1])
                || cl.clf_pairs.iter().any(|&p| p as usize >= np)
                || cl.reg_coef.len() != ns * cl.channels()
            {
                return bad("class sample store sizes");
            }
        }
        Ok(())
    }
}

fn build_class(
    c: usize,
    idx: &[usize],
    xc: MatrixRef<'_>,
    pairs: &[PairDual],
    duals: &[svr::SvrDual],
    chosen: &[(f64, f64)],
    projection: Option<&Projection>,
) -> Result<ClassModel, RegressError> {
    let n = idx.len();
    let own: Vec<usize> = (0..pairs.len())
        .filter(|&p| pairs[p].a == c || pairs[p].b == c)
        .collect();
    // Classifier coefficients of this class's samples, by local index, in its own pairs.
    let mut clf: Vec<Option<Vec<f64>>> = vec![None; n];
    for (j, d) in own.iter().map(|&p| &pairs[p]).enumerate() {
        for (&g, &a) in d.sv.iter().zip(&d.coef) {
            if let Ok(s) = idx.binary_search(&g) {
                clf[s].get_or_insert_with(|| vec![0.0; own.len()])[j] = a;
            }
        }
    }
    let mut order: Vec<usize> = (0..n).filter(|&s| clf[s].is_some()).collect();
    let n_classifier = order.len();
    order.extend((0..n).filter(|&s| clf[s].is_none() && duals.iter().any(|d| d.coef[s] != 0.0)));
    let samples = SampleRows::from_rows(xc, &order, projection)?;
    let norms = samples.norms();
    let clf_coef = order[..n_classifier]
        .iter()
        .flat_map(|&s| clf[s].clone().unwrap_or_default())
        .collect();
    let reg_coef = order
        .iter()
        .flat_map(|&s| duals.iter().map(move |d| d.coef[s]))
        .collect();
    Ok(ClassModel {
        samples,
        norms,
        n_classifier,
        clf_pairs: own.iter().map(|&p| p as u32).collect(),
        clf_coef,
        reg_coef,
        reg_rho: [duals[0].rho, duals[1].rho],
        reg_params: [chosen[0], chosen[1]],
        reg_info: [duals[0].info(), duals[1].info()],
        speed: duals.get(2).map(|d| SpeedRegressor {
            rho: d.rho,
            params: chosen[2],
            info: d.info(),
        }),
        n_train: n,
    })
}

/// `out (k) = kvals (n) · coef (n × k)`, accumulated in f64 in the order of
/// [`weighted_sums`] (one query: no parallel split).
fn weighted_sum(kvals: &[f32], coef: &[f64], out: &mut [f64]) {
    let k = out.len();
    out.fill(0.0);
    for (&kv, c) in kvals.iter().zip(coef.chunks_exact(k)) {
        let kv = kv as f64;
        out.iter_mut().zip(c).for_each(|(o, c)| *o += kv * c);
    }
}
