//! How much a mean over test sequences can be trusted: percentile intervals from a bootstrap
//! that resamples whole runs.
//!
//! The parts of a run split at a gap share its person, placement and start, so they are not
//! independent: a resample draws runs, and a drawn run brings all its parts. The statistic is
//! the plain mean over the drawn sequences, as a report's means are.
//!
//! Runs are drawn as if independent, though the runs of one person share that person (and, in
//! a leave-one-person-out protocol, the model trained without them): the intervals say how
//! well these runs pin a mean down, not how far it carries to other people.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Resamples per interval: the 2.5 % and 97.5 % percentiles move by about 0.002 m between
/// seeds at this count on the Tyrex RTE values.
pub const DRAWS: usize = 10_000;

/// Fewest runs an interval is given for. Resampling fewer says nothing of a 95 % interval: one
/// run resamples to itself (an interval of width 0), two to their mean and each alone (the
/// interval is their range), and below five the percentiles rest on a handful of distinct
/// means.
pub const MIN_INTERVAL_RUNS: usize = 5;

/// Fixed, so that a report is reproduced exactly.
const SEED: u64 = 2018;

/// A mean and its 95 % bootstrap interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Interval {
    /// The mean over every value (not over the resamples).
    pub mean: f64,
    /// The 2.5 % percentile of the resampled means; NaN (`null` in JSON) for a mean without
    /// bounds ([`Interval::unbounded`]).
    #[serde(deserialize_with = "nan_if_null")]
    pub low: f64,
    /// The 97.5 % percentile of the resampled means; NaN as `low`.
    #[serde(deserialize_with = "nan_if_null")]
    pub high: f64,
}

/// A float that JSON holds as `null` where it is NaN (serde_json writes a NaN as `null`).
pub(crate) fn nan_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

impl Interval {
    /// `mean` without bounds: a report's entry for a mean over fewer runs than an interval
    /// needs ([`MIN_INTERVAL_RUNS`]), so that the mean (a paired difference, say) is kept.
    pub fn unbounded(mean: f64) -> Self {
        Self {
            mean,
            low: f64::NAN,
            high: f64::NAN,
        }
    }

    /// Whether the interval has its bounds (it was resampled from enough runs).
    pub fn is_bounded(&self) -> bool {
        self.low.is_finite() && self.high.is_finite()
    }

    /// `true` when the interval holds `x` (for a difference: the protocol cannot tell the two
    /// apart).
    pub fn contains(&self, x: f64) -> bool {
        self.low <= x && x <= self.high
    }
}

/// The mean of `values`, summed in ascending order: the same bits whatever order the values
/// come in (a list file's order, say), so that a report reproduces to the last digit. NaN for
/// no values.
pub fn ordered_mean(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_unstable_by(f64::total_cmp);
    sorted.iter().sum::<f64>() / sorted.len() as f64
}

/// The mean of `values` (one per test sequence) and its 95 % percentile interval over
/// [`DRAWS`] resamples of the clusters (`cluster[i]` names the run of sequence `i`). `None`
/// with fewer than [`MIN_INTERVAL_RUNS`] clusters, with `cluster` of another length, or with a
/// non-finite value.
pub fn mean_interval(values: &[f64], cluster: &[&str]) -> Option<Interval> {
    if values.is_empty() || values.len() != cluster.len() || !values.iter().all(|v| v.is_finite()) {
        return None;
    }
    let mut names: Vec<&str> = cluster.to_vec();
    names.sort_unstable();
    names.dedup();
    // Sum and count of each cluster, its values added in ascending order (as `ordered_mean`):
    // a draw only adds them up.
    let mut sorted: Vec<(usize, f64)> = Vec::with_capacity(values.len());
    for (&v, c) in values.iter().zip(cluster) {
        sorted.push((names.binary_search(c).ok()?, v));
    }
    sorted.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut sums = vec![(0.0, 0usize); names.len()];
    for (k, v) in sorted {
        sums[k].0 += v;
        sums[k].1 += 1;
    }
    let mean = ordered_mean(values);
    percentile_interval(mean, sums.len(), |draw| {
        let (mut s, mut n) = (0.0, 0usize);
        for &k in draw {
            s += sums[k].0;
            n += sums[k].1;
        }
        s / n as f64
    })
}

