//! A plain row-major `f32` matrix, the exchange format between feature extraction and
//! regression.

use crate::FeatureError;

/// A contiguous row-major `rows x cols` matrix of `f32`: row `i` is
/// `data[i * cols..(i + 1) * cols]`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FeatureMatrix {
    rows: usize,
    cols: usize,
    data: Vec<f32>,
}

impl FeatureMatrix {
    /// A zero-filled matrix.
    pub fn zeros(rows: usize, cols: usize) -> Self {
        Self {
            rows,
            cols,
            data: vec![0.0; rows * cols],
        }
    }

    /// Wraps row-major data; fails unless `data.len() == rows * cols`.
    pub fn from_vec(rows: usize, cols: usize, data: Vec<f32>) -> Result<Self, FeatureError> {
        let expected = rows
            .checked_mul(cols)
            .ok_or(FeatureError::DimensionMismatch {
                expected: usize::MAX,
                found: data.len(),
            })?;
        if data.len() != expected {
            return Err(FeatureError::DimensionMismatch {
                expected,
                found: data.len(),
            });
        }
        Ok(Self { rows, cols, data })
    }

    /// Sets the shape, keeping the allocation; the values are unspecified until overwritten.
    pub(crate) fn reshape(&mut self, rows: usize, cols: usize) {
        self.data.resize(rows * cols, 0.0);
        self.rows = rows;
        self.cols = cols;
    }

    /// Number of rows (samples).
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of columns (feature dimension).
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// `true` without rows.
    pub fn is_empty(&self) -> bool {
        self.rows == 0
    }

    /// Row `i`.
    ///
    /// # Panics
    /// If `i >= rows`, like slice indexing.
    pub fn row(&self, i: usize) -> &[f32] {
        assert!(i < self.rows, "row {i} out of {} rows", self.rows);
        &self.data[i * self.cols..(i + 1) * self.cols]
    }

    /// Row `i`, mutable.
    ///
    /// # Panics
    /// If `i >= rows`.
    pub fn row_mut(&mut self, i: usize) -> &mut [f32] {
        assert!(i < self.rows, "row {i} out of {} rows", self.rows);
        &mut self.data[i * self.cols..(i + 1) * self.cols]
    }

    /// Iterator over the rows.
    pub fn iter_rows(&self) -> impl ExactSizeIterator<Item = &[f32]> + '_ {
        // chunks_exact(0) panics; a zero-column matrix has rows of nothing.
        let cols = self.cols.max(1);
        let n = if self.cols == 0 { 0 } else { self.rows };
        self.data.chunks_exact(cols).take(n)
    }

    /// All values, row-major.
    pub fn as_slice(&self) -> &[f32] {
        &self.data
    }

    /// All values, row-major, mutable.
    pub fn as_mut_slice(&mut self) -> &mut [f32] {
        &mut self.data
    }

    /// The row-major values.
    pub fn into_vec(self) -> Vec<f32> {
        self.data
    }

    /// Appends the rows of `other` (same column count), e.g. to pool sequences for training.
    pub fn append(&mut self, other: &FeatureMatrix) -> Result<(), FeatureError> {
        if self.rows == 0 && self.data.is_empty() {
            self.cols = other.cols;
        }
        if other.cols != self.cols {
            return Err(FeatureError::DimensionMismatch {
                expected: self.cols,
                found: other.cols,
            });
        }
        self.data.extend_from_slice(&other.data);
        self.rows += other.rows;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_rows_and_append() {
        let m = FeatureMatrix::from_vec(2, 3, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
        assert_eq!(m.row(1), &[4.0, 5.0, 6.0]);
        assert_eq!(m.iter_rows().count(), 2);
        assert!(FeatureMatrix::from_vec(2, 3, vec![0.0; 5]).is_err());
        let mut all = FeatureMatrix::default();
        all.append(&m).unwrap();
        all.append(&m).unwrap();
        assert_eq!((all.rows(), all.cols()), (4, 3));
        assert_eq!(all.row(3), &[4.0, 5.0, 6.0]);
        assert!(all.append(&FeatureMatrix::zeros(1, 2)).is_err());
        let empty_cols = FeatureMatrix::zeros(3, 0);
        assert_eq!(empty_cols.iter_rows().count(), 0);
    }
}
