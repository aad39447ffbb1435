//! 2D rigid alignment of a trajectory onto ground truth.
//!
//! Inertial trajectories start in an arbitrary horizontal frame (unknown initial heading and
//! position), so before any error is measured the estimate is moved onto the ground truth with
//! the rigid transform (rotation + translation, no scale) that best fits an initial stretch of
//! the sequence. RIDI fits on the first 10 s (2000 frames); fitting on a prefix rather than the
//! whole sequence keeps the drift that the metrics are meant to measure.

use serde::{Deserialize, Serialize};

use crate::error::{
    EvalError, Result, check_finite_points, check_non_empty, check_positive, check_same_len,
    check_times,
};

/// A 2D rigid transform `p ↦ R(angle) p + translation`.
///
/// `R(θ) = [[cos θ, −sin θ], [sin θ, cos θ]]` rotates counter-clockwise by `θ` radians.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rigid2 {
    /// Rotation angle, radians, counter-clockwise, in `(−π, π]`.
    pub angle: f64,
    /// Translation applied after the rotation.
    pub translation: [f64; 2],
}

impl Default for Rigid2 {
    fn default() -> Self {
        Self::identity()
    }
}

impl Rigid2 {
    /// The transform that leaves every point in place.
    pub const fn identity() -> Self {
        Self {
            angle: 0.0,
            translation: [0.0, 0.0],
        }
    }

    /// Builds a transform from an angle (radians) and a translation.
    pub fn new(angle: f64, translation: [f64; 2]) -> Self {
        Self { angle, translation }
    }

    /// Rotation matrix `R(angle)`, row-major.
    pub fn rotation_matrix(&self) -> [[f64; 2]; 2] {
        let (s, c) = self.angle.sin_cos();
        [[c, -s], [s, c]]
    }

    /// Applies the transform to one point: `R p + t`.
    pub fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.angle.sin_cos();
        [
            c * p[0] - s * p[1] + self.translation[0],
            s * p[0] + c * p[1] + self.translation[1],
        ]
    }

    /// Applies the transform to every point of a trajectory.
    pub fn apply_all(&self, points: &[[f64; 2]]) -> Vec<[f64; 2]> {
        points.iter().map(|&p| self.apply(p)).collect()
    }

    /// The transform `q ↦ R⁻¹ (q − t)` that undoes this one.
    pub fn inverse(&self) -> Self {
        let back = Self::new(-self.angle, [0.0, 0.0]).apply(self.translation);
        Self::new(-self.angle, [-back[0], -back[1]])
    }

    /// `self ∘ other`: applies `other` first, then `self`.
    pub fn compose(&self, other: &Self) -> Self {
        let angle = wrap_angle(self.angle + other.angle);
        Self::new(angle, self.apply(other.translation))
    }
}

/// Wraps an angle into `(−π, π]`.
fn wrap_angle(a: f64) -> f64 {
    let w = a.sin().atan2(a.cos());
    // atan2 returns −π for a negative-zero sine; keep one representative of the half-turn.
    if w == -std::f64::consts::PI {
        std::f64::consts::PI
    } else {
        w
    }
}

/// Least-squares rigid transform taking `source` onto `target` (2D Kabsch/Umeyama, no scale).
///
/// Minimises `Σᵢ ‖R(θ) sᵢ + t − qᵢ‖²`. With centroids `s̄`, `q̄` and centred points
/// `s'ᵢ = sᵢ − s̄`, `q'ᵢ = qᵢ − q̄`, the closed form is
///
/// ```text
/// θ = atan2( Σ (s'ₓ q'_y − s'_y q'ₓ),  Σ (s'ₓ q'ₓ + s'_y q'_y) )
/// t = q̄ − R(θ) s̄
/// ```
///
/// which is always a proper rotation (no reflection can arise in this parametrisation).
///
/// Degenerate case: when the source points all coincide (one point, or a device that never
/// moved during the fit window) the rotation is undetermined. The result is then the identity
/// rotation with `t = q̄ − s̄` (for a single point, the translation taking the first source point
/// onto the first target point); [`Rigid2`] carries no flag, use [`fit_alignment`] to learn
/// whether this happened. If instead only the target is stationary, every rotation fits equally
/// well and whichever angle the formula yields is returned.
///
/// # Errors
/// Empty inputs, different lengths, or non-finite coordinates.
pub fn fit_rigid_2d(source: &[[f64; 2]], target: &[[f64; 2]]) -> Result<Rigid2> {
    fit_rigid_2d_flagged(source, target).map(|(t, _)| t)
}

