//! Stretches where the motion capture's rotation contradicts the gyro's.
//!
//! Tyrex's mocap sometimes solves the rigid body flipped for a second or so (wrong marker
//! labelling): its orientation turns by up to half a turn and back, while the position stays
//! put. A tilt check cannot see a flip about the vertical; the gyro can, since over a tenth of a
//! second its integrated rotation is exact to a few hundredths of a degree. Targets are the
//! ground truth's velocity turned by the ground truth's orientation, so a flipped stretch
//! teaches the regressor a velocity pointing the wrong way.
//!
//! Two checks, one on changes and one on states. A window whose mocap rotation differs from
//! the gyro's finds the edges of a flip; the offset between the mocap's orientation and the
//! gyro's attitude, constant up to the gyro's drift wherever the mocap is right, finds what lies
//! between edges: a flip longer than [`MOCAP_MERGE_S`], or one already under way when the gyro
//! starts or the body reappears after a loss.

use ridi_frames::{Device, DeviceVec, Rot, WorldFromDevice};

use crate::resample::interpolate_rot;
use crate::validation::gyro_step;

/// Window over which the mocap's rotation is checked against the gyro's, s: long enough that a
/// flip interpolated across a short loss shows as one large disagreement, short enough that
/// gyro bias adds nothing (0.1 s at 0.01 rad/s is 0.06°).
pub const MOCAP_CHECK_WINDOW_S: f64 = 0.1;

/// Largest disagreement between the mocap's and the gyro's rotation over one window, rad, before
/// the mocap is taken as wrong. Flips disagree by up to π; everywhere else the shared runs agree
/// within 0.7 rad (40°, at worst in a pocket while running: marker jitter on impacts, and the
/// ~20 ms residual lag at rates up to 20 rad/s), which is left in: it is part of what the mocap
/// is.
pub const MAX_MOCAP_GYRO_RAD: f64 = 1.0;

/// Suspect windows closer than this, s, belong to one bad stretch: between two flips the body
/// is often still flipped even where the mocap and the gyro agree on the rotation.
pub const MOCAP_MERGE_S: f64 = 1.0;

/// Margin added on each side of a bad stretch, s.
pub const MOCAP_PAD_S: f64 = 0.25;

/// Shortest piece of mocap (between bad stretches and long losses) that other pieces are judged
/// against, s.
const MOCAP_ANCHOR_S: f64 = 2.0;

