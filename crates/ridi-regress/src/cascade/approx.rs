//! Training by the Nyström solver ([`Solver::Nystrom`](crate::Solver::Nystrom)): the
//! placement classifier on landmarks drawn from all rows, as linear one-vs-one machines by
//! dual coordinate descent (crate::linear) with the exact path's `C`, pairs and votes; each
//! placement's regressors on landmarks drawn from its own rows, as kernel ridge regressions
//! in closed form (crate::ridge), `C` chosen by the grid's cross-validation when it searches.
//! Only the weights folded back onto the landmarks are kept: the classifier's with the
//! shared landmarks, each placement's with its own (stored as its samples, so that its
//! regression is the exact model's arithmetic on fewer rows).

use rayon::prelude::*;

use super::train::{TrainingSet, channel_targets, in_placement, report};
use super::{Cascade, ClassModel, ClassifierHead, NystromParts, SpeedRegressor};
use super::{CascadeParams, RegressorChoice};
use crate::error::RegressError;
use crate::grid::{self, ChainPoint};
use crate::linear::{self, LinearFit, Rows, Stop};
use crate::nystrom::{self, Map, Nystrom};
use crate::progress::{Progress, Stage};
use crate::projection::Projection;
use crate::ridge::{Moments, RidgeFit};
use crate::svr::FitInfo;

/// Widths and storage the exact path resolved, shared by both solvers.
pub(super) struct Resolved {
    pub members: Vec<Vec<usize>>,
    pub gamma_c: f32,
    pub gamma_r: f32,
    pub projection: Option<Projection>,
}

fn info(fit: &LinearFit) -> FitInfo {
    FitInfo {
        iterations: fit.epochs,
        objective: fit.objective,
        converged: fit.converged,
        n_support: fit.n_support(),
    }
}

impl Cascade {
    /// The cascade by the Nyström solver (see the module documentation).
    pub(super) fn train_nystrom(
        data: &TrainingSet<'_>,
        params: &CascadeParams,
        cfg: Nystrom,
        r: Resolved,
        progress: &mut dyn Progress,
    ) -> Result<Self, RegressError> {
        let Resolved {
            members,
            gamma_c,
            gamma_r,
            projection,
        } = r;
        let x = data.features;
        let k = members.len();
        let stop = Stop::new(cfg.tol(), &params.solver_config.smo);
        // The classifier's landmarks, from all rows; none without a classifier.
        let picked = if k >= 2 {
            nystrom::pick(x.rows(), cfg.landmarks(), cfg.seed())
        } else {
            Vec::new()
        };
        let map = Map::new(x, &picked, projection.as_ref())?;
        let (classifier, clf_weights) = if k >= 2 {
            let wc = map.whitening(x, &picked, gamma_c)?;
            let phi_c = map.features(x, None, gamma_c, &wc);
            let rank_c = wc.rank;
            let pairs: Vec<(usize, usize)> = (0..k)
                .flat_map(|a| (a + 1..k).map(move |b| (a, b)))
                .collect();
            report(progress, Stage::Classifier, 0, pairs.len())?;
            let fits: Vec<LinearFit> = pairs
                .par_iter()
                .map(|&(a, b)| {
                    let mut rows: Vec<usize> =
                        members[a].iter().chain(&members[b]).copied().collect();
                    rows.sort_unstable();
                    let positive: Vec<bool> =
                        rows.iter().map(|&i| data.placements[i] == a).collect();
                    let x = Rows {
                        data: &phi_c,
                        dim: rank_c,
                        idx: &rows,
                    };
                    linear::svc(x, &positive, params.classifier_c, &stop, cfg.seed())
                })
                .collect();
            report(progress, Stage::Classifier, pairs.len(), pairs.len())?;
            let np = pairs.len();
            let m = map.m();
            let mut weights = vec![0.0f64; m * np];
            for (p, fit) in fits.iter().enumerate() {
                for (j, v) in nystrom::fold(&wc, &fit.w).into_iter().enumerate() {
                    weights[j * np + p] = v;
                }
            }
            let head = ClassifierHead {
                gamma: gamma_c,
                c: params.classifier_c,
                pairs: pairs.iter().map(|&(a, b)| (a as u32, b as u32)).collect(),
                rho: fits.iter().map(|f| -f.bias).collect(),
                info: fits.iter().map(info).collect(),
            };
            (Some(head), weights)
        } else {
            (None, Vec::new())
        };

        let channels = 2 + usize::from(params.speed);
        let mut classes = Vec::with_capacity(k);
        let mut grid_rows = Vec::new();
        for (c, idx) in members.iter().enumerate() {
            let name = data.placement_names[c].as_str();
            let targets = channel_targets(data, idx, channels);
            // The placement's own landmarks (training rows, so that an error names the row)
            // and its rows' features on them.
            let own: Vec<usize> =
                nystrom::pick(idx.len(), cfg.landmarks(), placement_seed(cfg.seed(), c))
                    .into_iter()
                    .map(|j| idx[j])
                    .collect();
            let pmap = Map::new(x, &own, projection.as_ref())?;
            let wr = pmap.whitening(x, &own, gamma_r)?;
            let phi = pmap.features(x, Some(idx), gamma_r, &wr);
            let (fits, chosen, table) =
                ridge_fits(&phi, wr.rank, &targets, data, idx, params, name, progress)
                    .map_err(in_placement(name))?;
            grid_rows.extend(table);
            let m = pmap.m();
            let mut reg_coef = vec![0.0f64; m * channels];
            for (ch, fit) in fits.iter().enumerate() {
                for (j, v) in nystrom::fold(&wr, &fit.w).into_iter().enumerate() {
                    reg_coef[j * channels + ch] = v;
                }
            }
            // A closed-form fit: no iterations, every row takes part.
            let rinfo = || FitInfo {
                iterations: 0,
                objective: 0.0,
                converged: true,
                n_support: idx.len(),
            };
            classes.push(ClassModel {
                norms: pmap.landmarks.norms(),
                samples: pmap.landmarks,
                n_classifier: 0,
                clf_pairs: Vec::new(),
                clf_coef: Vec::new(),
                reg_coef,
                reg_rho: [-fits[0].bias, -fits[1].bias],
                reg_params: [chosen[0], chosen[1]],
                reg_info: [rinfo(), rinfo()],
                speed: fits.get(2).map(|f| SpeedRegressor {
                    rho: -f.bias,
                    params: chosen[2],
                    info: rinfo(),
                }),
                n_train: idx.len(),
            });
        }
        let landmarks = map.landmarks;
        let norms = landmarks.norms();
        Ok(Self {
            feature_config: data.feature_config.clone(),
            dim: x.cols(),
            placements: data.placement_names.to_vec(),
            classifier,
            regressor_gamma: gamma_r,
            classes,
            grid: grid_rows,
            projection,
            nystrom: Some(Box::new(NystromParts {
                config: cfg,
                landmarks,
                norms,
                clf_weights,
            })),
            checked: true,
        })
    }
}

