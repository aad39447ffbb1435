//! What the cascade is trained with: the kernel widths, the regressors' hyper-parameters, the
//! sample storage and the solver settings.

use serde::{Deserialize, Serialize};

use crate::config::SolverConfig;
use crate::error::RegressError;
use crate::grid::GridSpec;
use crate::nystrom::Solver;
use ridi_features::FeatureMatrixRef;

/// How the RBF width is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Gamma {
    /// `1 / dim` (the paper's 1/1200).
    InverseDim,
    /// `1 / (dim · var(X))` over all training feature values (scikit-learn's `"scale"`;
    /// equals `1 / dim` on standardized features).
    Scale,
    /// A fixed value.
    Value(f32),
}

impl Gamma {
    /// The width for training features `x`.
    pub(super) fn resolve(self, x: FeatureMatrixRef<'_>) -> Result<f32, RegressError> {
        let d = x.cols() as f64;
        let g = match self {
            Gamma::InverseDim => 1.0 / d,
            Gamma::Value(g) => g as f64,
            Gamma::Scale => {
                let v = x.as_slice();
                let n = v.len() as f64;
                let mean = v.iter().map(|&a| a as f64).sum::<f64>() / n;
                let var = v.iter().map(|&a| (a as f64 - mean).powi(2)).sum::<f64>() / n;
                if var > 0.0 { 1.0 / (d * var) } else { 1.0 / d }
            }
        };
        let g = g as f32;
        if !(g.is_finite() && g > 0.0) {
            return Err(RegressError::InvalidParam(format!("gamma {g}")));
        }
        Ok(g)
    }
}

/// How a trained model stores its samples for prediction.
///
/// A query streams every stored sample it needs, so its time is set by their bytes. RIDI's
/// features are Gaussian-smoothed windows whose variance lies almost entirely in a few hundred
/// of the 1200 directions. Writing a sample as `μ + Uᵀz + r` (`U`: the leading principal
/// directions of the training features, `r`: the residual),
/// `|a − b|² = |a − μ|² + |b − μ|² − 2 z_a·z_b − 2 r_a·r_b`; a projected model keeps `z` and
/// the exact `|s − μ|²` of each sample, so every distance is right except for the product of
/// two small residuals. [`Cascade::rounding_effect`](crate::Cascade::rounding_effect)
/// measures what either storage changes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Storage {
    /// Every feature value in half precision.
    Half,
    /// Coordinates on the leading principal directions of the training features that hold at
    /// least `energy` of their variance (at least 64, in half precision; the 32 largest as two
    /// half-precision values, `hi + lo`), plus each sample's exact residual norm. Falls back
    /// to [`Storage::Half`] when that would not halve the bytes (features without
    /// low-dimensional structure, or fewer than 192 values per row).
    Projected {
        /// Share of the variance to keep, in `(0, 1]`.
        energy: f64,
    },
}

impl Storage {
    /// The default: [`Storage::Projected`] keeping 99.99 % of the variance (304 of 1200
    /// directions on standardized Tyrex features; the velocity moves by about as much as
    /// half-precision rounding moves it, measured in docs/benchmarks.md). At 99.95 % (256
    /// directions) the largest change was 3-6x that of half precision.
    pub const DEFAULT: Self = Self::Projected { energy: 0.9999 };

    /// The default of the Nyström solver: [`Storage::Projected`] keeping 90 % of the variance
    /// (64 of 1200 directions on standardized Tyrex features, 91 %). A Nyström machine computes
    /// its distances from these coordinates (and each row's exact norm) in training too, so
    /// for it they shape the kernel, not only the rounding of a trained model. The residual
    /// then holds about a tenth of the variance, and the distances are no longer exact up to a
    /// small product; measured on the leave-one-person-out protocol over both Tyrex phones, no
    /// figure got worse beyond its interval against 99.99 % (velocity MSE S-x got better),
    /// and a query streams a quarter of the bytes (docs/benchmarks.md). Not
    /// [`Storage::default`]: a library user who picks [`Solver::Nystrom`] picks it too, with
    /// [`Storage::projected_for`].
    pub const NYSTROM_DEFAULT: Self = Self::Projected { energy: 0.9 };