/// The stretches `(from, to)`, s, where the mocap (`mocap` at `mocap_time`) is wrong by the gyro
/// (`gyro` at `gyro_time`, both on one clock, both non-decreasing).
///
/// A window of [`MOCAP_CHECK_WINDOW_S`] is suspect when the rotation the mocap shows across it
/// and the one the gyro integrates over it differ by more than `max_rad`; suspect windows within
/// [`MOCAP_MERGE_S`] are merged into stretches. The stretches, and the mocap losses longer than
/// `max_gap_s`, cut the mocap into pieces; within each run of gyro samples without a gap longer
/// than the window (where the gyro's attitude is continuous), the longest piece is taken as
/// right, and outwards from it a piece whose offset between the mocap's orientation and the
/// gyro's attitude differs by more than twice `max_rad` from the nearest right piece of at
/// least 2 s (compared at their facing ends; twice, for the gyro's drift between them: up to
/// 0.02 rad/s on the shared runs, where a flip turns by 2.7-3.1 rad) is wrong as a whole. Each
/// stretch, and each wrong piece, is widened by [`MOCAP_PAD_S`]. Only mocap frames inside the gyro's time span are
/// judged; no window across a mocap loss longer than `max_gap_s` (the reader splits the
/// recording there) or a gyro gap. Empty when `max_rad` is infinite or either input has fewer
/// than two samples.
pub fn mocap_gyro_conflicts(
    mocap_time: &[f64],
    mocap: &[WorldFromDevice],
    gyro_time: &[f64],
    gyro: &[DeviceVec],
    max_rad: f64,
    max_gap_s: f64,
) -> Vec<(f64, f64)> {
    let (n, g) = (
        mocap_time.len().min(mocap.len()),
        gyro_time.len().min(gyro.len()),
    );
    if n < 2 || g < 2 || max_rad == f64::INFINITY {
        return Vec::new();
    }
    let gyro_time = &gyro_time[..g];
    // The gyro's attitude: each sample's device frame seen from the first sample's.
    let mut attitude: Vec<Rot<Device, Device>> = Vec::with_capacity(g);
    let mut q = Rot::<Device, Device>::identity();
    for k in 0..g {
        if k > 0 {
            let dt = (gyro_time[k] - gyro_time[k - 1]).max(0.0);
            q = q * gyro_step(dt, gyro[k - 1], gyro[k]);
        }
        attitude.push(q);
    }
    // Gyro steps longer than a window, counted up to each sample: the attitude is not
    // continuous across one (the reader splits there too, its sensor gap limit being 0.1 s).
    let gyro_gaps = gaps_before(gyro_time, MOCAP_CHECK_WINDOW_S);
    let gyro_gap_within = |a: f64, b: f64| {
        let i = gyro_time.partition_point(|&t| t < a);
        let j = gyro_time.partition_point(|&t| t <= b).min(g - 1);
        gyro_gaps[j] > gyro_gaps[i.saturating_sub(1).min(j)]
    };
    let (first, last) = (gyro_time[0], gyro_time[g - 1]);
    let from = mocap_time[..n].partition_point(|&t| t < first);
    let to = mocap_time[..n].partition_point(|&t| t <= last);
    if to <= from + 1 {
        return Vec::new();
    }
    let time = &mocap_time[from..to];
    let truth = &mocap[from..to];
    let by_gyro = interpolate_rot(gyro_time, &attitude, time);
    // The reader's split tolerance, so that a loss it bridges is judged.
    let lost = gaps_before(time, max_gap_s + crate::resample::GAP_TOLERANCE_S);

    // Edges: windows whose two rotations disagree, merged into stretches of frame indices.
    let mut stretches: Vec<(usize, usize)> = Vec::new();
    let mut end = 0;
    for k in 0..time.len() {
        while end + 1 < time.len() && time[end] < time[k] + MOCAP_CHECK_WINDOW_S {
            end += 1;
        }
        if end <= k {
            break;
        }
        if lost[end] > lost[k] || gyro_gap_within(time[k], time[end]) {
            continue;
        }
        let mocap_turn = truth[k].inverse() * truth[end];
        let gyro_turn = by_gyro[k].inverse() * by_gyro[end];
        if mocap_turn.angle_to(&gyro_turn) > max_rad {
            match stretches.last_mut() {
                Some(s) if time[k] - time[s.1] <= MOCAP_MERGE_S => s.1 = s.1.max(end),
                _ => stretches.push((k, end)),
            }
        }
    }

    // States: the pieces between stretches and long losses, each judged by its offset.
    let offset = |k: usize| truth[k] * by_gyro[k].inverse();
    let mut pieces: Vec<(usize, usize)> = Vec::new();
    let mut k = 0;
    let mut next = stretches.iter().peekable();
    while k < time.len() {
        if let Some(&&(_, b)) = next.peek().filter(|s| k >= s.0) {
            k = k.max(b + 1);
            next.next();
            continue;
        }
        let stop = next.peek().map_or(time.len(), |s| s.0);
        let mut e = k;
        while e + 1 < stop && lost[e + 1] == lost[e] {
            e += 1;
        }
        pieces.push((k, e));
        k = e + 1;
    }
    let mut wrong = Vec::new();
    let mut i = 0;
    while i < pieces.len() {
        // One run of pieces the gyro's attitude joins without a gap.
        let mut j = i;
        while j + 1 < pieces.len() && !gyro_gap_within(time[pieces[j].1], time[pieces[j + 1].0]) {
            j += 1;
        }
        let run = &pieces[i..=j];
        let span = |p: &(usize, usize)| time[p.1] - time[p.0];
        let best = (0..run.len())
            .max_by(|&a, &b| span(&run[a]).total_cmp(&span(&run[b])))
            .unwrap_or(0);
        // Outwards from the longest piece, each against the nearest right piece long enough
        // to be one (a short piece in a bad stretch may agree by chance).
        let mut right = best;
        for p in best + 1..run.len() {
            if offset(run[p].0).angle_to(&offset(run[right].1)) > 2.0 * max_rad {
                wrong.push(run[p]);
            } else if span(&run[p]) >= MOCAP_ANCHOR_S {
                right = p;
            }
        }
        right = best;
        for p in (0..best).rev() {
            if offset(run[p].1).angle_to(&offset(run[right].0)) > 2.0 * max_rad {
                wrong.push(run[p]);
            } else if span(&run[p]) >= MOCAP_ANCHOR_S {
                right = p;
            }
        }
        i = j + 1;
    }

    let mut out: Vec<(f64, f64)> = stretches
        .iter()
        .chain(&wrong)
        .map(|&(a, b)| (time[a] - MOCAP_PAD_S, time[b] + MOCAP_PAD_S))
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Overlapping stretches become one.
    let mut merged: Vec<(f64, f64)> = Vec::with_capacity(out.len());
    for (a, b) in out {
        match merged.last_mut() {
            Some(m) if a <= m.1 => m.1 = m.1.max(b),
            _ => merged.push((a, b)),
        }
    }
    merged
}

