//! A placement's stored samples, in one of two forms: every feature value in half precision,
//! or principal-component coordinates ([`crate::projection`]: the leading ones in `f32`, the
//! others in half precision) with each sample's exact residual.

use serde::{Deserialize, Serialize};

use crate::error::RegressError;
use crate::f16mat::F16Matrix;
use crate::kernel;
use crate::matrix::{Matrix, MatrixRef};
use crate::projection::{F32_LEAD, Projection};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) enum SampleRows {
    Half(F16Matrix),
    Projected {
        /// `rows × F32_LEAD` leading coordinates.
        lead: Matrix,
        /// `rows × (k − F32_LEAD)` further coordinates.
        rest: F16Matrix,
        /// `|s − μ|² − |z_s|²` per row: what the coordinates leave out of the squared norm.
        residual: Vec<f32>,
    },
}

impl SampleRows {
    /// Rows `idx` of `x`, in the form `projection` calls for.
    pub(crate) fn from_rows(
        x: MatrixRef<'_>,
        idx: &[usize],
        projection: Option<&Projection>,
    ) -> Self {
        let Some(p) = projection else {
            return Self::Half(F16Matrix::from_rows(x, idx));
        };
        let k = p.dim();
        let mut coords = vec![0.0f32; idx.len() * k];
        let mut residual = Vec::with_capacity(idx.len());
        let mut buf = Vec::new();
        for (z, &i) in coords.chunks_exact_mut(k).zip(idx) {
            let norm = p.project_one(x.row(i), &mut buf, z);
            residual.push((norm - kernel::dot(z, z)).max(0.0));
        }
        let lead: Vec<f32> = coords
            .chunks_exact(k)
            .flat_map(|z| &z[..F32_LEAD])
            .copied()
            .collect();
        let rest: Vec<f32> = coords
            .chunks_exact(k)
            .flat_map(|z| &z[F32_LEAD..])
            .copied()
            .collect();
        let all: Vec<usize> = (0..idx.len()).collect();
        Self::Projected {
            lead: Matrix::from_parts(lead, F32_LEAD),
            rest: F16Matrix::from_rows(MatrixRef::trusted(&rest, k - F32_LEAD), &all),
            residual,
        }
    }

    pub(crate) fn rows(&self) -> usize {
        match self {
            Self::Half(m) => m.rows(),
            Self::Projected { residual, .. } => residual.len(),
        }
    }

    /// Values per stored row.
    pub(crate) fn dim(&self) -> usize {
        match self {
            Self::Half(m) => m.dim(),
            Self::Projected { lead, rest, .. } => lead.dim() + rest.dim(),
        }
    }

    /// Squared norms as the distances need them: of the rounded rows, or of the stored
    /// coordinates plus the residual (`|s − μ|²` up to the rounding of the coordinates).
    pub(crate) fn norms(&self) -> Vec<f32> {
        match self {
            Self::Half(m) => m.sq_norms(),
            Self::Projected {
                lead,
                rest,
                residual,
            } => rest
                .sq_norms()
                .iter()
                .enumerate()
                .map(|(i, r)| kernel::dot(lead.row(i), lead.row(i)) + r + residual[i])
                .collect(),
        }
    }

    /// Rows `r0..r1` as `f32` (widened into `buf`, or borrowed).
    pub(crate) fn rows_f32<'a>(&'a self, r0: usize, r1: usize, buf: &'a mut Vec<f32>) -> &'a [f32] {
        match self {
            Self::Half(m) => {
                m.rows_f32(r0, r1, buf);
                buf
            }
            Self::Projected { lead, rest, .. } => {
                let mut wide = Vec::new();
                rest.rows_f32(r0, r1, &mut wide);
                let k = self.dim();
                buf.resize((r1 - r0) * k, 0.0);
                for (i, row) in buf.chunks_exact_mut(k).enumerate() {
                    row[..F32_LEAD].copy_from_slice(lead.row(r0 + i));
                    row[F32_LEAD..]
                        .copy_from_slice(&wide[i * (k - F32_LEAD)..(i + 1) * (k - F32_LEAD)]);
                }
                buf
            }
        }
    }

    /// `out[j] = q · row(r0 + j)`.
    pub(crate) fn dots(&self, q: &[f32], r0: usize, out: &mut [f32]) {
        match self {
            Self::Half(m) => m.dots(q, r0, out),
            Self::Projected { lead, rest, .. } => {
                let (ql, qr) = q.split_at(F32_LEAD);
                rest.dots(qr, r0, out);
                for (j, o) in out.iter_mut().enumerate() {
                    *o += kernel::dot(ql, lead.row(r0 + j));
                }
            }
        }
    }

    /// Bytes of row `i` as stored (to match stored rows against training rows).
    pub(crate) fn row_bytes(&self, i: usize) -> Vec<u8> {
        match self {
            Self::Half(m) => m.row_bits(i).iter().flat_map(|b| b.to_le_bytes()).collect(),
            Self::Projected { lead, rest, .. } => lead
                .row(i)
                .iter()
                .flat_map(|v| v.to_le_bytes())
                .chain(rest.row_bits(i).iter().flat_map(|b| b.to_le_bytes()))
                .collect(),
        }
    }

    /// Rejects values that are not finite and inconsistent sizes (the checksum does not catch
    /// a well-formed but wrong payload).
    pub(crate) fn check(&self) -> Result<(), RegressError> {
        match self {
            Self::Half(m) => m.check(),
            Self::Projected {
                lead,
                rest,
                residual,
            } => {
                rest.check()?;
                if lead.dim() != F32_LEAD
                    || rest.dim() == 0
                    || lead.rows() != residual.len()
                    || rest.rows() != residual.len()
                {
                    return Err(RegressError::Decode("projected sample sizes".into()));
                }
                if !lead.as_slice().iter().all(|v| v.is_finite())
                    || !residual.iter().all(|v| v.is_finite() && *v >= 0.0)
                {
                    return Err(RegressError::Decode(
                        "non-finite projected sample value".into(),
                    ));
                }
                Ok(())
            }
        }
    }
}
