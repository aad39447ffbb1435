//! The placement-change filter of the original code.
//!
//! A phone that is being moved between placements (pocket to hand, say) confuses the
//! placement classifier, whose label then flips back and forth; the regressed velocity of such
//! a moment is unreliable. The original zeroes a regressed velocity when more than two label
//! changes happen within ±7 regressions of it.

use serde::{Deserialize, Serialize};

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
    pub fn flags(&self, labels: &[Option<u32>]) -> Vec<bool> {
        // changes[i] = number of changes between consecutive known labels up to index i.
        let mut changes = Vec::with_capacity(labels.len());
        let mut prev: Option<u32> = None;
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
                let hi = (i + self.radius).min(labels.len() - 1);
                // Changes landing on indices lo+1..=hi happened inside the window; one landing
                // on lo came from a label before the window.
                changes[hi] - changes[lo] > self.max_changes
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
