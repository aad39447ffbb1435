//! The correction solve: an exact banded reformulation, factorized with faer's sparse
//! Cholesky (see [`Corrector`]).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side, Spec};
use ridi_frames::nalgebra::{Matrix3, Vector3};
use ridi_frames::{DeviceVec, WorldVec};
use serde::{Deserialize, Serialize};

use crate::config::{CorrectionConfig, InitialVelocity};
use crate::error::CorrectError;
use crate::input::{FrameVelocity, validate_imu, validate_targets};
use crate::integrate::{Pose, corrected_acceleration_unchecked, integrate_unchecked};
use crate::knots::{BiasCurve, Knots};
use ridi_frames::ImuFrames;

/// Result of a correction solve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Correction {
    /// The estimated device-frame bias, one value per knot.
    pub bias: BiasCurve,
    /// Velocity at the first frame: the fixed one, or the estimate.
    pub initial_velocity: WorldVec,
}

/// A corrected trajectory: poses of every frame plus the correction that produced them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trajectory {
    /// One pose per frame, world frame, starting at the origin.
    pub poses: Vec<Pose>,
    /// The bias and initial velocity used.
    pub correction: Correction,
}

impl Trajectory {
    /// The product of RIDI: the horizontal world trajectory, `[x, y]` per frame.
    pub fn horizontal(&self) -> Vec<[f64; 2]> {
        self.poses
            .iter()
            .map(|p| [p.position.x(), p.position.y()])
            .collect()
    }
}

/// Sums over a run of frames sharing a segment and a left knot, kept in registers and
/// flushed into the segment blocks when the run ends: `Σ c R`, `Σ c w R` and `Σ c R a`.
#[derive(Default)]
struct Run {
    seg: Option<(usize, usize)>,
    r0: Matrix3<f64>,
    r1: Matrix3<f64>,
    d: Vector3<f64>,
}

impl Run {
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn add(
        &mut self,
        s: &mut Scratch,
        j: usize,
        k: usize,
        c: f64,
        w: f64,
        rot: &Matrix3<f64>,
        a: &Vector3<f64>,
    ) {
        if self.seg != Some((j, k)) {
            self.flush(s);
            self.seg = Some((j, k));
        }
        self.r0 += rot * c;
        self.r1 += rot * (c * w);
        self.d += a * c;
    }

    fn flush(&mut self, s: &mut Scratch) {
        if let Some((j, k)) = self.seg.take() {
            let base = s.seg_off[j] + k - s.seg_lo[j];
            s.g[base] += self.r0 - self.r1;
            // The weight of the next knot is zero on the segment's last knot.
            if k < s.seg_hi[j] {
                s.g[base + 1] += self.r1;
            }
            s.d[j] += self.d;
        }
        self.r0 = Matrix3::zeros();
        self.r1 = Matrix3::zeros();
        self.d = Vector3::zeros();
    }
}

/// Cached symbolic factorization of one sparsity pattern, with its numeric workspace.
struct Factorization {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
    l_values: Vec<f64>,
    mem: MemBuffer,
}

/// Reusable buffers of the assembly, kept to avoid reallocating on every streaming update.
#[derive(Default)]
struct Scratch {
    seg_lo: Vec<usize>,
    seg_hi: Vec<usize>,
    seg_off: Vec<usize>,
    g: Vec<Matrix3<f64>>,
    d: Vec<Vector3<f64>>,
    pinv: Vec<Matrix3<f64>>,
    pm: Vec<Vector3<f64>>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    rhs: Vec<f64>,
}