/// [`fit_rigid_2d`] plus whether the degenerate fallback was used.
fn fit_rigid_2d_flagged(source: &[[f64; 2]], target: &[[f64; 2]]) -> Result<(Rigid2, bool)> {
    check_non_empty("alignment source", source.len())?;
    check_same_len("alignment source vs target", source.len(), target.len())?;
    check_finite_points("alignment source", source)?;
    check_finite_points("alignment target", target)?;

    let n = source.len() as f64;
    let centroid = |pts: &[[f64; 2]]| {
        let s = pts
            .iter()
            .fold([0.0, 0.0], |a, p| [a[0] + p[0], a[1] + p[1]]);
        [s[0] / n, s[1] / n]
    };
    let sc = centroid(source);
    let qc = centroid(target);

    let mut dot = 0.0;
    let mut cross = 0.0;
    let mut spread = 0.0;
    let mut scale: f64 = 1.0;
    for (s, q) in source.iter().zip(target) {
        let (sx, sy) = (s[0] - sc[0], s[1] - sc[1]);
        let (qx, qy) = (q[0] - qc[0], q[1] - qc[1]);
        dot += sx * qx + sy * qy;
        cross += sx * qy - sy * qx;
        spread += sx * sx + sy * sy;
        scale = scale.max(s[0].abs()).max(s[1].abs());
    }

    // Centring far from the origin leaves rounding noise of order |coordinate| · ε; a spread
    // below that is not a shape, and the angle fitted to it would be noise.
    let tol = 64.0 * f64::EPSILON * scale;
    if spread <= n * tol * tol {
        let t = [qc[0] - sc[0], qc[1] - sc[1]];
        return Ok((Rigid2::new(0.0, t), true));
    }

    let angle = wrap_angle(cross.atan2(dot));
    let rotated = Rigid2::new(angle, [0.0, 0.0]).apply(sc);
    Ok((
        Rigid2::new(angle, [qc[0] - rotated[0], qc[1] - rotated[1]]),
        false,
    ))
}

/// Which initial stretch of a sequence the alignment is fitted on.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AlignWindow {
    /// Frames whose time satisfies `t − t₀ < seconds` (10 s in RIDI, i.e. 2000 frames at 200 Hz).
    Seconds(f64),
    /// The first `n` frames (all of them if the sequence is shorter).
    Frames(usize),
    /// The whole sequence (a best-case view that hides initial-heading errors).
    All,
}

impl Default for AlignWindow {
    /// RIDI's choice: the first 10 s.
    fn default() -> Self {
        Self::Seconds(10.0)
    }
}

impl AlignWindow {
    /// Number of leading frames of `times` that this window covers (at least one).
    ///
    /// # Errors
    /// Invalid timeline (empty, non-finite, decreasing), `Seconds` not finite and positive, or
    /// `Frames(0)`.
    pub fn frame_count(&self, times: &[f64]) -> Result<usize> {
        check_times(times)?;
        match *self {
            Self::Seconds(s) => {
                check_positive("align window seconds", s)?;
                let t0 = times[0];
                Ok(times.partition_point(|&t| t - t0 < s))
            }
            Self::Frames(0) => Err(EvalError::InvalidParameter {
                name: "align window frames",
                reason: "must be at least 1".into(),
            }),
            Self::Frames(n) => Ok(n.min(times.len())),
            Self::All => Ok(times.len()),
        }
    }
}

/// A fitted alignment and how it was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AlignmentFit {
    /// Transform taking the estimate onto the ground truth.
    pub transform: Rigid2,
    /// Number of leading frames used for the fit.
    pub frames_used: usize,
    /// True when the estimate did not move within the fit window, so only a translation was
    /// fitted (see [`fit_rigid_2d`]).
    pub degenerate: bool,
    /// How far the ground truth moved within the fit window, metres: the largest distance of
    /// a ground-truth point in the window from the window's first one
    /// ([`target_extent`]). The fitted rotation is only as good as this lever: below
    /// [`WEAK_ALIGNMENT_EXTENT_M`] it rests on a few steps, or on noise when the walker stood
    /// still, and every later error inherits the heading error.
    pub target_extent_m: f64,
}

