//! C-SVC with an RBF kernel: binary problems and one-vs-one multi-class voting (libsvm's
//! scheme: pair `(a, b)`, `a < b`, votes for `a` when its decision value is positive).

use serde::{Deserialize, Serialize};

use crate::cache::FullKernel;
use crate::cache::KernelRows;
use crate::config::{self, Precompute, SolverConfig};
use crate::error::RegressError;
use crate::expansion::Expansion;
use crate::matrix::View as _;
use crate::smo::{self, SmoProblem, SmoSettings};
use crate::svr::{FitInfo, check_c_gamma, check_smo, check_xy};
use ridi_features::FeatureMatrixRef;

/// Hyper-parameters of the classifier.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SvcParams {
    /// Box constraint `C > 0` (paper: 10).
    pub c: f64,
    /// RBF width (paper: 1/1200).
    pub gamma: f32,
    /// Solver settings.
    pub solver_config: SolverConfig,
}

impl SvcParams {
    /// Parameters with default solver settings.
    pub fn new(c: f64, gamma: f32) -> Self {
        Self {
            c,
            gamma,
            solver_config: SolverConfig::default(),
        }
    }

    pub(crate) fn validate(&self) -> Result<(), RegressError> {
        check_c_gamma(self.c, self.gamma)?;
        check_smo(&self.solver_config.smo)
    }
}

/// Dual solution of one binary problem over base samples `idx`.
#[derive(Debug, Clone)]
pub(crate) struct BinaryDual {
    /// `y_s α_s` for every sample of the subset.
    pub coef: Vec<f64>,
    pub rho: f64,
    pub obj: f64,
    pub iterations: usize,
    pub converged: bool,
}

impl BinaryDual {
    fn info(&self) -> FitInfo {
        FitInfo {
            iterations: self.iterations,
            objective: self.obj,
            converged: self.converged,
            n_support: self.coef.iter().filter(|c| **c != 0.0).count(),
        }
    }
}

/// Solves the C-SVC dual on base samples `idx`; `positive[s]` gives the label of `idx[s]`.
pub(crate) fn solve_binary(
    rows: &dyn KernelRows,
    idx: &[usize],
    positive: &[bool],
    c: f64,
    settings: &SmoSettings,
) -> BinaryDual {
    let y: Vec<f64> = positive
        .iter()
        .map(|&p| if p { 1.0 } else { -1.0 })
        .collect();
    let sol = smo::solve(
        rows,
        SmoProblem {
            kidx: idx.iter().map(|&i| i as u32).collect(),
            y: y.clone(),
            p: vec![-1.0; idx.len()],
            c,
            alpha0: None,
        },
        settings,
    );
    BinaryDual {
        coef: sol.alpha.iter().zip(&y).map(|(a, y)| a * y).collect(),
        rho: sol.rho,
        obj: sol.obj,
        iterations: sol.iterations,
        converged: sol.converged,
    }
}

/// One fitted pair of a one-vs-one classifier, in global sample indices.
#[derive(Debug, Clone)]
pub(crate) struct PairDual {
    pub a: usize,
    pub b: usize,
    /// Global indices of the support vectors and their coefficients `y α`.
    pub sv: Vec<usize>,
    pub coef: Vec<f64>,
    pub rho: f64,
    pub info: FitInfo,
}

