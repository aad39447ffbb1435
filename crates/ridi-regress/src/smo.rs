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

use crate::cache::{KernelRows, Row};

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
    /// How often the compact kernel was built, and re-compacted after shrinking.
    #[cfg_attr(not(test), allow(dead_code))]
    pub compactions: (usize, usize),
}

/// Largest compact kernel, in values (1 GiB of `f32`).
const COMPACT_MAX: usize = 1 << 28;

/// The active list is rebuilt when shrinking leaves at most this many tenths of it.
const RELIST_FRACTION_TENTHS: usize = 7;

const NONE: u32 = u32::MAX;

/// Solver state, organized by kernel base rather than by variable: the variables of one base
/// (two for epsilon-SVR, one for C-SVC) share `yG_t - y_t p_t = Σ_i y_i α_i K_{i,t}`, so
/// the hot loops (working-set selection, gradient update) run over the distinct active bases,
/// with `yG` of the best member of each side folded into the masks `aup` / `alow`.
///
/// Kernel values at the active bases come from, in order of preference: a compact kernel over
/// the active bases (built once the gathers it saves have cost as much as building it, and
/// kept contiguous under shrinking by moving tail rows and columns into the holes, as libsvm's
/// swapping does), the provider's rows as they are (when the active bases are exactly rows
/// `0..len`), or a gather from the provider's rows.
struct Solver<'r> {
    rows: &'r dyn KernelRows,
    c: f64,
    tol: f64,
    // Per variable, in problem order.
    y: Vec<f64>,
    p: Vec<f64>,
    alpha: Vec<f64>,
    status: Vec<Status>,
    /// Base of every variable.
    vb: Vec<u32>,
    var_active: Vec<bool>,
    // Per base.
    /// Kernel row of every base.
    pb: Vec<u32>,
    /// The variables of every base (`NONE` when absent).
    slots: Vec<[u32; 2]>,
    /// `Σ_i y_i α_i K(x_i, x_b)`, so `yG_t = y_t p_t + s[vb[t]]`; exact for active bases,
    /// for the others only after `reconstruct_gradient`.
    s: Vec<f64>,
    /// `C Σ_{i at upper bound} y_i K(x_i, x_b)`.
    sbar: Vec<f64>,
    /// `pb` is `0..rows.len()`.
    pb_direct: bool,
    // Compact active set, by position.
    act: Vec<u32>,
    ak: Vec<u32>,
    av: Vec<f64>,
    /// `max -y_t p_t` over the base's active members of `I_up`, `-inf` when there is none, so
    /// that `aup - av` is the best `-yG` of the base; `alow + av` likewise the best `yG` of
    /// `I_low`. Arithmetic masks keep the hot loops branch-free.
    aup: Vec<f64>,
    alow: Vec<f64>,
    /// The active bases are exactly kernel rows `0..rows.len()`, in order.
    direct: bool,
    /// Kernel among the active bases (row `q`, column `r` at `q * kc_stride + r`); empty when
    /// not built.
    kc: Vec<f32>,
    kc_stride: usize,
    /// Values gathered since the compact kernel was last built or dropped.
    rent: usize,
    compactions: (usize, usize),
    compact_max: usize,
    /// `max_{I_up} -yG` and its position, computed by the previous gradient update.
    next_gmax: Option<(f64, usize)>,
    unshrink: bool,
    /// Active position whose gathered row `buf_i` holds.
    buf_i_pos: Option<usize>,
    buf_i: Vec<f32>,
    buf_j: Vec<f32>,
    buf_full: Vec<f32>,
}

/// Kernel values of one row at the active bases.
enum ActiveRow<'a> {
    Slice(&'a [f32]),
    Row(Row<'a>),
}

impl std::ops::Deref for ActiveRow<'_> {
    type Target = [f32];
    fn deref(&self) -> &[f32] {
        match self {
            ActiveRow::Slice(s) => s,
            ActiveRow::Row(r) => r,
        }
    }
}

/// Positions `0..m` in a new order after removing the positions not in `keep`: kept positions
/// below the new size stay, the holes take the kept positions above it (ascending). Only the
/// moved positions change, which keeps re-compacting the kernel proportional to the moves.
fn fill_holes(keep: &[bool]) -> Vec<usize> {
    let m2 = keep.iter().filter(|&&k| k).count();
    let mut tail = (m2..keep.len()).filter(|&q| keep[q]);
    (0..m2)
        .map(|q| if keep[q] { q } else { tail.next().unwrap_or(q) })
        .collect()
}

