//! Kernel ridge regression on Nyström features, in closed form: the regressors of
//! the Nyström solver ([`crate::Solver::Nystrom`]).
//!
//! Each regressor minimizes `½‖w‖² + (C/2) Σ (φᵢ·w + b − yᵢ)²` over the rows of its
//! placement, with the offset `b` free (unregularized, as SMO's `rho`): the normal equations
//! `(Σ (φᵢ−φ̄)(φᵢ−φ̄)ᵀ + I/C) w = Σ (φᵢ−φ̄) yᵢ`, solved by Cholesky. Every channel of a
//! placement shares the matrix, and the sums are kept per cross-validation fold
//! ([`Moments`]), so a fold's training sums are the total minus its own and its validation
//! error follows from its own sums without another pass over the rows: the grid search costs
//! one `rank × rank` factorization per fold and `C`, whatever the number of rows. The one
//! pass over the rows is a GEMM of `O(rows · rank²)`.

use faer::linalg::matmul::matmul;
use faer::linalg::solvers::Solve as _;
use faer::{Accum, Mat, MatRef, Par, Side};
use rayon::prelude::*;

use crate::error::RegressError;

/// Rows gathered per GEMM block (bounds the `f64` copy to `BLOCK × rank`).
const BLOCK: usize = 2048;

/// Rows per parallel part of the sums (a multiple of [`BLOCK`]).
const PART: usize = 4 * BLOCK;

/// Sums over a set of rows: their count, `Σ φ`, `Σ φ φᵀ`, and per channel `Σ φ y`, `Σ y`,
/// `Σ y²`; everything the normal equations and a validation error need.
#[derive(Debug, Clone)]
pub(crate) struct Moments {
    n: f64,
    sum: Vec<f64>,
    /// `rank × rank`, both triangles.
    gram: Mat<f64>,
    /// `rank × channels`.
    xy: Mat<f64>,
    ysum: Vec<f64>,
    yy: Vec<f64>,
}

impl Moments {
    /// The sums over rows `rows` (indices into `phi`, `rank` values each), with targets
    /// `targets[ch][s]` of the `s`-th of them.
    pub(crate) fn of(phi: &[f32], rank: usize, rows: &[usize], targets: &[&[f64]]) -> Self {
        // Parts of a fixed number of rows, summed in parallel by sequential GEMMs and added in
        // order: the sums, and so the model's bytes, do not depend on the number of threads.
        let parts = rows.len().div_ceil(PART).max(1);
        let partial: Vec<Self> = (0..parts)
            .into_par_iter()
            .map(|p| {
                let (a, b) = ((p * PART).min(rows.len()), ((p + 1) * PART).min(rows.len()));
                let t: Vec<&[f64]> = targets.iter().map(|t| &t[a..b]).collect();
                Self::of_seq(phi, rank, &rows[a..b], &t)
            })
            .collect();
        partial
            .into_iter()
            .reduce(|acc, p| acc.plus(&p))
            .expect("at least one part")
    }

    fn of_seq(phi: &[f32], rank: usize, rows: &[usize], targets: &[&[f64]]) -> Self {
        let channels = targets.len();
        let mut gram = Mat::<f64>::zeros(rank, rank);
        let mut xy = Mat::<f64>::zeros(rank, channels);
        let mut sum = vec![0.0f64; rank];
        let mut block = Mat::<f64>::zeros(BLOCK.min(rows.len()).max(1), rank);
        let mut yb = Mat::<f64>::zeros(BLOCK.min(rows.len()).max(1), channels);
        for s0 in (0..rows.len()).step_by(BLOCK) {
            let s1 = (s0 + BLOCK).min(rows.len());
            let b = s1 - s0;
            for (r, &i) in rows[s0..s1].iter().enumerate() {
                let src = &phi[i * rank..(i + 1) * rank];
                for (j, &v) in src.iter().enumerate() {
                    block[(r, j)] = v as f64;
                    sum[j] += v as f64;
                }
                for (ch, t) in targets.iter().enumerate() {
                    yb[(r, ch)] = t[s0 + r];
                }
            }
            let bl = block.as_ref().subrows(0, b);
            matmul(gram.as_mut(), Accum::Add, bl.transpose(), bl, 1.0, Par::Seq);
            matmul(
                xy.as_mut(),
                Accum::Add,
                bl.transpose(),
                yb.as_ref().subrows(0, b),
                1.0,
                Par::Seq,
            );
        }
        let ysum = targets.iter().map(|t| t.iter().sum()).collect();
        let yy = targets
            .iter()
            .map(|t| t.iter().map(|v| v * v).sum())
            .collect();
        Self {
            n: rows.len() as f64,
            sum,
            gram,
            xy,
            ysum,
            yy,
        }
    }

