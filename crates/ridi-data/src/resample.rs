//! Resampling onto a timeline: linear interpolation for vectors and scalars, slerp for
//! rotations. Outside the source span values are held at the nearest end. [`Interpolator`]
//! does it on a stream of samples (a raw folder read row by row); the slice functions are it
//! on samples in memory, so that both give the same bits.

use std::convert::Infallible;

use ridi_frames::{Frame, Rot, Vec3};

/// Interpolates a stream of samples (strictly increasing times) at non-decreasing times,
/// blending the two neighbours of a time with a `mix(a, b, t)` ([`lerp_scalar`],
/// [`lerp_vec3`], [`slerp`]); before the first sample the first is held, from the last on
/// the last. Holds two samples: memory does not grow with the stream. `E` is the error a
/// sample of the stream may be instead.
pub(crate) struct Interpolator<T, I> {
    samples: I,
    /// The first sample.
    first: (f64, T),
    /// Time of the last sample.
    last_time: f64,
    /// The latest sample before the latest time asked for, and the one after it (none once
    /// the stream ended).
    before: (f64, T),
    after: Option<(f64, T)>,
}

impl<T: Clone, E, I: Iterator<Item = Result<(f64, T), E>>> Interpolator<T, I> {
    /// The interpolator of the sample `first` and the `rest` after it; the last sample is at
    /// `last_time` (a stream that ends elsewhere is its source's to refuse: [`Self::at`] holds
    /// whatever sample comes last).
    pub(crate) fn new(first: (f64, T), mut rest: I, last_time: f64) -> Result<Self, E> {
        let after = rest.next().transpose()?;
        Ok(Self {
            samples: rest,
            first: first.clone(),
            last_time,
            before: first,
            after,
        })
    }

    /// Moves on by one sample.
    fn advance(&mut self) -> Result<(), E> {
        if let Some(next) = self.after.take() {
            self.before = next;
            self.after = self.samples.next().transpose()?;
        }
        Ok(())
    }

    /// The value at `t`, not before the time of the previous call.
    pub(crate) fn at(&mut self, t: f64, mix: impl Fn(&T, &T, f64) -> T) -> Result<T, E> {
        if t <= self.first.0 {
            return Ok(self.first.1.clone());
        }
        if t >= self.last_time {
            self.read_to_end()?;
        }
        while self.after.as_ref().is_some_and(|a| a.0 < t) {
            self.advance()?;
        }
        let (t0, a) = &self.before;
        Ok(match &self.after {
            Some((t1, b)) => mix(a, b, (t - t0) / (t1 - t0)),
            // Read to its end: the last sample, held.
            None => a.clone(),
        })
    }

    /// Reads the rest of the stream, to its end.
    pub(crate) fn read_to_end(&mut self) -> Result<(), E> {
        while self.after.is_some() {
            self.advance()?;
        }
        Ok(())
    }
}

/// Interpolates `src` (sampled at strictly increasing `src_t`) at each time of `dst_t`
/// (non-decreasing), blending neighbours with `mix(a, b, t)`: an [`Interpolator`] over the
/// slices. Linear in `src.len() + dst_t.len()`.
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
    let mut samples = src_t.iter().copied().zip(src.iter().cloned());
    let first = samples.next().expect("not empty: checked above");
    let last_time = src_t[src.len() - 1];
    let Ok(mut at) = Interpolator::new(first, samples.map(Ok::<_, Infallible>), last_time);
    dst_t
        .iter()
        .map(|&t| {
            let Ok(v) = at.at(t, &mix);
            v
        })
        .collect()
}

/// Linear interpolation between two scalars.
pub(crate) fn lerp_scalar(a: &f64, b: &f64, t: f64) -> f64 {
    a + (b - a) * t
}

/// Linear interpolation between two vectors.
pub(crate) fn lerp_vec3<F: Frame>(a: &Vec3<F>, b: &Vec3<F>, t: f64) -> Vec3<F> {
    a.lerp(*b, t)
}

/// Spherical linear interpolation between two rotations (shortest path).
pub(crate) fn slerp<A: Frame, B: Frame>(a: &Rot<A, B>, b: &Rot<A, B>, t: f64) -> Rot<A, B> {
    a.slerp(b, t)
}

/// Linear interpolation of scalars.
pub(crate) fn interpolate_scalar(src_t: &[f64], src: &[f64], dst_t: &[f64]) -> Vec<f64> {
    interpolate_with(src_t, src, dst_t, lerp_scalar)
}

