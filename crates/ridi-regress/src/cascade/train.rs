//! Training: the training set and its checks, the one-vs-one classifier, the regressors of
//! each placement (with or without a grid search), and the stored form of each placement.

use rayon::prelude::*;
use ridi_features::FeatureConfig;
use ridi_features::ridi_frames::StabHorizontal;

use super::approx::Resolved;
use super::{Cascade, ClassModel, ClassifierHead, SpeedRegressor};
use super::{CascadeParams, RegressorChoice, Storage};
use crate::config;
use crate::error::RegressError;
use crate::f16mat::F16_MAX;
use crate::grid;
use crate::matrix::View as _;
use crate::nystrom::{Nystrom, Solver};
use crate::progress::{Progress, ProgressEvent, Stage};
use crate::projection::Projection;
use crate::store::SampleRows;
use crate::svc::{self, PairDual, SvcParams};
use crate::svr;
use ridi_features::FeatureMatrixRef;

/// Training data: one row per sample.
#[derive(Debug, Clone, Copy)]
pub struct TrainingSet<'a> {
    /// Feature matrix (`n × dim`).
    pub features: FeatureMatrixRef<'a>,
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

pub(super) fn report(
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

/// Targets of rows `idx` per channel: S-x, S-z and, as a third channel, the speed.
pub(super) fn channel_targets(
    data: &TrainingSet<'_>,
    idx: &[usize],
    channels: usize,
) -> Vec<Vec<f64>> {
    let target = |i: usize, ch: usize| {
        let t = data.targets[i];
        if ch < 2 { t[ch] } else { t.norm() }
    };
    (0..channels)
        .map(|ch| idx.iter().map(|&i| target(i, ch)).collect())
        .collect()
}

/// Names the placement in a grid search's lack of data.
pub(super) fn in_placement(name: &str) -> impl FnOnce(RegressError) -> RegressError + '_ {
    move |e| match e {
        RegressError::NotEnoughData(m) => {
            RegressError::NotEnoughData(format!("placement '{name}': {m}"))
        }
        other => other,
    }
}

/// Half-precision storage cannot hold feature values beyond ±65504.
fn check_f16_range(x: FeatureMatrixRef<'_>) -> Result<(), RegressError> {
    match x.as_slice().iter().position(|v| v.abs() > F16_MAX) {
        None => Ok(()),
        Some(pos) => Err(RegressError::BeyondHalfPrecision {
            what: "feature value",
            value: x.as_slice()[pos],
            row: pos / x.cols(),
            column: pos % x.cols(),
        }),
    }
}

fn check_training_set(
    data: &TrainingSet<'_>,
    params: &CascadeParams,
) -> Result<Vec<Vec<usize>>, RegressError> {
    let n = data.features.rows();
    for (what, found) in [
        ("targets (one per feature row)", data.targets.len()),
        ("placements (one per feature row)", data.placements.len()),
        ("group ids (one per feature row)", data.groups.len()),
    ] {
        if found != n {
            return Err(RegressError::LengthMismatch {
                what,
                expected: n,
                found,
            });
        }
    }
    if data.placement_names.is_empty() {
        return Err(RegressError::NotEnoughData("no placements".into()));
    }
    // As a model file's is checked when read: a model is never saved that cannot be loaded.
    data.feature_config.validate()?;
    let fd = data.feature_config.feature_dim();
    if fd != data.features.cols() {
        return Err(RegressError::LengthMismatch {
            what: "feature row (the feature configuration's)",
            expected: fd,
            found: data.features.cols(),
        });
    }
    if let Some(i) = data.targets.iter().position(|t| !t.is_finite()) {
        return Err(RegressError::NonFinite {
            what: "target",
            index: i,
        });
    }
    let k = data.placement_names.len();
    let mut members = vec![Vec::new(); k];
    for (i, &p) in data.placements.iter().enumerate() {
        if p >= k {
            return Err(RegressError::PlacementOutOfRange {
                index: i,
                placement: p,
                names: k,
            });
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
    svr::check_smo(&params.solver_config.smo)?;
    match &params.regressors {
        RegressorChoice::Fixed { c, epsilon } => {
            svr::SvrParams::new(*c, *epsilon, 1.0).validate()?;
        }
        RegressorChoice::Grid(g) => {
            g.validate()?;
            // Checked before any training, not when the search reaches the placement: a
            // search cross-validates by sequence, so each placement needs two.
            for (c, m) in members.iter().enumerate() {
                let mut groups: Vec<u64> = m.iter().map(|&i| data.groups[i]).collect();
                groups.sort_unstable();
                groups.dedup();
                if groups.len() < 2 {
                    return Err(RegressError::TooFewSequences {
                        placement: data.placement_names[c].clone(),
                        found: groups.len(),
                    });
                }
            }
        }
    }
    if let Solver::Nystrom(n) = params.solver {
        // A deserialized config is checked too (the type's constructor checks the others).
        Nystrom::new(n.landmarks(), n.seed())?.with_tol(n.tol())?;
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
        if let Solver::Nystrom(cfg) = params.solver {
            let resolved = Resolved {
                members,
                gamma_c,
                gamma_r,
                projection,
            };
            return Self::train_nystrom(data, params, cfg, resolved, progress);
        }

        let (classifier, pair_duals) = if k >= 2 {
            let total = k * (k - 1) / 2;
            report(progress, Stage::Classifier, 0, total)?;
            let svc_params = SvcParams {
                c: params.classifier_c,
                gamma: gamma_c,
                solver_config: params.solver_config,
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
                params.solver_config.kernel_memory,
                params.solver_config.regressor_kernel,
            );
            let channels = 2 + usize::from(params.speed);
            let targets = channel_targets(data, idx, channels);
            let chosen: Vec<(f64, f64)> = match &params.regressors {
                RegressorChoice::Fixed { c, epsilon } => vec![(*c, *epsilon); channels],
                RegressorChoice::Grid(spec) => {
                    let groups: Vec<u64> = idx.iter().map(|&i| data.groups[i]).collect();
                    let table = grid::search(
                        rows.as_ref(),
                        &targets,
                        &groups,
                        spec,
                        &params.solver_config,
                        name,
                        progress,
                    )
                    .map_err(in_placement(name))?;
                    let best = grid::best(&table, channels);
                    grid_rows.extend(table);
                    best
                }
            };
            report(progress, Stage::Regressors { placement: name }, 0, channels)?;
            let local: Vec<usize> = (0..idx.len()).collect();
            let smo = &params.solver_config.smo;
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
            dim: x.cols(),
            placements: data.placement_names.to_vec(),
            classifier,
            regressor_gamma: gamma_r,
            classes,
            grid: grid_rows,
            projection,
            nystrom: None,
            checked: true,
        })
    }
}

fn build_class(
    c: usize,
    idx: &[usize],
    xc: FeatureMatrixRef<'_>,
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
