//! Principal-component coordinates for the stored samples.
//!
//! RIDI's features are Gaussian-smoothed windows of six IMU channels, so nearly all of their
//! variance lies in a few hundred of the 1200 directions (what is left is sensor noise spread
//! thinly over the others). Writing a
//! sample `s` as `μ + Uᵀz_s + r_s`, with `U` the `k` leading principal directions and `r_s`
//! the residual,
//!
//! `|a − b|² = |a − μ|² + |b − μ|² − 2 z_a·z_b − 2 r_a·r_b`,
//!
//! and a model that keeps `z_s` and the exact `|s − μ|²` of each sample gets every distance
//! right except the last term. That term is the product of two residuals that lie in the
//! leftover directions and is close to zero. A query then reads `k` values per stored sample
//! instead of `dim`: on standardized Tyrex features 99.99 % of the variance takes 304 of the
//! 1200 directions, a 3.6x cut in the bytes a query streams, for a velocity change of the
//! same size as half-precision rounding ([`crate::Cascade::rounding_effect`] measures both;
//! figures in docs/benchmarks.md).
//!
//! Coordinates are stored in half precision, the first [`SPLIT_LEAD`] of them as two binary16
//! values each (`hi = f16(z)`, `lo = f16(z − hi)`, about 22 significant bits). A query is
//! written in the same layout, `[z_lead, z_lead, z_rest]`, so one half-precision dot product
//! over `k + SPLIT_LEAD` values gives `z_q·(hi + lo) + z_q·rest` in a single stream.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::RegressError;
use crate::kernel;
use ridi_features::{FeatureMatrix, FeatureMatrixRef};

/// Rows used to estimate the covariance at most (evenly spaced; the directions are settled
/// long before, and the `n × dim²` product would otherwise dominate small trainings).
const FIT_ROWS: usize = 16_384;

/// Rows per partial covariance product.
const CHUNK_ROWS: usize = 2048;

/// Components are kept in multiples of this (the SIMD width of the dot products).
const ROUND_TO: usize = 16;

/// Leading coordinates stored as two binary16 values (`hi + lo`); the others as one. The
/// leading ones are large (they carry most of the variance), and plain half precision on them
/// would cost more than the truncation does (on features with few dominant directions, 2x the
/// velocity change); further down the coordinates are small and binary16's relative precision
/// is plenty.
pub(crate) const SPLIT_LEAD: usize = 32;

/// Fewest coordinates kept (the half-precision part then has at least 32).
const MIN_COMPONENTS: usize = 64;

/// Bytes per sample for `k` coordinates.
fn stored_bytes(k: usize) -> usize {
    2 * (k + SPLIT_LEAD)
}

/// Mean and leading principal directions of the training features.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct Projection {
    mean: Vec<f32>,
    /// `k × dim`, orthonormal rows.
    #[serde(with = "crate::matrix::stored")]
    basis: FeatureMatrix,
    /// Share of the training variance the kept directions hold.
    energy: f64,
}

