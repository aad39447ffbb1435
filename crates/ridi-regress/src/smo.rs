//! SMO solver for the libsvm dual
//!
//! ```text
//! min_α ½ αᵀQα + pᵀα   s.t.  yᵀα = 0,  0 ≤ α_t ≤ C,   Q_st = y_s y_t K(x_kidx(s), x_kidx(t))
//! ```
//!
//! with second-order working-set selection (WSS3 of Fan, Chen and Lin 2005) and libsvm's
//! shrinking, including unshrinking with gradient reconstruction from `Ḡ`. The RBF kernel has
//! `K(x, x) = 1`, so `Q_tt = 1` throughout. Variables address kernel rows through `kidx`, which
//! lets the 2l variables of epsilon-SVR share l kernel rows and lets any subset of a class
//! (a fold, a class pair) index one shared kernel.

use crate::cache::KernelRows;

const TAU: f64 = 1e-12;

#[derive(Clone, Copy, PartialEq, Eq)]
enum Status {
    Lower,
    Upper,
    Free,
}

/// Stopping and shrinking settings (libsvm defaults: tolerance 1e-3, shrinking on).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SmoSettings {
    /// Stop when the maximal KKT violation `m(α) - M(α)` falls below this.
    pub tol: f64,
    /// Temporarily remove bounded variables that are unlikely to move.
    pub shrinking: bool,
    /// Iteration cap; `None` uses libsvm's `max(10⁷, 100 l)`.
    pub max_iter: Option<usize>,
}

impl Default for SmoSettings {
    fn default() -> Self {
        Self {
            tol: 1e-3,
            shrinking: true,
            max_iter: None,
        }
    }
}

/// One dual problem.
pub(crate) struct SmoProblem {
    /// Base kernel index of every variable.
    pub kidx: Vec<u32>,
    /// Sign `y_t` (±1) of every variable.
    pub y: Vec<f64>,
    /// Linear term.
    pub p: Vec<f64>,
    /// Box bound.
    pub c: f64,
    /// Feasible starting point (`yᵀα = 0`, inside the box); zero when absent.
    pub alpha0: Option<Vec<f64>>,
}

/// Solution of a dual problem.
#[derive(Debug, Clone)]
pub(crate) struct SmoSolution {
    pub alpha: Vec<f64>,
    /// Offset: decision values are `Σ y_t α_t K(x_t, x) - rho`.
    pub rho: f64,
    /// Dual objective `½ αᵀQα + pᵀα`.
    pub obj: f64,
    pub iterations: usize,
    /// False when the iteration cap stopped the solver.
    pub converged: bool,
}

/// Solver state. Gradients are kept as `yG_t = y_t G_t`, which makes every update sign-free:
/// `yG_t = y_t p_t + Σ_i (y_i α_i) K_it` and `yḠ_t = C Σ_{i at upper bound} y_i K_it`.
/// The active (unshrunk) variables are copied into compact arrays so that the two hot loops
/// (working-set selection, gradient update) run over contiguous memory.
struct Solver<'r> {
    rows: &'r dyn KernelRows,
    c: f64,
    tol: f64,
    // Per variable, in problem order.
    kidx: Vec<u32>,
    y: Vec<f64>,
    p: Vec<f64>,
    alpha: Vec<f64>,
    status: Vec<Status>,
    /// `y G`, exact for inactive variables only after `sync`.
    yg: Vec<f64>,
    ygbar: Vec<f64>,
    // Compact active set, by position.
    act: Vec<u32>,
    ak: Vec<u32>,
    ayg: Vec<f64>,
    /// 0 for members of `I_up` / `I_low`, -inf otherwise: masks as arithmetic, so the hot
    /// loops have no branches and vectorize.
    aup: Vec<f64>,
    alow: Vec<f64>,
    /// `max_{I_up} -yG` and its position, computed by the previous gradient update.
    next_gmax: Option<(f64, usize)>,
    unshrink: bool,
    /// Scratch: kernel values gathered at the active positions, selection scores.
    buf_i: Vec<f32>,
    buf_j: Vec<f32>,
    scores: Vec<f32>,
}

