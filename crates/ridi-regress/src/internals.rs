//! What this crate's benches and timing examples measure or reuse beyond the public API,
//! behind the feature `bench-internals` (off by default; the crate's dev-dependency on itself
//! turns it on for its own benches, examples and tests). Not a supported API: it follows the
//! internals it wraps.

use crate::error::RegressError;
use ridi_features::FeatureMatrixRef;

/// Squared Euclidean norm of every row, as [`gram`] takes them.
pub fn sq_norms(x: FeatureMatrixRef<'_>) -> Vec<f32> {
    crate::kernel::sq_norms(x)
}

/// The full RBF kernel matrix of `x` (row-major `n × n`) from the squared norms of its rows:
/// what a precomputed kernel costs.
pub fn gram(x: FeatureMatrixRef<'_>, norms: &[f32], gamma: f32) -> Vec<f32> {
    crate::kernel::gram(x, norms, gamma)
}

/// The cross-validation folds of a grid search over samples of the sequences `groups`: the
/// fold of every sample and the number of folds (so that another implementation can be scored
/// on the same splits).
pub fn assign_folds(
    groups: &[u64],
    folds: usize,
    seed: u64,
) -> Result<(Vec<usize>, usize), RegressError> {
    crate::grid::assign_folds(groups, folds, seed)
}