impl Projection {
    /// Principal directions of `x` holding at least `energy` of its variance, rounded up to a
    /// multiple of 16 and at least 64; `None` when the coordinates would take more than half
    /// the bytes of the `dim` half-precision values they replace.
    pub(crate) fn fit(x: FeatureMatrixRef<'_>, energy: f64) -> Result<Option<Self>, RegressError> {
        if !(energy > 0.0 && energy <= 1.0) {
            return Err(RegressError::InvalidParam(format!(
                "projection energy {energy} (must be in (0, 1])"
            )));
        }
        let d = x.cols();
        if stored_bytes(MIN_COMPONENTS) > d || x.rows() < 2 {
            return Ok(None);
        }
        let stride = x.rows().div_ceil(FIT_ROWS);
        let rows: Vec<usize> = (0..x.rows()).step_by(stride).collect();
        let m = rows.len();
        let mut mean = vec![0.0f64; d];
        for &i in &rows {
            mean.iter_mut()
                .zip(x.row(i))
                .for_each(|(a, &v)| *a += v as f64);
        }
        mean.iter_mut().for_each(|a| *a /= m as f64);
        let mean: Vec<f32> = mean.iter().map(|&a| a as f32).collect();
        let mut centred = vec![0.0f32; m * d];
        for (dst, &i) in centred.chunks_exact_mut(d).zip(&rows) {
            dst.iter_mut()
                .zip(x.row(i))
                .zip(&mean)
                .for_each(|((o, &v), &mu)| *o = v - mu);
        }
        // Partial products over row blocks in parallel (faer runs sequentially here).
        let cov64 = centred
            .par_chunks(CHUNK_ROWS * d)
            .map(|block| {
                let xc = MatRef::from_row_major_slice(block, block.len() / d, d);
                let mut cov = Mat::<f32>::zeros(d, d);
                matmul(
                    cov.as_mut(),
                    Accum::Replace,
                    xc.transpose(),
                    xc,
                    1.0f32,
                    Par::Seq,
                );
                Mat::<f64>::from_fn(d, d, |i, j| cov[(i, j)] as f64)
            })
            .reduce(|| Mat::<f64>::zeros(d, d), |a, b| a + b);
        // f32 is plenty for the leading directions and the energy sums, and 1.7x faster.
        let cov32 = Mat::<f32>::from_fn(d, d, |i, j| cov64[(i, j)] as f32);
        let eig = cov32.self_adjoint_eigen(Side::Lower).map_err(|_| {
            RegressError::InvalidParam(
                "the eigendecomposition of the feature covariance did not converge".into(),
            )
        })?;
        // Ascending order: the leading directions are at the end.
        let values: Vec<f64> = (0..d).rev().map(|j| (eig.S()[j] as f64).max(0.0)).collect();
        let total: f64 = values.iter().sum();
        if total <= 0.0 {
            return Ok(None);
        }
        let mut kept = 0.0;
        let mut k = d;
        for (j, v) in values.iter().enumerate() {
            kept += v;
            if kept >= energy * total {
                k = j + 1;
                break;
            }
        }
        let k = (k.div_ceil(ROUND_TO) * ROUND_TO).max(MIN_COMPONENTS);
        if stored_bytes(k) > d {
            return Ok(None);
        }
        let u = eig.U();
        let mut basis = Vec::with_capacity(k * d);
        for j in 0..k {
            let col = d - 1 - j;
            basis.extend((0..d).map(|i| u[(i, col)]));
        }
        Ok(Some(Self {
            mean,
            basis: {
                // Eigenvectors of a finite covariance are finite: the scan is a guard.
                FeatureMatrixRef::new(&basis, d)?;
                crate::matrix::owned(basis, d)
            },
            energy: values[..k].iter().sum::<f64>() / total,
        }))
    }

    /// Number of coordinates.
    pub(crate) fn dim(&self) -> usize {
        self.basis.rows()
    }

    /// Values per stored sample and per query in stored form (`dim() + SPLIT_LEAD`).
    pub(crate) fn stored_dim(&self) -> usize {
        self.dim() + SPLIT_LEAD
    }

    /// Dimension of the vectors projected.
    pub(crate) fn input_dim(&self) -> usize {
        self.mean.len()
    }

    /// Share of the training variance the coordinates hold.
    pub(crate) fn energy(&self) -> f64 {
        self.energy
    }

    /// Writes `q` in stored form, `[z_lead, z_lead, z_rest]` (`stored_dim()` values; the
    /// coordinates `z` are `out[SPLIT_LEAD..]`), using `centred` as scratch, and returns the
    /// exact `|q − μ|²`. Row by row, so the same input always gives the same bits (stored
    /// samples are matched against training rows by them).
    pub(crate) fn project_one(&self, q: &[f32], centred: &mut Vec<f32>, out: &mut [f32]) -> f32 {
        centred.clear();
        centred.extend(q.iter().zip(&self.mean).map(|(&v, &mu)| v - mu));
        for (o, b) in out[SPLIT_LEAD..]
            .iter_mut()
            .zip(self.basis.as_slice().chunks_exact(self.input_dim()))
        {
            *o = kernel::dot(centred, b);
        }
        out.copy_within(SPLIT_LEAD..2 * SPLIT_LEAD, 0);
        kernel::dot(centred, centred)
    }

    /// Every row of `x` in stored form (as [`Self::project_one`]) and the exact `|x_i − μ|²`
    /// (one GEMM; the batched query path).
    pub(crate) fn project(&self, x: FeatureMatrixRef<'_>) -> (FeatureMatrix, Vec<f32>) {
        let (n, d, k) = (x.rows(), self.input_dim(), self.dim());
        let mut centred = x.as_slice().to_vec();
        for row in centred.chunks_exact_mut(d) {
            row.iter_mut().zip(&self.mean).for_each(|(v, &mu)| *v -= mu);
        }
        let norms = kernel::sq_norms(FeatureMatrixRef::trusted(&centred, d));
        let mut data = vec![0.0f32; n * k];
        matmul(
            MatMut::from_row_major_slice_mut(&mut data, n, k),
            Accum::Replace,
            MatRef::from_row_major_slice(&centred, n, d),
            MatRef::from_row_major_slice(self.basis.as_slice(), k, d).transpose(),
            1.0f32,
            Par::Seq,
        );
        let w = self.stored_dim();
        let mut out = vec![0.0f32; n * w];
        for (o, z) in out.chunks_exact_mut(w).zip(data.chunks_exact(k)) {
            o[..SPLIT_LEAD].copy_from_slice(&z[..SPLIT_LEAD]);
            o[SPLIT_LEAD..].copy_from_slice(z);
        }
        (crate::matrix::owned(out, w), norms)
    }

