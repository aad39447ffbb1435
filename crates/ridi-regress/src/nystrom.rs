//! Nyström features: the approximate solver of the cascade ([`Solver::Nystrom`]).
//!
//! `m` landmarks `L` are drawn uniformly (without replacement, fixed seed) from the rows a
//! machine trains on (all rows for the classifier, a placement's for its regressors),
//! `W = K(L, L)` with the model's RBF width, and a row `x` maps to
//! `φ(x) = Λ^{-1/2} Uᵀ k(L, x)` (`W = UΛUᵀ`, eigenvalues below [`EIGEN_FLOOR`] times the
//! largest dropped), so that `φ(a)·φ(b) = k(L, a)ᵀ W⁺ k(L, b)`: the kernel projected on the
//! span of the landmarks' feature maps, exact when `a` or `b` is a landmark. Every kernel
//! machine of the cascade is then a linear one in `φ`-space (crate::linear for the
//! classifier, crate::ridge for the regressors), and its weights fold back into one weight per
//! landmark, `w' = UΛ^{-1/2} w`, so that a query is `k(L, x)·w' + b`: one kernel row against
//! the landmarks, then a dot product per classifier pair or regressor channel.
//!
//! Kernel values are those a query sees: the landmarks in the model's stored form (half
//! precision, or principal coordinates, [`crate::Storage`]) and each row as the query path
//! writes it, so a trained model predicts its training rows exactly as it was fitted to them.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::RegressError;
use crate::kernel;
use crate::linear::SplitMix64;
use crate::matrix::View as _;
use crate::projection::Projection;
use crate::store::SampleRows;
use ridi_features::{FeatureMatrix, FeatureMatrixRef};

/// How the cascade's kernel machines are trained ([`CascadeParams::solver`](crate::CascadeParams::solver)).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub enum Solver {
    /// The exact kernel machines by SMO (the paper's; the default and the reference). Time
    /// and memory grow faster than the square of a placement's rows, and the model keeps
    /// every support vector.
    #[default]
    Exact,
    /// Nyström features on landmarks per machine, then a linear SVM by dual coordinate
    /// descent for the classifier and kernel ridge regression in closed form for the
    /// regressors: training time and memory linear in the rows beyond the landmarks' fixed
    /// cost, a model of the landmarks and one weight per landmark and machine, a query of one
    /// kernel row against the classifier's landmarks and one against its placement's.
    /// Approximates kernel machines on the span of the landmarks' feature maps (the
    /// regressors with a squared loss); how closely is measured in the crate documentation.
    Nystrom(Nystrom),
}

/// Settings of [`Solver::Nystrom`], checked when built ([`Nystrom::new`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "NystromRepr")]
pub struct Nystrom {
    landmarks: usize,
    seed: u64,
    tol: f64,
}

#[derive(Deserialize)]
struct NystromRepr {
    landmarks: usize,
    seed: u64,
    tol: f64,
}

impl TryFrom<NystromRepr> for Nystrom {
    type Error = RegressError;
    fn try_from(r: NystromRepr) -> Result<Self, RegressError> {
        Self::new(r.landmarks, r.seed)?.with_tol(r.tol)
    }
}

impl Nystrom {
    /// Landmarks by default: see the crate documentation for what fewer or more change.
    pub const DEFAULT_LANDMARKS: usize = 2048;
    /// Most landmarks: `W` is `m × m` and its eigendecomposition `O(m³)`.
    pub const MAX_LANDMARKS: usize = 16_384;
    /// LIBLINEAR's default stopping tolerance of the classifier's dual solver: it stops when
    /// the projected gradients of an epoch span at most this. Tighter costs epochs for no
    /// measured gain on held-out data (the approximation, not the optimization, limits it).
    /// The regressors are solved in closed form.
    pub const DEFAULT_TOL: f64 = 0.1;

    /// `landmarks` rows drawn with `seed` (a training set with fewer rows uses them all), which
    /// also orders the linear classifier's sweeps.
    /// Fails unless `2 <= landmarks <= MAX_LANDMARKS`.
    pub fn new(landmarks: usize, seed: u64) -> Result<Self, RegressError> {
        if !(2..=Self::MAX_LANDMARKS).contains(&landmarks) {
            return Err(RegressError::InvalidParam(format!(
                "Nyström landmarks {landmarks} (must be 2 to {})",
                Self::MAX_LANDMARKS
            )));
        }
        Ok(Self {
            landmarks,
            seed,
            tol: Self::DEFAULT_TOL,
        })
    }

    /// The same with another stopping tolerance ([`Self::DEFAULT_TOL`]); fails unless it is
    /// finite and positive.
    pub fn with_tol(self, tol: f64) -> Result<Self, RegressError> {
        if !(tol.is_finite() && tol > 0.0) {
            return Err(RegressError::InvalidParam(format!(
                "Nyström solver tolerance {tol} (must be finite and > 0)"
            )));
        }
        Ok(Self { tol, ..self })
    }

