//! The linear SVM of the Nyström path's classifier ([`crate::Solver::Nystrom`]): the L1-loss
//! C-SVC of Hsieh et al. (ICML 2008) by dual coordinate descent, as LIBLINEAR implements it
//! (random order each epoch, shrinking of variables at a bound whose gradient points
//! outwards).
//!
//! Each epoch costs `O(rows × dim)`, against SMO's `O(rows²)` kernel: the Nyström features
//! turn the kernel machine into a linear one. The offset is a constant feature [`BIAS`]
//! appended to every row (LIBLINEAR's `-B 1`), so it is regularized, unlike the exact
//! solver's `rho`.
//!
//! Stopping is LIBLINEAR's ([`Stop`]): on the spread of the projected gradients, at most
//! [`MAX_EPOCHS`] epochs (or [`SmoSettings::max_iter`]). SMO's absolute gap of 1e-3 takes
//! cyclic coordinate descent thousands of epochs on RBF features, whose Gram matrix is close
//! to singular, for no gain on held-out data.

use crate::smo::SmoSettings;

/// Value of the constant feature that carries the offset.
pub(crate) const BIAS: f64 = 1.0;

/// Epoch cap (LIBLINEAR's) when [`SmoSettings::max_iter`] is not set.
pub(crate) const MAX_EPOCHS: usize = 1000;

/// When to stop.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stop {
    /// Largest minus smallest projected gradient of an epoch at most `tol`.
    pub tol: f64,
    /// Shrinking (LIBLINEAR's; [`SmoSettings::shrinking`]).
    pub shrinking: bool,
    pub max_epochs: usize,
}

impl Stop {
    /// `tol` with the SMO settings' shrinking and iteration cap (epochs here).
    pub(crate) fn new(tol: f64, s: &SmoSettings) -> Self {
        Self {
            tol,
            shrinking: s.shrinking,
            max_epochs: s.max_iter.unwrap_or(MAX_EPOCHS).max(1),
        }
    }
}

/// Rows of a row-major `f32` matrix, by index.
#[derive(Clone, Copy)]
pub(crate) struct Rows<'a> {
    pub data: &'a [f32],
    pub dim: usize,
    pub idx: &'a [usize],
}

impl Rows<'_> {
    fn row(&self, s: usize) -> &[f32] {
        let i = self.idx[s];
        &self.data[i * self.dim..(i + 1) * self.dim]
    }
}

/// A fitted linear model `f(x) = w·x + bias` and its dual.
#[derive(Debug, Clone)]
pub(crate) struct LinearFit {
    pub w: Vec<f64>,
    pub bias: f64,
    /// Dual variables `α` (in `[0, C]`), per row.
    pub dual: Vec<f64>,
    pub epochs: usize,
    pub converged: bool,
    /// Dual objective (minimized).
    pub objective: f64,
}

impl LinearFit {
    /// Rows with a non-zero dual variable.
    pub(crate) fn n_support(&self) -> usize {
        self.dual.iter().filter(|a| **a != 0.0).count()
    }
}

/// `w · x` in `f64`, lane-wise partial sums (vectorizable without reassociation).
pub(crate) fn dot(w: &[f64], x: &[f32]) -> f64 {
    const L: usize = 8;
    let mut acc = [0.0f64; L];
    let mut cw = w.chunks_exact(L);
    let mut cx = x.chunks_exact(L);
    for (a, b) in (&mut cw).zip(&mut cx) {
        for l in 0..L {
            acc[l] += a[l] * b[l] as f64;
        }
    }
    let tail: f64 = cw
        .remainder()
        .iter()
        .zip(cx.remainder())
        .map(|(a, &b)| a * b as f64)
        .sum();
    acc.iter().sum::<f64>() + tail
}

fn axpy(w: &mut [f64], d: f64, x: &[f32]) {
    w.iter_mut().zip(x).for_each(|(w, &x)| *w += d * x as f64);
}

/// SplitMix64: the crate's deterministic shuffles (epoch order here, so that the same
/// problem always gives the same fit; folds; landmarks), the same on every platform.
pub(crate) struct SplitMix64(pub u64);

impl SplitMix64 {
    pub(crate) fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Fisher-Yates.
    pub(crate) fn shuffle(&mut self, v: &mut [usize]) {
        for i in (1..v.len()).rev() {
            let j = (self.next() % (i as u64 + 1)) as usize;
            v.swap(i, j);
        }
    }
}