/// Mask value: 0 for members, -inf for non-members.
fn pen(member: bool) -> f64 {
    if member { 0.0 } else { f64::NEG_INFINITY }
}

impl Solver<'_> {
    fn l(&self) -> usize {
        self.alpha.len()
    }

    fn status_of(&self, a: f64) -> Status {
        if a >= self.c {
            Status::Upper
        } else if a <= 0.0 {
            Status::Lower
        } else {
            Status::Free
        }
    }

    /// Member of `I_up`: `α_t` can move in the direction that increases `y_t α_t`.
    fn up_ok(&self, t: usize) -> bool {
        if self.y[t] > 0.0 {
            self.status[t] != Status::Upper
        } else {
            self.status[t] != Status::Lower
        }
    }

    /// Member of `I_low`.
    fn low_ok(&self, t: usize) -> bool {
        if self.y[t] > 0.0 {
            self.status[t] != Status::Lower
        } else {
            self.status[t] != Status::Upper
        }
    }

    fn set_active(&mut self, list: Vec<u32>) {
        self.ak = list.iter().map(|&t| self.kidx[t as usize]).collect();
        self.ayg = list.iter().map(|&t| self.yg[t as usize]).collect();
        self.aup = list.iter().map(|&t| pen(self.up_ok(t as usize))).collect();
        self.alow = list.iter().map(|&t| pen(self.low_ok(t as usize))).collect();
        self.act = list;
        self.next_gmax = None;
    }

    fn sync(&mut self) {
        for (pos, &t) in self.act.iter().enumerate() {
            self.yg[t as usize] = self.ayg[pos];
        }
    }

    /// `yG` and `yḠ` from scratch, grouped by kernel row so that a warm start with both
    /// variables of an SVR sample nonzero still reads each row once.
    fn init_gradient(&mut self) {
        let l = self.l();
        let nb = self.rows.len();
        self.yg = (0..l).map(|t| self.y[t] * self.p[t]).collect();
        self.ygbar = vec![0.0; l];
        let mut w = vec![0.0f64; nb];
        let mut u = vec![0.0f64; nb];
        for t in 0..l {
            if self.status[t] != Status::Lower {
                let b = self.kidx[t] as usize;
                w[b] += self.y[t] * self.alpha[t];
                if self.status[t] == Status::Upper {
                    u[b] += self.y[t] * self.c;
                }
            }
        }
        let used: Vec<usize> = (0..nb).filter(|&b| w[b] != 0.0 || u[b] != 0.0).collect();
        let chunk = self.rows.batch_size().max(1);
        for part in used.chunks(chunk) {
            if chunk > 1 {
                self.rows.prefetch(part);
            }
            for &b in part {
                let row = self.rows.row(b);
                let (wb, ub) = (w[b], u[b]);
                for t in 0..l {
                    let k = row[self.kidx[t] as usize] as f64;
                    self.yg[t] += wb * k;
                    self.ygbar[t] += ub * k;
                }
            }
        }
    }

    /// Prefetches the rows of the variables most likely to be picked next (largest first-order
    /// violations on both sides), so that the cache computes them in one GEMM pass.
    fn prefetch_around(&self, first: usize) {
        let batch = self.rows.batch_size();
        if batch <= 1 || self.rows.is_cached(first) {
            return;
        }
        let mut up: Vec<(f64, u32)> = Vec::new();
        let mut low: Vec<(f64, u32)> = Vec::new();
        for pos in 0..self.act.len() {
            if self.aup[pos] == 0.0 {
                up.push((-self.ayg[pos], self.ak[pos]));
            }
            if self.alow[pos] == 0.0 {
                low.push((self.ayg[pos], self.ak[pos]));
            }
        }
        let half = batch / 2;
        let mut want = vec![first];
        for v in [&mut up, &mut low] {
            if v.len() > half {
                v.select_nth_unstable_by(half, |a, b| b.0.total_cmp(&a.0));
                v.truncate(half);
            }
            want.extend(v.iter().map(|&(_, b)| b as usize));
        }
        want.sort_unstable();
        want.dedup();
        self.rows.prefetch(&want);
    }

    fn gmax(&self) -> (f64, usize) {
        hot::masked_max_neg(&self.ayg, &self.aup)
    }

    /// WSS3 over the active set; returns active positions, `None` when optimal within `tol`.
    fn select_working_set(&mut self) -> Option<(usize, usize)> {
        let (gmax, pi) = self.next_gmax.take().unwrap_or_else(|| self.gmax());
        let row_i = if pi != usize::MAX {
            self.prefetch_around(self.ak[pi] as usize);
            Some(self.rows.row(self.ak[pi] as usize))
        } else {
            None
        };
        let mut gmax2 = f64::NEG_INFINITY;
        let mut pj = usize::MAX;
        let n = self.ayg.len();
        match &row_i {
            Some(ri) => {
                self.buf_i.resize(n, 0.0);
                self.scores.resize(n, 0.0);
                hot::gather(ri, &self.ak, &mut self.buf_i);
                gmax2 = hot::wss_scores(&self.ayg, &self.alow, &self.buf_i, gmax, &mut self.scores);
                if let Some(k) = hot::argmax_positive(&self.scores) {
                    pj = k;
                }
            }
            None => {
                for k in 0..n {
                    gmax2 = gmax2.max(self.ayg[k] + self.alow[k]);
                }
            }
        }
        if gmax + gmax2 < self.tol || pj == usize::MAX {
            None
        } else {
            Some((pi, pj))
        }
    }

    fn update_pair(&mut self, pi: usize, pj: usize) {
        let (i, j) = (self.act[pi] as usize, self.act[pj] as usize);
        let row_i = self.rows.row(self.kidx[i] as usize);
        let row_j = self.rows.row(self.kidx[j] as usize);
        let c = self.c;
        let kij = row_i[self.kidx[j] as usize] as f64;
        let quad = 2.0 - 2.0 * kij;
        let quad = if quad <= 0.0 { TAU } else { quad };
        let (gi, gj) = (self.y[i] * self.ayg[pi], self.y[j] * self.ayg[pj]);
        let (old_i, old_j) = (self.alpha[i], self.alpha[j]);
        let (mut ai, mut aj) = (old_i, old_j);
        if self.y[i] != self.y[j] {
            let delta = (-gi - gj) / quad;
            let diff = ai - aj;
            ai += delta;
            aj += delta;
            if diff > 0.0 {
                if aj < 0.0 {
                    aj = 0.0;
                    ai = diff;
                }
            } else if ai < 0.0 {
                ai = 0.0;
                aj = -diff;
            }
            if diff > 0.0 {
                if ai > c {
                    ai = c;
                    aj = c - diff;
                }
            } else if aj > c {
                aj = c;
                ai = c + diff;
            }
        } else {
            let delta = (gi - gj) / quad;
            let sum = ai + aj;
            ai -= delta;
            aj += delta;
            if sum > c {
                if ai > c {
                    ai = c;
                    aj = sum - c;
                }
            } else if aj < 0.0 {
                aj = 0.0;
                ai = sum;
            }
            if sum > c {
                if aj > c {
                    aj = c;
                    ai = sum - c;
                }
            } else if ai < 0.0 {
                ai = 0.0;
                aj = sum;
            }
        }
        self.alpha[i] = ai;
        self.alpha[j] = aj;
        for (t, pos, row) in [(i, pi, &row_i), (j, pj, &row_j)] {
            let was_upper = self.status[t] == Status::Upper;
            self.status[t] = self.status_of(self.alpha[t]);
            self.aup[pos] = pen(self.up_ok(t));
            self.alow[pos] = pen(self.low_ok(t));
            if was_upper != (self.status[t] == Status::Upper) {
                let s = if was_upper { -c } else { c } * self.y[t];
                for (gb, &b) in self.ygbar.iter_mut().zip(&self.kidx) {
                    *gb += s * row[b as usize] as f64;
                }
            }
        }
        // Gradient update, then the first half of the next selection.
        let dyi = (ai - old_i) * self.y[i];
        let dyj = (aj - old_j) * self.y[j];
        let n = self.ayg.len();
        self.buf_i.resize(n, 0.0);
        self.buf_j.resize(n, 0.0);
        hot::gather(&row_i, &self.ak, &mut self.buf_i);
        hot::gather(&row_j, &self.ak, &mut self.buf_j);
        hot::axpy2(&mut self.ayg, dyi, &self.buf_i, dyj, &self.buf_j);
        let (gmax, gpos) = hot::masked_max_neg(&self.ayg, &self.aup);
        self.next_gmax = Some((gmax, gpos));
    }

    fn do_shrinking(&mut self) {
        let mut gmax1 = f64::NEG_INFINITY;
        let mut gmax2 = f64::NEG_INFINITY;
        for k in 0..self.act.len() {
            gmax1 = gmax1.max(-self.ayg[k] + self.aup[k]);
            gmax2 = gmax2.max(self.ayg[k] + self.alow[k]);
        }
        self.sync();
        if !self.unshrink && gmax1 + gmax2 <= self.tol * 10.0 {
            self.unshrink = true;
            self.reconstruct_gradient();
        }
        // A bounded variable is dropped when it violates nothing by a margin: members of
        // I_up only when yG > max_{I_low} yG, members of I_low only when -yG > max_{I_up} -yG.
        let keep: Vec<u32> = self
            .act
            .iter()
            .copied()
            .filter(|&t| {
                let t = t as usize;
                match (self.up_ok(t), self.low_ok(t)) {
                    (true, true) => true,
                    (true, false) => self.yg[t] <= gmax2,
                    (false, true) => -self.yg[t] <= gmax1,
                    (false, false) => true,
                }
            })
            .collect();
        if keep.len() != self.act.len() {
            self.set_active(keep);
        }
    }

    /// Restores the exact gradient of shrunk variables from `yḠ` plus the free variables'
    /// contributions, then reactivates everything.
    fn reconstruct_gradient(&mut self) {
        let l = self.l();
        self.sync();
        if self.act.len() == l {
            return;
        }
        let mut is_active = vec![false; l];
        for &t in &self.act {
            is_active[t as usize] = true;
        }
        let inactive: Vec<usize> = (0..l).filter(|&t| !is_active[t]).collect();
        for &t in &inactive {
            self.yg[t] = self.y[t] * self.p[t] + self.ygbar[t];
        }
        let free: Vec<usize> = self
            .act
            .iter()
            .map(|&t| t as usize)
            .filter(|&t| self.status[t] == Status::Free)
            .collect();
        // Read whichever set of rows is smaller (free variables' or inactive variables').
        let chunk = self.rows.batch_size().max(1);
        let rows_of =
            |set: &[usize]| -> Vec<usize> { set.iter().map(|&t| self.kidx[t] as usize).collect() };
        if free.len() <= inactive.len() {
            for part in free.chunks(chunk) {
                if chunk > 1 {
                    self.rows.prefetch(&rows_of(part));
                }
                for &i in part {
                    let row = self.rows.row(self.kidx[i] as usize);
                    let ay = self.alpha[i] * self.y[i];
                    for &t in &inactive {
                        self.yg[t] += ay * row[self.kidx[t] as usize] as f64;
                    }
                }
            }
        } else {
            for part in inactive.chunks(chunk) {
                if chunk > 1 {
                    self.rows.prefetch(&rows_of(part));
                }
                for &t in part {
                    let row = self.rows.row(self.kidx[t] as usize);
                    let s: f64 = free
                        .iter()
                        .map(|&i| self.alpha[i] * self.y[i] * row[self.kidx[i] as usize] as f64)
                        .sum();
                    self.yg[t] += s;
                }
            }
        }
        self.set_active((0..l as u32).collect());
    }

    fn rho(&self) -> f64 {
        let mut ub = f64::INFINITY;
        let mut lb = f64::NEG_INFINITY;
        let mut nr_free = 0usize;
        let mut sum_free = 0.0;
        for t in 0..self.l() {
            let yg = self.yg[t];
            let pos = self.y[t] > 0.0;
            match self.status[t] {
                Status::Upper => {
                    if pos {
                        lb = lb.max(yg);
                    } else {
                        ub = ub.min(yg);
                    }
                }
                Status::Lower => {
                    if pos {
                        ub = ub.min(yg);
                    } else {
                        lb = lb.max(yg);
                    }
                }
                Status::Free => {
                    nr_free += 1;
                    sum_free += yg;
                }
            }
        }
        if nr_free > 0 {
            sum_free / nr_free as f64
        } else if ub.is_finite() && lb.is_finite() {
            (ub + lb) / 2.0
        } else if ub.is_finite() {
            ub
        } else if lb.is_finite() {
            lb
        } else {
            0.0
        }
    }
}

