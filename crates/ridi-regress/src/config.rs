//! Solver configuration shared by the SVR, the classifier, the cascade and the grid search.

use serde::{Deserialize, Serialize};

use crate::cache::{CachedKernel, FullKernel, KernelRows};
use crate::kernel;
use crate::smo::SmoSettings;
use ridi_features::FeatureMatrixRef;

/// When to precompute a full kernel matrix instead of caching rows on demand.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Precompute {
    /// Full matrix whenever it fits in [`SolverConfig::kernel_memory`] (one parallel GEMM;
    /// best when most samples end up as support vectors, as in epsilon-SVR with small epsilon).
    Auto,
    /// Always rows on demand (best when few samples become support vectors).
    Never,
}

/// Settings of one training run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SolverConfig {
    /// SMO stopping and shrinking.
    pub smo: SmoSettings,
    /// Memory cap in bytes for kernel values (full matrix or row cache) of one class / class
    /// pair. Default 2 GiB.
    pub kernel_memory: u64,
    /// Kernel strategy of the regressors.
    pub regressor_kernel: Precompute,
    /// Kernel strategy of the classifier.
    pub classifier_kernel: Precompute,
}

impl Default for SolverConfig {
    fn default() -> Self {
        Self {
            smo: SmoSettings::default(),
            kernel_memory: 2 << 30,
            regressor_kernel: Precompute::Auto,
            classifier_kernel: Precompute::Never,
        }
    }
}

/// Builds the kernel row provider for `x` under the memory cap.
pub(crate) fn kernel_rows<'x>(
    x: FeatureMatrixRef<'x>,
    gamma: f32,
    memory: u64,
    strategy: Precompute,
) -> Box<dyn KernelRows + 'x> {
    if strategy == Precompute::Auto && FullKernel::bytes_for(x.rows()) <= memory {
        let norms = kernel::sq_norms(x);
        Box::new(FullKernel::new(x, &norms, gamma))
    } else {
        Box::new(CachedKernel::new(x, gamma, memory))
    }
}
