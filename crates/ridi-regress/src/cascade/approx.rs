//! Training by the Nyström solver ([`Solver::Nystrom`](crate::Solver::Nystrom)): landmarks
//! shared by every machine, Nyström features of all rows once (crate::nystrom), then the
//! one-vs-one classifier and each placement's regressors, grid search included, as linear
//! machines by dual coordinate descent (crate::linear) with the exact path's `C`, epsilon,
//! pairs and votes. Only the weights folded back onto the landmarks are kept.

use rayon::prelude::*;

use super::train::{TrainingSet, channel_targets, in_placement, report};
use super::{Cascade, ClassModel, ClassifierHead, NystromParts, SpeedRegressor};
use super::{CascadeParams, RegressorChoice};
use crate::error::RegressError;
use crate::grid::{self, ChainPoint, GridSpec};
use crate::linear::{self, LinearFit, Rows, Stop};
use crate::nystrom::{self, Map, Nystrom, Whitening};
use crate::progress::{Progress, Stage};
use crate::projection::Projection;
use crate::store::SampleRows;
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

/// Linear epsilon-SVR on targets centred on their mean (the offset is regularized, its
/// deviation from the mean less so); the fit's bias includes the mean.
fn svr_centred(
    x: Rows<'_>,
    y: &[f64],
    c: f64,
    eps: f64,
    beta0: Option<Vec<f64>>,
    stop: &Stop,
) -> LinearFit {
    let mean = y.iter().sum::<f64>() / y.len().max(1) as f64;
    let yc: Vec<f64> = y.iter().map(|v| v - mean).collect();
    let mut fit = linear::svr(x, &yc, c, eps, beta0, stop);
    fit.bias += mean;
    fit
}

