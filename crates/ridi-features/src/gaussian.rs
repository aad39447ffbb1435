//! Gaussian smoothing with the semantics of `scipy.ndimage.gaussian_filter1d`.
//!
//! - Kernel radius `r = int(truncate * sigma + 0.5)`, weights `exp(-x^2 / (2 sigma^2))` for
//!   `x = -r..=r`, normalized to sum 1 (computed in `f64`, like scipy).
//! - Borders in scipy's `'reflect'` mode, the half-sample symmetric extension
//!   `d c b a | a b c d | d c b a`. A signal shorter than the radius is extended by repeated
//!   reflection, which makes the extension periodic with period `2 n`.
//!
//! One deliberate difference: `sigma = 0` is allowed and means "no smoothing" (a one-tap
//! kernel), where scipy produces NaN weights.

use crate::FeatureError;

/// Kernel radius scipy uses: `int(truncate * sigma + 0.5)`.
///
/// Both arguments must be finite and non-negative (checked by the public constructors that
/// call this); the result saturates for absurd products rather than wrapping.
pub(crate) fn kernel_radius(sigma: f64, truncate: f64) -> usize {
    // `as` truncates toward zero like Python's int() for the non-negative values allowed here.
    (truncate * sigma + 0.5) as usize
}

fn check_params(sigma: f64, truncate: f64) -> Result<(), FeatureError> {
    if !(sigma.is_finite() && sigma >= 0.0) {
        return Err(FeatureError::InvalidConfig(format!(
            "sigma must be finite and >= 0, got {sigma}"
        )));
    }
    if !(truncate.is_finite() && truncate > 0.0) {
        return Err(FeatureError::InvalidConfig(format!(
            "truncate must be finite and > 0, got {truncate}"
        )));
    }
    // A radius beyond this is a configuration mistake, not a smoothing request, and would
    // allocate absurd kernels.
    if kernel_radius(sigma, truncate) > 1 << 20 {
        return Err(FeatureError::InvalidConfig(format!(
            "kernel radius for sigma {sigma} and truncate {truncate} is too large"
        )));
    }
    Ok(())
}

/// The normalized Gaussian kernel, `2 r + 1` taps from `-r` to `r` (see the module docs).
pub fn gaussian_kernel(sigma: f64, truncate: f64) -> Result<Vec<f64>, FeatureError> {
    let half = half_kernel(sigma, truncate)?;
    let r = half.len() - 1;
    Ok((0..=2 * r)
        .map(|i| half[i.abs_diff(r)])
        .collect::<Vec<f64>>())
}

/// The non-negative half of the kernel, `[w_0, w_1, ..., w_r]`, normalized so that the full
/// symmetric kernel sums to 1.
pub(crate) fn half_kernel(sigma: f64, truncate: f64) -> Result<Vec<f64>, FeatureError> {
    check_params(sigma, truncate)?;
    let r = kernel_radius(sigma, truncate);
    if r == 0 {
        return Ok(vec![1.0]);
    }
    let a = -0.5 / (sigma * sigma);
    // The centre tap is 1 whatever `a` is: for a sigma whose square underflows, `a` is -inf
    // and `-inf * 0` would be NaN.
    let half: Vec<f64> = (0..=r)
        .map(|x| {
            if x == 0 {
                1.0
            } else {
                (a * (x * x) as f64).exp()
            }
        })
        .collect();
    // Sum in scipy's order (from -r to r) so the normalization matches to the last bit as
    // closely as a different summation engine allows.
    let sum: f64 = (0..=2 * r).map(|i| half[i.abs_diff(r)]).sum();
    Ok(half.into_iter().map(|w| w / sum).collect())
}

/// Index into a signal of length `n >= 1` for any position of its `'reflect'` extension.
#[inline]
pub(crate) fn reflect_index(i: isize, n: usize) -> usize {
    debug_assert!(n > 0);
    let period = 2 * n as isize;
    let m = i.rem_euclid(period) as usize;
    if m < n { m } else { 2 * n - 1 - m }
}

/// `scipy.ndimage.gaussian_filter1d(input, sigma, truncate=truncate, mode='reflect')` for a
/// 1-D `f64` signal. An empty input gives an empty output.
pub fn gaussian_filter1d(
    input: &[f64],
    sigma: f64,
    truncate: f64,
) -> Result<Vec<f64>, FeatureError> {
    let half = half_kernel(sigma, truncate)?;
    let mut out = vec![0.0; input.len()];
    filter_strided_f64(input, &mut out, 1, &half);
    Ok(out)
}

