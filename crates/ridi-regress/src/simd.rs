//! The x86-64 vector code paths and the one run-time check of the CPU that picks them.
//!
//! Each hot loop has a portable version beside its caller, which calls the version here when
//! [`avx2`] (AVX2 and FMA) or [`avx2_f16c`] (and F16C) says the running CPU has the features:
//! a build for generic x86-64 still runs vector code where the CPU allows it. The CPU is
//! asked once per process.
//!
//! - The kernel's dot product, RBF values from dot products and `exp(-γ d²)` (`kernel`): the
//!   portable code compiled with AVX2 and FMA enabled, which the compiler vectorizes.
//! - The half-precision dot products of prediction (`F16Matrix::dots`): hand-written, rows
//!   widened by F16C.
//! - The SMO solver's gather, fused gradient update and maximum search, and WSS3 selection
//!   (`smo::hot`): hand-written, with exactly the portable results (tested below).

use std::arch::x86_64::*;
use std::sync::OnceLock;

use crate::kernel;
use crate::smo::hot::{wss_gain, wss_select_generic};

/// The CPU has AVX2 and FMA.
pub(crate) fn avx2() -> bool {
    static FLAG: OnceLock<bool> = OnceLock::new();
    *FLAG.get_or_init(|| is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma"))
}

/// The CPU has AVX2, FMA and F16C (half-precision conversion).
pub(crate) fn avx2_f16c() -> bool {
    static FLAG: OnceLock<bool> = OnceLock::new();
    *FLAG.get_or_init(|| {
        is_x86_feature_detected!("avx2")
            && is_x86_feature_detected!("fma")
            && is_x86_feature_detected!("f16c")
    })
}

// The kernel's loops: the portable code, vectorized by the compiler for AVX2 and FMA.

/// [`kernel::dot`].
///
/// # Safety
/// AVX2 and FMA must be available.
#[target_feature(enable = "avx2,fma")]
pub(crate) unsafe fn dot_avx2(a: &[f32], b: &[f32]) -> f32 {
    kernel::dot_generic(a, b)
}

/// [`kernel::exp_neg_scaled`].
///
/// # Safety
/// AVX2 and FMA must be available.
#[target_feature(enable = "avx2,fma")]
pub(crate) unsafe fn exp_neg_scaled_avx2(d2: &[f32], gamma: f32, out: &mut [f32]) {
    kernel::exp_neg_scaled_generic(d2, gamma, out)
}

/// [`kernel::rbf_from_dots`].
///
/// # Safety
/// AVX2 and FMA must be available.
#[target_feature(enable = "avx2,fma")]
pub(crate) unsafe fn rbf_from_dots_avx2(out: &mut [f32], na: f32, nb: &[f32], gamma: f32) {
    kernel::rbf_from_dots_generic(out, na, nb, gamma)
}

// Half-precision rows (`F16Matrix::dots`).

/// Rows ahead to prefetch: a DRAM stream of several rows at once outruns the hardware
/// prefetcher, which then leaves the core waiting on misses.
const PREFETCH_ROWS: usize = 8;

/// Hint only: never faults, so it may point past the matrix.
#[inline(always)]
fn prefetch(p: *const u16) {
    // SAFETY: a prefetch does not access memory architecturally.
    unsafe { _mm_prefetch::<_MM_HINT_T0>(p as *const i8) };
}

/// `F16Matrix::dots` over the binary16 bits of `out.len()` rows of `q.len()` values. Rows
/// four at a time so that each loaded block of the query feeds four rows, with two
/// accumulators per row to cover the FMA latency. Every row is summed in the same order
/// whatever block it falls in, so a row's dot product does not depend on its position.
///
/// # Safety
/// AVX2, FMA and F16C must be available; `rows` must hold `out.len()` rows of `q.len()`
/// values.
#[target_feature(enable = "avx2,fma,f16c")]
pub(crate) unsafe fn f16_dots_avx2(q: &[f32], rows: &[u16], out: &mut [f32]) {
    let dim = q.len();
    let mut j = 0;
    while j + 4 <= out.len() {
        // SAFETY: rows `j..j + 4` exist (`rows` holds `out.len()` rows of `dim`).
        let d = unsafe { block::<4>(q, rows.as_ptr().add(j * dim)) };
        out[j..j + 4].copy_from_slice(&d);
        j += 4;
    }
    while j < out.len() {
        // SAFETY: as above, row `j`.
        out[j] = unsafe { block::<1>(q, rows.as_ptr().add(j * dim)) }[0];
        j += 1;
    }
}

/// Dot products of `q` with the `R` consecutive rows of `q.len()` values at `p`.
#[target_feature(enable = "avx2,fma,f16c")]
#[inline]
unsafe fn block<const R: usize>(q: &[f32], p: *const u16) -> [f32; R] {
    let dim = q.len();
    let main = dim / 16 * 16;
    let qp = q.as_ptr();
    let mut acc = [[_mm256_setzero_ps(); 2]; R];
    let mut k = 0;
    // SAFETY (all pointer reads): `k + 16 <= main <= dim` inside each row, and the
    // caller guarantees `R` rows of `dim` values at `p`.
    unsafe {
        while k < main {
            let q0 = _mm256_loadu_ps(qp.add(k));
            let q1 = _mm256_loadu_ps(qp.add(k + 8));
            for (r, a) in acc.iter_mut().enumerate() {
                let s = p.add(r * dim + k);
                if k % 32 == 0 {
                    prefetch(s.wrapping_add(PREFETCH_ROWS * dim));
                }
                let s0 = _mm256_cvtph_ps(_mm_loadu_si128(s as *const __m128i));
                let s1 = _mm256_cvtph_ps(_mm_loadu_si128(s.add(8) as *const __m128i));
                a[0] = _mm256_fmadd_ps(q0, s0, a[0]);
                a[1] = _mm256_fmadd_ps(q1, s1, a[1]);
            }
            k += 16;
        }
    }
    let mut out = [0.0f32; R];
    for (r, (o, a)) in out.iter_mut().zip(&acc).enumerate() {
        let v = _mm256_add_ps(a[0], a[1]);
        let h = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
        let h = _mm_add_ps(h, _mm_movehl_ps(h, h));
        let h = _mm_add_ss(h, _mm_shuffle_ps(h, h, 1));
        let mut s = _mm_cvtss_f32(h);
        for (c, &qc) in q.iter().enumerate().skip(main) {
            // SAFETY: `c < dim` inside row `r`.
            let b = unsafe { *p.add(r * dim + c) };
            s += qc * half::f16::from_bits(b).to_f32();
        }
        *o = s;
    }
    out
}

// The SMO solver's loops (`smo::hot`).

/// `out[k] = row[idx[k]]` (`smo`'s gather).
///
/// # Safety
/// AVX2 must be available; every index must be below `row.len()` and fit `i32`.
#[target_feature(enable = "avx2,fma")]
pub(crate) unsafe fn gather_avx2(row: &[f32], idx: &[u32], out: &mut [f32]) {
    let n = out.len().min(idx.len());
    let mut k = 0;
    while k + 8 <= n {
        // SAFETY: k + 8 <= n; the gathered indices are below row.len() (caller contract).
        unsafe {
            let vi = _mm256_loadu_si256(idx.as_ptr().add(k) as *const __m256i);
            let v = _mm256_i32gather_ps::<4>(row.as_ptr(), vi);
            _mm256_storeu_ps(out.as_mut_ptr().add(k), v);
        }
        k += 8;
    }
    for t in k..n {
        out[t] = row[idx[t] as usize];
    }
}

/// Largest lane value and the smallest index holding it (`(-inf, usize::MAX)` when every
/// value is `-inf`, or below `floor`): the reduction of per-lane "first maximum" trackers.
fn reduce_lanes<T: Copy + PartialOrd>(vals: &[T], idx: &[usize], floor: T) -> (T, usize) {
    let mut best = (floor, usize::MAX);
    for (&v, &i) in vals.iter().zip(idx) {
        if v > best.0 || (v == best.0 && i < best.1 && v > floor) {
            best = (v, i);
        }
    }
    best
}

/// `smo`'s `masked_max_neg`.
///
/// # Safety
/// AVX2 must be available.
#[target_feature(enable = "avx2,fma")]
pub(crate) unsafe fn masked_max_neg_avx2(v: &[f64], mask: &[f64]) -> (f64, usize) {
    let n = v.len().min(mask.len());
    // SAFETY: AVX2 is enabled here; without the update `v` is only read.
    unsafe { max_pass::<false>(v.as_ptr() as *mut f64, n, (0.0, &[]), (0.0, &[]), mask) }
}

/// `max_k mask[k] - v[k]` with the position of its first occurrence, after (with `UPDATE`)
/// `v[k] += a x[k] + b z[k]` in the same pass. Per-lane maxima and positions in two
/// independent sets of lanes (to overlap the compare-blend latency), then `reduce_lanes`.
///
/// # Safety
/// AVX2 must be available; `v` and `mask` must hold `n` values, and so must `x` and `z`
/// with `UPDATE` (which writes `v`).
#[target_feature(enable = "avx2,fma")]
pub(crate) unsafe fn max_pass<const UPDATE: bool>(
    v: *mut f64,
    n: usize,
    (a, x): (f64, &[f32]),
    (b, z): (f64, &[f32]),
    mask: &[f64],
) -> (f64, usize) {
    let (va, vb) = (_mm256_set1_pd(a), _mm256_set1_pd(b));
    let mut best = [_mm256_set1_pd(f64::NEG_INFINITY); 2];
    let mut bidx = [_mm256_set1_pd(0.0); 2];
    let mut idx = [
        _mm256_setr_pd(0.0, 1.0, 2.0, 3.0),
        _mm256_setr_pd(4.0, 5.0, 6.0, 7.0),
    ];
    let eight = _mm256_set1_pd(8.0);
    let mut k = 0;
    while k + 8 <= n {
        for h in 0..2 {
            let o = k + 4 * h;
            // SAFETY: o + 4 <= n, within every slice (caller contract).
            unsafe {
                let mut cur = _mm256_loadu_pd(v.add(o));
                if UPDATE {
                    let xv = _mm256_cvtps_pd(_mm_loadu_ps(x.as_ptr().add(o)));
                    let zv = _mm256_cvtps_pd(_mm_loadu_ps(z.as_ptr().add(o)));
                    let d = _mm256_add_pd(_mm256_mul_pd(va, xv), _mm256_mul_pd(vb, zv));
                    cur = _mm256_add_pd(cur, d);
                    _mm256_storeu_pd(v.add(o), cur);
                }
                let m = _mm256_sub_pd(_mm256_loadu_pd(mask.as_ptr().add(o)), cur);
                let gt = _mm256_cmp_pd::<_CMP_GT_OQ>(m, best[h]);
                best[h] = _mm256_blendv_pd(best[h], m, gt);
                bidx[h] = _mm256_blendv_pd(bidx[h], idx[h], gt);
            }
            idx[h] = _mm256_add_pd(idx[h], eight);
        }
        k += 8;
    }
    let (mut vals, mut pos) = ([0.0f64; 8], [0.0f64; 8]);
    // SAFETY: both arrays hold eight f64.
    unsafe {
        for h in 0..2 {
            _mm256_storeu_pd(vals.as_mut_ptr().add(4 * h), best[h]);
            _mm256_storeu_pd(pos.as_mut_ptr().add(4 * h), bidx[h]);
        }
    }
    let pos = pos.map(|p| p as usize);
    let mut out = reduce_lanes(&vals, &pos, f64::NEG_INFINITY);
    for t in k..n {
        // SAFETY: t < n (caller contract).
        let cur = unsafe {
            if UPDATE {
                *v.add(t) += a * x[t] as f64 + b * z[t] as f64;
            }
            *v.add(t)
        };
        let m = mask[t] - cur;
        if m > out.0 {
            out = (m, t);
        }
    }
    out
}

/// `smo`'s `wss_select`, eight candidates per step: the `f64` sums in two halves, the `f32`
/// gains in one vector.
///
/// # Safety
/// AVX2 must be available; `low` and `kv` must hold at least `v.len()` values.
#[target_feature(enable = "avx2,fma")]
pub(crate) unsafe fn wss_select_avx2(
    v: &[f64],
    low: &[f64],
    kv: &[f32],
    gmax: f64,
) -> (f64, Option<usize>) {
    let n = v.len();
    let vg = _mm256_set1_pd(gmax);
    let two = _mm256_set1_ps(2.0);
    let tiny = _mm256_set1_ps(1e-12);
    let zero = _mm256_setzero_ps();
    let mut acc = [_mm256_set1_pd(f64::NEG_INFINITY); 2];
    let mut best = _mm256_setzero_ps();
    let mut bidx = _mm256_setzero_si256();
    let mut idx = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    let eight = _mm256_set1_epi32(8);
    let mut k = 0;
    while k + 8 <= n {
        // SAFETY: k + 8 <= n <= every slice's length (checked by the caller).
        unsafe {
            let mut gd = [_mm_setzero_ps(); 2];
            for h in 0..2 {
                let o = k + 4 * h;
                let m = _mm256_add_pd(
                    _mm256_loadu_pd(v.as_ptr().add(o)),
                    _mm256_loadu_pd(low.as_ptr().add(o)),
                );
                acc[h] = _mm256_max_pd(acc[h], m);
                gd[h] = _mm256_cvtpd_ps(_mm256_add_pd(vg, m));
            }
            let gd = _mm256_set_m128(gd[1], gd[0]);
            let kvv = _mm256_loadu_ps(kv.as_ptr().add(k));
            let q = _mm256_max_ps(_mm256_sub_ps(two, _mm256_mul_ps(two, kvv)), tiny);
            let pos = _mm256_cmp_ps::<_CMP_GT_OQ>(gd, zero);
            let sc = _mm256_and_ps(_mm256_div_ps(_mm256_mul_ps(gd, gd), q), pos);
            let gt = _mm256_cmp_ps::<_CMP_GT_OQ>(sc, best);
            best = _mm256_blendv_ps(best, sc, gt);
            bidx = _mm256_blendv_epi8(bidx, idx, _mm256_castps_si256(gt));
        }
        idx = _mm256_add_epi32(idx, eight);
        k += 8;
    }
    let (mut lanes, mut vals, mut pos) = ([0.0f64; 8], [0.0f32; 8], [0i32; 8]);
    // SAFETY: the arrays hold eight lanes each.
    unsafe {
        _mm256_storeu_pd(lanes.as_mut_ptr(), acc[0]);
        _mm256_storeu_pd(lanes.as_mut_ptr().add(4), acc[1]);
        _mm256_storeu_ps(vals.as_mut_ptr(), best);
        _mm256_storeu_si256(pos.as_mut_ptr() as *mut __m256i, bidx);
    }
    let pos = pos.map(|p| p as usize);
    let mut out = reduce_lanes(&vals, &pos, 0.0f32);
    // The tail, then the lanes: a later position wins only with a strictly larger gain.
    let (tail_g2, tail_pos) = wss_select_generic(&v[k..], &low[k..], &kv[k..n], gmax);
    if let Some(t) = tail_pos {
        let sc = wss_gain(gmax, v[k + t] + low[k + t], kv[k + t]);
        if sc > out.0 {
            out = (sc, k + t);
        }
    }
    let gmax2 = lanes
        .iter()
        .fold(tail_g2, |a, &b| if b > a { b } else { a });
    (gmax2, (out.1 != usize::MAX).then_some(out.1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::smo::hot::{masked_max_neg_generic, update_gmax_generic_mut, wss_select_generic};

    #[test]
    fn vector_kernels_match_the_scalar_ones() {
        if !avx2() {
            return;
        }
        for n in [0, 1, 3, 4, 7, 8, 33, 257] {
            let v: Vec<f64> = (0..n)
                .map(|k| ((k * 37 % 11) as f64 - 5.0) * 0.25)
                .collect();
            // Ties (repeated values) and non-members.
            let mask: Vec<f64> = (0..n)
                .map(|k| {
                    if k % 5 == 2 {
                        f64::NEG_INFINITY
                    } else {
                        (k % 3) as f64 * 0.5
                    }
                })
                .collect();
            let kv: Vec<f32> = (0..n).map(|k| ((k * 13 % 7) as f32) / 7.0).collect();
            let x: Vec<f32> = (0..n).map(|k| (k as f32 * 0.3).sin()).collect();
            // SAFETY: AVX2 checked above.
            let fast = unsafe { masked_max_neg_avx2(&v, &mask) };
            assert_eq!(fast, masked_max_neg_generic(&v, &mask), "n = {n}");
            for gmax in [-1.0, 0.0, 0.75, 3.0] {
                // SAFETY: AVX2 checked above.
                let fast = unsafe { wss_select_avx2(&v, &mask, &kv, gmax) };
                assert_eq!(fast, wss_select_generic(&v, &mask, &kv, gmax), "n = {n}");
            }
            let (mut v1, mut v2) = (v.clone(), v.clone());
            // SAFETY: AVX2 checked above; all slices have length n.
            let fast =
                unsafe { max_pass::<true>(v1.as_mut_ptr(), n, (0.5, &x), (-2.0, &kv), &mask) };
            let slow = update_gmax_generic_mut(&mut v2, (0.5, &x), (-2.0, &kv), &mask);
            assert_eq!((fast, &v1), (slow, &v2), "n = {n}");
        }
    }
}
