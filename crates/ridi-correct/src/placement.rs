//! Placement labels over time: the placement-change filter of the original code, and a
//! majority smoother for batch tracking.
//!
//! A phone that is being moved between placements (pocket to hand, say) confuses the
//! placement classifier, whose label then flips back and forth; the regressed velocity of such
//! a moment is unreliable. The original zeroes a regressed velocity when more than two label
//! changes happen within ±7 regressions of it.

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use crate::CorrectError;

/// Parameters of the placement-change filter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct PlacementFilter {
    /// Half-width of the window, in regressions (original: 7).
    pub radius: usize,
    /// Largest tolerated number of label changes within the window (original: 2).
    pub max_changes: usize,
}

impl Default for PlacementFilter {
    fn default() -> Self {
        Self {
            radius: 7,
            max_changes: 2,
        }
    }
}

impl PlacementFilter {
    /// For each regression, `true` when its velocity should be zeroed: more than
    /// `max_changes` changes between consecutive known labels within
    /// `[i - radius, i + radius]` (clipped to the slice). Unknown labels (`None`) are skipped,
    /// so they neither count as nor hide a change.
    pub fn flags(&self, labels: &[Option<usize>]) -> Vec<bool> {
        // changes[i] = number of changes between consecutive known labels up to index i.
        let mut changes = Vec::with_capacity(labels.len());
        let mut prev: Option<usize> = None;
        let mut count = 0usize;
        for l in labels {
            if let Some(l) = *l {
                if prev.is_some_and(|p| p != l) {
                    count += 1;
                }
                prev = Some(l);
            }
            changes.push(count);
        }
        (0..labels.len())
            .map(|i| {
                let lo = i.saturating_sub(self.radius);
                let hi = i.saturating_add(self.radius).min(labels.len() - 1);
                // Changes landing on indices lo+1..=hi happened inside the window; one landing
                // on lo came from a label before the window.
                changes[hi] - changes[lo] > self.max_changes
            })
            .collect()
    }
}

/// Majority vote over the placement labels of a time window (batch tracking).
///
/// The classifier labels each feature window alone, so a sequence held one way collects
/// scattered wrong labels, and each one sends its window to the wrong placement's
/// regressors. Phones change placement seldom: replacing every label by the most frequent
/// label within `±window_s / 2` seconds removes the scatter and keeps real changes that last
/// longer than half a window. Not in the paper (its online code only zeroes velocities during
/// label flicker, see [`PlacementFilter`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PlacementSmoother {
    /// Width of the voting window, seconds (centred on each label).
    pub window_s: f64,
}

impl Default for PlacementSmoother {
    /// A 10 s window (±5 s).
    fn default() -> Self {
        Self { window_s: 10.0 }
    }
}

impl PlacementSmoother {
    /// A smoother voting over `window_s` seconds.
    ///
    /// # Errors
    /// A `window_s` that is not finite and positive.
    pub fn new(window_s: f64) -> Result<Self, CorrectError> {
        let s = Self { window_s };
        s.validate()?;
        Ok(s)
    }

    /// Checks the window (its field is public): finite and positive. A window of another
    /// value smooths nothing, or not as asked, but never panics.
    pub fn validate(&self) -> Result<(), CorrectError> {
        if self.window_s.is_finite() && self.window_s > 0.0 {
            Ok(())
        } else {
            Err(CorrectError::InvalidConfig(
                "placement smoothing window_s must be finite and positive",
            ))
        }
    }