impl AlignmentFit {
    /// True when the ground truth moved less than [`WEAK_ALIGNMENT_EXTENT_M`] within the fit
    /// window, so the fitted heading is weakly determined.
    pub fn is_weak(&self) -> bool {
        self.target_extent_m < WEAK_ALIGNMENT_EXTENT_M
    }
}

/// Ground-truth travel (metres) below which an alignment's rotation counts as weakly
/// determined ([`AlignmentFit::is_weak`]).
///
/// One metre is about a step and a half: over a shorter lever, an estimate off by 0.3 m at the
/// end of the window (a normal error over 10 s) already turns the fit by 15 degrees or more.
pub const WEAK_ALIGNMENT_EXTENT_M: f64 = 1.0;

/// The largest distance of a point of `points` from the first one, metres (0 for no points).
pub fn target_extent(points: &[[f64; 2]]) -> f64 {
    let Some(&first) = points.first() else {
        return 0.0;
    };
    points
        .iter()
        .map(|p| (p[0] - first[0]).hypot(p[1] - first[1]))
        .fold(0.0, f64::max)
}

/// Fits the rigid transform taking `est` onto `gt` over the initial `window` of the timeline.
///
/// # Errors
/// Invalid timeline, lengths that differ between `times`, `est` and `gt`, non-finite
/// coordinates inside the window, or an invalid window.
pub fn fit_alignment(
    times: &[f64],
    est: &[[f64; 2]],
    gt: &[[f64; 2]],
    window: AlignWindow,
) -> Result<AlignmentFit> {
    check_same_len("times vs estimate", times.len(), est.len())?;
    check_same_len("times vs ground truth", times.len(), gt.len())?;
    let frames_used = window.frame_count(times)?;
    let (transform, degenerate) = fit_rigid_2d_flagged(&est[..frames_used], &gt[..frames_used])?;
    Ok(AlignmentFit {
        transform,
        frames_used,
        degenerate,
        target_extent_m: target_extent(&gt[..frames_used]),
    })
}

