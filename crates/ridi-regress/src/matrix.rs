//! The crate's side of ridi-features' matrices: the unchecked view of a matrix the crate
//! built itself, and the model file's layout of a stored one.

use ridi_features::{FeatureMatrix, FeatureMatrixRef};

/// The view of a matrix this crate computed from checked values (projected rows, selected
/// training rows, support vectors): no new scan.
pub(crate) trait View {
    /// The whole matrix, borrowed.
    fn view(&self) -> FeatureMatrixRef<'_>;
}

impl View for FeatureMatrix {
    fn view(&self) -> FeatureMatrixRef<'_> {
        FeatureMatrixRef::trusted(self.as_slice(), self.cols())
    }
}

/// A matrix this crate computed from checked values, `data` whole rows of `cols` values.
pub(crate) fn owned(data: Vec<f32>, cols: usize) -> FeatureMatrix {
    debug_assert!(cols > 0 && data.len().is_multiple_of(cols));
    let rows = data.len().checked_div(cols).unwrap_or(0);
    FeatureMatrix::from_vec(rows, cols, data).expect("whole rows by construction")
}

/// Serde layout of a [`FeatureMatrix`] field of a model: the values, then the values per
/// row, as the model file format has always stored them (`#[serde(with = "...")]`).
pub(crate) mod stored {
    use ridi_features::FeatureMatrix;
    use serde::de::Error as _;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    #[derive(Serialize)]
    struct Ref<'a> {
        data: &'a [f32],
        dim: usize,
    }

    #[derive(Deserialize)]
    struct Owned {
        data: Vec<f32>,
        dim: usize,
    }

    pub(crate) fn serialize<S: Serializer>(m: &FeatureMatrix, s: S) -> Result<S::Ok, S::Error> {
        Ref {
            data: m.as_slice(),
            dim: m.cols(),
        }
        .serialize(s)
    }

    pub(crate) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<FeatureMatrix, D::Error> {
        let Owned { data, dim } = Owned::deserialize(d)?;
        let rows = data.len().checked_div(dim).unwrap_or(0);
        FeatureMatrix::from_vec(rows, dim, data).map_err(D::Error::custom)
    }
}