    /// The smoothed label of each entry of `labels` (indices below `classes`) observed at
    /// `times` (seconds, non-decreasing). A tie keeps the label itself when it is among the
    /// most frequent, else the lowest tied label: the result does not depend on anything but
    /// the inputs.
    ///
    /// # Panics
    /// If `times` and `labels` differ in length or a label is not below `classes`: both are
    /// produced by the caller's own classifier, never read from user input.
    pub fn smooth(&self, times: &[f64], labels: &[usize], classes: usize) -> Vec<usize> {
        assert_eq!(times.len(), labels.len(), "one time per label");
        let half = self.window_s / 2.0;
        let mut counts = vec![0usize; classes];
        let (mut lo, mut hi) = (0, 0);
        let mut out = Vec::with_capacity(labels.len());
        for (i, &t) in times.iter().enumerate() {
            while hi < labels.len() && times[hi] <= t + half {
                counts[labels[hi]] += 1;
                hi += 1;
            }
            // `lo < hi`: a negative window (unvalidated) would run past what was counted.
            while lo < hi && times[lo] < t - half {
                counts[labels[lo]] -= 1;
                lo += 1;
            }
            out.push(majority(&counts, labels[i]));
        }
        out
    }

    /// The streaming form: each label against those of the `window_s` seconds before it.
    pub fn trailing(&self, classes: usize) -> TrailingMajority {
        TrailingMajority {
            window_s: self.window_s,
            seen: VecDeque::new(),
            counts: vec![0; classes],
        }
    }
}

/// The most frequent label of `counts`; `own` when it is among the most frequent, else the
/// lowest such label.
fn majority(counts: &[usize], own: usize) -> usize {
    let best = counts.iter().copied().max().unwrap_or(0);
    if counts[own] == best {
        own
    } else {
        counts.iter().position(|&c| c == best).unwrap_or(own)
    }
}

/// Majority vote over the labels of the last `window_s` seconds, one label at a time (the
/// streaming tracker cannot look ahead). Built by [`PlacementSmoother::trailing`].
#[derive(Debug, Clone)]
pub struct TrailingMajority {
    window_s: f64,
    seen: VecDeque<(f64, usize)>,
    counts: Vec<usize>,
}

impl TrailingMajority {
    /// Adds `label` seen at `time` (seconds, non-decreasing) and returns the majority label of
    /// `[time - window_s, time]`, with the tie rule of [`PlacementSmoother::smooth`].
    ///
    /// # Panics
    /// If `label` is not below the number of classes given at construction.
    pub fn push(&mut self, time: f64, label: usize) -> usize {
        self.seen.push_back((time, label));
        self.counts[label] += 1;
        while let Some(&(t, l)) = self.seen.front() {
            if t >= time - self.window_s {
                break;
            }
            self.counts[l] -= 1;
            self.seen.pop_front();
        }
        majority(&self.counts, label)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_window_wider_than_any_slice_takes_the_whole_slice() {
        let wide = PlacementFilter {
            radius: usize::MAX,
            max_changes: 0,
        };
        assert_eq!(wide.flags(&[Some(0), Some(1)]), [true, true]);
        assert_eq!(wide.flags(&[Some(0), None, Some(0)]), [false; 3]);
    }

    #[test]
    fn a_window_that_is_not_positive_is_refused_and_does_not_panic_unchecked() {
        for window_s in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(PlacementSmoother::new(window_s).is_err(), "{window_s}");
            // Built through the public field, unchecked: labels come back, no panic.
            let s = PlacementSmoother { window_s };
            assert_eq!(s.smooth(&[0.0, 1.0, 2.0], &[0, 1, 0], 2).len(), 3);
            let mut live = s.trailing(2);
            assert!(live.push(0.0, 1) < 2);
        }
        assert_eq!(
            PlacementSmoother::new(10.0).unwrap(),
            PlacementSmoother::default()
        );
    }