/// Solves one dual problem.
pub(crate) fn solve(
    rows: &dyn KernelRows,
    problem: SmoProblem,
    settings: &SmoSettings,
) -> SmoSolution {
    let l = problem.y.len();
    let alpha = problem.alpha0.unwrap_or_else(|| vec![0.0; l]);
    let mut s = Solver {
        rows,
        c: problem.c,
        tol: settings.tol,
        kidx: problem.kidx,
        y: problem.y,
        p: problem.p,
        status: Vec::new(),
        alpha,
        yg: Vec::new(),
        ygbar: Vec::new(),
        act: Vec::new(),
        ak: Vec::new(),
        ayg: Vec::new(),
        aup: Vec::new(),
        alow: Vec::new(),
        next_gmax: None,
        unshrink: false,
        buf_i: Vec::new(),
        buf_j: Vec::new(),
        scores: Vec::new(),
    };
    // The vectorized gathers rely on this; the crate builds every problem from valid indices.
    assert!(
        s.kidx.iter().all(|&b| (b as usize) < rows.len()),
        "kernel index out of range"
    );
    s.status = s.alpha.iter().map(|&a| s.status_of(a)).collect();
    s.init_gradient();
    s.set_active((0..l as u32).collect());

    let max_iter = settings
        .max_iter
        .unwrap_or_else(|| 10_000_000usize.max(l.saturating_mul(100)));
    let mut iter = 0usize;
    let mut counter = l.min(1000) + 1;
    let mut converged = false;
    while iter < max_iter {
        counter -= 1;
        if counter == 0 {
            counter = l.min(1000);
            if settings.shrinking {
                s.do_shrinking();
            }
        }
        let pair = match s.select_working_set() {
            Some(p) => p,
            None => {
                s.reconstruct_gradient();
                match s.select_working_set() {
                    Some(p) => {
                        // Shrinking hid a violation: check again right away.
                        counter = 1;
                        p
                    }
                    None => {
                        converged = true;
                        break;
                    }
                }
            }
        };
        iter += 1;
        s.update_pair(pair.0, pair.1);
    }
    s.reconstruct_gradient();
    let rho = s.rho();
    let obj = (0..l)
        .map(|t| s.alpha[t] * (s.y[t] * s.yg[t] + s.p[t]))
        .sum::<f64>()
        / 2.0;
    SmoSolution {
        alpha: s.alpha,
        rho,
        obj,
        iterations: iter,
        converged,
    }
}

