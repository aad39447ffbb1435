//! RBF kernel values from blocked `f32` GEMM.
//!
//! `K(a, b) = exp(-gamma * (|a|² + |b|² - 2 a·b))`: with the squared norms precomputed, a block
//! of kernel values is one matrix product plus an element-wise exponential, which runs at GEMM
//! speed instead of the memory-bound speed of one distance at a time. On a CPU with AVX2 the
//! element-wise loops run compiled for it (`crate::simd`).

use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};
use rayon::prelude::*;

use crate::matrix::View as _;
use ridi_features::FeatureMatrixRef;

/// Tile edge for blocked kernel computation: large enough for GEMM efficiency with
/// `dim = 1200`, small enough to give both cores work on a few thousand samples.
const TILE: usize = 256;

/// Squared Euclidean norm of every row.
pub(crate) fn sq_norms(x: FeatureMatrixRef<'_>) -> Vec<f32> {
    (0..x.rows())
        .into_par_iter()
        .with_min_len(64)
        .map(|i| dot(x.row(i), x.row(i)))
        .collect()
}

/// `a · b` with lane-wise partial sums (vectorizable without reassociation by the compiler).
pub(crate) fn dot(a: &[f32], b: &[f32]) -> f32 {
    #[cfg(target_arch = "x86_64")]
    if crate::simd::avx2() {
        // SAFETY: the CPU supports AVX2 and FMA (checked at run time).
        return unsafe { crate::simd::dot_avx2(a, b) };
    }
    dot_generic(a, b)
}

#[inline(always)]
pub(crate) fn dot_generic(a: &[f32], b: &[f32]) -> f32 {
    const L: usize = 16;
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f32; L];
    let mut ca = a.chunks_exact(L);
    let mut cb = b.chunks_exact(L);
    for (x, y) in (&mut ca).zip(&mut cb) {
        for l in 0..L {
            acc[l] += x[l] * y[l];
        }
    }
    let mut tail = 0.0f32;
    for (x, y) in ca.remainder().iter().zip(cb.remainder()) {
        tail += x * y;
    }
    acc.iter().sum::<f32>() + tail
}

/// Turns dot products into kernel values in place:
/// `out[j] = exp(-gamma * max(0, na + nb[j] - 2 out[j]))`.
pub(crate) fn rbf_from_dots(out: &mut [f32], na: f32, nb: &[f32], gamma: f32) {
    #[cfg(target_arch = "x86_64")]
    if crate::simd::avx2() {
        // SAFETY: the CPU supports AVX2 and FMA (checked at run time).
        unsafe { crate::simd::rbf_from_dots_avx2(out, na, nb, gamma) };
        return;
    }
    rbf_from_dots_generic(out, na, nb, gamma)
}

/// `out[j] = max(0, na + nb[j] - 2 out[j])`.
pub(crate) fn dist_from_dots(out: &mut [f32], na: f32, nb: &[f32]) {
    for (o, &b) in out.iter_mut().zip(nb) {
        *o = (na + b - 2.0 * *o).max(0.0);
    }
}

/// `out[j] = exp(-gamma d2[j])`.
pub(crate) fn exp_neg_scaled(d2: &[f32], gamma: f32, out: &mut [f32]) {
    #[cfg(target_arch = "x86_64")]
    if crate::simd::avx2() {
        // SAFETY: the CPU supports AVX2 and FMA (checked at run time).
        unsafe { crate::simd::exp_neg_scaled_avx2(d2, gamma, out) };
        return;
    }
    exp_neg_scaled_generic(d2, gamma, out)
}

#[inline(always)]
pub(crate) fn exp_neg_scaled_generic(d2: &[f32], gamma: f32, out: &mut [f32]) {
    for (o, &d) in out.iter_mut().zip(d2) {
        *o = exp_nonpos(-gamma * d);
    }
}

#[inline(always)]
pub(crate) fn rbf_from_dots_generic(out: &mut [f32], na: f32, nb: &[f32], gamma: f32) {
    for (o, &b) in out.iter_mut().zip(nb) {
        // Cancellation can make the distance slightly negative for near-duplicates.
        let d2 = (na + b - 2.0 * *o).max(0.0);
        *o = exp_nonpos(-gamma * d2);
    }
}