    /// The projected storage ridi uses with `solver`: [`Storage::NYSTROM_DEFAULT`] for
    /// [`Solver::Nystrom`], [`Storage::DEFAULT`] for the exact solver (whose machines see the
    /// features themselves; the projection only stores them).
    pub fn projected_for(solver: &Solver) -> Self {
        match solver {
            Solver::Exact => Self::DEFAULT,
            Solver::Nystrom(_) => Self::NYSTROM_DEFAULT,
        }
    }
}

impl Default for Storage {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Hyper-parameters of the regressors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum RegressorChoice {
    /// The same `C` and epsilon for every placement and channel.
    Fixed {
        /// Box constraint.
        c: f64,
        /// Tube width.
        epsilon: f64,
    },
    /// Cross-validated grid search per placement and channel (lowest mean fold MSE).
    Grid(GridSpec),
}

/// Training settings of the cascade. [`Default`] is the paper with its regressor grid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CascadeParams {
    /// Classifier `C` (paper: 10).
    pub classifier_c: f64,
    /// Classifier RBF width.
    pub classifier_gamma: Gamma,
    /// Regressor RBF width.
    pub regressor_gamma: Gamma,
    /// Regressor `C` / epsilon selection.
    pub regressors: RegressorChoice,
    /// Exact kernel machines (SMO, the default) or their Nyström approximation (linear
    /// machines on features of shared landmarks; [`Solver::Nystrom`]): `ridi train --solver`.
    /// Both take the same `C`, epsilon, RBF widths and grid.
    pub solver: Solver,
    /// How the solver runs: the SMO's stop and shrinking (the Nyström solver's linear machines
    /// stop by its shrinking and iteration cap too), and the exact solver's kernel memory and
    /// strategy.
    pub solver_config: SolverConfig,
    /// Placements with fewer training samples are rejected with
    /// [`RegressError::NotEnoughData`] (default 10).
    pub min_class_samples: usize,
    /// Sample storage of the trained model (prediction speed against a small, measured
    /// change of the predictions); with [`Solver::Nystrom`] also the input of its kernel
    /// ([`Storage::projected_for`] gives ridi's choice per solver).
    pub storage: Storage,
    /// Also regress the speed `|v|` per placement (a third epsilon-SVR on the same kernel)
    /// and scale each regressed velocity to it
    /// ([`Prediction::velocity`](crate::Prediction::velocity)). Not in the paper: where the
    /// heading of the phone relative to the walk is uncertain (training on turned windows),
    /// the two velocity components shrink towards zero while the speed, which does
    /// not depend on the heading, does not.
    pub speed: bool,
}

impl CascadeParams {
    /// Seeds the random draws of training: the grid's sequence-to-fold shuffle
    /// ([`GridSpec::seed`]) and, with the Nyström solver ([`Nystrom::seed`](crate::Nystrom::seed)),
    /// its landmarks and the order of its linear classifier's sweeps; 0 by default. Set it after [`Self::regressors`] and [`Self::solver`]. Models trained
    /// with other seeds show how much a figure owes to these draws.
    pub fn set_seed(&mut self, seed: u64) {
        if let RegressorChoice::Grid(g) = &mut self.regressors {
            g.seed = seed;
        }
        if let Solver::Nystrom(n) = &mut self.solver {
            n.reseed(seed);
        }
    }
}

impl Default for CascadeParams {
    fn default() -> Self {
        Self {
            classifier_c: 10.0,
            classifier_gamma: Gamma::InverseDim,
            regressor_gamma: Gamma::InverseDim,
            regressors: RegressorChoice::Grid(GridSpec::default()),
            solver: Solver::Exact,
            solver_config: SolverConfig::default(),
            min_class_samples: 10,
            storage: Storage::DEFAULT,
            speed: false,
        }
    }
}