    #[test]
    fn smoother_removes_scatter_and_keeps_lasting_changes() {
        let s = PlacementSmoother { window_s: 2.0 };
        let times: Vec<f64> = (0..40).map(|i| i as f64 * 0.25).collect();
        // Class 0 for 5 s, then class 2 for 5 s, with isolated wrong labels in both halves.
        let mut labels: Vec<usize> = (0..40).map(|i| if i < 20 { 0 } else { 2 }).collect();
        labels[5] = 1;
        labels[30] = 0;
        let out = s.smooth(&times, &labels, 3);
        let want: Vec<usize> = (0..40).map(|i| if i < 20 { 0 } else { 2 }).collect();
        assert_eq!(out, want);
        // A label tied with another for the most votes keeps itself; else the lowest wins.
        let times = [0.0, 0.1, 0.2, 0.3];
        assert_eq!(s.smooth(&times, &[1, 0, 1, 0], 2), vec![1, 0, 1, 0]);
        assert_eq!(s.smooth(&times, &[2, 1, 0, 3], 4), vec![2, 1, 0, 3]);
        assert_eq!(s.smooth(&times, &[2, 2, 1, 0], 3), vec![2, 2, 2, 2]);
        assert!(s.smooth(&[], &[], 3).is_empty());
    }

    #[test]
    fn trailing_majority_counts_the_window_before_each_label() {
        let s = PlacementSmoother { window_s: 1.0 };
        let times: Vec<f64> = (0..300).map(|i| (i as f64 * 0.137).powf(1.05)).collect();
        let labels: Vec<usize> = (0..300).map(|i| (i * 7 + i / 13) % 5 % 3).collect();
        let mut live = s.trailing(3);
        for i in 0..300 {
            let mut c = [0usize; 3];
            for j in 0..=i {
                if times[j] >= times[i] - 1.0 {
                    c[labels[j]] += 1;
                }
            }
            assert_eq!(
                live.push(times[i], labels[i]),
                majority(&c, labels[i]),
                "entry {i}"
            );
        }
        // A lasting change takes over once it holds the majority of the window.
        let mut live = s.trailing(2);
        let out: Vec<usize> = (0..20)
            .map(|i| live.push(i as f64 * 0.1, usize::from(i >= 10)))
            .collect();
        assert_eq!(&out[..10], &[0; 10]);
        assert_eq!(&out[16..], &[1; 4]);
    }

    #[test]
    fn smoother_agrees_with_a_plain_count() {
        // Uneven times, several classes: compare with counting each window from scratch.
        let s = PlacementSmoother { window_s: 1.3 };
        let times: Vec<f64> = (0..200).map(|i| (i as f64 * 0.173).powf(1.1)).collect();
        let labels: Vec<usize> = (0..200).map(|i| (i * i + 3 * i) % 7 % 4).collect();
        let out = s.smooth(&times, &labels, 4);
        for i in 0..200 {
            let mut c = [0usize; 4];
            for j in 0..200 {
                if (times[j] - times[i]).abs() <= 0.65 {
                    c[labels[j]] += 1;
                }
            }
            let best = *c.iter().max().unwrap();
            let want = if c[labels[i]] == best {
                labels[i]
            } else {
                c.iter().position(|&x| x == best).unwrap()
            };
            assert_eq!(out[i], want, "entry {i}");
        }
    }

    #[test]
    fn flags_flipping_labels_only() {
        let f = PlacementFilter::default();
        let steady = vec![Some(1); 30];
        assert!(f.flags(&steady).iter().all(|&z| !z));
        let mut flip = vec![Some(1); 30];
        flip[15] = Some(2);
        flip[17] = Some(3);
        // Changes at 15, 16, 17, 18: four within ±7 of frames near 16.
        let flags = f.flags(&flip);
        assert!(flags[16]);
        assert!(!flags[0]);
        assert!(!flags[29]);
        // Two changes only (one excursion) are tolerated.
        let mut once = vec![Some(1); 30];
        once[15] = Some(2);
        assert!(f.flags(&once).iter().all(|&z| !z));
        // Unknown labels are skipped.
        let mut gaps = vec![Some(1); 10];
        gaps[4] = None;
        assert!(f.flags(&gaps).iter().all(|&z| !z));
        assert!(f.flags(&[]).is_empty());
    }
}
