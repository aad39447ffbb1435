//! Prediction: the batched path (GEMM over blocks of queries, half-precision rows widened a
//! tile at a time) and the single-query path (one streaming pass, thread-local buffers).

use std::cell::RefCell;

use rayon::prelude::*;
use ridi_features::ridi_frames::StabHorizontal;

use super::{Cascade, ClassModel, ClassifierHead, NystromParts};
use crate::error::RegressError;
use crate::expansion::weighted_sums;
use crate::kernel;
use crate::matrix::View as _;
use crate::svc;
use ridi_features::{FeatureMatrix, FeatureMatrixRef};

/// Queries per block in batched prediction (bounds temporaries to a few MB).
const QUERY_BLOCK: usize = 256;

/// Stored rows widened to `f32` per GEMM call in batched prediction (a 9.8 MB temporary at
/// dim 1200; two column tiles of `cross_kernel`, so both cores get work on a small batch).
const WIDEN_ROWS: usize = 2048;

/// Output for one query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction {
    /// Placement index (into [`Cascade::placement_names`]).
    pub placement: usize,
    /// Velocity in S (same components as the targets). With a speed regressor
    /// ([`CascadeParams::speed`](crate::CascadeParams::speed)) the regressed components `v`
    /// scaled by `max(s, 0) / max(|v|, 0.1 m/s)`, `s` the regressed speed: the floor keeps a
    /// direction that is barely known from being blown up.
    pub velocity: StabHorizontal,
}

/// Below this regressed velocity (m/s) the speed channel scales by `s / SPEED_FLOOR` at most.
const SPEED_FLOOR: f64 = 0.1;

impl ClassModel {
    /// The velocity from the kernel-weighted sums of the channels (before their offsets).
    fn velocity(&self, sums: &[f64]) -> StabHorizontal {
        let v = StabHorizontal::new(sums[0] - self.reg_rho[0], sums[1] - self.reg_rho[1]);
        match &self.speed {
            None => v,
            Some(sp) => v * ((sums[2] - sp.rho).max(0.0) / v.norm().max(SPEED_FLOOR)),
        }
    }
}