/// Fits all `k (k-1) / 2` pairs. `class_of[i] < k` is the class of sample `i`.
/// `on_pair(done, total)` is called after each pair and may cancel by returning `false`.
pub(crate) fn fit_ovo(
    x: FeatureMatrixRef<'_>,
    class_of: &[usize],
    k: usize,
    params: &SvcParams,
    on_pair: &mut dyn FnMut(usize, usize) -> bool,
) -> Result<Vec<PairDual>, RegressError> {
    if k > Svc::MAX_CLASSES {
        return Err(RegressError::InvalidParam(format!(
            "{k} classes: a one-vs-one classifier fits a machine per pair of them, at most {} \
             classes",
            Svc::MAX_CLASSES
        )));
    }
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); k];
    for (i, &c) in class_of.iter().enumerate() {
        members[c].push(i);
    }
    if let Some(c) = members.iter().position(|m| m.is_empty()) {
        return Err(RegressError::NotEnoughData(format!(
            "class {c} has no training samples"
        )));
    }
    let cfg = &params.solver_config;
    // One kernel for all pairs when it fits; otherwise one per pair over the pair's samples.
    let shared: Option<FullKernel> = (cfg.classifier_kernel == Precompute::Auto
        && FullKernel::bytes_for(x.rows()) <= cfg.kernel_memory)
        .then(|| FullKernel::new(x, &crate::kernel::sq_norms(x), params.gamma));
    let total = k * (k - 1) / 2;
    let mut out = Vec::with_capacity(total);
    for a in 0..k {
        for b in a + 1..k {
            let global: Vec<usize> = members[a].iter().chain(&members[b]).copied().collect();
            let positive: Vec<bool> = global.iter().map(|&i| class_of[i] == a).collect();
            let dual = match &shared {
                Some(full) => solve_binary(full, &global, &positive, params.c, &cfg.smo),
                None => {
                    let xs = x.select(&global);
                    let rows = config::kernel_rows(
                        xs.view(),
                        params.gamma,
                        cfg.kernel_memory,
                        cfg.classifier_kernel,
                    );
                    let local: Vec<usize> = (0..global.len()).collect();
                    solve_binary(rows.as_ref(), &local, &positive, params.c, &cfg.smo)
                }
            };
            let keep: Vec<usize> = (0..global.len()).filter(|&s| dual.coef[s] != 0.0).collect();
            out.push(PairDual {
                a,
                b,
                sv: keep.iter().map(|&s| global[s]).collect(),
                coef: keep.iter().map(|&s| dual.coef[s]).collect(),
                rho: dual.rho,
                info: dual.info(),
            });
            if !on_pair(out.len(), total) {
                return Err(RegressError::Cancelled);
            }
        }
    }
    Ok(out)
}

/// One-vs-one votes from pair decision values (`dec[p]` for pair `p` in `(a, b)` order);
/// ties go to the lowest class index, as in libsvm.
pub(crate) fn vote(dec: &[f64], pairs: &[(u32, u32)], k: usize, votes: &mut [u32]) -> usize {
    votes[..k].fill(0);
    for (&d, &(a, b)) in dec.iter().zip(pairs) {
        votes[if d > 0.0 { a } else { b } as usize] += 1;
    }
    let mut best = 0;
    for c in 1..k {
        if votes[c] > votes[best] {
            best = c;
        }
    }
    best
}

/// Trained multi-class (or binary) C-SVC over integer labels. Its serde form is checked when
/// read (labels, pairs, sizes, finite values), so a deserialized one predicts or was refused.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "SvcParts")]
pub struct Svc {
    /// Sorted distinct labels; class index `c` stands for `labels[c]`.
    pub(crate) labels: Vec<usize>,
    pub(crate) pairs: Vec<(u32, u32)>,
    /// Union of the support vectors, one coefficient column per pair.
    pub(crate) exp: Expansion,
    pub(crate) rho: Vec<f64>,
    pub(crate) params: SvcParams,
    pub(crate) info: Vec<FitInfo>,
}

/// [`Svc`] as stored, checked on the way in: voting indexes by its pairs.
#[derive(Deserialize)]
struct SvcParts {
    labels: Vec<usize>,
    pairs: Vec<(u32, u32)>,
    exp: Expansion,
    rho: Vec<f64>,
    params: SvcParams,
    info: Vec<FitInfo>,
}

impl TryFrom<SvcParts> for Svc {
    type Error = RegressError;
    fn try_from(p: SvcParts) -> Result<Self, RegressError> {
        let k = p.labels.len();
        let consistent = (2..=Svc::MAX_CLASSES).contains(&k)
            && p.labels.windows(2).all(|w| w[0] < w[1])
            && p.pairs.len() == k * (k - 1) / 2
            && p.pairs.iter().all(|&(a, b)| a < b && (b as usize) < k)
            && p.rho.len() == p.pairs.len()
            && p.rho.iter().all(|r| r.is_finite())
            && p.exp.k == p.pairs.len();
        if !consistent {
            return Err(RegressError::Decode(
                "SVC: labels, class pairs, offsets and coefficient columns disagree".into(),
            ));
        }
        Ok(Self {
            labels: p.labels,
            pairs: p.pairs,
            exp: p.exp,
            rho: p.rho,
            params: p.params,
            info: p.info,
        })
    }
}