/// Solves corrections; keeps the symbolic Cholesky factorization of the last system shape
/// (and all assembly buffers) so that repeated solves of the same shape, as in the streaming
/// tracker, only redo the numeric work.
///
/// # Why the direct normal equations are dense
///
/// The velocity at a target frame integrates the bias of *every* earlier frame, so each
/// residual row touches all knots before it and `JᵀJ` is dense (`O(K²)` memory, `O(K³)`
/// time for `K` knots).
///
/// # The banded reformulation (exact)
///
/// Give the velocity at each target frame its own unknown `w_j` and tie consecutive ones by
/// the integration itself, a *hard* linear constraint:
///
/// ```text
/// minimise   Σ_j ||M_j w_j - u_j||²  +  λ ||x||²
/// subject to w_j - w_{j-1} - G_j x = d_j          (w_{-1} = v0)
/// ```
///
/// `M_j` stacks the weighted rows `√w_h e_xᵀR_SW`, `√w_h e_zᵀR_SW`, `√w_v e_zᵀ`; `u_j` the
/// weighted targets; `d_j` the integral of the uncorrected world acceleration over the
/// segment `(r_{j-1}, r_j]` (plus `v0` for `j = 0`); `G_j` the 3x3 blocks that map the
/// knots touching that segment to its velocity increment. With multipliers `y`, the KKT
/// conditions give `w = P⁻¹(Mᵀu - Dᵀy)` (`P_j = M_jᵀM_j`, block diagonal) and
/// `x = Gᵀy / λ`; substituting into the constraints leaves
///
/// ```text
/// (D P⁻¹ Dᵀ + G Gᵀ / λ) y = D P⁻¹ Mᵀu - d
/// ```
///
/// `D` is block bidiagonal and `G` block banded (a segment touches 2-3 knots), so the matrix
/// is block banded; it is symmetric positive definite whenever `λ > 0` and every `P_j` is
/// (both weights positive, gravity and orientation not 90 degrees apart). No approximation is
/// involved: the solution is that of the original objective (tests compare it with a dense
/// solve).
///
/// With an estimated initial velocity (no prior on it), stationarity in `v0` forces `y_0 = 0`:
/// the first constraint drops out of the system and `v0` is recovered from it afterwards.
pub struct Corrector {
    config: CorrectionConfig,
    cache: Option<Factorization>,
    scratch: Scratch,
    symbolic_count: usize,
}

impl std::fmt::Debug for Corrector {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Corrector")
            .field("config", &self.config)
            .field("symbolic_factorizations", &self.symbolic_count)
            .finish_non_exhaustive()
    }
}

