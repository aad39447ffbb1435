//! Row-major `f32` sample matrices (one feature vector per row).

use serde::{Deserialize, Serialize};

use crate::error::RegressError;

/// Borrowed row-major matrix: `rows × dim` values, row `i` at `data[i*dim..(i+1)*dim]`.
#[derive(Debug, Clone, Copy)]
pub struct MatrixRef<'a> {
    data: &'a [f32],
    dim: usize,
}

impl<'a> MatrixRef<'a> {
    /// Wraps `data` as rows of `dim` values; `data.len()` must be a multiple of `dim` and
    /// every value finite (the solver has no meaningful answer for NaN or infinity).
    pub fn new(data: &'a [f32], dim: usize) -> Result<Self, RegressError> {
        if dim == 0 || !data.len().is_multiple_of(dim) {
            return Err(RegressError::Shape(format!(
                "{} values do not form rows of {dim}",
                data.len()
            )));
        }
        if let Some(pos) = data.iter().position(|v| !v.is_finite()) {
            return Err(RegressError::NonFinite(format!(
                "feature value at row {}, column {}",
                pos / dim,
                pos % dim
            )));
        }
        Ok(Self { data, dim })
    }

    /// Wraps values known to be finite whole rows (no scan, for hot paths).
    pub(crate) fn trusted(data: &'a [f32], dim: usize) -> Self {
        debug_assert!(dim > 0 && data.len().is_multiple_of(dim));
        Self { data, dim }
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.data.len() / self.dim
    }

    /// Rows `r0..r1` (no re-validation: the parent was validated).
    ///
    /// # Panics
    /// If `r0 > r1` or `r1 > self.rows()`, as slicing would.
    pub fn rows_range(&self, r0: usize, r1: usize) -> MatrixRef<'a> {
        MatrixRef {
            data: &self.data[r0 * self.dim..r1 * self.dim],
            dim: self.dim,
        }
    }

    /// Number of values per row.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Row `i`.
    pub fn row(&self, i: usize) -> &'a [f32] {
        &self.data[i * self.dim..(i + 1) * self.dim]
    }

    /// All values, row-major.
    pub fn as_slice(&self) -> &'a [f32] {
        self.data
    }

    /// Copies the rows listed in `idx` (in that order) into an owned matrix.
    pub fn select(&self, idx: &[usize]) -> Matrix {
        let mut data = Vec::with_capacity(idx.len() * self.dim);
        for &i in idx {
            data.extend_from_slice(self.row(i));
        }
        Matrix {
            data,
            dim: self.dim,
        }
    }
}

/// Borrows a feature matrix of ridi-features (the features [`crate::TrainingSet`] and
/// [`crate::Cascade::predict`] take), with the checks of [`MatrixRef::new`].
impl<'a> TryFrom<&'a ridi_features::FeatureMatrix> for MatrixRef<'a> {
    type Error = RegressError;

    fn try_from(m: &'a ridi_features::FeatureMatrix) -> Result<Self, RegressError> {
        MatrixRef::new(m.as_slice(), m.cols())
    }
}

/// Owned row-major `f32` matrix.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Matrix {
    data: Vec<f32>,
    dim: usize,
}

impl Matrix {
    /// Takes ownership of `data` as rows of `dim` values (same checks as [`MatrixRef::new`]).
    pub fn new(data: Vec<f32>, dim: usize) -> Result<Self, RegressError> {
        MatrixRef::new(&data, dim)?;
        Ok(Self { data, dim })
    }

    /// Takes values known to be finite whole rows (no scan, for hot paths).
    pub(crate) fn from_parts(data: Vec<f32>, dim: usize) -> Self {
        debug_assert!(dim > 0 && data.len().is_multiple_of(dim));
        Self { data, dim }
    }

    /// Borrowed view.
    pub fn view(&self) -> MatrixRef<'_> {
        MatrixRef {
            data: &self.data,
            dim: self.dim,
        }
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.data.len().checked_div(self.dim).unwrap_or(0)
    }

    /// Number of values per row.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Row `i`.
    pub fn row(&self, i: usize) -> &[f32] {
        &self.data[i * self.dim..(i + 1) * self.dim]
    }

    /// All values, row-major.
    pub fn as_slice(&self) -> &[f32] {
        &self.data
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ridi_features::FeatureMatrix;

    #[test]
    fn borrows_a_feature_matrix_with_the_same_checks() {
        let m = FeatureMatrix::from_vec(2, 3, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
        let r = MatrixRef::try_from(&m).unwrap();
        assert_eq!((r.rows(), r.dim()), (2, 3));
        assert_eq!(r.row(1), &[4.0, 5.0, 6.0]);
        let bad = FeatureMatrix::from_vec(1, 2, vec![1.0, f32::NAN]).unwrap();
        assert!(matches!(
            MatrixRef::try_from(&bad),
            Err(RegressError::NonFinite(_))
        ));
    }
}