    pub(crate) fn reseed(&mut self, seed: u64) {
        self.seed = seed;
    }

    /// Stopping tolerance of the classifier's dual solver.
    pub fn tol(&self) -> f64 {
        self.tol
    }

    /// Landmarks asked for.
    pub fn landmarks(&self) -> usize {
        self.landmarks
    }

    /// Seed of the landmark draw and of the linear classifier's sweep order.
    pub fn seed(&self) -> u64 {
        self.seed
    }
}

impl Default for Nystrom {
    fn default() -> Self {
        Self {
            landmarks: Self::DEFAULT_LANDMARKS,
            seed: 0,
            tol: Self::DEFAULT_TOL,
        }
    }
}

/// Eigenvalues of `W` below this share of the largest are dropped: `W` is built from `f32`
/// kernel values (relative error about 1e-6 after the distance's cancellation), so the
/// directions beneath carry rounding, and `Λ^{-1/2}` would amplify it.
pub(crate) const EIGEN_FLOOR: f64 = 1e-6;

/// Rows of training features computed per block (bounds the kernel block to `BLOCK × m`).
const BLOCK: usize = 2048;

/// `m` distinct row indices of `0..n`, ascending: a partial Fisher-Yates shuffle with
/// SplitMix64 (the same on every platform).
pub(crate) fn pick(n: usize, m: usize, seed: u64) -> Vec<usize> {
    let m = m.min(n);
    let mut rng = SplitMix64(seed);
    let mut all: Vec<usize> = (0..n).collect();
    for i in 0..m {
        let j = i + (rng.next() % (n - i) as u64) as usize;
        all.swap(i, j);
    }
    let mut out = all[..m].to_vec();
    out.sort_unstable();
    out
}

/// The landmarks in stored form and the maps `T = UΛ^{-1/2}` (`m × rank`) per kernel width.
pub(crate) struct Map<'p> {
    pub landmarks: SampleRows,
    norms: Vec<f32>,
    /// Landmarks widened to `f32` (stored form).
    wide: Vec<f32>,
    projection: Option<&'p Projection>,
}

/// `T` of one kernel width: `m × rank`, row-major.
pub(crate) struct Whitening {
    pub t: Vec<f64>,
    pub rank: usize,
}

impl<'p> Map<'p> {
    /// Stores rows `idx` of `x` as the landmarks.
    pub(crate) fn new(
        x: FeatureMatrixRef<'_>,
        idx: &[usize],
        projection: Option<&'p Projection>,
    ) -> Result<Self, RegressError> {
        let landmarks = SampleRows::from_rows(x, idx, projection)?;
        let norms = landmarks.norms();
        let mut wide = Vec::new();
        landmarks.rows_f32(0, landmarks.rows(), &mut wide);
        Ok(Self {
            landmarks,
            norms,
            wide,
            projection,
        })
    }

    pub(crate) fn m(&self) -> usize {
        self.landmarks.rows()
    }

    /// Squared distances `rows × m` from rows of `x` (as the query path writes them) to the
    /// landmarks.
    pub(crate) fn sq_dists(&self, x: FeatureMatrixRef<'_>) -> Vec<f32> {
        let (q, qn) = match self.projection {
            Some(p) => {
                let (z, n) = p.project(x);
                (Some(z), n)
            }
            None => (None, kernel::sq_norms(x)),
        };
        let qv = q.as_ref().map_or(x, FeatureMatrix::view);
        let mut out = vec![0.0f32; x.rows() * self.m()];
        let l = FeatureMatrixRef::trusted(&self.wide, self.landmarks.dim());
        kernel::cross_sq_dist(qv, &qn, l, &self.norms, &mut out);
        out
    }

    /// `T` for width `gamma` from `W`, the kernel of the landmarks' training rows (as
    /// queries) against their stored form, symmetrized.
    pub(crate) fn whitening(
        &self,
        x: FeatureMatrixRef<'_>,
        idx: &[usize],
        gamma: f32,
    ) -> Result<Whitening, RegressError> {
        let m = self.m();
        let xl = x.select(idx);
        let d = self.sq_dists(xl.view());
        let mut k = vec![0.0f32; d.len()];
        kernel::exp_neg_scaled(&d, gamma, &mut k);
        let w = Mat::<f64>::from_fn(m, m, |i, j| {
            0.5 * (k[i * m + j] as f64 + k[j * m + i] as f64)
        });
        let eig = w.self_adjoint_eigen(Side::Lower).map_err(|_| {
            RegressError::InvalidParam(
                "the eigendecomposition of the landmarks' kernel did not converge".into(),
            )
        })?;
        let s = eig.S();
        let top = (0..m).map(|j| s[j]).fold(0.0f64, f64::max);
        // Ascending order: keep from the largest down to the floor.
        let kept: Vec<usize> = (0..m).rev().filter(|&j| s[j] > EIGEN_FLOOR * top).collect();
        let u = eig.U();
        let rank = kept.len();
        let mut t = vec![0.0f64; m * rank];
        for (c, &j) in kept.iter().enumerate() {
            let scale = 1.0 / s[j].sqrt();
            for i in 0..m {
                t[i * rank + c] = u[(i, j)] * scale;
            }
        }
        Ok(Whitening { t, rank })
    }

