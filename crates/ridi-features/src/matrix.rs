//! The row-major `f32` matrix of the workspace, owned ([`FeatureMatrix`]) and borrowed
//! ([`FeatureMatrixRef`]): what feature extraction fills and the regressors of `ridi-regress`
//! take (faer's `Mat` / `MatRef` pair, without faer).

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
    ///
    /// # Panics
    /// If `rows * cols` overflows `usize` (no allocation could hold it; unchecked, it would
    /// wrap into a matrix smaller than its shape).
    pub fn zeros(rows: usize, cols: usize) -> Self {
        let len = rows
            .checked_mul(cols)
            .expect("FeatureMatrix::zeros: rows * cols overflows usize");
        Self {
            rows,
            cols,
            data: vec![0.0; len],
        }
    }

    /// Wraps row-major data; fails unless `data.len() == rows * cols`.
    pub fn from_vec(rows: usize, cols: usize, data: Vec<f32>) -> Result<Self, FeatureError> {
        let mismatch = |expected| FeatureError::LengthMismatch {
            what: "matrix data",
            expected,
            found: data.len(),
        };
        let expected = rows.checked_mul(cols).ok_or(mismatch(usize::MAX))?;
        if data.len() != expected {
            return Err(mismatch(expected));
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
            return Err(FeatureError::LengthMismatch {
                what: "appended matrix row",
                expected: self.cols,
                found: other.cols,
            });
        }
        self.data.extend_from_slice(&other.data);
        self.rows += other.rows;
        Ok(())
    }
}

/// A borrowed row-major `f32` matrix of at least one column: row `i` is
/// `as_slice()[i * cols..(i + 1) * cols]`.
///
/// [`FeatureMatrixRef::new`] (and `try_from` a [`FeatureMatrix`]) checks that the values form
/// whole rows and are all finite: the regressors that take a view (ridi-regress's SMO) have no
/// meaningful answer for NaN or infinity. [`FeatureMatrixRef::trusted`] skips the scan for
/// values known to be finite.
#[derive(Debug, Clone, Copy)]
pub struct FeatureMatrixRef<'a> {
    data: &'a [f32],
    cols: usize,
}

impl<'a> FeatureMatrixRef<'a> {
    /// Views `data` as rows of `cols` values.
    ///
    /// # Errors
    /// [`FeatureError::LengthMismatch`] when `cols` is 0 (a row of at least one value is
    /// expected) or `data` does not hold whole rows,
    /// [`FeatureError::NonFinite`] (naming the row) for a NaN or infinite value.
    pub fn new(data: &'a [f32], cols: usize) -> Result<Self, FeatureError> {
        if cols == 0 {
            return Err(FeatureError::LengthMismatch {
                what: "matrix row",
                expected: 1,
                found: 0,
            });
        }
        if !data.len().is_multiple_of(cols) {
            return Err(FeatureError::LengthMismatch {
                what: "matrix data (whole rows)",
                expected: data.len().div_ceil(cols) * cols,
                found: data.len(),
            });
        }
        if let Some(pos) = data.iter().position(|v| !v.is_finite()) {
            return Err(FeatureError::NonFinite {
                what: "feature value",
                index: pos / cols,
            });
        }
        Ok(Self { data, cols })
    }

    /// Views values the caller knows to be finite whole rows (computed from a checked view,
    /// say), without [`new`](Self::new)'s scan: for hot paths. Debug builds assert the shape;
    /// a non-finite value gives meaningless results downstream, never undefined behaviour.
    pub fn trusted(data: &'a [f32], cols: usize) -> Self {
        debug_assert!(cols > 0 && data.len().is_multiple_of(cols));
        Self { data, cols }
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.data.len() / self.cols
    }

    /// Number of values per row.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Rows `r0..r1` (no new scan: the parent's values are checked).
    ///
    /// # Panics
    /// If `r0 > r1` or `r1 > self.rows()`, as slicing would.
    pub fn rows_range(&self, r0: usize, r1: usize) -> FeatureMatrixRef<'a> {
        FeatureMatrixRef {
            data: &self.data[r0 * self.cols..r1 * self.cols],
            cols: self.cols,
        }
    }

    /// Row `i`.
    ///
    /// # Panics
    /// If `i >= rows`, like slice indexing.
    pub fn row(&self, i: usize) -> &'a [f32] {
        &self.data[i * self.cols..(i + 1) * self.cols]
    }

    /// All values, row-major.
    pub fn as_slice(&self) -> &'a [f32] {
        self.data
    }

    /// Copies the rows listed in `idx` (in that order) into an owned matrix.
    ///
    /// # Panics
    /// If an index is not below `rows`.
    pub fn select(&self, idx: &[usize]) -> FeatureMatrix {
        let mut data = Vec::with_capacity(idx.len() * self.cols);
        for &i in idx {
            data.extend_from_slice(self.row(i));
        }
        FeatureMatrix {
            rows: idx.len(),
            cols: self.cols,
            data,
        }
    }

    /// An owned copy.
    pub fn to_owned(&self) -> FeatureMatrix {
        FeatureMatrix {
            rows: self.rows(),
            cols: self.cols,
            data: self.data.to_vec(),
        }
    }
}

/// Views a feature matrix with the checks of [`FeatureMatrixRef::new`].
impl<'a> TryFrom<&'a FeatureMatrix> for FeatureMatrixRef<'a> {
    type Error = FeatureError;

    fn try_from(m: &'a FeatureMatrix) -> Result<Self, FeatureError> {
        FeatureMatrixRef::new(m.as_slice(), m.cols())
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

    #[test]
    fn a_view_is_checked_whole_rows_of_finite_values() {
        let m = FeatureMatrix::from_vec(2, 3, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
        let r = FeatureMatrixRef::try_from(&m).unwrap();
        assert_eq!((r.rows(), r.cols()), (2, 3));
        assert_eq!(r.row(1), &[4.0, 5.0, 6.0]);
        assert_eq!(r.rows_range(1, 2).as_slice(), &[4.0, 5.0, 6.0]);
        assert_eq!(r.select(&[1, 0]).row(0), &[4.0, 5.0, 6.0]);
        assert_eq!(r.to_owned(), m);
        let bad = FeatureMatrix::from_vec(2, 2, vec![1.0, 2.0, 3.0, f32::NAN]).unwrap();
        assert_eq!(
            FeatureMatrixRef::try_from(&bad).unwrap_err(),
            FeatureError::NonFinite {
                what: "feature value",
                index: 1
            }
        );
        assert!(matches!(
            FeatureMatrixRef::new(&[1.0; 5], 2),
            Err(FeatureError::LengthMismatch {
                expected: 6,
                found: 5,
                ..
            })
        ));
        assert!(FeatureMatrixRef::new(&[], 0).is_err());
    }
}
