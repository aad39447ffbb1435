//! linfa vocabulary: [`Fit`] on linfa datasets for [`SvrParams`] and [`SvcParams`], and
//! [`PredictInplace`] for the fitted [`Svr`] and [`Svc`]. Datasets are `f32` throughout, records
//! and regression targets alike (linfa's usual single float type); the adapter converts the
//! targets to the `f64` of [`Svr::fit`] and its predictions back.
//!
//! ```
//! use linfa::prelude::*;
//! use ndarray::{Array1, Array2};
//! use ridi_regress::{Svr, SvrParams};
//!
//! let x = Array2::from_shape_fn((40, 3), |(i, j)| (i as f32 * 0.1 + j as f32).sin());
//! let y = Array1::from_shape_fn(40, |i| (i as f32 * 0.1).cos());
//! let model: Svr = SvrParams::new(10.0, 0.01, 0.5).fit(&Dataset::new(x.clone(), y.clone()))?;
//! // `Svr::predict` (inherent, on `FeatureMatrixRef`) shadows the trait method; name the trait.
//! let pred: Array1<f32> = Predict::predict(&model, &x);
//! assert!(pred.iter().zip(&y).all(|(p, t)| (p - t).abs() < 0.05));
//! # Ok::<(), ridi_regress::RegressError>(())
//! ```

use linfa::dataset::{AsSingleTargets, DatasetBase};
use linfa::traits::{Fit, PredictInplace};
use ndarray::{Array1, ArrayBase, Data, Ix2};

use crate::error::RegressError;
use crate::svc::{Svc, SvcParams};
use crate::svr::{Svr, SvrParams};
use ridi_features::FeatureMatrixRef;

impl From<linfa::Error> for RegressError {
    fn from(e: linfa::Error) -> Self {
        RegressError::InvalidParam(e.to_string())
    }
}

/// Row-major copy of the records when they are not already standard layout.
fn records<D: Data<Elem = f32>>(x: &ArrayBase<D, Ix2>) -> Vec<f32> {
    x.as_standard_layout().iter().copied().collect()
}

impl<D, T> Fit<ArrayBase<D, Ix2>, T, RegressError> for SvrParams
where
    D: Data<Elem = f32>,
    T: AsSingleTargets<Elem = f32>,
{
    type Object = Svr;

    fn fit(&self, dataset: &DatasetBase<ArrayBase<D, Ix2>, T>) -> Result<Svr, RegressError> {
        let x = records(dataset.records());
        let y: Vec<f64> = dataset
            .as_single_targets()
            .iter()
            .map(|&v| f64::from(v))
            .collect();
        Svr::fit(
            FeatureMatrixRef::new(&x, dataset.records().ncols().max(1))?,
            &y,
            self,
        )
    }
}

impl<D, T> Fit<ArrayBase<D, Ix2>, T, RegressError> for SvcParams
where
    D: Data<Elem = f32>,
    T: AsSingleTargets<Elem = usize>,
{
    type Object = Svc;

    fn fit(&self, dataset: &DatasetBase<ArrayBase<D, Ix2>, T>) -> Result<Svc, RegressError> {
        let x = records(dataset.records());
        let y: Vec<usize> = dataset.as_single_targets().iter().copied().collect();
        Svc::fit(
            FeatureMatrixRef::new(&x, dataset.records().ncols().max(1))?,
            &y,
            self,
        )
    }
}

/// Rows that cannot be predicted (wrong feature count, non-finite values) get NaN, since the
/// trait has no error channel.
impl<D: Data<Elem = f32>> PredictInplace<ArrayBase<D, Ix2>, Array1<f32>> for Svr {
    fn predict_inplace(&self, x: &ArrayBase<D, Ix2>, y: &mut Array1<f32>) {
        let data = records(x);
        let pred = FeatureMatrixRef::new(&data, x.ncols().max(1))
            .map_err(RegressError::from)
            .and_then(|m| self.predict(m));
        match pred {
            Ok(p) if p.len() == y.len() => y.iter_mut().zip(p).for_each(|(o, v)| *o = v as f32),
            _ => y.fill(f32::NAN),
        }
    }

    fn default_target(&self, x: &ArrayBase<D, Ix2>) -> Array1<f32> {
        Array1::zeros(x.nrows())
    }
}

/// Rows that cannot be predicted (wrong feature count, non-finite values) get `usize::MAX`,
/// since the trait has no error channel.
impl<D: Data<Elem = f32>> PredictInplace<ArrayBase<D, Ix2>, Array1<usize>> for Svc {
    fn predict_inplace(&self, x: &ArrayBase<D, Ix2>, y: &mut Array1<usize>) {
        let data = records(x);
        let pred = FeatureMatrixRef::new(&data, x.ncols().max(1))
            .map_err(RegressError::from)
            .and_then(|m| self.predict(m));
        match pred {
            Ok(p) if p.len() == y.len() => y.iter_mut().zip(p).for_each(|(o, v)| *o = v),
            _ => y.fill(usize::MAX),
        }
    }

    fn default_target(&self, x: &ArrayBase<D, Ix2>) -> Array1<usize> {
        Array1::zeros(x.nrows())
    }
}