    /// Nyström features `φ = Tᵀ k(L, x)` of width `gamma` (map `w`) of rows `rows` of `x`
    /// (`None`: every row), `rows × rank` (`f32`), in blocks of rows: only a block of `x` is
    /// gathered at a time.
    pub(crate) fn features(
        &self,
        x: FeatureMatrixRef<'_>,
        rows: Option<&[usize]>,
        gamma: f32,
        w: &Whitening,
    ) -> Vec<f32> {
        let m = self.m();
        let n = rows.map_or(x.rows(), <[usize]>::len);
        let rank = w.rank;
        let mut out = vec![0.0f32; n * rank];
        let t: Vec<f32> = w.t.iter().map(|&v| v as f32).collect();
        for r0 in (0..n).step_by(BLOCK) {
            let r1 = (r0 + BLOCK).min(n);
            let d = match rows {
                None => self.sq_dists(x.rows_range(r0, r1)),
                Some(idx) => self.sq_dists(x.select(&idx[r0..r1]).view()),
            };
            let mut k = vec![0.0f32; d.len()];
            kernel::exp_neg_scaled(&d, gamma, &mut k);
            let dst = &mut out[r0 * rank..r1 * rank];
            // Row blocks in parallel, each GEMM sequential (the crate's pattern).
            dst.par_chunks_mut(256 * rank)
                .zip(k.par_chunks(256 * m))
                .for_each(|(o, kb)| {
                    let rows = kb.len() / m;
                    matmul(
                        MatMut::from_row_major_slice_mut(o, rows, rank),
                        Accum::Replace,
                        MatRef::from_row_major_slice(kb, rows, m),
                        MatRef::from_row_major_slice(&t, m, rank),
                        1.0f32,
                        Par::Seq,
                    );
                });
        }
        out
    }
}

/// `w' = T w`: weights per landmark from weights in `φ`-space.
pub(crate) fn fold(w: &Whitening, phi_w: &[f64]) -> Vec<f64> {
    w.t.chunks_exact(w.rank)
        .map(|row| row.iter().zip(phi_w).map(|(a, b)| a * b).sum())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::tests::data;

    #[test]
    fn picks_are_distinct_sorted_and_seeded() {
        let a = pick(1000, 100, 7);
        assert_eq!(a.len(), 100);
        assert!(a.windows(2).all(|w| w[0] < w[1]) && a[99] < 1000);
        assert_eq!(a, pick(1000, 100, 7));
        assert_ne!(a, pick(1000, 100, 8));
        assert_eq!(pick(5, 100, 0), vec![0, 1, 2, 3, 4]);
    }

    #[test]
    fn features_reproduce_the_kernel_with_every_row_a_landmark() {
        // φ(a)·φ(b) = k(L, a)ᵀ W⁺ k(L, b) = K(a, b) when the rows are the landmarks.
        let x = data(60, 12);
        let idx: Vec<usize> = (0..60).collect();
        let map = Map::new(x.view(), &idx, None).unwrap();
        let gamma = 0.05;
        let w = map.whitening(x.view(), &idx, gamma).unwrap();
        let phi = &map.features(x.view(), None, gamma, &w);
        let d = map.sq_dists(x.view());
        let mut worst = 0.0f64;
        for i in 0..60 {
            for j in 0..60 {
                let a = &phi[i * w.rank..(i + 1) * w.rank];
                let b = &phi[j * w.rank..(j + 1) * w.rank];
                let dot: f64 = a.iter().zip(b).map(|(p, q)| *p as f64 * *q as f64).sum();
                let k = (-(gamma as f64) * d[i * 60 + j] as f64).exp();
                worst = worst.max((dot - k).abs());
            }
        }
        // Kernel values within 1e-3: f32 features and eigenvalues dropped below 1e-6.
        assert!(worst < 1e-3, "{worst} (rank {})", w.rank);
        // Weights fold back: k(L, x)·(T w) = φ(x)·w.
        let wphi: Vec<f64> = (0..w.rank).map(|c| (c as f64 * 0.3).sin()).collect();
        let folded = fold(&w, &wphi);
        let mut kv = vec![0.0f32; 60];
        kernel::exp_neg_scaled(&d[5 * 60..6 * 60], gamma, &mut kv);
        let direct: f64 = kv.iter().zip(&folded).map(|(k, w)| *k as f64 * w).sum();
        let via_phi: f64 = phi[5 * w.rank..6 * w.rank]
            .iter()
            .zip(&wphi)
            .map(|(p, w)| *p as f64 * w)
            .sum();
        assert!(
            (direct - via_phi).abs() < 1e-2 * (1.0 + direct.abs()),
            "{direct} vs {via_phi}"
        );
    }
}