/// `exp(x)` for `x <= 0` (Cephes polynomial, relative error about 2e-7), written so that the
/// compiler vectorizes it; `std`'s `expf` is a scalar libm call and would dominate the
/// `n²` kernel evaluations.
#[inline(always)]
pub(crate) fn exp_nonpos(x: f32) -> f32 {
    const LOG2E: f32 = std::f32::consts::LOG2_E;
    const ROUND: f32 = 12_582_912.0; // 1.5 * 2^23: adding and subtracting it rounds to integer
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    let x = x.clamp(-87.0, 0.0);
    let n = (x * LOG2E + ROUND) - ROUND;
    let r = x - n * LN2_HI - n * LN2_LO;
    let p = ((((1.987_569_1e-4 * r + 1.398_199_9e-3) * r + 8.333_452e-3) * r + 4.166_579_6e-2) * r
        + 1.666_666_5e-1)
        * r
        + 0.5;
    let e = p * (r * r) + r + 1.0;
    let scale = f32::from_bits((((n as i32) + 127) as u32) << 23);
    e * scale
}

/// `out (ma × mb, row stride ldo) = A Bᵀ` for row-major `A (ma × dim)`, `B (mb × dim)`,
/// sequential (callers parallelize over tiles).
fn gemm_abt(a: &[f32], b: &[f32], dim: usize, out: MatMut<'_, f32>) {
    let ma = a.len() / dim;
    let mb = b.len() / dim;
    let lhs = MatRef::from_row_major_slice(a, ma, dim);
    let rhs = MatRef::from_row_major_slice(b, mb, dim).transpose();
    matmul(out, Accum::Replace, lhs, rhs, 1.0f32, Par::Seq);
}

/// Raw output pointer shared by tiles that write disjoint regions.
#[derive(Clone, Copy)]
struct OutPtr(*mut f32);
// SAFETY: only used to write disjoint tiles of one buffer from different threads.
unsafe impl Send for OutPtr {}
unsafe impl Sync for OutPtr {}

impl OutPtr {
    /// Method access makes closures capture the whole (`Sync`) wrapper, not the raw field.
    fn at(self, offset: usize) -> *mut f32 {
        self.0.wrapping_add(offset)
    }
}

/// Computes `out[i * ldo + j] = K(a_i, b_j)` (or the squared distance when `gamma` is
/// `None`) for a tile, where `out` points at the tile's
/// first element.
///
/// # Safety
/// `out` must be valid for the `ma × mb` tile with row stride `ldo`, and no other thread may
/// access that region concurrently.
unsafe fn kernel_tile(
    a: FeatureMatrixRef<'_>,
    na: &[f32],
    b: FeatureMatrixRef<'_>,
    nb: &[f32],
    gamma: Option<f32>,
    out: *mut f32,
    ldo: usize,
) {
    let (ma, mb, dim) = (a.rows(), b.rows(), a.cols());
    if ma == 0 || mb == 0 {
        return;
    }
    // SAFETY: guaranteed by the caller.
    let tile = unsafe { MatMut::from_raw_parts_mut(out, ma, mb, ldo as isize, 1) };
    gemm_abt(a.as_slice(), b.as_slice(), dim, tile);
    for (i, &nai) in na.iter().enumerate().take(ma) {
        // SAFETY: row `i` of the tile lies inside the region the caller handed us.
        let row = unsafe { std::slice::from_raw_parts_mut(out.add(i * ldo), mb) };
        match gamma {
            Some(g) => rbf_from_dots(row, nai, nb, g),
            None => dist_from_dots(row, nai, nb),
        }
    }
}