/// Fits the alignment on the initial `window` and applies it to the whole estimate.
///
/// Returns the fit and the aligned estimate (same length as `est`).
///
/// # Errors
/// As [`fit_alignment`], plus non-finite coordinates anywhere in `est`.
pub fn align_trajectory(
    times: &[f64],
    est: &[[f64; 2]],
    gt: &[[f64; 2]],
    window: AlignWindow,
) -> Result<(AlignmentFit, Vec<[f64; 2]>)> {
    let fit = fit_alignment(times, est, gt, window)?;
    check_finite_points("estimate", est)?;
    Ok((fit, fit.transform.apply_all(est)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn close(a: [f64; 2], b: [f64; 2], tol: f64) -> bool {
        (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol
    }

    fn sample_path() -> Vec<[f64; 2]> {
        (0..50)
            .map(|i| {
                let t = f64::from(i) * 0.1;
                [t * 1.3 + (2.0 * t).sin(), 0.5 * t * t - t.cos()]
            })
            .collect()
    }

    #[test]
    fn recovers_known_rotation_and_translation() {
        let truth = Rigid2::new(0.7, [3.0, -2.0]);
        let src = sample_path();
        let dst = truth.apply_all(&src);
        let fit = fit_rigid_2d(&src, &dst).unwrap();
        assert!((fit.angle - 0.7).abs() < 1e-12, "angle {}", fit.angle);
        assert!(close(fit.translation, [3.0, -2.0], 1e-12));
    }

    #[test]
    fn recovers_half_turn_without_reflection() {
        let truth = Rigid2::new(std::f64::consts::PI, [1.0, 1.0]);
        let src = sample_path();
        let dst = truth.apply_all(&src);
        let fit = fit_rigid_2d(&src, &dst).unwrap();
        for (p, q) in src.iter().zip(&dst) {
            assert!(close(fit.apply(*p), *q, 1e-9));
        }
        assert!((fit.angle.abs() - std::f64::consts::PI).abs() < 1e-12);
    }

    #[test]
    fn least_squares_angle_of_a_noisy_cross() {
        // Four points at ±1 on the axes, target rotated by +90° except one point nudged: the
        // optimum is computable by hand. Source centred at 0; target centred at (0, 0.25).
        let src = [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]];
        let dst = [[0.0, 2.0], [-1.0, 0.0], [0.0, -1.0], [1.0, 0.0]];
        // Centred target: (0,1.75), (−1,−0.25), (0,−1.25), (1,−0.25).
        // dot = 0 + (−0.25) + 0 + 0.25 = 0; cross = 1.75 + 1 + 1.25 + 1 = 5 → θ = π/2.
        let fit = fit_rigid_2d(&src, &dst).unwrap();
        assert!((fit.angle - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert!(close(fit.translation, [0.0, 0.25], 1e-12));
    }

    #[test]
    fn single_point_is_pure_translation() {
        let fit = fit_alignment(&[0.0], &[[1.0, 2.0]], &[[4.0, 6.0]], AlignWindow::All).unwrap();
        assert!(fit.degenerate);
        assert_eq!(fit.transform, Rigid2::new(0.0, [3.0, 4.0]));
    }

    #[test]
    fn stationary_estimate_is_degenerate_far_from_origin() {
        let est = vec![[1.0e6, -2.0e6]; 20];
        let gt: Vec<[f64; 2]> = (0..20).map(|i| [f64::from(i), 0.0]).collect();
        let times: Vec<f64> = (0..20).map(|i| f64::from(i) * 0.005).collect();
        let fit = fit_alignment(&times, &est, &gt, AlignWindow::All).unwrap();
        assert!(fit.degenerate);
        assert_eq!(fit.transform.angle, 0.0);
        assert!(close(fit.transform.apply(est[0]), [9.5, 0.0], 1e-9));
    }

    #[test]
    fn window_selection_by_time_and_frames() {
        let times: Vec<f64> = (0..3000).map(|i| f64::from(i) / 200.0).collect();
        assert_eq!(
            AlignWindow::Seconds(10.0).frame_count(&times).unwrap(),
            2000
        );
        assert_eq!(AlignWindow::Frames(10).frame_count(&times).unwrap(), 10);
        assert_eq!(AlignWindow::Frames(5000).frame_count(&times).unwrap(), 3000);
        assert_eq!(AlignWindow::All.frame_count(&times).unwrap(), 3000);
        assert!(AlignWindow::Frames(0).frame_count(&times).is_err());
        assert!(AlignWindow::Seconds(0.0).frame_count(&times).is_err());
        assert!(AlignWindow::Seconds(f64::NAN).frame_count(&times).is_err());
    }

    #[test]
    fn fit_uses_only_the_window() {
        // The estimate matches ground truth rotated by 0.3 for the first second, then drifts;
        // a 1 s window must recover exactly 0.3 regardless of the drift.
        let times: Vec<f64> = (0..400).map(|i| f64::from(i) / 200.0).collect();
        let gt: Vec<[f64; 2]> = times.iter().map(|&t| [t, (3.0 * t).sin()]).collect();
        let to_est = Rigid2::new(0.3, [1.0, 2.0]).inverse();
        let mut est = to_est.apply_all(&gt);
        for p in est.iter_mut().skip(200) {
            p[0] += 5.0;
        }
        let (fit, aligned) =
            align_trajectory(&times, &est, &gt, AlignWindow::Seconds(1.0)).unwrap();
        assert_eq!(fit.frames_used, 200);
        assert!(!fit.degenerate);
        assert!((fit.transform.angle - 0.3).abs() < 1e-12);
        assert!(close(aligned[100], gt[100], 1e-12));
        assert!((aligned[300][0] - gt[300][0]).abs() > 1.0);
    }

    #[test]
    fn extent_measures_the_ground_truth_lever_inside_the_window() {
        // Stands (swaying by 5 cm) for the first 10 s, then walks at 1.2 m/s along y.
        let times: Vec<f64> = (0..4000).map(|i| f64::from(i) / 200.0).collect();
        let gt: Vec<[f64; 2]> = times
            .iter()
            .map(|&t| {
                let sway = 0.05 * (2.0 * t).sin();
                [sway, 1.2 * (t - 10.0).max(0.0)]
            })
            .collect();
        let est = Rigid2::new(0.4, [3.0, -1.0]).apply_all(&gt);
        let standing = fit_alignment(&times, &est, &gt, AlignWindow::default()).unwrap();
        assert!((standing.target_extent_m - 0.05).abs() < 1e-6);
        assert!(standing.is_weak());
        let whole = fit_alignment(&times, &est, &gt, AlignWindow::All).unwrap();
        assert!((whole.target_extent_m - 12.0).abs() < 0.01);
        assert!(!whole.is_weak());
        assert_eq!(target_extent(&[]), 0.0);
        assert_eq!(target_extent(&[[4.0, 5.0]]), 0.0);
        assert_eq!(target_extent(&[[0.0, 0.0], [3.0, 4.0], [1.0, 0.0]]), 5.0);
    }

    #[test]
    fn bad_inputs_are_errors() {
        assert!(matches!(
            fit_rigid_2d(&[], &[]),
            Err(EvalError::Empty { .. })
        ));
        assert!(matches!(
            fit_rigid_2d(&[[0.0, 0.0]], &[[0.0, 0.0], [1.0, 1.0]]),
            Err(EvalError::LengthMismatch { .. })
        ));
        assert!(matches!(
            fit_rigid_2d(&[[f64::NAN, 0.0]], &[[0.0, 0.0]]),
            Err(EvalError::NonFinite { .. })
        ));
        assert!(matches!(
            fit_alignment(
                &[1.0, 0.0],
                &[[0.0; 2]; 2],
                &[[0.0; 2]; 2],
                AlignWindow::All
            ),
            Err(EvalError::TimeDecreasing { index: 1 })
        ));
        assert!(matches!(
            fit_alignment(&[0.0], &[[0.0; 2]; 2], &[[0.0; 2]; 2], AlignWindow::All),
            Err(EvalError::LengthMismatch { .. })
        ));
    }

    #[test]
    fn inverse_and_compose() {
        let a = Rigid2::new(1.1, [0.5, -4.0]);
        let b = Rigid2::new(-2.5, [2.0, 1.0]);
        let p = [0.3, 7.0];
        assert!(close(a.inverse().apply(a.apply(p)), p, 1e-12));
        assert!(close(a.compose(&b).apply(p), a.apply(b.apply(p)), 1e-12));
        let m = a.rotation_matrix();
        let r = a.apply(p);
        assert!(close(
            [
                m[0][0] * p[0] + m[0][1] * p[1] + 0.5,
                m[1][0] * p[0] + m[1][1] * p[1] - 4.0
            ],
            r,
            1e-12
        ));
    }

    proptest! {
        #[test]
        fn aligning_a_rigid_copy_leaves_no_error(
            angle in -std::f64::consts::PI..std::f64::consts::PI,
            tx in -1.0e3f64..1.0e3,
            ty in -1.0e3f64..1.0e3,
            pts in prop::collection::vec((-100.0f64..100.0, -100.0f64..100.0), 2..40),
        ) {
            let src: Vec<[f64; 2]> = pts.iter().map(|&(x, y)| [x, y]).collect();
            let spread = src.iter().map(|p| (p[0] - src[0][0]).hypot(p[1] - src[0][1])).fold(0.0, f64::max);
            prop_assume!(spread > 1e-3);
            let dst = Rigid2::new(angle, [tx, ty]).apply_all(&src);
            let fit = fit_rigid_2d(&src, &dst).unwrap();
            let angle_error = wrap_angle(fit.angle - angle).abs();
            prop_assert!(angle_error < 1e-6, "angle {} vs {angle}", fit.angle);
            for (p, q) in src.iter().zip(&dst) {
                let a = fit.apply(*p);
                prop_assert!((a[0] - q[0]).abs() < 1e-7 && (a[1] - q[1]).abs() < 1e-7,
                    "{a:?} vs {q:?}");
            }
        }
    }
}