/// The [`RowSrc`] of a solver, borrowing only its row-source fields (a method would borrow the
/// whole solver, and the hot loops write other fields while the rows are in use).
macro_rules! row_src {
    ($s:expr) => {
        RowSrc {
            rows: $s.rows,
            kc: &$s.kc,
            kc_stride: $s.kc_stride,
            direct: $s.direct,
            ak: &$s.ak,
        }
    };
}

fn status_of(a: f64, c: f64) -> Status {
    if a >= c {
        Status::Upper
    } else if a <= 0.0 {
        Status::Lower
    } else {
        Status::Free
    }
}

impl Solver<'_> {
    fn l(&self) -> usize {
        self.alpha.len()
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

    fn yg(&self, t: usize) -> f64 {
        self.y[t] * self.p[t] + self.s[self.vb[t] as usize]
    }

    /// Best active member of `I_up` (`low == false`) or `I_low` of base `b` and its mask value
    /// (`(NONE, -inf)` when there is none); ties go to the first slot.
    fn best_member(&self, b: usize, low: bool) -> (u32, f64) {
        let mut best = (NONE, f64::NEG_INFINITY);
        for t in self.slots[b] {
            if t == NONE || !self.var_active[t as usize] {
                continue;
            }
            let t_ = t as usize;
            let v = self.y[t_] * self.p[t_];
            let (ok, v) = if low {
                (self.low_ok(t_), v)
            } else {
                (self.up_ok(t_), -v)
            };
            if ok && (best.0 == NONE || v > best.1) {
                best = (t, v);
            }
        }
        best
    }

    fn refresh_masks(&mut self, pos: usize) {
        let b = self.act[pos] as usize;
        self.aup[pos] = self.best_member(b, false).1;
        self.alow[pos] = self.best_member(b, true).1;
    }

    fn set_active(&mut self, list: Vec<u32>) {
        self.ak = list.iter().map(|&b| self.pb[b as usize]).collect();
        self.av = list.iter().map(|&b| self.s[b as usize]).collect();
        self.act = list;
        let m = self.act.len();
        self.aup = vec![0.0; m];
        self.alow = vec![0.0; m];
        for pos in 0..m {
            self.refresh_masks(pos);
        }
        self.direct =
            m == self.rows.len() && self.ak.iter().enumerate().all(|(q, &k)| k as usize == q);
        self.next_gmax = None;
        self.buf_i_pos = None;
    }

    fn sync(&mut self) {
        for (pos, &b) in self.act.iter().enumerate() {
            self.s[b as usize] = self.av[pos];
        }
    }

    /// Kernel row `k` at every base, into `buf_full` unless the bases are the provider's rows.
    fn full_row(&mut self, k: usize) -> ActiveRow<'_> {
        let row = self.rows.row(k);
        if self.pb_direct {
            return ActiveRow::Row(row);
        }
        self.buf_full.resize(self.pb.len(), 0.0);
        hot::gather(&row, &self.pb, &mut self.buf_full);
        ActiveRow::Slice(&self.buf_full)
    }

    /// `s` and `sbar` from scratch, one kernel row per base with a nonzero coefficient.
    fn init_gradient(&mut self) {
        let nb = self.pb.len();
        self.s = vec![0.0; nb];
        self.sbar = vec![0.0; nb];
        let mut w = vec![0.0f64; nb];
        let mut u = vec![0.0f64; nb];
        for t in 0..self.l() {
            if self.status[t] != Status::Lower {
                let b = self.vb[t] as usize;
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
                let ks: Vec<usize> = part.iter().map(|&b| self.pb[b] as usize).collect();
                self.rows.prefetch(&ks);
            }
            for &b in part {
                let (wb, ub) = (w[b], u[b]);
                let mut s = std::mem::take(&mut self.s);
                let mut sbar = std::mem::take(&mut self.sbar);
                let row = self.full_row(self.pb[b] as usize);
                hot::axpy1(&mut s, wb, &row);
                hot::axpy1(&mut sbar, ub, &row);
                drop(row);
                self.s = s;
                self.sbar = sbar;
            }
        }
    }

    /// Prefetches the rows of the bases most likely to be picked next (largest first-order
    /// violations on both sides), so that the cache computes them in one GEMM pass.
    fn prefetch_around(&self, first: usize) {
        let batch = self.rows.batch_size();
        if batch <= 1 || self.rows.is_cached(first) {
            return;
        }
        let mut up: Vec<(f64, u32)> = Vec::new();
        let mut low: Vec<(f64, u32)> = Vec::new();
        for pos in 0..self.act.len() {
            if self.aup[pos] > f64::NEG_INFINITY {
                up.push((self.aup[pos] - self.av[pos], self.ak[pos]));
            }
            if self.alow[pos] > f64::NEG_INFINITY {
                low.push((self.av[pos] + self.alow[pos], self.ak[pos]));
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

    /// Builds the compact kernel over the active bases.
    fn build_compact(&mut self) {
        let m = self.ak.len();
        let mut kc = vec![0.0f32; m * m];
        let chunk = self.rows.batch_size().max(1);
        for (ci, part) in self.ak.chunks(chunk).enumerate() {
            if chunk > 1 {
                let ks: Vec<usize> = part.iter().map(|&k| k as usize).collect();
                self.rows.prefetch(&ks);
            }
            for (o, &k) in part.iter().enumerate() {
                let q = ci * chunk + o;
                hot::gather(
                    &self.rows.row(k as usize),
                    &self.ak,
                    &mut kc[q * m..(q + 1) * m],
                );
            }
        }
        self.kc = kc;
        self.kc_stride = m;
        self.compactions.0 += 1;
        self.rent = 0;
        self.buf_i_pos = None;
    }

    /// Reorders the compact kernel after shrinking: new position `q` holds old position
    /// `order[q]`; only rows and columns that move are touched.
    fn permute_compact(&mut self, order: &[usize]) {
        let st = self.kc_stride;
        let moves: Vec<(usize, usize)> = order
            .iter()
            .enumerate()
            .filter(|&(q, &o)| q != o)
            .map(|(q, &o)| (q, o))
            .collect();
        for (q, &o) in order.iter().enumerate() {
            if q == o {
                let row = &mut self.kc[q * st..(q + 1) * st];
                for &(h, src) in &moves {
                    row[h] = row[src];
                }
            } else {
                // Row `o` lies beyond the new size, so no new row overwrites it.
                let (head, tail) = self.kc.split_at_mut(o * st);
                let src = &tail[..st];
                let dst = &mut head[q * st..(q + 1) * st];
                for (d, &oc) in dst.iter_mut().zip(order) {
                    *d = src[oc];
                }
            }
        }
    }

    fn gmax(&self) -> (f64, usize) {
        hot::masked_max_neg(&self.av, &self.aup)
    }

    /// WSS3 over the active bases; returns the variables `(i, j)` with their active positions
    /// and `K_ij`, `None` when optimal within `tol`.
    fn select_working_set(&mut self) -> Option<([(usize, usize); 2], f64)> {
        let m = self.act.len();
        if self.kc.is_empty() && !self.direct && self.rent >= m * m && m * m <= self.compact_max {
            self.build_compact();
        }
        let (gmax, pi) = self.next_gmax.take().unwrap_or_else(|| self.gmax());
        if pi == usize::MAX {
            return None;
        }
        self.prefetch_around(self.ak[pi] as usize);
        let src = row_src!(self);
        let (ri, rent) = src.fetch(pi, &mut self.buf_i, false);
        let (gmax2, pj) = hot::wss_select(&self.av, &self.alow, &ri, gmax);
        let kij = pj.map(|pj| ri[pj] as f64);
        drop(ri);
        self.rent += rent;
        self.buf_i_pos = Some(pi);
        let (pj, kij) = (pj?, kij?);
        if gmax + gmax2 < self.tol {
            return None;
        }
        let i = self.best_member(self.act[pi] as usize, false).0 as usize;
        let j = self.best_member(self.act[pj] as usize, true).0 as usize;
        Some(([(i, pi), (j, pj)], kij))
    }

    /// Takes the step on pair `(i, j)` (`kij = K_ij`, from the selection's row).
    fn update_pair(&mut self, [(i, pi), (j, pj)]: [(usize, usize); 2], kij: f64) {
        let c = self.c;
        let quad = 2.0 - 2.0 * kij;
        let quad = if quad <= 0.0 { TAU } else { quad };
        debug_assert!(self.act[pi] == self.vb[i] && self.act[pj] == self.vb[j]);
        let ygi = self.y[i] * self.p[i] + self.av[pi];
        let ygj = self.y[j] * self.p[j] + self.av[pj];
        let (gi, gj) = (self.y[i] * ygi, self.y[j] * ygj);
        let (old_i, old_j) = (self.alpha[i], self.alpha[j]);
        let (ai, aj) = pair_step(self.y[i] != self.y[j], old_i, old_j, gi, gj, quad, c);
        self.alpha[i] = ai;
        self.alpha[j] = aj;
        for t in [i, j] {
            let was_upper = self.status[t] == Status::Upper;
            self.status[t] = status_of(self.alpha[t], c);
            if was_upper != (self.status[t] == Status::Upper) {
                let s = if was_upper { -c } else { c } * self.y[t];
                let row = self.rows.row(self.pb[self.vb[t] as usize] as usize);
                if self.pb_direct {
                    hot::axpy1(&mut self.sbar, s, &row);
                } else {
                    self.buf_full.resize(self.pb.len(), 0.0);
                    hot::gather(&row, &self.pb, &mut self.buf_full);
                    hot::axpy1(&mut self.sbar, s, &self.buf_full);
                }
            }
        }
        // The pair's masks change before the fused maximum reads them.
        self.refresh_masks(pi);
        self.refresh_masks(pj);
        // Gradient update, then the first half of the next selection.
        let dyi = (ai - old_i) * self.y[i];
        let dyj = (aj - old_j) * self.y[j];
        let reuse_i = self.buf_i_pos == Some(pi);
        let src = row_src!(self);
        let (ri, rent_i) = src.fetch(pi, &mut self.buf_i, reuse_i);
        let (rj, rent_j) = src.fetch(pj, &mut self.buf_j, false);
        let next = hot::update_gmax(&mut self.av, (dyi, &ri), (dyj, &rj), &self.aup);
        drop((ri, rj));
        self.rent += rent_i + rent_j;
        self.next_gmax = Some(next);
    }

    fn do_shrinking(&mut self) {
        let (gmax1, _) = self.gmax();
        let mut gmax2 = f64::NEG_INFINITY;
        for k in 0..self.act.len() {
            gmax2 = gmax2.max(self.av[k] + self.alow[k]);
        }
        self.sync();
        if !self.unshrink && gmax1 + gmax2 <= self.tol * 10.0 {
            self.unshrink = true;
            self.reconstruct_gradient();
        }
        // A bounded variable is dropped when it violates nothing by a margin: members of
        // I_up only when yG > max_{I_low} yG, members of I_low only when -yG > max_{I_up} -yG.
        // A base leaves the active set with its last variable.
        let mut changed = false;
        let mut keep = vec![false; self.act.len()];
        for (pos, kp) in keep.iter_mut().enumerate() {
            let b = self.act[pos] as usize;
            for t in self.slots[b] {
                let t = t as usize;
                if t == NONE as usize || !self.var_active[t] {
                    continue;
                }
                let yg = self.yg(t);
                let stay = match (self.up_ok(t), self.low_ok(t)) {
                    (true, true) | (false, false) => true,
                    (true, false) => yg <= gmax2,
                    (false, true) => -yg <= gmax1,
                };
                if stay {
                    *kp = true;
                } else {
                    self.var_active[t] = false;
                    changed = true;
                }
            }
        }
        if !changed {
            return;
        }
        // Positions of shrunk bases stay (masked, their `s` kept exact) until enough are gone
        // to make a shorter list pay for re-listing.
        let kept = keep.iter().filter(|&&k| k).count();
        if kept * 10 > keep.len() * RELIST_FRACTION_TENTHS {
            for pos in 0..keep.len() {
                self.refresh_masks(pos);
            }
            self.next_gmax = None;
            return;
        }
        let order: Vec<usize> = if self.kc.is_empty() {
            (0..keep.len()).filter(|&q| keep[q]).collect()
        } else {
            let order = fill_holes(&keep);
            self.permute_compact(&order);
            self.compactions.1 += 1;
            order
        };
        let list = order.iter().map(|&q| self.act[q]).collect();
        self.set_active(list);
    }

    /// Restores the exact `s` of inactive bases from `sbar` plus the free variables'
    /// contributions, then reactivates everything.
    fn reconstruct_gradient(&mut self) {
        self.sync();
        let nb = self.pb.len();
        if self.act.len() == nb {
            if !self.var_active.iter().all(|&a| a) {
                self.var_active.fill(true);
                for pos in 0..nb {
                    self.refresh_masks(pos);
                }
                self.next_gmax = None;
            }
            return;
        }
        let mut base_active = vec![false; nb];
        for &b in &self.act {
            base_active[b as usize] = true;
        }
        let inactive: Vec<usize> = (0..nb).filter(|&b| !base_active[b]).collect();
        for &b in &inactive {
            self.s[b] = self.sbar[b];
        }
        // Free variables are never shrunk, so their bases are active.
        let mut w = vec![0.0f64; nb];
        for t in 0..self.l() {
            if self.status[t] == Status::Free {
                w[self.vb[t] as usize] += self.alpha[t] * self.y[t];
            }
        }
        let free: Vec<usize> = (0..nb).filter(|&b| w[b] != 0.0).collect();
        // Read whichever set of rows is smaller (free bases' or inactive bases').
        let chunk = self.rows.batch_size().max(1);
        let (outer, inner) = if free.len() <= inactive.len() {
            (&free, &inactive)
        } else {
            (&inactive, &free)
        };
        let mut acc = vec![0.0f64; outer.len()];
        for (ci, part) in outer.chunks(chunk).enumerate() {
            if chunk > 1 {
                let ks: Vec<usize> = part.iter().map(|&b| self.pb[b] as usize).collect();
                self.rows.prefetch(&ks);
            }
            for (o, &b) in part.iter().enumerate() {
                let row = self.rows.row(self.pb[b] as usize);
                if free.len() <= inactive.len() {
                    let wb = w[b];
                    for &t in inner {
                        self.s[t] += wb * row[self.pb[t] as usize] as f64;
                    }
                } else {
                    acc[ci * chunk + o] = inner
                        .iter()
                        .map(|&f| w[f] * row[self.pb[f] as usize] as f64)
                        .sum();
                }
            }
        }
        if free.len() > inactive.len() {
            for (&b, a) in inactive.iter().zip(&acc) {
                self.s[b] += a;
            }
        }
        self.var_active.fill(true);
        self.kc = Vec::new();
        self.rent = 0;
        self.set_active((0..nb as u32).collect());
    }

    fn rho(&self) -> f64 {
        let mut ub = f64::INFINITY;
        let mut lb = f64::NEG_INFINITY;
        let mut nr_free = 0usize;
        let mut sum_free = 0.0;
        for t in 0..self.l() {
            let yg = self.yg(t);
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

/// Where the kernel values at the active bases come from (fields of `Solver`, borrowed
/// separately from the vectors the hot loops write).
struct RowSrc<'a> {
    rows: &'a dyn KernelRows,
    kc: &'a [f32],
    kc_stride: usize,
    direct: bool,
    ak: &'a [u32],
}

impl<'a> RowSrc<'a> {
    /// Row of active position `pos` at the active bases, and how many values were gathered;
    /// `reuse` says `buf` already holds it.
    fn fetch<'b>(&self, pos: usize, buf: &'b mut Vec<f32>, reuse: bool) -> (ActiveRow<'b>, usize)
    where
        'a: 'b,
    {
        let m = self.ak.len();
        if !self.kc.is_empty() {
            let st = self.kc_stride;
            return (ActiveRow::Slice(&self.kc[pos * st..pos * st + m]), 0);
        }
        let row = self.rows.row(self.ak[pos] as usize);
        if self.direct {
            return (ActiveRow::Row(row), 0);
        }
        if reuse && buf.len() == m {
            return (ActiveRow::Slice(buf), 0);
        }
        buf.resize(m, 0.0);
        hot::gather(&row, self.ak, buf);
        (ActiveRow::Slice(buf), m)
    }
}

/// The two-variable subproblem of libsvm (`Solver::solve`, the `y_i != y_j` and `y_i == y_j`
/// cases): new `(α_i, α_j)` clipped to the box along the equality constraint.
fn pair_step(
    opposite: bool,
    mut ai: f64,
    mut aj: f64,
    gi: f64,
    gj: f64,
    quad: f64,
    c: f64,
) -> (f64, f64) {
    if opposite {
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
        (ai, aj) = clip_sum(ai - delta, aj + delta, sum, c);
        (aj, ai) = clip_sum(aj, ai, sum, c);
    }
    (ai, aj)
}

/// One half of libsvm's clipping along `a + b = sum`: `a` against the upper bound when the
/// sum exceeds `C`, otherwise `b` against zero.
fn clip_sum(mut a: f64, mut b: f64, sum: f64, c: f64) -> (f64, f64) {
    if sum > c {
        if a > c {
            a = c;
            b = sum - c;
        }
    } else if b < 0.0 {
        b = 0.0;
        a = sum;
    }
    (a, b)
}

pub(crate) use hot::gather;

/// Solves one dual problem.
pub(crate) fn solve(
    rows: &dyn KernelRows,
    problem: SmoProblem,
    settings: &SmoSettings,
) -> SmoSolution {
    solve_with(rows, problem, settings, COMPACT_MAX)
}

/// [`solve`] with a cap on the compact kernel (values; 0 disables it).
pub(crate) fn solve_with(
    rows: &dyn KernelRows,
    problem: SmoProblem,
    settings: &SmoSettings,
    compact_max: usize,
) -> SmoSolution {
    let l = problem.y.len();
    let nk = rows.len();
    // The vectorized gathers rely on this; the crate builds every problem from valid indices.
    assert!(
        problem.kidx.iter().all(|&b| (b as usize) < nk),
        "kernel index out of range"
    );
    // Bases in order of first use; at most two variables each (SVR: α and α*).
    let mut base_of = vec![NONE; nk];
    let mut pb = Vec::new();
    let mut slots: Vec<[u32; 2]> = Vec::new();
    let mut vb = Vec::with_capacity(l);
    for (t, &k) in problem.kidx.iter().enumerate() {
        let b = match base_of[k as usize] {
            NONE => {
                base_of[k as usize] = pb.len() as u32;
                pb.push(k);
                slots.push([t as u32, NONE]);
                pb.len() - 1
            }
            b => {
                let b = b as usize;
                assert!(
                    slots[b][1] == NONE,
                    "more than two variables share a kernel row"
                );
                slots[b][1] = t as u32;
                b
            }
        };
        vb.push(b as u32);
    }
    drop(base_of);
    let pb_direct = pb.len() == nk && pb.iter().enumerate().all(|(b, &k)| k as usize == b);
    let alpha = problem.alpha0.unwrap_or_else(|| vec![0.0; l]);
    let mut s = Solver {
        rows,
        c: problem.c,
        tol: settings.tol,
        y: problem.y,
        p: problem.p,
        alpha,
        status: Vec::new(),
        vb,
        var_active: vec![true; l],
        pb,
        slots,
        s: Vec::new(),
        sbar: Vec::new(),
        pb_direct,
        act: Vec::new(),
        ak: Vec::new(),
        av: Vec::new(),
        aup: Vec::new(),
        alow: Vec::new(),
        direct: false,
        kc: Vec::new(),
        kc_stride: 0,
        rent: 0,
        compactions: (0, 0),
        // Only over precomputed rows: on a row cache, building it would compute rows that
        // the solve may never need. At most a quarter of the provider's size on top of it
        // (on 17,000 samples a half was no faster and took 270 MB more).
        compact_max: if rows.batch_size() == 0 {
            compact_max.min(nk * nk / 4)
        } else {
            0
        },
        next_gmax: None,
        unshrink: false,
        buf_i_pos: None,
        buf_i: Vec::new(),
        buf_j: Vec::new(),
        buf_full: Vec::new(),
    };
    s.status = s.alpha.iter().map(|&a| status_of(a, s.c)).collect();
    s.init_gradient();
    s.set_active((0..s.pb.len() as u32).collect());

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
        .map(|t| s.alpha[t] * (s.y[t] * s.yg(t) + s.p[t]))
        .sum::<f64>()
        / 2.0;
    SmoSolution {
        alpha: s.alpha,
        rho,
        obj,
        iterations: iter,
        converged,
        compactions: s.compactions,
    }
}

/// The two O(active) loops of every iteration, written so that they vectorize (gathers first,
/// then branch-free arithmetic, then a max reduction and a position search); with AVX2 they
/// run the hand-written versions of `crate::simd`.
pub(crate) mod hot {
    #[cfg(target_arch = "x86_64")]
    use crate::simd;

    /// `out[k] = row[idx[k]]`; every index must be below `row.len()` (checked once per
    /// problem in `solve`).
    pub(crate) fn gather(row: &[f32], idx: &[u32], out: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        if simd::avx2() && row.len() < i32::MAX as usize {
            // SAFETY: AVX2 is available; indices are in bounds (caller contract) and fit i32.
            unsafe { simd::gather_avx2(row, idx, out) };
            return;
        }
        for (o, &i) in out.iter_mut().zip(idx) {
            *o = row[i as usize];
        }
    }

    /// `y[k] += a x[k]`.
    pub(super) fn axpy1(y: &mut [f64], a: f64, x: &[f32]) {
        for (v, &xi) in y.iter_mut().zip(x) {
            *v += a * xi as f64;
        }
    }

    /// `max_{mask} -v` and its first position (`(-inf, usize::MAX)` when the mask is empty);
    /// `mask` is `-inf` for non-members.
    pub(super) fn masked_max_neg(v: &[f64], mask: &[f64]) -> (f64, usize) {
        #[cfg(target_arch = "x86_64")]
        if simd::avx2() {
            // SAFETY: AVX2 and FMA are available (checked at run time).
            return unsafe { simd::masked_max_neg_avx2(v, mask) };
        }
        masked_max_neg_generic(v, mask)
    }

    /// Gradient update `v[k] += a x[k] + b z[k]` fused with the next `masked_max_neg(v, mask)`.
    pub(super) fn update_gmax(
        v: &mut [f64],
        (a, x): (f64, &[f32]),
        (b, z): (f64, &[f32]),
        mask: &[f64],
    ) -> (f64, usize) {
        let n = v.len();
        assert!(x.len() >= n && z.len() >= n && mask.len() >= n);
        #[cfg(target_arch = "x86_64")]
        if simd::avx2() {
            // SAFETY: AVX2 and FMA are available; lengths checked above.
            return unsafe { simd::max_pass::<true>(v.as_mut_ptr(), n, (a, x), (b, z), mask) };
        }
        update_gmax_generic_mut(v, (a, x), (b, z), mask)
    }

    pub(crate) fn masked_max_neg_generic(v: &[f64], mask: &[f64]) -> (f64, usize) {
        let mut best = (f64::NEG_INFINITY, usize::MAX);
        for (k, (&vk, &mk)) in v.iter().zip(mask).enumerate() {
            let m = mk - vk;
            if m > best.0 {
                best = (m, k);
            }
        }
        best
    }

    pub(crate) fn update_gmax_generic_mut(
        v: &mut [f64],
        (a, x): (f64, &[f32]),
        (b, z): (f64, &[f32]),
        mask: &[f64],
    ) -> (f64, usize) {
        for ((vk, &xk), &zk) in v.iter_mut().zip(x).zip(z) {
            *vk += a * xk as f64 + b * zk as f64;
        }
        masked_max_neg_generic(v, mask)
    }

    /// WSS3's second index: second-order gains `(gmax + yG_j)² / (2 - 2 K_ij)` of the `I_low`
    /// members with a positive first-order gain, in `f32` (they only rank candidates).
    /// Returns `max_{I_low} yG` (`yG_j = v[j] + low[j]`, `low` is `-inf` for non-members) and
    /// the first position of the largest positive gain.
    pub(super) fn wss_select(
        v: &[f64],
        low: &[f64],
        kv: &[f32],
        gmax: f64,
    ) -> (f64, Option<usize>) {
        let n = v.len();
        assert!(low.len() >= n && kv.len() >= n);
        #[cfg(target_arch = "x86_64")]
        if simd::avx2() {
            // SAFETY: AVX2 and FMA are available; lengths checked above.
            return unsafe { simd::wss_select_avx2(v, low, kv, gmax) };
        }
        wss_select_generic(v, low, kv, gmax)
    }

    #[inline(always)]
    pub(crate) fn wss_gain(gmax: f64, m: f64, kv: f32) -> f32 {
        let gd = (gmax + m) as f32;
        let q = (2.0 - 2.0 * kv).max(1e-12);
        if gd > 0.0 { gd * gd / q } else { 0.0 }
    }

    pub(crate) fn wss_select_generic(
        v: &[f64],
        low: &[f64],
        kv: &[f32],
        gmax: f64,
    ) -> (f64, Option<usize>) {
        let mut gmax2 = f64::NEG_INFINITY;
        let mut best = (0.0f32, None);
        for k in 0..v.len() {
            let m = v[k] + low[k];
            if m > gmax2 {
                gmax2 = m;
            }
            let sc = wss_gain(gmax, m, kv[k]);
            if sc > best.0 {
                best = (sc, Some(k));
            }
        }
        (gmax2, best.1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cache::{CachedKernel, FullKernel};
    use crate::kernel;
    use crate::matrix::{View as _, owned};
    use ridi_features::FeatureMatrix;

    fn data(n: usize) -> FeatureMatrix {
        let v: Vec<f32> = (0..n * 6)
            .map(|k| ((k as f32) * 0.713).sin() + ((k / 6) as f32 * 0.05).cos())
            .collect();
        owned(v, 6)
    }

    fn svr_problem(idx: &[usize], c: f64, eps: f64) -> SmoProblem {
        let m = idx.len();
        let z = |s: usize| (idx[s] as f64 * 0.37).sin() + 0.3 * (idx[s] as f64 * 1.7).cos();
        SmoProblem {
            kidx: idx.iter().chain(idx).map(|&i| i as u32).collect(),
            y: (0..2 * m).map(|t| if t < m { 1.0 } else { -1.0 }).collect(),
            p: (0..2 * m)
                .map(|t| if t < m { eps - z(t) } else { eps + z(t - m) })
                .collect(),
            c,
            alpha0: None,
        }
    }

    /// Same objective and the same decision values at every base sample (the dual solution
    /// itself need not be unique when the kernel matrix is nearly singular).
    fn assert_same(full: &FullKernel, problem: &SmoProblem, a: &SmoSolution, b: &SmoSolution) {
        assert!(a.converged && b.converged);
        assert!(
            (a.obj - b.obj).abs() < 1e-6 * a.obj.abs().max(1.0),
            "{} vs {}",
            a.obj,
            b.obj
        );
        let coef = |sol: &SmoSolution| -> Vec<f64> {
            let mut w = vec![0.0; full.len()];
            for (t, &k) in problem.kidx.iter().enumerate() {
                w[k as usize] += problem.y[t] * sol.alpha[t];
            }
            w
        };
        let (wa, wb) = (coef(a), coef(b));
        let mut worst = 0.0f64;
        for &k in &problem.kidx {
            let row = full.row(k as usize);
            let dec = |w: &[f64], rho: f64| -> f64 {
                w.iter()
                    .zip(row.iter())
                    .map(|(w, &r)| w * r as f64)
                    .sum::<f64>()
                    - rho
            };
            worst = worst.max((dec(&wa, a.rho) - dec(&wb, b.rho)).abs());
        }
        assert!(worst < 1e-3, "largest decision value difference {worst}");
    }

    #[test]
    fn compact_kernel_gives_the_uncompacted_solution() {
        let x = data(700);
        let full = FullKernel::new(x.view(), &kernel::sq_norms(x.view()), 0.2);
        let settings = SmoSettings {
            tol: 1e-7,
            ..SmoSettings::default()
        };
        // A fold-like subset (rows gathered, then compacted) and all rows (used directly
        // until shrinking, then compacted).
        let fold: Vec<usize> = (0..700).filter(|i| i % 4 != 1).collect();
        let all: Vec<usize> = (0..700).collect();
        for idx in [&fold, &all] {
            let with = solve(&full, svr_problem(idx, 10.0, 0.01), &settings);
            let without = solve_with(&full, svr_problem(idx, 10.0, 0.01), &settings, 0);
            assert!(
                with.compactions.0 >= 1 && with.compactions.1 >= 1,
                "{:?}",
                with.compactions
            );
            assert_eq!(without.compactions, (0, 0));
            assert_same(&full, &svr_problem(idx, 10.0, 0.01), &with, &without);
        }
    }

    #[test]
    fn classifier_problem_agrees_across_kernel_providers_and_compaction() {
        let x = data(500);
        let full = FullKernel::new(x.view(), &kernel::sq_norms(x.view()), 0.2);
        let cached = CachedKernel::new(x.view(), 0.2, 64 * 500 * 4);
        let idx: Vec<usize> = (0..500).filter(|i| i % 5 != 0).collect();
        let problem = || SmoProblem {
            kidx: idx.iter().map(|&i| i as u32).collect(),
            y: idx
                .iter()
                // Labels that the kernel separates only partly: many iterations, many SV.
                .map(|&i| {
                    if x.row(i)[0] + 0.5 * x.row(i)[3] > 0.4 || i % 7 == 0 {
                        1.0
                    } else {
                        -1.0
                    }
                })
                .collect(),
            p: vec![-1.0; idx.len()],
            c: 10.0,
            alpha0: None,
        };
        let settings = SmoSettings {
            tol: 1e-7,
            ..SmoSettings::default()
        };
        let a = solve(&full, problem(), &settings);
        let b = solve_with(&full, problem(), &settings, 0);
        let c = solve(&cached, problem(), &settings);
        assert!(a.compactions.0 >= 1, "{:?}", a.compactions);
        assert_eq!(c.compactions, (0, 0));
        assert_same(&full, &problem(), &a, &b);
        assert_same(&full, &problem(), &a, &c);
    }

    #[test]
    fn hole_filling_moves_only_tail_positions() {
        let keep = [true, false, true, false, true, true, false, true];
        assert_eq!(fill_holes(&keep), vec![0, 5, 2, 7, 4]);
        assert_eq!(fill_holes(&[false, false]), Vec::<usize>::new());
    }
}