/// Seed of placement `c`'s landmark draw: distinct per placement, fixed by the model's seed.
fn placement_seed(seed: u64, c: usize) -> u64 {
    seed ^ (c as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15)
}

/// A placement's ridge fits, the `(C, epsilon)` of each channel and the grid's table.
type Fitted = (Vec<RidgeFit>, Vec<(f64, f64)>, Vec<grid::GridRow>);

/// Ridge fits of one placement's channels on its features `phi` (`rank` values per row, in
/// the order of `idx`), `C` by the grid's cross-validation over sequences when it searches:
/// the fits, the `(C, 0)` chosen per channel (no epsilon: the loss is squared) and the grid's
/// table.
#[allow(clippy::too_many_arguments)]
fn ridge_fits(
    phi: &[f32],
    rank: usize,
    targets: &[Vec<f64>],
    data: &TrainingSet<'_>,
    idx: &[usize],
    params: &CascadeParams,
    name: &str,
    progress: &mut dyn Progress,
) -> Result<Fitted, RegressError> {
    let channels = targets.len();
    let local = |rows: &[usize]| -> Moments {
        let ys: Vec<Vec<f64>> = targets
            .iter()
            .map(|t| rows.iter().map(|&s| t[s]).collect())
            .collect();
        let yr: Vec<&[f64]> = ys.iter().map(Vec::as_slice).collect();
        Moments::of(phi, rank, rows, &yr)
    };
    match &params.regressors {
        RegressorChoice::Fixed { c, .. } => {
            let stage = Stage::Regressors { placement: name };
            report(progress, stage, 0, channels)?;
            let all: Vec<usize> = (0..idx.len()).collect();
            let fits = local(&all).solve(*c)?;
            report(progress, stage, channels, channels)?;
            Ok((fits, vec![(*c, 0.0); channels], Vec::new()))
        }
        RegressorChoice::Grid(spec) => {
            let groups: Vec<u64> = idx.iter().map(|&i| data.groups[i]).collect();
            let (fold, k, cs, _) = grid::prepare(&groups, spec, name)?;
            let stage = Stage::Grid { placement: name };
            report(progress, stage, 0, k * cs.len())?;
            let folds: Vec<Moments> = (0..k)
                .map(|f| {
                    local(
                        &(0..fold.len())
                            .filter(|&s| fold[s] == f)
                            .collect::<Vec<_>>(),
                    )
                })
                .collect();
            let all = folds[1..].iter().fold(folds[0].clone(), |a, b| a.plus(b));
            let mut results: Vec<(usize, usize, Vec<ChainPoint>)> = Vec::new();
            for (f, own) in folds.iter().enumerate() {
                let train = all.minus(own);
                let mut per_ch: Vec<Vec<ChainPoint>> = vec![Vec::new(); channels];
                for (ci, &c) in cs.iter().enumerate() {
                    for (ch, fit) in train.solve(c)?.iter().enumerate() {
                        let mse = own.sse(ch, fit) / own.rows().max(1) as f64;
                        per_ch[ch].push((ci, 0, mse, 0));
                    }
                    report(progress, stage, f * cs.len() + ci + 1, k * cs.len())?;
                }
                results.extend(per_ch.into_iter().enumerate().map(|(ch, r)| (f, ch, r)));
            }
            let table = grid::tabulate(name, &cs, &[0.0], channels, k, &results);
            let best = grid::best(&table, channels);
            let stage = Stage::Regressors { placement: name };
            report(progress, stage, 0, channels)?;
            // Channels may choose different `C`: one factorization per distinct value.
            let mut fits: Vec<Option<RidgeFit>> = vec![None; channels];
            for ch in 0..channels {
                if fits[ch].is_some() {
                    continue;
                }
                let c = best[ch].0;
                for (other, fit) in all.solve(c)?.into_iter().enumerate() {
                    if best[other].0 == c {
                        fits[other] = Some(fit);
                    }
                }
            }
            report(progress, stage, channels, channels)?;
            let fits = fits.into_iter().flatten().collect();
            Ok((fits, best, table))
        }
    }
}
