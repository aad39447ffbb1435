//! Epsilon-SVR with an RBF kernel (libsvm's 2l-variable dual).

use serde::{Deserialize, Serialize};

use crate::cache::KernelRows;
use crate::config::{self, SolverConfig};
use crate::error::RegressError;
use crate::expansion::Expansion;
use crate::matrix::View as _;
use crate::smo::{self, SmoProblem, SmoSettings};
use ridi_features::FeatureMatrixRef;

/// Hyper-parameters of one epsilon-SVR.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SvrParams {
    /// Box constraint `C > 0`.
    pub c: f64,
    /// Width of the insensitive tube, `>= 0`.
    pub epsilon: f64,
    /// RBF width `gamma > 0`.
    pub gamma: f32,
    /// Solver settings.
    pub solver_config: SolverConfig,
}

impl SvrParams {
    /// Parameters with default solver settings.
    pub fn new(c: f64, epsilon: f64, gamma: f32) -> Self {
        Self {
            c,
            epsilon,
            gamma,
            solver_config: SolverConfig::default(),
        }
    }

    pub(crate) fn validate(&self) -> Result<(), RegressError> {
        check_c_gamma(self.c, self.gamma)?;
        if !(self.epsilon.is_finite() && self.epsilon >= 0.0) {
            return Err(RegressError::InvalidParam(format!(
                "epsilon must be finite and >= 0, got {}",
                self.epsilon
            )));
        }
        check_smo(&self.solver_config.smo)
    }
}

pub(crate) fn check_c_gamma(c: f64, gamma: f32) -> Result<(), RegressError> {
    if !(c.is_finite() && c > 0.0) {
        return Err(RegressError::InvalidParam(format!(
            "C must be finite and > 0, got {c}"
        )));
    }
    if !(gamma.is_finite() && gamma > 0.0) {
        return Err(RegressError::InvalidParam(format!(
            "gamma must be finite and > 0, got {gamma}"
        )));
    }
    Ok(())
}

pub(crate) fn check_smo(s: &SmoSettings) -> Result<(), RegressError> {
    if !(s.tol.is_finite() && s.tol > 0.0) {
        return Err(RegressError::InvalidParam(format!(
            "solver tolerance must be > 0, got {}",
            s.tol
        )));
    }
    Ok(())
}

/// Solver statistics of one fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FitInfo {
    /// SMO iterations.
    pub iterations: usize,
    /// Final dual objective (libsvm's `obj`).
    pub objective: f64,
    /// False when the iteration cap stopped the solver before the tolerance was met.
    pub converged: bool,
    /// Number of support vectors.
    pub n_support: usize,
}

/// Dual solution of an SVR over a subset of a kernel's base samples.
#[derive(Debug, Clone)]
pub(crate) struct SvrDual {
    /// `α_s - α*_s` for every sample of the subset.
    pub coef: Vec<f64>,
    /// The 2l dual variables (for warm starts).
    pub alpha: Vec<f64>,
    pub rho: f64,
    pub obj: f64,
    pub iterations: usize,
    pub converged: bool,
}

impl SvrDual {
    pub(crate) fn info(&self) -> FitInfo {
        FitInfo {
            iterations: self.iterations,
            objective: self.obj,
            converged: self.converged,
            n_support: self.coef.iter().filter(|c| **c != 0.0).count(),
        }
    }
}

/// Solves the SVR dual on base samples `idx` of `rows` with targets `y` (one per `idx`).
pub(crate) fn solve_svr(
    rows: &dyn KernelRows,
    idx: &[usize],
    y: &[f64],
    c: f64,
    epsilon: f64,
    alpha0: Option<Vec<f64>>,
    settings: &SmoSettings,
) -> SvrDual {
    let m = idx.len();
    let kidx: Vec<u32> = idx.iter().chain(idx).map(|&i| i as u32).collect();
    let sign: Vec<f64> = (0..2 * m).map(|t| if t < m { 1.0 } else { -1.0 }).collect();
    let p: Vec<f64> = (0..2 * m)
        .map(|t| {
            if t < m {
                epsilon - y[t]
            } else {
                epsilon + y[t - m]
            }
        })
        .collect();
    let sol = smo::solve(
        rows,
        SmoProblem {
            kidx,
            y: sign,
            p,
            c,
            alpha0,
        },
        settings,
    );
    let coef = (0..m).map(|s| sol.alpha[s] - sol.alpha[s + m]).collect();
    SvrDual {
        coef,
        alpha: sol.alpha,
        rho: sol.rho,
        obj: sol.obj,
        iterations: sol.iterations,
        converged: sol.converged,
    }
}

/// Trained epsilon-SVR: `f(x) = Σ_s coef_s K(sv_s, x) - rho`. Its serde form is checked when
/// read (sizes, finite values), so a deserialized one predicts or was refused.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "SvrParts")]
pub struct Svr {
    pub(crate) exp: Expansion,
    pub(crate) rho: f64,
    pub(crate) params: SvrParams,
    pub(crate) info: FitInfo,
}

/// [`Svr`] as stored, checked on the way in.
#[derive(Deserialize)]
struct SvrParts {
    exp: Expansion,
    rho: f64,
    params: SvrParams,
    info: FitInfo,
}