    /// Consistency after decoding.
    pub(crate) fn check(&self) -> Result<(), RegressError> {
        let bad = |m: &str| Err(RegressError::Decode(format!("projection: {m}")));
        if self.basis.cols() != self.mean.len() || self.dim() == 0 || self.dim() > self.input_dim()
        {
            return bad("sizes");
        }
        if !self
            .mean
            .iter()
            .chain(self.basis.as_slice())
            .all(|v| v.is_finite())
        {
            return bad("non-finite value");
        }
        if !(self.energy > 0.0 && self.energy <= 1.0 + 1e-9) {
            return bad("energy");
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::matrix::{View as _, owned};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Rows near a 3-dimensional subspace of R^256, plus faint noise.
    fn low_rank(n: usize, noise: f32) -> FeatureMatrix {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let d = 256;
        let dirs: Vec<Vec<f32>> = (0..3)
            .map(|_| (0..d).map(|_| rng.random_range(-1.0..1.0)).collect())
            .collect();
        let mut data = Vec::with_capacity(n * d);
        for _ in 0..n {
            let c: Vec<f32> = (0..3).map(|_| rng.random_range(-3.0..3.0)).collect();
            for j in 0..d {
                let v: f32 = c.iter().zip(&dirs).map(|(c, dir)| c * dir[j]).sum();
                data.push(2.0 + v + noise * rng.random_range(-1.0..1.0));
            }
        }
        owned(data, d)
    }

    #[test]
    fn keeps_the_subspace_and_distances() {
        let x = low_rank(500, 1e-3);
        let p = Projection::fit(x.view(), 0.9999)
            .unwrap()
            .expect("low rank gains");
        assert_eq!(p.dim(), 64, "3 directions, at least 64 kept");
        assert!(p.energy() > 0.9999);
        assert_eq!(p.stored_dim(), 64 + SPLIT_LEAD);
        let (z, n) = p.project(x.view());
        let mut buf = Vec::new();
        let mut zi = vec![0.0; p.stored_dim()];
        let coords = |i: usize| &z.row(i)[SPLIT_LEAD..];
        for (i, j) in [(0, 1), (10, 400), (77, 78)] {
            assert_eq!(&z.row(i)[..SPLIT_LEAD], &coords(i)[..SPLIT_LEAD]);
            let exact: f32 = x
                .row(i)
                .iter()
                .zip(x.row(j))
                .map(|(a, b)| (a - b) * (a - b))
                .sum();
            let approx = n[i] + n[j] - 2.0 * kernel::dot(coords(i), coords(j));
            assert!(
                (exact - approx).abs() < 1e-3 * exact.max(1.0),
                "{exact} vs {approx}"
            );
            // The one-row path gives the coordinates of the GEMM path.
            let ni = p.project_one(x.row(i), &mut buf, &mut zi);
            assert!((ni - n[i]).abs() <= 1e-4 * n[i]);
            for (a, b) in zi.iter().zip(z.row(i)) {
                assert!((a - b).abs() < 1e-4, "{a} vs {b}");
            }
        }
    }

    #[test]
    fn no_projection_when_it_would_not_save_bytes() {
        // White noise: every direction matters.
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let data: Vec<f32> = (0..200 * 48).map(|_| rng.random_range(-1.0..1.0)).collect();
        let x = owned(data, 48);
        assert!(Projection::fit(x.view(), 0.999).unwrap().is_none());
        // Too few values per row to gain from 64 coordinates.
        let small = owned(vec![1.0; 60], 6);
        assert!(Projection::fit(small.view(), 0.5).unwrap().is_none());
    }

    #[test]
    fn rejects_bad_energy() {
        let x = low_rank(50, 0.0);
        for e in [0.0, -1.0, 1.5, f64::NAN] {
            assert!(matches!(
                Projection::fit(x.view(), e),
                Err(RegressError::InvalidParam(_))
            ));
        }
    }
}