/// Where the batched path reads a placement's sample rows as `f32`.
#[derive(Clone, Copy)]
pub(super) enum Rows<'a> {
    /// The stored half-precision rows, widened a tile at a time.
    Stored,
    /// Exact rows in the stored order with their squared norms (reference evaluation).
    Exact(&'a [(FeatureMatrix, Vec<f32>)]),
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

impl Cascade {
    /// Classifies and regresses one query (the online path).
    pub fn predict_one(&self, q: &[f32]) -> Result<Prediction, RegressError> {
        self.check_decoded()?;
        if q.len() != self.dim {
            return Err(RegressError::LengthMismatch {
                what: "query row",
                expected: self.dim,
                found: q.len(),
            });
        }
        // Non-finite values are refused here.
        FeatureMatrixRef::new(q, self.dim.max(1))?;
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
    /// A Nyström model's classifier is its landmarks' ([`Self::classify_single_nystrom`]);
    /// its placements hold no classifier rows, so their regressors reuse no distance.
    fn predict_single(&self, q: &[f32], qn: f32, s: &mut Scratch) -> Prediction {
        let k = self.classes.len();
        // Where each placement's classifier distances start in `s.dist`.
        let offset = |p: usize| -> usize { self.classes[..p].iter().map(|c| c.n_classifier).sum() };
        let total: usize = self.classes.iter().map(|cl| cl.n_classifier).sum();
        s.dist.resize(total, 0.0);
        let placement = match (&self.classifier, &self.nystrom) {
            (None, _) => 0,
            (Some(head), Some(n)) => self.classify_single_nystrom(head, n, q, qn, s),
            (Some(head), None) => {
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

    /// The placement of one query by a Nyström model's classifier: one pass over its
    /// landmarks, then a dot product per pair.
    fn classify_single_nystrom(
        &self,
        head: &ClassifierHead,
        n: &NystromParts,
        q: &[f32],
        qn: f32,
        s: &mut Scratch,
    ) -> usize {
        let m = n.landmarks.rows();
        s.dist.resize(m, 0.0);
        s.kv.resize(m, 0.0);
        n.landmarks.dots(q, 0, &mut s.dist);
        kernel::dist_from_dots(&mut s.dist, qn, &n.norms);
        kernel::exp_neg_scaled(&s.dist, head.gamma, &mut s.kv);
        s.dec.resize(head.pairs.len(), 0.0);
        weighted_sum(&s.kv, &n.clf_weights, &mut s.dec);
        s.dec.iter_mut().zip(&head.rho).for_each(|(v, r)| *v -= r);
        s.votes.resize(self.classes.len(), 0);
        svc::vote(&s.dec, &head.pairs, self.classes.len(), &mut s.votes)
    }

    /// The placements of a block of queries by a Nyström model's classifier: one distance
    /// block from the queries (stored form) to its landmarks, then weighted sums.
    fn classify_block_nystrom(
        &self,
        head: &ClassifierHead,
        n: &NystromParts,
        q: FeatureMatrixRef<'_>,
        qn: &[f32],
        out: &mut [Prediction],
    ) {
        let (rows, m) = (q.rows(), n.landmarks.rows());
        let mut wide = Vec::new();
        n.landmarks.rows_f32(0, m, &mut wide);
        let lv = FeatureMatrixRef::trusted(&wide, n.landmarks.dim());
        let mut kv = vec![0.0f32; rows * m];
        kernel::cross_kernel(q, qn, lv, &n.norms, head.gamma, &mut kv);
        let np = head.pairs.len();
        let mut dec = vec![0.0f64; rows * np];
        weighted_sums(&kv, &n.clf_weights, np, &mut dec);
        let mut votes = vec![0u32; self.classes.len()];
        for (o, row) in out.iter_mut().zip(dec.chunks_exact_mut(np)) {
            row.iter_mut().zip(&head.rho).for_each(|(v, r)| *v -= r);
            o.placement = svc::vote(row, &head.pairs, self.classes.len(), &mut votes);
        }
    }

    /// Classifies and regresses every row of `x` (batched GEMM path).
    pub fn predict(&self, x: FeatureMatrixRef<'_>) -> Result<Vec<Prediction>, RegressError> {
        self.check_dim(x)?;
        Ok(self.predict_blocks(Rows::Stored, x, None))
    }

    /// Predictions of every row, `QUERY_BLOCK` rows per GEMM, blocks in parallel; `placement`
    /// skips the classifier.
    pub(super) fn predict_blocks(
        &self,
        rows: Rows<'_>,
        x: FeatureMatrixRef<'_>,
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
        x: FeatureMatrixRef<'_>,
        placement: usize,
    ) -> Result<Vec<StabHorizontal>, RegressError> {
        self.check_dim(x)?;
        if placement >= self.classes.len() {
            return Err(RegressError::InvalidParam(format!(
                "placement {placement}, the model has {} placements",
                self.classes.len()
            )));
        }
        Ok(self
            .predict_blocks(Rows::Stored, x, Some(placement))
            .into_iter()
            .map(|p| p.velocity)
            .collect())
    }

    pub(super) fn check_dim(&self, x: FeatureMatrixRef<'_>) -> Result<(), RegressError> {
        self.check_decoded()?;
        if x.cols() != self.dim {
            return Err(RegressError::LengthMismatch {
                what: "query row",
                expected: self.dim,
                found: x.cols(),
            });
        }
        Ok(())
    }

    /// `out (q.rows() × (r1 - r0))`: squared distances (`gamma` `None`) or kernel values from
    /// the queries to sample rows `r0..r1` of placement `p`.
    #[allow(clippy::too_many_arguments)]
    fn class_block(
        &self,
        rows: Rows<'_>,
        p: usize,
        q: FeatureMatrixRef<'_>,
        qn: &[f32],
        (r0, r1): (usize, usize),
        gamma: Option<f32>,
        out: &mut [f32],
    ) {
        let run = |b: FeatureMatrixRef<'_>, nb: &[f32], o: &mut [f32]| match gamma {
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
                    let b = FeatureMatrixRef::trusted(&wide, cl.samples.dim());
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
        q: FeatureMatrixRef<'_>,
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
        let q = projected.as_ref().map_or(q, FeatureMatrix::view);
        // Squared distances to the classifier part of each placement (none of a Nyström
        // model's: its classifier is its landmarks').
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
        match (forced, &self.classifier, &self.nystrom) {
            (Some(p), _, _) => out.iter_mut().for_each(|o| o.placement = p),
            (None, None, _) => out.iter_mut().for_each(|o| o.placement = 0),
            (None, Some(head), Some(n)) => self.classify_block_nystrom(head, n, q, &qn, out),
            (None, Some(head), None) => {
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
        self.regress_block(rows, q, &qn, &dists, forced, out);
    }

    /// The regressions of a block of queries (in stored form, `qn` their squared norms) whose
    /// placements are set, per placement: kernel values to its samples, reusing `dists` to
    /// its classifier rows unless `forced`.
    fn regress_block(
        &self,
        rows: Rows<'_>,
        q: FeatureMatrixRef<'_>,
        qn: &[f32],
        dists: &[Vec<f32>],
        forced: Option<usize>,
        out: &mut [Prediction],
    ) {
        let m = q.rows();
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