/// The mean of one value per run and its 95 % interval over [`DRAWS`] resamples of the runs.
/// `None` with fewer than [`MIN_INTERVAL_RUNS`] values or with a non-finite one.
pub fn runs_interval(values: &[f64]) -> Option<Interval> {
    if values.is_empty() || !values.iter().all(|v| v.is_finite()) {
        return None;
    }
    let mean = ordered_mean(values);
    percentile_interval(mean, values.len(), |draw| {
        draw.iter().map(|&k| values[k]).sum::<f64>() / draw.len() as f64
    })
}

/// The ratio of the means of paired per-run values, `mean(num) / mean(den)`, and its 95 %
/// interval over resamples of the runs (a drawn run brings both its values). `None` with fewer
/// than [`MIN_INTERVAL_RUNS`] runs, slices of different lengths, a non-finite value or a mean
/// of `den` that is not positive.
pub fn ratio_interval(num: &[f64], den: &[f64]) -> Option<Interval> {
    let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
    if num.is_empty() || num.len() != den.len() || !finite(num) || !finite(den) {
        return None;
    }
    let ratio = |draw: &mut dyn Iterator<Item = usize>| {
        let (mut a, mut b) = (0.0, 0.0);
        for k in draw {
            a += num[k];
            b += den[k];
        }
        a / b
    };
    if den.iter().sum::<f64>() <= 0.0 {
        return None;
    }
    let point = ratio(&mut (0..num.len()));
    // A draw whose denominators sum to 0 has no ratio: +inf sorts it into the upper tail.
    percentile_interval(point, num.len(), |draw| {
        let r = ratio(&mut draw.iter().copied());
        if r.is_finite() { r } else { f64::INFINITY }
    })
}