impl Corrector {
    /// A corrector for `config` (validated here).
    pub fn new(config: CorrectionConfig) -> Result<Self, CorrectError> {
        config.validate()?;
        Ok(Self {
            config,
            cache: None,
            scratch: Scratch::default(),
            symbolic_count: 0,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &CorrectionConfig {
        &self.config
    }

    /// How many symbolic factorizations were computed so far (a solve of an already seen
    /// shape reuses the cached one).
    pub fn symbolic_factorizations(&self) -> usize {
        self.symbolic_count
    }

    /// Estimates the bias (and, if configured, the initial velocity) from the frames of `imu`
    /// and the velocity `targets`, with the configured initial velocity.
    pub fn solve(
        &mut self,
        imu: &ImuFrames<'_>,
        targets: &[FrameVelocity],
    ) -> Result<Correction, CorrectError> {
        let initial = self.config.initial_velocity;
        self.solve_from(imu, targets, initial)
    }

    /// [`solve`](Self::solve) with an explicit initial velocity (the tracker fixes each
    /// window's start to its earlier output).
    pub fn solve_from(
        &mut self,
        imu: &ImuFrames<'_>,
        targets: &[FrameVelocity],
        initial: InitialVelocity,
    ) -> Result<Correction, CorrectError> {
        validate_imu(imu, self.config.max_dt)?;
        validate_targets(targets, imu.len())?;
        if let InitialVelocity::Fixed(v) = initial
            && !v.is_finite()
        {
            return Err(CorrectError::NonFinite {
                what: "initial velocity",
                index: 0,
            });
        }
        if targets.is_empty() && initial == InitialVelocity::Estimate {
            return Err(CorrectError::NoTargets);
        }
        self.solve_validated(imu, targets, initial)
    }

    /// Solve followed by integration from the origin: the corrected trajectory.
    pub fn correct(
        &mut self,
        imu: &ImuFrames<'_>,
        targets: &[FrameVelocity],
    ) -> Result<Trajectory, CorrectError> {
        let correction = self.solve(imu, targets)?;
        let acc = corrected_acceleration_unchecked(imu, &correction.bias);
        let poses =
            integrate_unchecked(imu.time, &acc, correction.initial_velocity, WorldVec::ZERO);
        Ok(Trajectory { poses, correction })
    }

    pub(crate) fn solve_validated(
        &mut self,
        imu: &ImuFrames<'_>,
        targets: &[FrameVelocity],
        initial: InitialVelocity,
    ) -> Result<Correction, CorrectError> {
        let knots = Knots::new(imu.time, self.config.knot_spacing);
        let n_knots = knots.len();
        if targets.is_empty() {
            let v0 = match initial {
                InitialVelocity::Fixed(v) => v,
                InitialVelocity::Estimate => return Err(CorrectError::NoTargets),
            };
            return Ok(Correction {
                bias: BiasCurve::zero(knots),
                initial_velocity: v0,
            });
        }
        self.assemble_segments(imu, targets, &knots);
        self.target_blocks(imu, targets)?;
        let first = usize::from(initial == InitialVelocity::Estimate);
        let v0 = match initial {
            InitialVelocity::Fixed(v) => *v.vector(),
            InitialVelocity::Estimate => Vector3::zeros(),
        };
        self.assemble_system(targets.len(), first, v0);
        self.factor_and_solve()?;

        // Back-substitution: x = Gᵀy / λ, and v0 from the dropped first constraint.
        let s = &self.scratch;
        let inv_lambda = 1.0 / self.config.lambda;
        let y = |j: usize| -> Vector3<f64> {
            if j < first {
                Vector3::zeros()
            } else {
                let o = 3 * (j - first);
                Vector3::new(s.rhs[o], s.rhs[o + 1], s.rhs[o + 2])
            }
        };
        let blocks = |j: usize| {
            let (lo, hi) = (s.seg_lo[j], s.seg_hi[j]);
            (lo..=hi, &s.g[s.seg_off[j]..=s.seg_off[j] + hi - lo])
        };
        let mut x = vec![Vector3::<f64>::zeros(); n_knots];
        for j in first..targets.len() {
            let yj = y(j);
            let (range, g) = blocks(j);
            for (xk, gk) in x[range].iter_mut().zip(g) {
                *xk += gk.tr_mul(&yj) * inv_lambda;
            }
        }
        let v0 = match initial {
            InitialVelocity::Fixed(v) => v,
            InitialVelocity::Estimate => {
                let y1 = if targets.len() > 1 {
                    y(1)
                } else {
                    Vector3::zeros()
                };
                let w0 = s.pm[0] + s.pinv[0] * y1;
                let mut inc = s.d[0];
                let (range, g) = blocks(0);
                for (xk, gk) in x[range].iter().zip(g) {
                    inc += gk * xk;
                }
                WorldVec::from_vector(w0 - inc)
            }
        };
        Ok(Correction {
            bias: BiasCurve {
                knots,
                values: x.into_iter().map(DeviceVec::from_vector).collect(),
            },
            initial_velocity: v0,
        })
    }

    /// Segment integrals: `d_j` (uncorrected world acceleration) and the blocks `G_j`.
    fn assemble_segments(&mut self, imu: &ImuFrames<'_>, targets: &[FrameVelocity], knots: &Knots) {
        let s = &mut self.scratch;
        let r = targets.len();
        s.seg_lo.clear();
        s.seg_hi.clear();
        s.seg_off.clear();
        let mut off = 0;
        for j in 0..r {
            let prev = if j == 0 { 0 } else { targets[j - 1].frame };
            let lo = knots.locate(prev, imu.time[prev]).0;
            let hi = knots.upper(targets[j].frame).max(lo);
            s.seg_lo.push(lo);
            s.seg_hi.push(hi);
            s.seg_off.push(off);
            off += hi - lo + 1;
        }
        s.g.clear();
        s.g.resize(off, Matrix3::zeros());
        s.d.clear();
        s.d.resize(r, Vector3::zeros());

        let last = targets[r - 1].frame;
        let kf = knots.frames();
        let kt = knots.times();
        let mut acc = Run::default();
        let mut jf = 0;
        let mut k = 0;
        for f in 0..=last {
            let t = imu.time[f];
            // Same knot lookup as `Knots::locate`, walked incrementally.
            while k + 1 < kf.len() && kf[k + 1] <= f {
                k += 1;
            }
            let w = if kf[k] == f || k + 1 == kf.len() {
                0.0
            } else {
                (t - kt[k]) / (kt[k + 1] - kt[k])
            };
            let rot = imu.orientation[f].matrix();
            let a = rot * imu.linacce[f].vector();
            while targets[jf].frame < f {
                jf += 1;
            }
            // Frame f weighs half of step f (ending at f) and half of step f + 1; both steps
            // lie in segment jf unless f is itself a target frame.
            let before = if f >= 1 {
                0.5 * (t - imu.time[f - 1])
            } else {
                0.0
            };
            let after = if f < last {
                0.5 * (imu.time[f + 1] - t)
            } else {
                0.0
            };
            if targets[jf].frame > f {
                acc.add(s, jf, k, before + after, w, &rot, &a);
            } else {
                if before != 0.0 {
                    acc.add(s, jf, k, before, w, &rot, &a);
                }
                if after != 0.0 {
                    acc.add(s, jf + 1, k, after, w, &rot, &a);
                }
            }
        }
        acc.flush(s);
    }

    /// Per-target `P_j⁻¹` and `P_j⁻¹ M_jᵀ u_j`.
    fn target_blocks(
        &mut self,
        imu: &ImuFrames<'_>,
        targets: &[FrameVelocity],
    ) -> Result<(), CorrectError> {
        let (wh, wv) = (self.config.horizontal_weight, self.config.vertical_weight);
        let up_axis = self.config.up_axis;
        let s = &mut self.scratch;
        s.pinv.clear();
        s.pm.clear();
        let ez = Vector3::z();
        for t in targets {
            let rsw = up_axis
                .stab_from_world(imu.orientation[t.frame], imu.gravity[t.frame])
                .matrix();
            let h1: Vector3<f64> = rsw.row(0).transpose();
            let h2: Vector3<f64> = rsw.row(2).transpose();
            let p = (h1 * h1.transpose() + h2 * h2.transpose()) * wh + ez * ez.transpose() * wv;
            // For consistent inputs the three rows are orthonormal and det P = w_h² w_v.
            let det = p.determinant();
            let pinv = match p.try_inverse() {
                Some(m) if det > 1e-9 * wh * wh * wv => m,
                _ => return Err(CorrectError::DegenerateFrame { frame: t.frame }),
            };
            let m = (h1 * t.velocity[0] + h2 * t.velocity[1]) * wh;
            s.pinv.push(pinv);
            s.pm.push(pinv * m);
        }
        Ok(())
    }

    /// Upper triangle (CSC) and right-hand side of `(D P⁻¹ Dᵀ + G Gᵀ/λ) y = D P⁻¹ Mᵀu - d`
    /// over the constraints `first..r`.
    fn assemble_system(&mut self, r: usize, first: usize, v0: Vector3<f64>) {
        let inv_lambda = 1.0 / self.config.lambda;
        let s = &mut self.scratch;
        s.col_ptr.clear();
        s.row_idx.clear();
        s.values.clear();
        s.rhs.clear();
        s.col_ptr.push(0);
        let block = |s: &Scratch, j: usize, i: usize| -> Matrix3<f64> {
            let mut m = Matrix3::zeros();
            let lo = s.seg_lo[i].max(s.seg_lo[j]);
            let hi = s.seg_hi[i].min(s.seg_hi[j]);
            for k in lo..=hi {
                let gj = &s.g[s.seg_off[j] + k - s.seg_lo[j]];
                let gi = &s.g[s.seg_off[i] + k - s.seg_lo[i]];
                m += gj * gi.transpose();
            }
            m *= inv_lambda;
            if j == i {
                m += s.pinv[j];
                if j >= 1 {
                    m += s.pinv[j - 1];
                }
            } else if j == i + 1 {
                m -= s.pinv[i];
            }
            m
        };
        let mut blocks: Vec<Matrix3<f64>> = Vec::with_capacity(4);
        for j in first..r {
            // Rows of block column j in the upper triangle: its D-neighbour j - 1 and every
            // earlier constraint sharing a knot (knot ranges are monotone, so they are
            // contiguous), then j itself.
            let mut imin = j;
            if j > first {
                imin = j - 1;
                while imin > first && s.seg_hi[imin - 1] >= s.seg_lo[j] {
                    imin -= 1;
                }
            }
            blocks.clear();
            for i in imin..=j {
                blocks.push(block(s, j, i));
            }
            for c in 0..3 {
                for (bi, m) in blocks.iter().enumerate() {
                    let i = imin + bi;
                    let row0 = 3 * (i - first);
                    let end = if i == j { c + 1 } else { 3 };
                    for rr in 0..end {
                        // Entry (i, j) of the upper triangle is entry (j, i) transposed.
                        s.row_idx.push(row0 + rr);
                        s.values.push(m[(c, rr)]);
                    }
                }
                s.col_ptr.push(s.row_idx.len());
            }
            let i = j;
            let mut b = s.pm[i] - s.d[i];
            if i >= 1 {
                b -= s.pm[i - 1];
            } else {
                b -= v0;
            }
            s.rhs.extend_from_slice(b.as_slice());
        }
    }

    /// Factorizes the assembled matrix (reusing the symbolic part when the pattern is the
    /// cached one) and overwrites `rhs` with the solution.
    fn factor_and_solve(&mut self) -> Result<(), CorrectError> {
        let s = &mut self.scratch;
        let dim = s.rhs.len();
        if dim == 0 {
            return Ok(());
        }
        let reuse =
            matches!(&self.cache, Some(c) if c.col_ptr == s.col_ptr && c.row_idx == s.row_idx);
        if !reuse {
            let sym = SymbolicSparseColMatRef::new_checked(dim, dim, &s.col_ptr, None, &s.row_idx);
            // The matrix is banded in its natural order, so no fill-reducing permutation
            // can beat it. Without a permutation faer analyses the matrix as given, which
            // must then be the upper triangle.
            let symbolic = factorize_symbolic_cholesky(
                sym,
                Side::Upper,
                SymmetricOrdering::Identity,
                CholeskySymbolicParams::default(),
            )
            .map_err(|_| CorrectError::OutOfMemory)?;
            let req = symbolic
                .factorize_numeric_llt_scratch::<f64>(Par::Seq, Spec::default())
                .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
            let mem = MemBuffer::try_new(req).map_err(|_| CorrectError::OutOfMemory)?;
            self.cache = Some(Factorization {
                col_ptr: s.col_ptr.clone(),
                row_idx: s.row_idx.clone(),
                l_values: vec![0.0; symbolic.len_val()],
                symbolic,
                mem,
            });
            self.symbolic_count += 1;
        }
        let Some(Factorization {
            col_ptr,
            row_idx,
            symbolic,
            l_values,
            mem,
        }) = self.cache.as_mut()
        else {
            return Err(CorrectError::OutOfMemory);
        };
        let sym = SymbolicSparseColMatRef::new_checked(dim, dim, col_ptr, None, row_idx);
        let mat = SparseColMatRef::new(sym, &s.values);
        let stack = MemStack::new(mem);
        let llt = symbolic
            .factorize_numeric_llt(
                l_values,
                mat,
                Side::Upper,
                LltRegularization::default(),
                Par::Seq,
                stack,
                Spec::default(),
            )
            .map_err(|_| CorrectError::NotPositiveDefinite)?;
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut s.rhs, dim, 1),
            Par::Seq,
            stack,
        );
        if s.rhs.iter().any(|v| !v.is_finite()) {
            return Err(CorrectError::NotPositiveDefinite);
        }
        Ok(())
    }
}

/// One-shot batch correction with `config`: solve, then integrate from the origin.
pub fn correct(
    config: CorrectionConfig,
    imu: &ImuFrames<'_>,
    targets: &[FrameVelocity],
) -> Result<Trajectory, CorrectError> {
    Corrector::new(config)?.correct(imu, targets)
}