/// Smooths `len = src.len() / stride` rows of `stride` interleaved channels along the rows,
/// each channel independently, with `'reflect'` borders at the ends of `src`. `half` is
/// [`half_kernel`]; `src` and `out` have equal lengths, a multiple of `stride`.
///
/// Interleaved channels are a flat signal whose taps are `stride` apart, so the interior is one
/// contiguous loop per tap over all channels at once (which the compiler vectorizes); only the
/// `r` rows at each end need the reflected indices.
pub(crate) fn filter_strided_f64(src: &[f64], out: &mut [f64], stride: usize, half: &[f64]) {
    filter_strided(src, out, stride, half);
}

/// The `f32` twin of [`filter_strided_f64`], used for feature windows.
///
/// On x86-64 CPUs with AVX2 the same code is compiled a second time for 8-lane vectors and
/// picked at run time. No fused multiply-add is involved and every lane performs the same
/// operations in the same order, so both versions give bit-identical results.
pub(crate) fn filter_strided_f32(src: &[f32], out: &mut [f32], stride: usize, half: &[f32]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2, checked just above.
        unsafe { filter_strided_f32_avx2(src, out, stride, half) };
        return;
    }
    filter_strided(src, out, stride, half);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn filter_strided_f32_avx2(src: &[f32], out: &mut [f32], stride: usize, half: &[f32]) {
    filter_strided(src, out, stride, half);
}

trait Sample:
    Copy + Default + std::ops::Add<Output = Self> + std::ops::Mul<Output = Self> + std::ops::AddAssign
{
}
impl Sample for f32 {}
impl Sample for f64 {}

#[inline(always)]
fn filter_strided<T: Sample>(src: &[T], out: &mut [T], stride: usize, half: &[T]) {
    debug_assert_eq!(src.len(), out.len());
    debug_assert!(stride > 0 && src.len().is_multiple_of(stride) && !half.is_empty());
    let len = src.len() / stride;
    if len == 0 {
        return;
    }
    let r = half.len() - 1;
    // Rows [lo, hi) have all 2r+1 taps inside the signal; the rest are border rows.
    let lo = r.min(len);
    let hi = len.saturating_sub(r).max(lo);

    if lo < hi {
        let (a, b) = (lo * stride, hi * stride);
        interior(src, a, &mut out[a..b], stride, half);
    }
    border(src, out, stride, half, 0..lo);
    border(src, out, stride, half, hi..len);
}

/// Largest padded border block kept on the stack (elements). The paper's windows need
/// `(8 + 2 * 8) * 6 = 144`.
const PAD_MAX: usize = 512;

/// Output rows `rows` (within `r` of an end), whose taps need the reflected extension.
#[inline(always)]
fn border<T: Sample>(
    src: &[T],
    out: &mut [T],
    stride: usize,
    half: &[T],
    rows: std::ops::Range<usize>,
) {
    if rows.is_empty() {
        return;
    }
    let len = src.len() / stride;
    let r = half.len() - 1;
    let first = rows.start as isize - r as isize;
    let ext_rows = rows.len() + 2 * r;
    let n = ext_rows * stride;
    if n <= PAD_MAX {
        // Copy the reflected neighbourhood into a small contiguous buffer, then run the same
        // register-blocked loop as the interior: border rows cost about as much as inner ones.
        let mut buf = [T::default(); PAD_MAX];
        for k in 0..ext_rows {
            let s = reflect_fast(first + k as isize, len, r) * stride;
            buf[k * stride..(k + 1) * stride].copy_from_slice(&src[s..s + stride]);
        }
        interior(
            &buf[..n],
            r * stride,
            &mut out[rows.start * stride..rows.end * stride],
            stride,
            half,
        );
        return;
    }
    // Wide kernels (targets) or wide rows: few rows, so a plain loop is fine. The accumulator
    // stays in a register, never in `out`, to avoid a store-to-load chain per tap.
    for t in rows {
        for c in 0..stride {
            let mut acc = T::default();
            for j in -(r as isize)..=(r as isize) {
                let s = reflect_fast(t as isize + j, len, r);
                acc += half[j.unsigned_abs()] * src[s * stride + c];
            }
            out[t * stride + c] = acc;
        }
    }
}

/// [`reflect_index`], with two comparisons instead of a division when one reflection is
/// enough (offsets up to `r <= n`); only signals shorter than the radius need the modulo.
#[inline]
fn reflect_fast(i: isize, n: usize, r: usize) -> usize {
    if r > n {
        return reflect_index(i, n);
    }
    if i < 0 {
        (-i - 1) as usize
    } else if (i as usize) < n {
        i as usize
    } else {
        2 * n - 1 - i as usize
    }
}