    /// `self − other`: the sums over the rows of `self` that are not in `other` (a subset).
    pub(crate) fn minus(&self, other: &Self) -> Self {
        let sub = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x - y).collect();
        Self {
            n: self.n - other.n,
            sum: sub(&self.sum, &other.sum),
            gram: &self.gram - &other.gram,
            xy: &self.xy - &other.xy,
            ysum: sub(&self.ysum, &other.ysum),
            yy: sub(&self.yy, &other.yy),
        }
    }

    /// `self + other` (disjoint rows).
    pub(crate) fn plus(&self, other: &Self) -> Self {
        let add = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x + y).collect();
        Self {
            n: self.n + other.n,
            sum: add(&self.sum, &other.sum),
            gram: &self.gram + &other.gram,
            xy: &self.xy + &other.xy,
            ysum: add(&self.ysum, &other.ysum),
            yy: add(&self.yy, &other.yy),
        }
    }

    /// Rows summed.
    pub(crate) fn rows(&self) -> usize {
        self.n as usize
    }

    /// The ridge fit of every channel at `c` (weights `w` per channel and offsets).
    pub(crate) fn solve(&self, c: f64) -> Result<Vec<RidgeFit>, RegressError> {
        let rank = self.sum.len();
        let channels = self.ysum.len();
        if self.n < 1.0 {
            return Err(RegressError::InvalidParam(
                "ridge regression on no rows".into(),
            ));
        }
        let inv_n = 1.0 / self.n;
        // Centred sums: the offset is free, so it absorbs the means.
        let mut a = Mat::<f64>::from_fn(rank, rank, |i, j| {
            self.gram[(i, j)] - self.sum[i] * self.sum[j] * inv_n
        });
        let ridge = 1.0 / c;
        for i in 0..rank {
            a[(i, i)] += ridge;
        }
        let rhs = Mat::<f64>::from_fn(rank, channels, |i, ch| {
            self.xy[(i, ch)] - self.sum[i] * self.ysum[ch] * inv_n
        });
        // The centred Gram is positive semi-definite and `1/C > 0` is added, so the factor
        // exists unless rounding ate the ridge: then it is named, not hidden.
        let llt = a.llt(Side::Lower).map_err(|_| {
            RegressError::InvalidParam(format!(
                "the ridge system at C = {c} is not positive definite in floating point: use \
                 a smaller C"
            ))
        })?;
        let w = llt.solve(&rhs);
        Ok((0..channels)
            .map(|ch| {
                let wv: Vec<f64> = (0..rank).map(|i| w[(i, ch)]).collect();
                let dot: f64 = wv.iter().zip(&self.sum).map(|(a, b)| a * b).sum();
                let bias = (self.ysum[ch] - dot) * inv_n;
                RidgeFit { w: wv, bias }
            })
            .collect())
    }

    /// `Σ (φ·w + b − y)²` over these rows for channel `ch`, from the sums alone.
    pub(crate) fn sse(&self, ch: usize, fit: &RidgeFit) -> f64 {
        let w = &fit.w;
        let b = fit.bias;
        let rank = w.len();
        let wv = MatRef::from_column_major_slice(w, rank, 1);
        let mut gw = Mat::<f64>::zeros(rank, 1);
        matmul(
            gw.as_mut(),
            Accum::Replace,
            self.gram.as_ref(),
            wv,
            1.0,
            Par::Seq,
        );
        let wgw: f64 = (0..rank).map(|i| w[i] * gw[(i, 0)]).sum();
        let ws: f64 = w.iter().zip(&self.sum).map(|(a, s)| a * s).sum();
        let wxy: f64 = (0..rank).map(|i| w[i] * self.xy[(i, ch)]).sum();
        let v =
            wgw + 2.0 * b * ws + self.n * b * b - 2.0 * wxy - 2.0 * b * self.ysum[ch] + self.yy[ch];
        v.max(0.0)
    }
}