/// `w = Σ d_s x_s`, `bias = BIAS Σ d_s` and the diagonal `|x_s|² + BIAS²`.
fn primal(x: Rows<'_>, d: &[f64]) -> (Vec<f64>, f64, Vec<f64>) {
    let mut w = vec![0.0; x.dim];
    let mut b = 0.0;
    let mut qd = Vec::with_capacity(d.len());
    for (s, &a) in d.iter().enumerate() {
        let r = x.row(s);
        if a != 0.0 {
            axpy(&mut w, a, r);
            b += a * BIAS;
        }
        qd.push(r.iter().map(|&v| v as f64 * v as f64).sum::<f64>() + BIAS * BIAS);
    }
    (w, b, qd)
}

/// L1-loss C-SVC: `min_α ½ αᵀQα − Σα`, `0 ≤ α ≤ C`, `Q_st = y_s y_t (x_s·x_t + BIAS²)`.
/// `positive[s]` is the label of row `s`; `seed` orders the sweeps over the rows.
pub(crate) fn svc(x: Rows<'_>, positive: &[bool], c: f64, settings: &Stop, seed: u64) -> LinearFit {
    let n = x.idx.len();
    let y: Vec<f64> = positive
        .iter()
        .map(|&p| if p { 1.0 } else { -1.0 })
        .collect();
    let mut alpha = vec![0.0f64; n];
    let (mut w, mut b, qd) = primal(x, &alpha);
    let mut index: Vec<usize> = (0..n).collect();
    let mut active = n;
    let (mut pg_max_old, mut pg_min_old) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut rng = SplitMix64(seed);
    let mut epochs = 0;
    let mut converged = false;
    while epochs < settings.max_epochs {
        epochs += 1;
        let (mut pg_max, mut pg_min) = (f64::NEG_INFINITY, f64::INFINITY);
        rng.shuffle(&mut index[..active]);
        let mut s = 0;
        while s < active {
            let i = index[s];
            let r = x.row(i);
            let g = y[i] * (dot(&w, r) + b * BIAS) - 1.0;
            let pg = if alpha[i] == 0.0 {
                if g > pg_max_old && settings.shrinking {
                    active -= 1;
                    index.swap(s, active);
                    continue;
                }
                g.min(0.0)
            } else if alpha[i] == c {
                if g < pg_min_old && settings.shrinking {
                    active -= 1;
                    index.swap(s, active);
                    continue;
                }
                g.max(0.0)
            } else {
                g
            };
            pg_max = pg_max.max(pg);
            pg_min = pg_min.min(pg);
            if pg.abs() > 1e-12 {
                let old = alpha[i];
                alpha[i] = (old - g / qd[i]).clamp(0.0, c);
                let d = (alpha[i] - old) * y[i];
                axpy(&mut w, d, r);
                b += d * BIAS;
            }
            s += 1;
        }
        if pg_max - pg_min <= settings.tol {
            if active == n {
                converged = true;
                break;
            }
            // Check the shrunk variables once more on a full epoch.
            active = n;
            (pg_max_old, pg_min_old) = (f64::INFINITY, f64::NEG_INFINITY);
            continue;
        }
        pg_max_old = if pg_max <= 0.0 { f64::INFINITY } else { pg_max };
        pg_min_old = if pg_min >= 0.0 {
            f64::NEG_INFINITY
        } else {
            pg_min
        };
    }
    let objective =
        0.5 * (w.iter().map(|v| v * v).sum::<f64>() + b * b) - alpha.iter().sum::<f64>();
    LinearFit {
        w,
        bias: b * BIAS,
        dual: alpha.iter().zip(&y).map(|(a, y)| a * y).collect(),
        epochs,
        converged,
        objective,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small problem: `n` rows of `d` values (with a constant feature the offset handles).
    fn problem(n: usize, d: usize) -> (Vec<f32>, Vec<f64>) {
        let x: Vec<f32> = (0..n * d)
            .map(|k| ((k as f32) * 0.71).sin() + ((k / d) as f32 * 0.13).cos() * 0.5)
            .collect();
        let y = (0..n)
            .map(|i| {
                let r = &x[i * d..(i + 1) * d];
                0.8 * r[0] as f64 - 0.5 * r[1] as f64 + 0.3 + 0.1 * ((i as f64) * 1.7).sin()
            })
            .collect();
        (x, y)
    }

    /// Dense reference: the same dual by projected (proximal) gradient with the explicit
    /// `Q`, to convergence. The proximal step of `ε|β| + box` is a soft threshold, then
    /// the clip.
    fn reference(
        x: &[f32],
        d: usize,
        lin: &[f64],
        eps: f64,
        lo: &[f64],
        hi: &[f64],
        sign: &[f64],
    ) -> Vec<f64> {
        let n = lin.len();
        let q: Vec<f64> = (0..n * n)
            .map(|k| {
                let (i, j) = (k / n, k % n);
                let dot: f64 = (0..d)
                    .map(|t| x[i * d + t] as f64 * x[j * d + t] as f64)
                    .sum();
                sign[i] * sign[j] * (dot + BIAS * BIAS)
            })
            .collect();
        let trace: f64 = (0..n).map(|i| q[i * n + i]).sum();
        let step = 1.0 / trace;
        let mut b = vec![0.0; n];
        for _ in 0..200_000 {
            let g: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| q[i * n + j] * b[j]).sum::<f64>() - lin[i])
                .collect();
            for i in 0..n {
                let v = b[i] - step * g[i];
                let soft = v.signum() * (v.abs() - step * eps).max(0.0);
                b[i] = soft.clamp(lo[i], hi[i]);
            }
        }
        b
    }

    fn primal_of(x: &[f32], d: usize, coef: &[f64]) -> (Vec<f64>, f64) {
        let mut w = vec![0.0; d];
        let mut b = 0.0;
        for (i, &c) in coef.iter().enumerate() {
            axpy(&mut w, c, &x[i * d..(i + 1) * d]);
            b += c * BIAS * BIAS;
        }
        (w, b)
    }

    fn tight() -> Stop {
        Stop {
            tol: 1e-9,
            shrinking: true,
            max_epochs: 100_000,
        }
    }

    #[test]
    fn svc_matches_a_dense_solve_of_its_dual_and_separates() {
        let (n, d) = (30, 3);
        let (x, y) = problem(n, d);
        let positive: Vec<bool> = y.iter().map(|&v| v > 0.3).collect();
        let sign: Vec<f64> = positive
            .iter()
            .map(|&p| if p { 1.0 } else { -1.0 })
            .collect();
        let idx: Vec<usize> = (0..n).collect();
        let rows = Rows {
            data: &x,
            dim: d,
            idx: &idx,
        };
        let c = 5.0;
        let fit = svc(rows, &positive, c, &tight(), 0);
        assert!(fit.converged);
        let alpha = reference(&x, d, &vec![1.0; n], 0.0, &vec![0.0; n], &vec![c; n], &sign);
        let coef: Vec<f64> = alpha.iter().zip(&sign).map(|(a, s)| a * s).collect();
        let (w, b) = primal_of(&x, d, &coef);
        for (a, r) in fit.w.iter().zip(&w) {
            assert!((a - r).abs() < 1e-5, "{:?} vs {w:?}", fit.w);
        }
        assert!((fit.bias - b).abs() < 1e-5);
        // A separable problem (the label is the sign of a linear function): all right.
        let sep: Vec<bool> = (0..n)
            .map(|i| x[i * d] - 0.5 * x[i * d + 1] > 0.1)
            .collect();
        let fit = svc(
            rows,
            &sep,
            100.0,
            &Stop::new(0.1, &SmoSettings::default()),
            0,
        );
        for (i, &s) in sep.iter().enumerate() {
            let f = dot(&fit.w, &x[i * d..(i + 1) * d]) + fit.bias;
            assert_eq!(f > 0.0, s, "row {i}: {f}");
        }
    }

    #[test]
    fn fits_are_deterministic() {
        let (x, y) = problem(40, 4);
        let idx: Vec<usize> = (0..40).rev().collect();
        let rows = Rows {
            data: &x,
            dim: 4,
            idx: &idx,
        };
        let stop = Stop::new(0.1, &SmoSettings::default());
        let positive: Vec<bool> = y.iter().map(|&v| v > 0.3).collect();
        let a = svc(rows, &positive, 1.0, &stop, 0);
        let b = svc(rows, &positive, 1.0, &stop, 0);
        assert_eq!(a.w, b.w);
        assert_eq!(a.dual, b.dual);
    }
}
