//! A placement's stored samples, in half precision: the feature values themselves, or
//! principal-component coordinates ([`crate::projection`]; the leading ones split into
//! `hi + lo`) with each sample's exact residual.

use half::f16;
use serde::{Deserialize, Serialize};

use crate::error::RegressError;
use crate::f16mat::{F16_MAX, F16Matrix};
use crate::kernel;
use crate::projection::{Projection, SPLIT_LEAD};
use ridi_features::FeatureMatrixRef;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct SampleRows {
    /// Feature values, or coordinates in stored form `[hi_lead, lo_lead, rest]`.
    rows: F16Matrix,
    /// Projected samples: `|s − μ|² − |z_s|²` per row, what the coordinates leave out of the
    /// squared norm. `None`: the rows are the features.
    residual: Option<Vec<f32>>,
}

impl SampleRows {
    /// Rows `idx` of `x`, in the form `projection` calls for. Fails when a value to store
    /// is beyond the half-precision range (the caller checks the features themselves).
    pub(crate) fn from_rows(
        x: FeatureMatrixRef<'_>,
        idx: &[usize],
        projection: Option<&Projection>,
    ) -> Result<Self, RegressError> {
        let Some(p) = projection else {
            return Ok(Self {
                rows: F16Matrix::from_rows(x, idx),
                residual: None,
            });
        };
        let w = p.stored_dim();
        let mut stored = vec![0.0f32; idx.len() * w];
        let mut residual = Vec::with_capacity(idx.len());
        let mut buf = Vec::new();
        for (out, &i) in stored.chunks_exact_mut(w).zip(idx) {
            let norm = p.project_one(x.row(i), &mut buf, out);
            let z = &out[SPLIT_LEAD..];
            if let Some(j) = z.iter().position(|v| v.abs() > F16_MAX) {
                return Err(RegressError::BeyondHalfPrecision {
                    what: "principal coordinate",
                    value: z[j],
                    row: i,
                    column: SPLIT_LEAD + j,
                });
            }
            residual.push((norm - kernel::dot(z, z)).max(0.0));
            // `out[..SPLIT_LEAD]` rounds to `hi`; keep what that rounding loses as `lo`.
            for j in 0..SPLIT_LEAD {
                out[SPLIT_LEAD + j] = out[j] - f16::from_f32(out[j]).to_f32();
            }
        }
        let all: Vec<usize> = (0..idx.len()).collect();
        Ok(Self {
            rows: F16Matrix::from_rows(FeatureMatrixRef::trusted(&stored, w), &all),
            residual: Some(residual),
        })
    }

    pub(crate) fn rows(&self) -> usize {
        self.rows.rows()
    }

    /// Values per stored row.
    pub(crate) fn dim(&self) -> usize {
        self.rows.dim()
    }

    /// Whether the rows are projected coordinates.
    pub(crate) fn is_projected(&self) -> bool {
        self.residual.is_some()
    }

    /// Squared norms as the distances need them: of the rounded rows, or of the stored
    /// coordinates (`hi + lo` for the leading ones) plus the residual, which is `|s − μ|²` up
    /// to the rounding of the coordinates.
    pub(crate) fn norms(&self) -> Vec<f32> {
        let Some(residual) = &self.residual else {
            return self.rows.sq_norms();
        };
        let mut buf = Vec::new();
        (0..self.rows())
            .map(|i| {
                self.rows.rows_f32(i, i + 1, &mut buf);
                let (lead, rest) = buf.split_at_mut(SPLIT_LEAD);
                let (lo, rest) = rest.split_at(SPLIT_LEAD);
                lead.iter_mut().zip(lo).for_each(|(h, l)| *h += l);
                kernel::dot(lead, lead) + kernel::dot(rest, rest) + residual[i]
            })
            .collect()
    }

    /// Rows `r0..r1` widened to `f32` into `buf` (resized to fit).
    pub(crate) fn rows_f32(&self, r0: usize, r1: usize, buf: &mut Vec<f32>) {
        self.rows.rows_f32(r0, r1, buf)
    }

    /// `out[j] = q · row(r0 + j)`, `q` in stored form.
    pub(crate) fn dots(&self, q: &[f32], r0: usize, out: &mut [f32]) {
        self.rows.dots(q, r0, out)
    }

    /// Bytes of row `i` as stored (to match stored rows against training rows).
    pub(crate) fn row_bytes(&self, i: usize) -> Vec<u8> {
        self.rows
            .row_bits(i)
            .iter()
            .flat_map(|b| b.to_le_bytes())
            .collect()
    }

    /// Rejects values that are not finite and inconsistent sizes (the checksum does not catch
    /// a well-formed but wrong payload).
    pub(crate) fn check(&self) -> Result<(), RegressError> {
        self.rows.check()?;
        let Some(residual) = &self.residual else {
            return Ok(());
        };
        if residual.len() != self.rows() || self.dim() < 2 * SPLIT_LEAD {
            return Err(RegressError::Decode("projected sample sizes".into()));
        }
        if !residual.iter().all(|v| v.is_finite() && *v >= 0.0) {
            return Err(RegressError::Decode(
                "non-finite projected sample value".into(),
            ));
        }
        Ok(())
    }
}