/// Linear interpolation of vectors.
pub(crate) fn interpolate_vec3<F: Frame>(
    src_t: &[f64],
    src: &[Vec3<F>],
    dst_t: &[f64],
) -> Vec<Vec3<F>> {
    interpolate_with(src_t, src, dst_t, lerp_vec3)
}

/// Spherical linear interpolation of rotations (shortest path).
pub(crate) fn interpolate_rot<A: Frame, B: Frame>(
    src_t: &[f64],
    src: &[Rot<A, B>],
    dst_t: &[f64],
) -> Vec<Rot<A, B>> {
    interpolate_with(src_t, src, dst_t, slerp)
}

/// How many times a uniform timeline from `start` to at most `end` at `rate_hz` has (none
/// when the span or the rate is not finite, or the rate not positive).
pub(crate) fn uniform_len(start: f64, end: f64, rate_hz: f64) -> usize {
    let finite = start.is_finite() && end.is_finite() && rate_hz.is_finite();
    if !(finite && end >= start && rate_hz > 0.0) {
        return 0;
    }
    // Saturating: a span of petaseconds has no end either way.
    (((end - start) * rate_hz + 1e-9).floor() as usize).saturating_add(1)
}

/// Time `i` of the uniform timeline from `start` at `rate_hz`.
pub(crate) fn uniform_time(start: f64, rate_hz: f64, i: usize) -> f64 {
    start + i as f64 / rate_hz
}

/// A uniform timeline from `start` to at most `end` at `rate_hz` ([`uniform_len`] times).
pub(crate) fn uniform_timeline(start: f64, end: f64, rate_hz: f64) -> Vec<f64> {
    (0..uniform_len(start, end, rate_hz))
        .map(|i| uniform_time(start, rate_hz, i))
        .collect()
}

/// Slack on a gap limit, s, so that a gap of exactly the limit (e.g. 15 mocap frames at 60 Hz
/// against 0.25 s) counts as within it despite rounding.
pub(crate) const GAP_TOLERANCE_S: f64 = 1e-9;

/// Time spans without long gaps: `[start, end]` of each run of samples whose spacing stays
/// within `max_gap`; `on_gap` is called with the index of the sample after each gap.
pub(crate) fn intervals(
    time: &[f64],
    max_gap: f64,
    mut on_gap: impl FnMut(usize),
) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let Some(&first) = time.first() else {
        return out;
    };
    let mut start = first;
    for (i, w) in time.windows(2).enumerate() {
        if w[1] - w[0] > max_gap + GAP_TOLERANCE_S {
            out.push((start, w[0]));
            on_gap(i + 1);
            start = w[1];
        }
    }
    out.push((start, time[time.len() - 1]));
    out
}

/// Intersection of two sorted lists of disjoint closed intervals.
pub(crate) fn intersect(a: &[(f64, f64)], b: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let (mut i, mut j) = (0, 0);
    let mut out = Vec::new();
    while i < a.len() && j < b.len() {
        let start = a[i].0.max(b[j].0);
        let end = a[i].1.min(b[j].1);
        if start <= end {
            out.push((start, end));
        }
        if a[i].1 < b[j].1 {
            i += 1;
        } else {
            j += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intervals_split_only_at_long_gaps() {
        let t = [0.0, 0.1, 0.2, 0.7, 0.8, 0.9];
        let mut gaps = Vec::new();
        assert_eq!(
            intervals(&t, 0.25, |i| gaps.push(i)),
            [(0.0, 0.2), (0.7, 0.9)]
        );
        assert_eq!(gaps, [3]);
        // Exactly the limit is not a split, despite rounding in 15 / 60.
        let t: Vec<f64> = [0.0, 15.0, 16.0].iter().map(|f| f / 60.0).collect();
        assert_eq!(intervals(&t, 0.25, |_| panic!("split")).len(), 1);
        assert!(intervals(&[], 1.0, |_| {}).is_empty());
    }

    #[test]
    fn intersection_of_interval_lists() {
        let a = [(0.0, 10.0), (20.0, 30.0)];
        let b = [(5.0, 25.0), (28.0, 40.0)];
        assert_eq!(intersect(&a, &b), [(5.0, 10.0), (20.0, 25.0), (28.0, 30.0)]);
        assert!(intersect(&a, &[]).is_empty());
        assert_eq!(intersect(&[(0.0, 1.0)], &[(1.0, 2.0)]), [(1.0, 1.0)]);
    }
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