impl Svc {
    /// Most distinct labels a classifier is trained for: one-vs-one fits `k (k - 1) / 2`
    /// machines, 499,500 at this bound (a placement classifier has a handful).
    pub const MAX_CLASSES: usize = 1000;

    /// Trains on rows of `x` with labels `y` (at least two distinct labels, at most
    /// [`Svc::MAX_CLASSES`]).
    pub fn fit(
        x: FeatureMatrixRef<'_>,
        y: &[usize],
        params: &SvcParams,
    ) -> Result<Self, RegressError> {
        params.validate()?;
        check_xy(x, y.len())?;
        let mut labels = y.to_vec();
        labels.sort_unstable();
        labels.dedup();
        if labels.len() < 2 {
            return Err(RegressError::NotEnoughData(
                "classification needs at least two distinct labels".into(),
            ));
        }
        let class_of: Vec<usize> = y
            .iter()
            .map(|l| labels.binary_search(l).unwrap_or(0))
            .collect();
        let duals = fit_ovo(x, &class_of, labels.len(), params, &mut |_, _| true)?;
        Ok(Self::from_pairs(x, labels, &duals, *params))
    }

    pub(crate) fn from_pairs(
        x: FeatureMatrixRef<'_>,
        labels: Vec<usize>,
        duals: &[PairDual],
        params: SvcParams,
    ) -> Self {
        let mut union: Vec<usize> = duals.iter().flat_map(|d| d.sv.iter().copied()).collect();
        union.sort_unstable();
        union.dedup();
        let np = duals.len();
        let mut coef = vec![0.0; union.len() * np];
        for (p, d) in duals.iter().enumerate() {
            for (&g, &c) in d.sv.iter().zip(&d.coef) {
                if let Ok(u) = union.binary_search(&g) {
                    coef[u * np + p] = c;
                }
            }
        }
        Self {
            labels,
            pairs: duals.iter().map(|d| (d.a as u32, d.b as u32)).collect(),
            exp: Expansion::new(x.select(&union), coef, np, params.gamma),
            rho: duals.iter().map(|d| d.rho).collect(),
            params,
            info: duals.iter().map(|d| d.info).collect(),
        }
    }

    /// Decision values, `rows × pairs` row-major, pairs in `(0,1), (0,2), …, (k-2,k-1)` order;
    /// positive favours the first class of the pair.
    pub fn decision_function(&self, x: FeatureMatrixRef<'_>) -> Result<Vec<f64>, RegressError> {
        let mut d = self.exp.eval(x)?;
        let np = self.pairs.len();
        for row in d.chunks_mut(np) {
            for (v, r) in row.iter_mut().zip(&self.rho) {
                *v -= r;
            }
        }
        Ok(d)
    }

    /// Predicted labels.
    pub fn predict(&self, x: FeatureMatrixRef<'_>) -> Result<Vec<usize>, RegressError> {
        let d = self.decision_function(x)?;
        let k = self.labels.len();
        let mut votes = vec![0u32; k];
        Ok(d.chunks(self.pairs.len())
            .map(|row| self.labels[vote(row, &self.pairs, k, &mut votes)])
            .collect())
    }

    /// Distinct labels in class-index order.
    pub fn labels(&self) -> &[usize] {
        &self.labels
    }

    /// Offsets `rho` per pair.
    pub fn rho(&self) -> &[f64] {
        &self.rho
    }

    /// Union of the support vectors of all pairs (row-major).
    pub fn support_vectors(&self) -> FeatureMatrixRef<'_> {
        self.exp.sv.view()
    }

    /// Coefficients `y α`, `n_support × pairs` row-major (zero where a support vector does
    /// not belong to a pair).
    pub fn dual_coef(&self) -> &[f64] {
        &self.exp.coef
    }

    /// Number of distinct support vectors over all pairs.
    pub fn n_support(&self) -> usize {
        self.exp.n_sv()
    }

    /// Solver statistics per pair.
    pub fn info(&self) -> &[FitInfo] {
        &self.info
    }
}