/// Cross-validated grid search of one placement on its Nyström features, as `grid::search`
/// does on its kernel: the same folds, chains (epsilon descending at each `C`, warm started)
/// and table.
#[allow(clippy::too_many_arguments)]
fn grid_search(
    phi: &[f32],
    rank: usize,
    idx: &[usize],
    targets: &[Vec<f64>],
    groups: &[u64],
    spec: &GridSpec,
    stop: &Stop,
    placement: &str,
    progress: &mut dyn Progress,
) -> Result<Vec<grid::GridRow>, RegressError> {
    let (fold, k, cs, eps) = grid::prepare(groups, spec, placement)?;
    let channels = targets.len();
    let total = k * channels * eps.len() * cs.len();
    let stage = Stage::Grid { placement };
    report(progress, stage, 0, total)?;
    // Per fold: training rows (local and global), validation rows (local and global).
    let split: Vec<[Vec<usize>; 4]> = (0..k)
        .map(|f| {
            let tl: Vec<usize> = (0..fold.len()).filter(|&s| fold[s] != f).collect();
            let vl: Vec<usize> = (0..fold.len()).filter(|&s| fold[s] == f).collect();
            let tg = tl.iter().map(|&s| idx[s]).collect();
            let vg = vl.iter().map(|&s| idx[s]).collect();
            [tl, tg, vl, vg]
        })
        .collect();
    let chains = grid::chains(&cs, &eps);
    let nh = chains.len();
    let tasks: Vec<(usize, usize, usize)> = (0..k)
        .flat_map(|f| (0..channels).flat_map(move |ch| (0..nh).map(move |h| (f, ch, h))))
        .collect();
    let progress = grid::GridProgress::new(progress, stage, total);
    // Every task is a sequential chain of its own: the results do not depend on the threads.
    let results: Vec<(usize, usize, Vec<ChainPoint>)> = tasks
        .par_iter()
        .map(|&(f, ch, h)| {
            let [tl, tg, vl, vg] = &split[f];
            let y: Vec<f64> = tl.iter().map(|&s| targets[ch][s]).collect();
            let rows = Rows {
                data: phi,
                dim: rank,
                idx: tg,
            };
            let mut prev: Option<Vec<f64>> = None;
            let mut out = Vec::with_capacity(chains[h].len());
            for &(ci, e) in &chains[h] {
                if progress.cancelled() {
                    break;
                }
                let fit = svr_centred(rows, &y, cs[ci], eps[e], prev.take(), stop);
                let sse: f64 = vl
                    .iter()
                    .zip(vg)
                    .map(|(&s, &g)| {
                        let f = linear::dot(&fit.w, &phi[g * rank..(g + 1) * rank]) + fit.bias;
                        (targets[ch][s] - f).powi(2)
                    })
                    .sum();
                out.push((ci, e, sse / vl.len().max(1) as f64, fit.epochs));
                prev = Some(fit.dual);
                progress.step();
            }
            (f, ch, out)
        })
        .collect();
    if progress.cancelled() {
        return Err(RegressError::Cancelled);
    }
    Ok(grid::tabulate(placement, &cs, &eps, channels, k, &results))
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
        let stop = Stop::new(cfg.tol(), &params.solver.smo);
        let picked = nystrom::pick(x.rows(), cfg.landmarks(), cfg.seed());
        let map = Map::new(x, &picked, projection.as_ref())?;
        let m = map.m();
        let wr = map.whitening(x, &picked, gamma_r)?;
        // A classifier of another width needs its own `W`; of the same width, it shares.
        let wc_own = if k >= 2 && gamma_c != gamma_r {
            Some(map.whitening(x, &picked, gamma_c)?)
        } else {
            None
        };
        let mut widths: Vec<(f32, &Whitening)> = vec![(gamma_r, &wr)];
        if let Some(w) = &wc_own {
            widths.push((gamma_c, w));
        }
        let phis = map.features(x, &widths);
        let (phi_r, rank_r) = (&phis[0], wr.rank);
        let wc = wc_own.as_ref().unwrap_or(&wr);
        let (phi_c, rank_c) = (phis.get(1).unwrap_or(&phis[0]), wc.rank);

        let (classifier, clf_weights) = if k >= 2 {
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
                        data: phi_c,
                        dim: rank_c,
                        idx: &rows,
                    };
                    linear::svc(x, &positive, params.classifier_c, &stop)
                })
                .collect();
            report(progress, Stage::Classifier, pairs.len(), pairs.len())?;
            let np = pairs.len();
            let mut weights = vec![0.0f64; m * np];
            for (p, fit) in fits.iter().enumerate() {
                for (j, v) in nystrom::fold(wc, &fit.w).into_iter().enumerate() {
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
        let mut reg_weights = Vec::with_capacity(k);
        let mut grid_rows = Vec::new();
        for (c, idx) in members.iter().enumerate() {
            let name = data.placement_names[c].as_str();
            let targets = channel_targets(data, idx, channels);
            let chosen: Vec<(f64, f64)> = match &params.regressors {
                RegressorChoice::Fixed { c, epsilon } => vec![(*c, *epsilon); channels],
                RegressorChoice::Grid(spec) => {
                    let groups: Vec<u64> = idx.iter().map(|&i| data.groups[i]).collect();
                    let table = grid_search(
                        phi_r, rank_r, idx, &targets, &groups, spec, &stop, name, progress,
                    )
                    .map_err(in_placement(name))?;
                    let best = grid::best(&table, channels);
                    grid_rows.extend(table);
                    best
                }
            };
            report(progress, Stage::Regressors { placement: name }, 0, channels)?;
            let rows = Rows {
                data: phi_r,
                dim: rank_r,
                idx,
            };
            let fits: Vec<LinearFit> = (0..channels)
                .into_par_iter()
                .map(|ch| svr_centred(rows, &targets[ch], chosen[ch].0, chosen[ch].1, None, &stop))
                .collect();
            report(
                progress,
                Stage::Regressors { placement: name },
                channels,
                channels,
            )?;
            let mut weights = vec![0.0f64; m * channels];
            for (ch, fit) in fits.iter().enumerate() {
                for (j, v) in nystrom::fold(&wr, &fit.w).into_iter().enumerate() {
                    weights[j * channels + ch] = v;
                }
            }
            reg_weights.push(weights);
            classes.push(ClassModel {
                samples: SampleRows::from_rows(x, &[], projection.as_ref())?,
                norms: Vec::new(),
                n_classifier: 0,
                clf_pairs: Vec::new(),
                clf_coef: Vec::new(),
                reg_coef: Vec::new(),
                reg_rho: [-fits[0].bias, -fits[1].bias],
                reg_params: [chosen[0], chosen[1]],
                reg_info: [info(&fits[0]), info(&fits[1])],
                speed: fits.get(2).map(|f| SpeedRegressor {
                    rho: -f.bias,
                    params: chosen[2],
                    info: info(f),
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
                rank: [rank_r as u32, rank_c as u32],
                clf_weights,
                reg_weights,
            })),
        })
    }
}