/// One channel's ridge fit: `f(φ) = w·φ + bias`.
#[derive(Debug, Clone)]
pub(crate) struct RidgeFit {
    pub w: Vec<f64>,
    pub bias: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dense solve of the same problem, row by row: the oracle.
    fn direct(phi: &[f32], rank: usize, rows: &[usize], y: &[f64], c: f64) -> RidgeFit {
        // Augmented least squares: [Φ 1] with ridge 1/C on w only.
        let mut a = Mat::<f64>::zeros(rank + 1, rank + 1);
        let mut r = Mat::<f64>::zeros(rank + 1, 1);
        for (s, &i) in rows.iter().enumerate() {
            let mut x: Vec<f64> = phi[i * rank..(i + 1) * rank]
                .iter()
                .map(|&v| v as f64)
                .collect();
            x.push(1.0);
            for p in 0..=rank {
                r[(p, 0)] += x[p] * y[s];
                for q in 0..=rank {
                    a[(p, q)] += x[p] * x[q];
                }
            }
        }
        for p in 0..rank {
            a[(p, p)] += 1.0 / c;
        }
        let sol = a.partial_piv_lu().solve(&r);
        RidgeFit {
            w: (0..rank).map(|p| sol[(p, 0)]).collect(),
            bias: sol[(rank, 0)],
        }
    }

    fn data(n: usize, rank: usize) -> (Vec<f32>, Vec<f64>) {
        let phi: Vec<f32> = (0..n * rank)
            .map(|i| ((i as f32 * 0.37).sin() + (i % 7) as f32 * 0.1) * 0.5)
            .collect();
        let y: Vec<f64> = (0..n)
            .map(|i| {
                let r = &phi[i * rank..(i + 1) * rank];
                r.iter()
                    .enumerate()
                    .map(|(j, v)| *v as f64 * (j as f64 - 1.5))
                    .sum::<f64>()
                    + 0.7
                    + 0.05 * (i as f64 * 1.3).cos()
            })
            .collect();
        (phi, y)
    }

    #[test]
    fn closed_form_matches_a_dense_solve_and_folds_add_up() {
        let (rank, n) = (5, 5000);
        let (phi, y) = data(n, rank);
        // Rows in an order the blocks do not align with, over two folds.
        let rows: Vec<usize> = (0..n).rev().collect();
        let yr: Vec<f64> = rows.iter().map(|&i| y[i]).collect();
        let all = Moments::of(&phi, rank, &rows, &[&yr]);
        let c = 3.0;
        let fit = &all.solve(c).unwrap()[0];
        let oracle = direct(&phi, rank, &rows, &yr, c);
        for (a, b) in fit.w.iter().zip(&oracle.w) {
            assert!((a - b).abs() < 1e-8 * (1.0 + b.abs()), "{a} vs {b}");
        }
        assert!((fit.bias - oracle.bias).abs() < 1e-8);
        // The SSE from sums equals the SSE row by row.
        let direct_sse: f64 = rows
            .iter()
            .zip(&yr)
            .map(|(&i, t)| {
                let f: f64 = phi[i * rank..(i + 1) * rank]
                    .iter()
                    .zip(&fit.w)
                    .map(|(p, w)| *p as f64 * w)
                    .sum::<f64>()
                    + fit.bias;
                (f - t).powi(2)
            })
            .sum();
        assert!((all.sse(0, fit) - direct_sse).abs() < 1e-6 * (1.0 + direct_sse));
        // Folds: total minus one fold is the other fold.
        let (a, b) = rows.split_at(1234);
        let ma = Moments::of(&phi, rank, a, &[&yr[..1234]]);
        let mb = Moments::of(&phi, rank, b, &[&yr[1234..]]);
        let rest = all.minus(&ma);
        let fb = &rest.solve(c).unwrap()[0];
        let fb2 = &mb.solve(c).unwrap()[0];
        for (x, z) in fb.w.iter().zip(&fb2.w) {
            assert!((x - z).abs() < 1e-6 * (1.0 + z.abs()));
        }
        assert_eq!(ma.plus(&mb).rows(), n);
    }

    #[test]
    fn the_sums_do_not_depend_on_the_number_of_threads() {
        // More rows than one part, so that parts run in parallel: a model's bytes must not
        // change with --jobs.
        let (rank, n) = (3, 3 * PART + 17);
        let (phi, y) = data(n, rank);
        let rows: Vec<usize> = (0..n).collect();
        let sums = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let m = pool.install(|| Moments::of(&phi, rank, &rows, &[&y]));
            let fit = m.solve(10.0).unwrap().swap_remove(0);
            (fit.w, fit.bias)
        };
        assert_eq!(sums(1), sums(3));
    }
}