/// `point` and the 2.5 % and 97.5 % percentiles of `stat` over [`DRAWS`] draws of `n` cluster
/// indices with replacement (fixed seed); `None` for fewer than [`MIN_INTERVAL_RUNS`] clusters.
fn percentile_interval(point: f64, n: usize, stat: impl Fn(&[usize]) -> f64) -> Option<Interval> {
    if n < MIN_INTERVAL_RUNS {
        return None;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let mut draw = vec![0; n];
    let mut stats: Vec<f64> = (0..DRAWS)
        .map(|_| {
            for k in draw.iter_mut() {
                *k = rng.random_range(0..n);
            }
            stat(&draw)
        })
        .collect();
    stats.sort_unstable_by(f64::total_cmp);
    // The 250th draw from each end, so that both tails leave out the same number.
    let tail = (0.025 * DRAWS as f64).round() as usize;
    Some(Interval {
        mean: point,
        low: stats[tail - 1],
        high: stats[DRAWS - tail],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interval_of_identical_values_is_the_value() {
        let i = mean_interval(&[0.7; 6], &["a", "b", "b", "c", "d", "e"]).unwrap();
        for x in [i.mean, i.low, i.high] {
            assert!((x - 0.7).abs() < 1e-12, "{i:?}");
        }
        assert!(i.contains(i.mean));
        assert!(!i.contains(0.71) && !i.contains(0.69));
    }

    #[test]
    fn interval_holds_the_mean_and_narrows_with_more_runs() {
        // Values alternating 0 and 1 over n runs: mean 0.5, standard error 0.5 / sqrt(n).
        let interval = |n: usize| {
            let names: Vec<String> = (0..n).map(|i| format!("run{i}")).collect();
            let cluster: Vec<&str> = names.iter().map(String::as_str).collect();
            let values: Vec<f64> = (0..n).map(|i| (i % 2) as f64).collect();
            mean_interval(&values, &cluster).unwrap()
        };
        let (small, large) = (interval(24), interval(400));
        for (i, n) in [(small, 24.0), (large, 400.0)] {
            assert_eq!(i.mean, 0.5);
            // About +-1.96 standard errors.
            let half = (i.high - i.low) / 2.0;
            let se = 0.5 / f64::sqrt(n);
            assert!(
                (half / se - 1.96).abs() < 0.25,
                "half width {half}, se {se}"
            );
            assert!(i.contains(0.5));
        }
        assert!(large.high - large.low < 0.3 * (small.high - small.low));
        // Reproducible.
        assert_eq!(interval(24), small);
    }

    #[test]
    fn parts_of_a_run_move_together() {
        // One run of ten parts at 1.0 and ten single runs at 0.0: drawn as ten parts at once,
        // the run makes the interval far wider than ten independent sequences would.
        let mut values = vec![1.0; 10];
        values.extend([0.0; 10]);
        let mut cluster = vec!["big"; 10];
        let names: Vec<String> = (0..10).map(|i| format!("single{i}")).collect();
        cluster.extend(names.iter().map(String::as_str));
        let runs = mean_interval(&values, &cluster).unwrap();
        let names: Vec<String> = (0..20).map(|i| format!("s{i}")).collect();
        let independent: Vec<&str> = names.iter().map(String::as_str).collect();
        let seqs = mean_interval(&values, &independent).unwrap();
        assert_eq!(runs.mean, 0.5);
        assert!(runs.high - runs.low > 1.5 * (seqs.high - seqs.low));
    }

    #[test]
    fn fewer_runs_than_the_least_have_no_interval() {
        // One run resamples to itself, two to their range: no 95 % interval at all.
        let names = ["a", "b", "c", "d", "e"];
        let values = [0.2, 0.9, 0.4, 1.3, 0.7];
        for n in 1..MIN_INTERVAL_RUNS {
            assert_eq!(mean_interval(&values[..n], &names[..n]), None, "{n}");
            assert_eq!(runs_interval(&values[..n]), None, "{n}");
            assert_eq!(ratio_interval(&values[..n], &values[..n]), None, "{n}");
        }
        // Five sequences of two runs are two runs.
        assert_eq!(mean_interval(&values, &["a", "a", "a", "b", "b"]), None);
        assert!(mean_interval(&values, &names).is_some());
    }

    #[test]
    fn one_value_per_run_is_one_cluster_per_value() {
        let values = [0.2, 0.9, 0.4, 1.3, 0.7];
        let names = ["a", "b", "c", "d", "e"];
        assert_eq!(runs_interval(&values), mean_interval(&values, &names));
        assert_eq!(runs_interval(&[]), None);
        assert_eq!(runs_interval(&[1.0, f64::INFINITY]), None);
    }

    #[test]
    fn ratio_of_paired_means() {
        // A constant ratio has no spread, whatever the runs drawn.
        let den = [1.0, 2.0, 4.0, 0.5, 3.0];
        let num = den.map(|d| 1.2 * d);
        let i = ratio_interval(&num, &den).unwrap();
        for x in [i.mean, i.low, i.high] {
            assert!((x - 1.2).abs() < 1e-12, "{i:?}");
        }
        // The ratio of the means, not the mean of the ratios: (5 + 1 + 3 + 1 + 0) / 5 = 2.
        let i = ratio_interval(&[5.0, 1.0, 3.0, 1.0, 0.0], &[1.0; 5]).unwrap();
        assert_eq!(i.mean, 2.0);
        assert!(i.low >= 0.0 && i.high <= 5.0 && i.low < i.high, "{i:?}");
        assert_eq!(ratio_interval(&[1.0; 5], &[0.0; 5]), None);
        assert_eq!(ratio_interval(&[1.0], &[1.0, 2.0]), None);
        assert_eq!(ratio_interval(&[], &[]), None);
    }

    #[test]
    fn refuses_what_it_cannot_resample() {
        assert_eq!(mean_interval(&[], &[]), None);
        assert_eq!(mean_interval(&[1.0], &["a", "b"]), None);
        assert_eq!(mean_interval(&[f64::NAN, 1.0], &["a", "b"]), None);
    }
}