impl TryFrom<SvrParts> for Svr {
    type Error = RegressError;
    fn try_from(p: SvrParts) -> Result<Self, RegressError> {
        if p.exp.k != 1 || !p.rho.is_finite() {
            return Err(RegressError::Decode(
                "SVR: one coefficient column and a finite offset are needed".into(),
            ));
        }
        Ok(Self {
            exp: p.exp,
            rho: p.rho,
            params: p.params,
            info: p.info,
        })
    }
}

pub(crate) fn check_xy(x: FeatureMatrixRef<'_>, n_targets: usize) -> Result<(), RegressError> {
    if x.rows() != n_targets {
        return Err(RegressError::LengthMismatch {
            what: "targets (one per sample row)",
            expected: x.rows(),
            found: n_targets,
        });
    }
    if x.rows() == 0 {
        return Err(RegressError::NotEnoughData("no training samples".into()));
    }
    Ok(())
}

impl Svr {
    /// Trains on rows of `x` with targets `y`.
    pub fn fit(
        x: FeatureMatrixRef<'_>,
        y: &[f64],
        params: &SvrParams,
    ) -> Result<Self, RegressError> {
        params.validate()?;
        check_xy(x, y.len())?;
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(RegressError::NonFinite {
                what: "target",
                index: i,
            });
        }
        let rows = config::kernel_rows(
            x,
            params.gamma,
            params.solver_config.kernel_memory,
            params.solver_config.regressor_kernel,
        );
        let idx: Vec<usize> = (0..x.rows()).collect();
        let dual = solve_svr(
            rows.as_ref(),
            &idx,
            y,
            params.c,
            params.epsilon,
            None,
            &params.solver_config.smo,
        );
        Ok(Self::from_dual(x, &idx, &dual, *params))
    }

    pub(crate) fn from_dual(
        x: FeatureMatrixRef<'_>,
        idx: &[usize],
        dual: &SvrDual,
        params: SvrParams,
    ) -> Self {
        let keep: Vec<usize> = (0..idx.len()).filter(|&s| dual.coef[s] != 0.0).collect();
        let sv_rows: Vec<usize> = keep.iter().map(|&s| idx[s]).collect();
        let coef: Vec<f64> = keep.iter().map(|&s| dual.coef[s]).collect();
        Self {
            exp: Expansion::new(x.select(&sv_rows), coef, 1, params.gamma),
            rho: dual.rho,
            params,
            info: dual.info(),
        }
    }

    /// Predictions for every row of `x`.
    pub fn predict(&self, x: FeatureMatrixRef<'_>) -> Result<Vec<f64>, RegressError> {
        Ok(self
            .exp
            .eval(x)?
            .into_iter()
            .map(|s| s - self.rho)
            .collect())
    }

    /// Offset `rho` (libsvm sign convention: `f(x) = Σ coef K - rho`).
    pub fn rho(&self) -> f64 {
        self.rho
    }

    /// Dual coefficients `α_s - α*_s` of the support vectors.
    pub fn dual_coef(&self) -> &[f64] {
        &self.exp.coef
    }

    /// Support vectors (row-major).
    pub fn support_vectors(&self) -> FeatureMatrixRef<'_> {
        self.exp.sv.view()
    }

    /// Hyper-parameters used.
    pub fn params(&self) -> &SvrParams {
        &self.params
    }

    /// Solver statistics.
    pub fn info(&self) -> &FitInfo {
        &self.info
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cache::FullKernel;
    use crate::kernel;
    use crate::matrix::owned;

    #[test]
    fn fit_warm_started_from_another_epsilon_reaches_the_cold_solution() {
        let n = 120;
        let x: Vec<f32> = (0..n * 5).map(|k| ((k as f32) * 0.61).sin()).collect();
        let x = owned(x, 5);
        let y: Vec<f64> = (0..n).map(|i| (i as f64 * 0.1).cos()).collect();
        let full = FullKernel::new(x.view(), &kernel::sq_norms(x.view()), 0.3);
        let settings = SmoSettings {
            tol: 1e-6,
            ..SmoSettings::default()
        };
        // A fold-like subset, to exercise indexing into the shared kernel.
        let idx: Vec<usize> = (0..n).filter(|i| i % 3 != 0).collect();
        let ys: Vec<f64> = idx.iter().map(|&i| y[i]).collect();
        // The grid's chain: the same C, epsilon descending.
        let wide = solve_svr(&full, &idx, &ys, 10.0, 0.1, None, &settings);
        let cold = solve_svr(&full, &idx, &ys, 10.0, 0.01, None, &settings);
        let warm = solve_svr(&full, &idx, &ys, 10.0, 0.01, Some(wide.alpha), &settings);
        assert!(warm.converged && cold.converged);
        assert!((warm.obj - cold.obj).abs() < 1e-6 * cold.obj.abs().max(1.0));
        assert!((warm.rho - cold.rho).abs() < 1e-3);
        // The same function (the coefficients need not be unique).
        let decision = |d: &SvrDual, v: usize| -> f64 {
            let row = full.row(v);
            idx.iter()
                .zip(&d.coef)
                .map(|(&s, a)| a * row[s] as f64)
                .sum::<f64>()
                - d.rho
        };
        let worst = (0..n)
            .map(|v| (decision(&warm, v) - decision(&cold, v)).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-4, "largest decision value difference {worst}");
        assert!(
            warm.iterations < cold.iterations,
            "{} vs {}",
            warm.iterations,
            cold.iterations
        );
    }
}