fn sub(x: FeatureMatrixRef<'_>, r0: usize, r1: usize) -> FeatureMatrixRef<'_> {
    x.rows_range(r0, r1)
}

/// Kernel block `out (a.rows() × b.rows(), row-major) = K(a_i, b_j)`, tiled and parallel.
pub(crate) fn cross_kernel(
    a: FeatureMatrixRef<'_>,
    na: &[f32],
    b: FeatureMatrixRef<'_>,
    nb: &[f32],
    gamma: f32,
    out: &mut [f32],
) {
    cross_block(a, na, b, nb, Some(gamma), out)
}

/// Squared distances `out (a.rows() × b.rows()) = |a_i - b_j|²`, from which kernels of any
/// width follow with [`exp_neg_scaled`] (the classifier and the regressors may differ).
pub(crate) fn cross_sq_dist(
    a: FeatureMatrixRef<'_>,
    na: &[f32],
    b: FeatureMatrixRef<'_>,
    nb: &[f32],
    out: &mut [f32],
) {
    cross_block(a, na, b, nb, None, out)
}

fn cross_block(
    a: FeatureMatrixRef<'_>,
    na: &[f32],
    b: FeatureMatrixRef<'_>,
    nb: &[f32],
    gamma: Option<f32>,
    out: &mut [f32],
) {
    let (ma, mb) = (a.rows(), b.rows());
    assert_eq!(out.len(), ma * mb, "cross_kernel output size");
    assert_eq!(a.cols(), b.cols(), "cross_kernel dimensions");
    if ma == 0 || mb == 0 {
        return;
    }
    // Wide column tiles when there are few queries, so that both cores get work.
    let tc = if ma < TILE { 1024 } else { 4 * TILE };
    let tiles: Vec<(usize, usize)> = (0..ma.div_ceil(TILE))
        .flat_map(|ti| (0..mb.div_ceil(tc)).map(move |tj| (ti, tj)))
        .collect();
    let ptr = OutPtr(out.as_mut_ptr());
    tiles.par_iter().for_each(|&(ti, tj)| {
        let (r0, r1) = (ti * TILE, ((ti + 1) * TILE).min(ma));
        let (c0, c1) = (tj * tc, ((tj + 1) * tc).min(mb));
        // SAFETY: tiles are disjoint rectangles inside `out`.
        unsafe {
            kernel_tile(
                sub(a, r0, r1),
                &na[r0..r1],
                sub(b, c0, c1),
                &nb[c0..c1],
                gamma,
                ptr.at(r0 * mb + c0),
                mb,
            )
        };
    });
}

/// Full symmetric kernel matrix of `x` (row-major `n × n`); only the upper tiles go through
/// GEMM, the lower ones are mirrored.
pub(crate) fn gram(x: FeatureMatrixRef<'_>, norms: &[f32], gamma: f32) -> Vec<f32> {
    let n = x.rows();
    let mut out = vec![0.0f32; n * n];
    if n == 0 {
        return out;
    }
    let nt = n.div_ceil(TILE);
    let tiles: Vec<(usize, usize)> = (0..nt)
        .flat_map(|ti| (ti..nt).map(move |tj| (ti, tj)))
        .collect();
    let ptr = OutPtr(out.as_mut_ptr());
    tiles.par_iter().for_each(|&(ti, tj)| {
        let (r0, r1) = (ti * TILE, ((ti + 1) * TILE).min(n));
        let (c0, c1) = (tj * TILE, ((tj + 1) * TILE).min(n));
        // SAFETY: upper tiles are disjoint rectangles inside `out`.
        unsafe {
            kernel_tile(
                sub(x, r0, r1),
                &norms[r0..r1],
                sub(x, c0, c1),
                &norms[c0..c1],
                Some(gamma),
                ptr.at(r0 * n + c0),
                n,
            )
        };
    });
    // Mirror: row block `ti` receives the transpose of the upper tiles of column block `ti`.
    (0..nt).into_par_iter().for_each(|ti| {
        let (r0, r1) = (ti * TILE, ((ti + 1) * TILE).min(n));
        for tj in 0..ti {
            let (c0, c1) = (tj * TILE, ((tj + 1) * TILE).min(n));
            for i in r0..r1 {
                for j in c0..c1 {
                    // SAFETY: reads the finished upper triangle (j < i), writes the lower
                    // triangle of this thread's own row block.
                    unsafe { *ptr.at(i * n + j) = *ptr.at(j * n + i) };
                }
            }
        }
        // Diagonal tile: mirror its own upper half.
        for i in r0..r1 {
            for j in r0..i {
                // SAFETY: as above, within this thread's row block.
                unsafe { *ptr.at(i * n + j) = *ptr.at(j * n + i) };
            }
        }
    });
    out
}

/// Kernel rows `K(x_r, x_j)` for every `r` in `rows` and all `j`, into `out`
/// (`rows.len() × x.rows()`): one GEMM of the gathered rows against `x`.
pub(crate) fn kernel_rows(
    x: FeatureMatrixRef<'_>,
    norms: &[f32],
    rows: &[usize],
    gamma: f32,
    out: &mut [f32],
) {
    let a = x.select(rows);
    let na: Vec<f32> = rows.iter().map(|&r| norms[r]).collect();
    cross_kernel(a.view(), &na, x, norms, gamma, out);
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::matrix::owned;
    use ridi_features::FeatureMatrix;

    /// Radial basis function kernel `exp(-gamma |a - b|²)`.
    struct Rbf {
        /// Width parameter; the paper uses `1 / 1200`.
        gamma: f32,
    }

    impl Rbf {
        /// Kernel value of two vectors (reference implementation, not the fast path).
        fn eval(&self, a: &[f32], b: &[f32]) -> f32 {
            let d2: f32 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
            (-self.gamma * d2).exp()
        }
    }

    /// Smooth test rows of magnitude up to about 3 (shared with other modules' tests).
    pub(crate) fn data(n: usize, d: usize) -> FeatureMatrix {
        let v: Vec<f32> = (0..n * d)
            .map(|k| ((k as f32) * 0.37).sin() * 2.0 + ((k / d) as f32 * 0.1).cos())
            .collect();
        owned(v, d)
    }

    #[test]
    fn fast_exp_matches_std() {
        let mut worst = 0.0f32;
        for k in 0..100_000 {
            let x = -(k as f32) * 8.0e-4;
            let rel = (exp_nonpos(x) - x.exp()).abs() / x.exp();
            worst = worst.max(rel);
        }
        assert!(worst < 5e-7, "worst relative error {worst}");
        assert_eq!(exp_nonpos(0.0), 1.0);
        assert!(exp_nonpos(-1000.0) < 1e-37);
    }

    #[test]
    fn gram_matches_direct_evaluation() {
        // 300 rows span two tiles, so both the GEMM tiles and the mirroring are exercised.
        let x = data(300, 37);
        let rbf = Rbf { gamma: 0.05 };
        let norms = sq_norms(x.view());
        let k = gram(x.view(), &norms, rbf.gamma);
        for i in (0..300).step_by(7) {
            for j in (0..300).step_by(11) {
                let direct = rbf.eval(x.row(i), x.row(j));
                assert!((k[i * 300 + j] - direct).abs() < 2e-5, "({i},{j})");
                assert_eq!(k[i * 300 + j], k[j * 300 + i]);
            }
            assert!((k[i * 300 + i] - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn rows_and_cross_blocks_agree() {
        let x = data(130, 20);
        let q = data(5, 20);
        let norms = sq_norms(x.view());
        let qn = sq_norms(q.view());
        let mut out = vec![0.0; 5 * 130];
        cross_kernel(q.view(), &qn, x.view(), &norms, 0.1, &mut out);
        let rbf = Rbf { gamma: 0.1 };
        for i in 0..5 {
            for j in 0..130 {
                assert!((out[i * 130 + j] - rbf.eval(q.row(i), x.row(j))).abs() < 2e-5);
            }
        }
        let mut rows = vec![0.0; 2 * 130];
        kernel_rows(x.view(), &norms, &[3, 77], 0.1, &mut rows);
        assert!((rows[130 + 77] - 1.0).abs() < 1e-5);
        assert!((rows[5] - rbf.eval(x.row(3), x.row(5))).abs() < 2e-5);
    }
}