/// `out[j]` = the smoothed value at flat index `start + j` of `src`, for outputs all of whose
/// taps (`start + j -+ r * stride`) lie inside `src`.
///
/// Blocks of `B` outputs keep their accumulators in registers across all taps, so each output
/// is stored once instead of once per tap; the fixed-size arrays let the compiler unroll and
/// vectorize the lane loop without bounds checks.
#[inline(always)]
fn interior<T: Sample>(src: &[T], start: usize, out: &mut [T], stride: usize, half: &[T]) {
    const B: usize = 16;
    let w0 = half[0];
    let mut blocks = out.chunks_exact_mut(B);
    let mut i = start;
    for o in &mut blocks {
        let mut acc = [T::default(); B];
        let c: &[T; B] = src[i..i + B].try_into().expect("block of B");
        for j in 0..B {
            acc[j] = w0 * c[j];
        }
        for (k, &w) in half.iter().enumerate().skip(1) {
            let d = k * stride;
            let l: &[T; B] = src[i - d..i - d + B].try_into().expect("block of B");
            let rt: &[T; B] = src[i + d..i + d + B].try_into().expect("block of B");
            for j in 0..B {
                acc[j] += w * (l[j] + rt[j]);
            }
        }
        o.copy_from_slice(&acc);
        i += B;
    }
    for o in blocks.into_remainder() {
        let mut acc = w0 * src[i];
        for (k, &w) in half.iter().enumerate().skip(1) {
            let d = k * stride;
            acc += w * (src[i - d] + src[i + d]);
        }
        *o = acc;
        i += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_kernel_is_the_kernel_from_its_centre() {
        let k = gaussian_kernel(2.0, 4.0).unwrap();
        assert_eq!(half_kernel(2.0, 4.0).unwrap()[..], k[8..]);
        assert_eq!(kernel_radius(30.0, 4.0), 120);
    }

    #[test]
    fn a_sigma_whose_square_underflows_is_the_identity_not_nan() {
        // Radius 1 (truncate * sigma + 0.5 rounds down), sigma^2 = 0: the centre tap alone.
        let out = gaussian_filter1d(&[1.0, 2.0, 3.0], 1e-300, 1e300).unwrap();
        assert_eq!(out, [1.0, 2.0, 3.0]);
    }

    #[test]
    fn radius_matches_scipy_rule() {
        assert_eq!(kernel_radius(2.0, 4.0), 8);
        assert_eq!(kernel_radius(30.0, 4.0), 120);
        assert_eq!(kernel_radius(1.1, 4.0), 4); // 4.4 + 0.5 = 4.9 -> 4
        assert_eq!(kernel_radius(1.125, 4.0), 5); // 4.5 + 0.5 = 5.0 -> 5
        assert_eq!(gaussian_kernel(2.0, 4.0).unwrap().len(), 17);
    }

    #[test]
    fn reflect_index_is_half_sample_symmetric() {
        // d c b a | a b c d | d c b a
        let n = 4;
        let ext: Vec<usize> = (-4..8).map(|i| reflect_index(i, n)).collect();
        assert_eq!(ext, vec![3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0]);
        // Repeated reflection for short signals: period 2n.
        let ext: Vec<usize> = (-5..7).map(|i| reflect_index(i, 2)).collect();
        assert_eq!(ext, vec![0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 1]);
        assert!((-10..10).all(|i| reflect_index(i, 1) == 0));
    }

    #[test]
    fn dispatched_f32_path_is_bit_identical_to_the_portable_one() {
        // On AVX2 machines filter_strided_f32 runs the 8-lane build; without FMA it must not
        // change a single bit, for interior, stack-buffer border and wide-kernel border paths.
        let x: Vec<f32> = (0..6 * 203)
            .map(|i| ((i * 7919 % 1013) as f32 * 0.013).sin() * 4.0)
            .collect();
        for (sigma, len) in [(2.0, 200), (2.0, 203), (2.0, 5), (30.0, 200), (0.5, 37)] {
            let half: Vec<f32> = half_kernel(sigma, 4.0)
                .unwrap()
                .into_iter()
                .map(|w| w as f32)
                .collect();
            let src = &x[..6 * len];
            let mut a = vec![0.0; src.len()];
            let mut b = vec![0.0; src.len()];
            filter_strided_f32(src, &mut a, 6, &half);
            filter_strided(src, &mut b, 6, &half);
            assert!(
                a.iter().zip(&b).all(|(p, q)| p.to_bits() == q.to_bits()),
                "{sigma} {len}"
            );
        }
    }

    #[test]
    fn bad_parameters_are_errors() {
        assert!(gaussian_kernel(f64::NAN, 4.0).is_err());
        assert!(gaussian_kernel(-1.0, 4.0).is_err());
        assert!(gaussian_kernel(2.0, 0.0).is_err());
        assert!(gaussian_kernel(1e300, 4.0).is_err());
        assert_eq!(gaussian_kernel(0.0, 4.0).unwrap(), vec![1.0]);
    }
}
