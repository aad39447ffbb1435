//! Kernel expansions `f_c(x) = Σ_s coef[s][c] K(sv_s, x)`: several decision functions sharing
//! one set of support vectors are evaluated with one kernel pass.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::RegressError;
use crate::kernel;
use crate::matrix::View as _;
use ridi_features::{FeatureMatrix, FeatureMatrixRef};

/// Queries per kernel block in batched evaluation: bounds the temporary kernel block to
/// `QUERY_BLOCK × n_sv` floats.
const QUERY_BLOCK: usize = 512;

/// Support vectors with `k` coefficient columns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ExpansionParts")]
pub(crate) struct Expansion {
    #[serde(with = "crate::matrix::stored")]
    pub sv: FeatureMatrix,
    /// Squared norms of the support vectors: recomputed when read, not stored.
    #[serde(skip)]
    pub norms: Vec<f32>,
    /// Row-major `n_sv × k`.
    pub coef: Vec<f64>,
    pub k: usize,
    pub gamma: f32,
}

/// [`Expansion`] as stored (the public serde form of [`Svr`](crate::Svr) and
/// [`Svc`](crate::Svc)), checked on the way in: evaluation indexes by its sizes.
#[derive(Deserialize)]
struct ExpansionParts {
    #[serde(with = "crate::matrix::stored")]
    sv: FeatureMatrix,
    coef: Vec<f64>,
    k: usize,
    gamma: f32,
}

impl TryFrom<ExpansionParts> for Expansion {
    type Error = RegressError;
    fn try_from(p: ExpansionParts) -> Result<Self, RegressError> {
        let bad = |m: &str| Err(RegressError::Decode(format!("support vectors: {m}")));
        if p.k == 0 || p.sv.rows().checked_mul(p.k) != Some(p.coef.len()) {
            return bad("one coefficient per support vector and column is needed");
        }
        if !p.sv.as_slice().iter().all(|v| v.is_finite()) || !p.coef.iter().all(|c| c.is_finite()) {
            return bad("non-finite value");
        }
        if !(p.gamma.is_finite() && p.gamma > 0.0) {
            return bad("the kernel width must be finite and positive");
        }
        Ok(Self::new(p.sv, p.coef, p.k, p.gamma))
    }
}

impl Expansion {
    pub(crate) fn new(sv: FeatureMatrix, coef: Vec<f64>, k: usize, gamma: f32) -> Self {
        let norms = kernel::sq_norms(sv.view());
        Self {
            sv,
            norms,
            coef,
            k,
            gamma,
        }
    }

    pub(crate) fn n_sv(&self) -> usize {
        self.sv.rows()
    }

    /// `m × k` sums (no offsets) for the query rows.
    pub(crate) fn eval(&self, q: FeatureMatrixRef<'_>) -> Result<Vec<f64>, RegressError> {
        if q.cols() != self.sv.cols() {
            return Err(RegressError::LengthMismatch {
                what: "query row",
                expected: self.sv.cols(),
                found: q.cols(),
            });
        }
        let (m, n, k) = (q.rows(), self.n_sv(), self.k);
        let mut out = vec![0.0f64; m * k];
        if n == 0 {
            return Ok(out);
        }
        let qn = kernel::sq_norms(q);
        let mut kbuf = vec![0.0f32; QUERY_BLOCK.min(m) * n];
        for (b, out_blk) in out.chunks_mut(QUERY_BLOCK * k).enumerate() {
            let r0 = b * QUERY_BLOCK;
            let rows = out_blk.len() / k;
            let qb = q.rows_range(r0, r0 + rows);
            let kb = &mut kbuf[..rows * n];
            kernel::cross_kernel(
                qb,
                &qn[r0..r0 + rows],
                self.sv.view(),
                &self.norms,
                self.gamma,
                kb,
            );
            weighted_sums(kb, &self.coef, k, out_blk);
        }
        Ok(out)
    }
}

/// `out (m × k) = kvals (m × n) · coef (n × k)`, accumulated in f64.
pub(crate) fn weighted_sums(kvals: &[f32], coef: &[f64], k: usize, out: &mut [f64]) {
    let m = out.len() / k.max(1);
    if m == 0 {
        return;
    }
    let n = kvals.len() / m;
    out.par_chunks_mut(k)
        .zip(kvals.par_chunks(n))
        .with_min_len(8)
        .for_each(|(o, kr)| {
            o.fill(0.0);
            for (s, &kv) in kr.iter().enumerate() {
                let kv = kv as f64;
                for c in 0..k {
                    o[c] += kv * coef[s * k + c];
                }
            }
        });
}