/// The two O(active) loops of every iteration, written so that they vectorize (gathers first,
/// then branch-free arithmetic, then a max reduction and a position search).
mod hot {
    /// `out[k] = row[idx[k]]`; every index must be below `row.len()` (checked once per
    /// problem in `solve`).
    pub(super) fn gather(row: &[f32], idx: &[u32], out: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        if avx2() && row.len() < i32::MAX as usize {
            // SAFETY: AVX2 is available; indices are in bounds (caller contract) and fit i32.
            unsafe { gather_avx2(row, idx, out) };
            return;
        }
        for (o, &i) in out.iter_mut().zip(idx) {
            *o = row[i as usize];
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn gather_avx2(row: &[f32], idx: &[u32], out: &mut [f32]) {
        use std::arch::x86_64::*;
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

    /// First position where `s[k] == target`, 8 lanes at a time.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn find_f32_avx2(s: &[f32], target: f32) -> Option<usize> {
        use std::arch::x86_64::*;
        let t = _mm256_set1_ps(target);
        let mut k = 0;
        while k + 8 <= s.len() {
            // SAFETY: k + 8 <= s.len().
            let eq = unsafe { _mm256_cmp_ps::<_CMP_EQ_OQ>(_mm256_loadu_ps(s.as_ptr().add(k)), t) };
            let bits = _mm256_movemask_ps(eq);
            if bits != 0 {
                return Some(k + bits.trailing_zeros() as usize);
            }
            k += 8;
        }
        s[k..].iter().position(|&v| v == target).map(|p| p + k)
    }

    /// Second-order gains `(gmax + yG_j)² / (2 - 2 K_ij)` of the `I_low` members with a
    /// positive first-order gain (0 elsewhere), in `f32` (they only rank candidates); returns
    /// `max_{I_low} yG`. `low` is the 0 / -inf membership mask.
    pub(super) fn wss_scores(
        ayg: &[f64],
        low: &[f64],
        kv: &[f32],
        gmax: f64,
        out: &mut [f32],
    ) -> f64 {
        #[cfg(target_arch = "x86_64")]
        if avx2() {
            // SAFETY: AVX2 and FMA are available (checked at run time).
            return unsafe { wss_scores_avx2(ayg, low, kv, gmax, out) };
        }
        wss_scores_generic(ayg, low, kv, gmax, out)
    }

    #[inline(always)]
    fn wss_scores_generic(ayg: &[f64], low: &[f64], kv: &[f32], gmax: f64, out: &mut [f32]) -> f64 {
        const L: usize = 8;
        let n = out.len();
        let (ayg, low, kv) = (&ayg[..n], &low[..n], &kv[..n]);
        let mut lanes = [f64::NEG_INFINITY; L];
        let mut k = 0;
        while k + L <= n {
            for l in 0..L {
                let m = ayg[k + l] + low[k + l];
                lanes[l] = if m > lanes[l] { m } else { lanes[l] };
                let gd = (gmax + m) as f32;
                let q = 2.0 - 2.0 * kv[k + l];
                let q = if q > 1e-12 { q } else { 1e-12 };
                let sc = gd * gd / q;
                out[k + l] = if gd > 0.0 { sc } else { 0.0 };
            }
            k += L;
        }
        let mut best = lanes
            .iter()
            .fold(f64::NEG_INFINITY, |a, &b| if b > a { b } else { a });
        while k < n {
            let m = ayg[k] + low[k];
            if m > best {
                best = m;
            }
            let gd = (gmax + m) as f32;
            let q = 2.0 - 2.0 * kv[k];
            let q = if q > 1e-12 { q } else { 1e-12 };
            out[k] = if gd > 0.0 { gd * gd / q } else { 0.0 };
            k += 1;
        }
        best
    }

    /// Position of the largest positive score (first on ties).
    pub(super) fn argmax_positive(s: &[f32]) -> Option<usize> {
        #[cfg(target_arch = "x86_64")]
        if avx2() {
            // SAFETY: AVX2 and FMA are available (checked at run time).
            return unsafe { argmax_positive_avx2(s) };
        }
        argmax_positive_generic(s)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn argmax_positive_avx2(s: &[f32]) -> Option<usize> {
        use std::arch::x86_64::*;
        let n = s.len();
        let mut acc = _mm256_setzero_ps();
        let mut k = 0;
        while k + 8 <= n {
            // SAFETY: k + 8 <= n.
            acc = _mm256_max_ps(acc, unsafe { _mm256_loadu_ps(s.as_ptr().add(k)) });
            k += 8;
        }
        let mut lanes = [0.0f32; 8];
        // SAFETY: `lanes` holds eight f32.
        unsafe { _mm256_storeu_ps(lanes.as_mut_ptr(), acc) };
        let mut best = lanes.iter().fold(0.0f32, |a, &b| if b > a { b } else { a });
        for &v in &s[k..] {
            if v > best {
                best = v;
            }
        }
        if best > 0.0 {
            // SAFETY: AVX2 is enabled in this function.
            unsafe { find_f32_avx2(s, best) }
        } else {
            None
        }
    }

    #[inline(always)]
    fn argmax_positive_generic(s: &[f32]) -> Option<usize> {
        const L: usize = 16;
        let mut lanes = [0.0f32; L];
        let mut chunks = s.chunks_exact(L);
        for c in &mut chunks {
            for l in 0..L {
                lanes[l] = if c[l] > lanes[l] { c[l] } else { lanes[l] };
            }
        }
        let mut best = lanes.iter().fold(0.0f32, |a, &b| if b > a { b } else { a });
        for &v in chunks.remainder() {
            if v > best {
                best = v;
            }
        }
        if best > 0.0 {
            s.iter().position(|&v| v == best)
        } else {
            None
        }
    }

    /// `y[k] += a x[k] + b z[k]`.
    pub(super) fn axpy2(y: &mut [f64], a: f64, x: &[f32], b: f64, z: &[f32]) {
        #[cfg(target_arch = "x86_64")]
        if avx2() {
            // SAFETY: AVX2 and FMA are available (checked at run time).
            unsafe { axpy2_avx2(y, a, x, b, z) };
            return;
        }
        axpy2_generic(y, a, x, b, z)
    }

    #[inline(always)]
    fn axpy2_generic(y: &mut [f64], a: f64, x: &[f32], b: f64, z: &[f32]) {
        for ((v, &xi), &zi) in y.iter_mut().zip(x).zip(z) {
            *v += a * xi as f64 + b * zi as f64;
        }
    }

    /// `max_{mask} -v` and its first position (`(-inf, usize::MAX)` when the mask is empty);
    /// `mask` is 0 / -inf.
    pub(super) fn masked_max_neg(v: &[f64], mask: &[f64]) -> (f64, usize) {
        #[cfg(target_arch = "x86_64")]
        if avx2() {
            // SAFETY: AVX2 and FMA are available (checked at run time).
            return unsafe { masked_max_neg_avx2(v, mask) };
        }
        masked_max_neg_generic(v, mask)
    }

    /// Common end of both `masked_max_neg` kernels: reduce the vector lanes, take the scalar
    /// tail from `k`, then find the first position of the maximum.
    #[inline(always)]
    fn finish_masked_max(lanes: &[f64], v: &[f64], mask: &[f64], mut k: usize) -> (f64, usize) {
        let n = v.len();
        let mut best = lanes
            .iter()
            .fold(f64::NEG_INFINITY, |a, &b| if b > a { b } else { a });
        while k < n {
            let m = mask[k] - v[k];
            if m > best {
                best = m;
            }
            k += 1;
        }
        if best == f64::NEG_INFINITY {
            return (best, usize::MAX);
        }
        let pos = (0..n)
            .find(|&k| mask[k] - v[k] == best)
            .unwrap_or(usize::MAX);
        (best, pos)
    }

    #[inline(always)]
    fn masked_max_neg_generic(v: &[f64], mask: &[f64]) -> (f64, usize) {
        const L: usize = 8;
        let n = v.len().min(mask.len());
        let (v, mask) = (&v[..n], &mask[..n]);
        let mut lanes = [f64::NEG_INFINITY; L];
        let mut k = 0;
        while k + L <= n {
            for l in 0..L {
                let m = mask[k + l] - v[k + l];
                lanes[l] = if m > lanes[l] { m } else { lanes[l] };
            }
            k += L;
        }
        finish_masked_max(&lanes, v, mask, k)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn masked_max_neg_avx2(v: &[f64], mask: &[f64]) -> (f64, usize) {
        use std::arch::x86_64::*;
        let n = v.len().min(mask.len());
        let (v, mask) = (&v[..n], &mask[..n]);
        let mut acc = _mm256_set1_pd(f64::NEG_INFINITY);
        let mut k = 0;
        while k + 4 <= n {
            // SAFETY: k + 4 <= n and both slices have length n.
            unsafe {
                let m = _mm256_sub_pd(
                    _mm256_loadu_pd(mask.as_ptr().add(k)),
                    _mm256_loadu_pd(v.as_ptr().add(k)),
                );
                acc = _mm256_max_pd(acc, m);
            }
            k += 4;
        }
        let mut lanes = [0.0f64; 4];
        // SAFETY: `lanes` holds four f64.
        unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), acc) };
        finish_masked_max(&lanes, v, mask, k)
    }

    #[cfg(target_arch = "x86_64")]
    fn avx2() -> bool {
        static FLAG: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
        *FLAG.get_or_init(|| {
            std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("fma")
        })
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn wss_scores_avx2(
        ayg: &[f64],
        low: &[f64],
        kv: &[f32],
        gmax: f64,
        out: &mut [f32],
    ) -> f64 {
        use std::arch::x86_64::*;
        let n = out.len();
        let (ayg, low, kv) = (&ayg[..n], &low[..n], &kv[..n]);
        let mut k = 0;
        let vg = _mm256_set1_pd(gmax);
        let two = _mm_set1_ps(2.0);
        let tiny = _mm_set1_ps(1e-12);
        let zero = _mm_setzero_ps();
        let mut acc = _mm256_set1_pd(f64::NEG_INFINITY);
        while k + 4 <= n {
            // SAFETY: k + 4 <= n and every slice has length n.
            unsafe {
                let m = _mm256_add_pd(
                    _mm256_loadu_pd(ayg.as_ptr().add(k)),
                    _mm256_loadu_pd(low.as_ptr().add(k)),
                );
                acc = _mm256_max_pd(acc, m);
                let gd = _mm256_cvtpd_ps(_mm256_add_pd(vg, m));
                let kvv = _mm_loadu_ps(kv.as_ptr().add(k));
                let q = _mm_max_ps(_mm_sub_ps(two, _mm_mul_ps(two, kvv)), tiny);
                let sc = _mm_div_ps(_mm_mul_ps(gd, gd), q);
                _mm_storeu_ps(
                    out.as_mut_ptr().add(k),
                    _mm_and_ps(sc, _mm_cmpgt_ps(gd, zero)),
                );
            }
            k += 4;
        }
        let mut lanes = [0.0f64; 4];
        // SAFETY: `lanes` holds four f64.
        unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), acc) };
        let mut best = lanes
            .iter()
            .fold(f64::NEG_INFINITY, |a, &b| if b > a { b } else { a });
        while k < n {
            let m = ayg[k] + low[k];
            if m > best {
                best = m;
            }
            let gd = (gmax + m) as f32;
            let q = (2.0 - 2.0 * kv[k]).max(1e-12);
            out[k] = if gd > 0.0 { gd * gd / q } else { 0.0 };
            k += 1;
        }
        best
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn axpy2_avx2(y: &mut [f64], a: f64, x: &[f32], b: f64, z: &[f32]) {
        axpy2_generic(y, a, x, b, z)
    }
}
