//! Resampling onto a timeline: linear interpolation for vectors and scalars, slerp for
//! rotations. Outside the source span values are held at the nearest end.

use ridi_frames::{Frame, Rot, Vec3};

/// Interpolates `src` (sampled at strictly increasing `src_t`) at each time of `dst_t`
/// (non-decreasing), blending neighbours with `mix(a, b, t)`. Linear in `src.len() + dst_t.len()`.
///
/// # Panics
/// When `src` is empty or its length differs from `src_t`'s.
pub(crate) fn interpolate_with<T: Clone>(
    src_t: &[f64],
    src: &[T],
    dst_t: &[f64],
    mix: impl Fn(&T, &T, f64) -> T,
) -> Vec<T> {
    assert_eq!(src_t.len(), src.len(), "times and values differ in length");
    assert!(!src.is_empty(), "nothing to interpolate from");
    let last = src.len() - 1;
    let mut j = 0;
    dst_t
        .iter()
        .map(|&t| {
            if t <= src_t[0] {
                return src[0].clone();
            }
            if t >= src_t[last] {
                return src[last].clone();
            }
            while src_t[j + 1] < t {
                j += 1;
            }
            let (t0, t1) = (src_t[j], src_t[j + 1]);
            mix(&src[j], &src[j + 1], (t - t0) / (t1 - t0))
        })
        .collect()
}

/// Linear interpolation of scalars.
pub(crate) fn interpolate_scalar(src_t: &[f64], src: &[f64], dst_t: &[f64]) -> Vec<f64> {
    interpolate_with(src_t, src, dst_t, |a, b, t| a + (b - a) * t)
}

/// Linear interpolation of vectors.
pub(crate) fn interpolate_vec3<F: Frame>(
    src_t: &[f64],
    src: &[Vec3<F>],
    dst_t: &[f64],
) -> Vec<Vec3<F>> {
    interpolate_with(src_t, src, dst_t, |a, b, t| a.lerp(*b, t))
}

/// Spherical linear interpolation of rotations (shortest path).
pub(crate) fn interpolate_rot<A: Frame, B: Frame>(
    src_t: &[f64],
    src: &[Rot<A, B>],
    dst_t: &[f64],
) -> Vec<Rot<A, B>> {
    interpolate_with(src_t, src, dst_t, |a, b, t| a.slerp(b, t))
}

/// A uniform timeline from `start` to at most `end` at `rate_hz`.
pub(crate) fn uniform_timeline(start: f64, end: f64, rate_hz: f64) -> Vec<f64> {
    if !(end >= start && rate_hz > 0.0 && start.is_finite() && end.is_finite()) {
        return Vec::new();
    }
    let n = ((end - start) * rate_hz + 1e-9).floor() as usize + 1;
    (0..n).map(|i| start + i as f64 / rate_hz).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use ridi_frames::{DeviceVec, WorldFromDevice};

    #[test]
    fn scalar_interpolation_is_linear_and_clamped() {
        let t = [0.0, 1.0, 3.0];
        let v = [0.0, 10.0, 30.0];
        let out = interpolate_scalar(&t, &v, &[-1.0, 0.5, 1.0, 2.0, 3.0, 4.0]);
        assert_eq!(out, vec![0.0, 5.0, 10.0, 20.0, 30.0, 30.0]);
    }

    #[test]
    fn vec3_interpolation_is_componentwise() {
        let t = [0.0, 2.0];
        let v = [
            DeviceVec::new(0.0, 2.0, -4.0),
            DeviceVec::new(2.0, 4.0, 0.0),
        ];
        let out = interpolate_vec3(&t, &v, &[0.5]);
        assert_eq!(out[0], DeviceVec::new(0.5, 2.5, -3.0));
    }

    #[test]
    fn rotation_interpolation_halves_the_angle() {
        let a = WorldFromDevice::identity();
        let axis = ridi_frames::nalgebra::Vector3::z_axis();
        let b = WorldFromDevice::from_axis_angle(&axis, 1.0);
        let out = interpolate_rot(&[0.0, 1.0], &[a, b], &[0.25]);
        assert!((out[0].angle_to(&a) - 0.25).abs() < 1e-12);
    }

    #[test]
    fn uniform_timeline_includes_both_ends_when_they_fit() {
        let t = uniform_timeline(1.0, 2.0, 200.0);
        assert_eq!(t.len(), 201);
        assert!((t[200] - 2.0).abs() < 1e-12);
        assert!(uniform_timeline(2.0, 1.0, 200.0).is_empty());
    }
}
