//! What the compact sample storage changes: the stored model against the same model with the
//! exact training rows ([`Cascade::rounding_effect`]).

use std::collections::HashMap;
use std::hash::{DefaultHasher, Hash, Hasher};

use rayon::prelude::*;

use super::Cascade;
use super::predict::Rows;
use crate::error::RegressError;
use crate::kernel;
use crate::matrix::View as _;
use crate::store::SampleRows;
use ridi_features::FeatureMatrixRef;

/// How far the compact sample storage (half precision or projection,
/// [`Storage`](crate::Storage)) moves predictions: the stored model against the same model
/// evaluated with the exact `f32` training rows ([`Cascade::rounding_effect`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoundingEffect {
    /// Queries compared.
    pub queries: usize,
    /// Share of the queries given the same placement by both.
    pub placement_agreement: f64,
    /// Largest absolute velocity difference per channel (queries with the same placement).
    pub max_velocity_diff: [f64; 2],
    /// Mean absolute velocity difference per channel (queries with the same placement).
    pub mean_velocity_diff: [f64; 2],
}

impl std::fmt::Display for RoundingEffect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} queries: same placement {:.4}, max |dv| {:.2e} / {:.2e} m/s, mean |dv| {:.2e} / \
             {:.2e} m/s",
            self.queries,
            self.placement_agreement,
            self.max_velocity_diff[0],
            self.max_velocity_diff[1],
            self.mean_velocity_diff[0],
            self.mean_velocity_diff[1]
        )
    }
}

impl Cascade {
    /// Compares [`Self::predict`] with the same model evaluated with the exact `f32` training
    /// rows in full dimension: each stored row is matched to the row of `training` (the rows
    /// the model was trained on) whose stored form (rounded, or projected) it is. Measures
    /// what the [`Storage`](crate::Storage) changes. Fails when a stored row has no match, and
    /// for a Nyström model ([`Solver::Nystrom`](crate::Solver::Nystrom)).
    pub fn rounding_effect(
        &self,
        training: FeatureMatrixRef<'_>,
        queries: FeatureMatrixRef<'_>,
    ) -> Result<RoundingEffect, RegressError> {
        if self.nystrom.is_some() {
            return Err(RegressError::InvalidParam(
                "rounding_effect compares an exact model with its training rows; a Nyström \
                 model stores landmarks"
                    .into(),
            ));
        }
        self.check_dim(training)?;
        self.check_dim(queries)?;
        let key = |bytes: &[u8]| {
            let mut h = DefaultHasher::new();
            bytes.hash(&mut h);
            h.finish()
        };
        let stored = |i: usize| {
            SampleRows::from_rows(training, &[i], self.projection.as_ref()).map(|s| s.row_bytes(0))
        };
        let forms: Vec<Vec<u8>> = (0..training.rows())
            .into_par_iter()
            .map(stored)
            .collect::<Result<_, _>>()?;
        let mut by_key: HashMap<u64, Vec<usize>> = HashMap::new();
        for (i, f) in forms.iter().enumerate() {
            by_key.entry(key(f)).or_default().push(i);
        }
        let mut exact = Vec::with_capacity(self.classes.len());
        for (p, cl) in self.classes.iter().enumerate() {
            let idx = (0..cl.samples.rows())
                .map(|j| {
                    let bytes = cl.samples.row_bytes(j);
                    by_key
                        .get(&key(&bytes))
                        .and_then(|c| c.iter().find(|&&i| forms[i] == bytes))
                        .copied()
                        .ok_or(RegressError::NotTrainingRow {
                            placement: p,
                            index: j,
                        })
                })
                .collect::<Result<Vec<usize>, _>>()?;
            let m = training.select(&idx);
            let norms = kernel::sq_norms(m.view());
            exact.push((m, norms));
        }
        let stored = self.predict_blocks(Rows::Stored, queries, None);
        let reference = self.predict_blocks(Rows::Exact(&exact), queries, None);
        let mut same = 0usize;
        let mut max = [0.0f64; 2];
        let mut sum = [0.0f64; 2];
        for (a, b) in stored.iter().zip(&reference) {
            if a.placement != b.placement {
                continue;
            }
            same += 1;
            for ch in 0..2 {
                let d = (a.velocity[ch] - b.velocity[ch]).abs();
                max[ch] = max[ch].max(d);
                sum[ch] += d;
            }
        }
        let n = stored.len();
        Ok(RoundingEffect {
            queries: n,
            placement_agreement: same as f64 / n.max(1) as f64,
            max_velocity_diff: max,
            mean_velocity_diff: sum.map(|s| s / same.max(1) as f64),
        })
    }
}
