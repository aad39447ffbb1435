//! The bootstrap's intervals (ridi-eval's, re-exported) and the means the protocols take.

pub use ridi::eval::{DRAWS, Interval, mean_interval, ratio_interval, runs_interval};

/// A weighted mean of the finite values added: a figure a sequence lacks (`NaN`, e.g. a path
/// length ratio without a path) is left out of that figure's mean, as the protocols do.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FiniteMean {
    sum: f64,
    weight: f64,
}

impl FiniteMean {
    /// Adds `value` with `weight`, unless `value` is not finite.
    pub fn add(&mut self, weight: f64, value: f64) {
        if value.is_finite() {
            self.sum += weight * value;
            self.weight += weight;
        }
    }

    /// The mean; `NaN` when nothing was added.
    pub fn mean(&self) -> f64 {
        if self.weight > 0.0 {
            self.sum / self.weight
        } else {
            f64::NAN
        }
    }

    /// The plain mean of the finite `values`.
    pub fn of(values: impl IntoIterator<Item = f64>) -> f64 {
        let mut m = Self::default();
        values.into_iter().for_each(|v| m.add(1.0, v));
        m.mean()
    }
}