/// For each of `time`, how many steps before it are longer than `limit`.
fn gaps_before(time: &[f64], limit: f64) -> Vec<usize> {
    let mut gaps = 0usize;
    (0..time.len())
        .map(|k| {
            if k > 0 && time[k] - time[k - 1] > limit {
                gaps += 1;
            }
            gaps
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use ridi_frames::World;
    use ridi_frames::nalgebra::Vector3;

    /// A body turning steadily about `axis` at 2 rad/s, seen by a 200 Hz gyro and a 100 Hz
    /// mocap whose rotation is turned by half a turn about z (a flip) inside `flipped`.
    fn scene(flipped: &[(f64, f64)]) -> (Vec<f64>, Vec<WorldFromDevice>, Vec<f64>, Vec<DeviceVec>) {
        let rate = Vector3::new(0.3, -0.4, 2.0);
        let gyro_time: Vec<f64> = (0..4000).map(|i| i as f64 / 200.0).collect();
        let gyro = vec![DeviceVec::new(rate.x, rate.y, rate.z); gyro_time.len()];
        let mocap_time: Vec<f64> = (0..2000).map(|i| 0.003 + i as f64 / 100.0).collect();
        let flip =
            Rot::<World, World>::from_scaled_axis(Vector3::new(0.0, 0.0, std::f64::consts::PI));
        let mocap = mocap_time
            .iter()
            .map(|&t| {
                let q = WorldFromDevice::from_scaled_axis(rate * t);
                if flipped.iter().any(|&(a, b)| t >= a && t <= b) {
                    flip * q
                } else {
                    q
                }
            })
            .collect();
        (mocap_time, mocap, gyro_time, gyro)
    }

    #[test]
    fn a_mocap_that_turns_as_the_gyro_does_is_trusted() {
        let (mt, m, gt, g) = scene(&[]);
        assert!(mocap_gyro_conflicts(&mt, &m, &gt, &g, MAX_MOCAP_GYRO_RAD, 0.25).is_empty());
    }

    #[test]
    fn flips_are_found_merged_and_padded() {
        // Two flips 0.5 s apart make one stretch; one 6 s later another.
        let (mt, m, gt, g) = scene(&[(5.0, 5.3), (5.8, 6.0), (12.0, 12.2)]);
        let found = mocap_gyro_conflicts(&mt, &m, &gt, &g, MAX_MOCAP_GYRO_RAD, 0.25);
        assert_eq!(found.len(), 2, "{found:?}");
        // Each stretch covers its flips with the margin, and not much more: the first suspect
        // window starts a window before the flip, the last ends a window after it.
        let (a, b) = found[0];
        assert!(
            (5.0 - MOCAP_PAD_S - 0.12..=5.0 - MOCAP_PAD_S).contains(&a),
            "{a}"
        );
        assert!(
            (6.0 + MOCAP_PAD_S..=6.0 + MOCAP_PAD_S + 0.12).contains(&b),
            "{b}"
        );
        let (a, b) = found[1];
        assert!(
            a <= 12.0 - MOCAP_PAD_S && b >= 12.2 + MOCAP_PAD_S,
            "{a} {b}"
        );
        assert!(b - a < 0.2 + 2.0 * MOCAP_PAD_S + 0.25, "{a} {b}");
        // An infinite limit trusts the mocap.
        assert!(mocap_gyro_conflicts(&mt, &m, &gt, &g, f64::INFINITY, 0.25).is_empty());
    }

    #[test]
    fn only_mocap_frames_the_gyro_covers_are_judged() {
        // Flipped outside the gyro's span (it ends at 20 s, the mocap runs on past it below).
        let (mut mt, mut m, gt, g) = scene(&[]);
        let flip = WorldFromDevice::from_scaled_axis(Vector3::new(0.0, 0.0, 3.0));
        for i in 0..200 {
            mt.push(20.5 + i as f64 / 100.0);
            m.push(if i % 20 < 10 {
                flip
            } else {
                WorldFromDevice::identity()
            });
        }
        assert!(mocap_gyro_conflicts(&mt, &m, &gt, &g, MAX_MOCAP_GYRO_RAD, 0.25).is_empty());
        // Nor across a gap in the gyro, where its integration knows nothing.
        let (mt, m, mut gt, mut g) = scene(&[(8.1, 8.4)]);
        let keep: Vec<bool> = gt.iter().map(|&t| !(8.0..8.5).contains(&t)).collect();
        let mut k = keep.iter();
        gt.retain(|_| *k.next().unwrap());
        let mut k = keep.iter();
        g.retain(|_| *k.next().unwrap());
        assert!(mocap_gyro_conflicts(&mt, &m, &gt, &g, MAX_MOCAP_GYRO_RAD, 0.25).is_empty());
        // Too little to judge.
        assert!(mocap_gyro_conflicts(&mt[..1], &m[..1], &gt, &g, 1.0, 0.25).is_empty());
        assert!(mocap_gyro_conflicts(&mt, &m, &gt[..1], &g[..1], 1.0, 0.25).is_empty());
    }

    /// `scene` with the mocap frames at `lost` times left out.
    fn with_losses(
        flipped: &[(f64, f64)],
        lost: impl Fn(f64) -> bool,
    ) -> (Vec<f64>, Vec<WorldFromDevice>, Vec<f64>, Vec<DeviceVec>) {
        let (mt, m, gt, g) = scene(flipped);
        let (mt, m) = mt.iter().zip(m).filter(|(t, _)| !lost(**t)).unzip();
        (mt, m, gt, g)
    }

    #[test]
    fn a_flip_longer_than_the_merge_window_is_cut_whole() {
        // 3 s flipped: its two edges are 3 s apart, the state between them is flipped too.
        let (mt, m, gt, g) = scene(&[(6.0, 9.0)]);
        let found = mocap_gyro_conflicts(&mt, &m, &gt, &g, MAX_MOCAP_GYRO_RAD, 0.25);
        assert_eq!(found.len(), 1, "{found:?}");
        let (a, b) = found[0];
        assert!(
            (6.0 - MOCAP_PAD_S - 0.12..=6.0 - MOCAP_PAD_S).contains(&a),
            "{a}"
        );
        assert!(
            (9.0 + MOCAP_PAD_S..9.0 + MOCAP_PAD_S + 0.12).contains(&b),
            "{b}"
        );
    }

    #[test]
    fn a_flip_at_the_start_or_after_a_loss_is_cut() {
        // Flipped from the first frame to 1.5 s: only the edge back is seen, and the piece
        // before it disagrees with the longer piece after.
        let (mt, m, gt, g) = scene(&[(0.0, 1.5)]);
        let found = mocap_gyro_conflicts(&mt, &m, &gt, &g, MAX_MOCAP_GYRO_RAD, 0.25);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(
            found[0].0 < mt[0] && found[0].1 >= 1.5 + MOCAP_PAD_S,
            "{found:?}"
        );
        // The body comes back flipped after a half-second loss (no window spans a loss the
        // reader splits at) and is flipped until 11 s.
        let (mt, m, gt, g) = with_losses(&[(8.5, 11.0)], |t| (8.0..8.5).contains(&t));
        let found = mocap_gyro_conflicts(&mt, &m, &gt, &g, MAX_MOCAP_GYRO_RAD, 0.25);
        assert_eq!(found.len(), 1, "{found:?}");
        let (a, b) = found[0];
        assert!(
            a <= 8.51 - MOCAP_PAD_S && b >= 11.0 + MOCAP_PAD_S,
            "{a} {b}"
        );
        // Flipped only between two half-second losses: an island the state check finds (the
        // reader would split around it anyway), where the window check skips the losses.
        let (mt, m, gt, g) = with_losses(&[(8.5, 8.6)], |t| {
            (8.0..8.5).contains(&t) || (8.6..9.1).contains(&t)
        });
        let found = mocap_gyro_conflicts(&mt, &m, &gt, &g, MAX_MOCAP_GYRO_RAD, 0.25);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(found[0].0 < 8.5 && found[0].1 > 8.6, "{found:?}");
        // A loss of exactly the limit (15 frames at 60 Hz in the reader) is judged across.
        let (mt, m, gt, g) = with_losses(&[], |t| (8.0..8.24).contains(&t));
        assert!(mocap_gyro_conflicts(&mt, &m, &gt, &g, MAX_MOCAP_GYRO_RAD, 0.25).is_empty());
    }
}
