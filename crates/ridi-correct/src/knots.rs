//! Knots of the piecewise-linear bias and the bias curve itself.

use ridi_frames::DeviceVec;
use serde::{Deserialize, Serialize};

use crate::error::CorrectError;

/// Knot placement over a sequence of `len` frames: frames `0, s, 2s, ...` (`s` the spacing)
/// plus a final knot at the last frame when it is not already one, so that every frame,
/// including the tail, lies between two knots (the original left the tail uncorrected).
///
/// Between two knots the bias is interpolated linearly in *time*, so irregular sampling does
/// not distort it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "KnotParts")]
pub struct Knots {
    spacing: usize,
    frames: Vec<usize>,
    times: Vec<f64>,
}

/// [`Knots`] as stored, checked on the way in: [`Knots::locate`] indexes by them.
#[derive(Deserialize)]
struct KnotParts {
    spacing: usize,
    frames: Vec<usize>,
    times: Vec<f64>,
}

impl TryFrom<KnotParts> for Knots {
    type Error = CorrectError;
    fn try_from(p: KnotParts) -> Result<Self, CorrectError> {
        let bad = CorrectError::InvalidKnots;
        if p.spacing == 0 {
            return Err(bad("spacing 0"));
        }
        if p.frames.len() != p.times.len() {
            return Err(bad("as many times as frames are needed"));
        }
        let n = p.frames.len();
        // Frames 0, s, 2s, ... and possibly a final knot after the last multiple of s.
        let at = |i: usize| i.checked_mul(p.spacing);
        let regular = |i: usize| at(i) == Some(p.frames[i]);
        let last_ok = n == 0
            || regular(n - 1)
            || (n >= 2 && at(n - 1).is_none_or(|next| p.frames[n - 1] < next));
        if !(0..n.saturating_sub(1)).all(regular)
            || !last_ok
            || p.frames.windows(2).any(|w| w[1] <= w[0])
        {
            return Err(bad("frames are not every `spacing` frames from 0"));
        }
        let knots = Self {
            spacing: p.spacing,
            frames: p.frames,
            times: p.times,
        };
        knots.check_times()?;
        Ok(knots)
    }
}

impl Knots {
    /// Knots for the frames of `time` every `spacing` frames. `spacing` is clamped to at
    /// least 1; an empty `time` gives no knot. `time` should increase strictly, as every
    /// correction input's does (checked there): knots at other times are refused when read
    /// back (deserialized) and by [`corrected_acceleration`](crate::corrected_acceleration).
    pub fn new(time: &[f64], spacing: usize) -> Self {
        let spacing = spacing.max(1);
        let n = time.len();
        let mut frames: Vec<usize> = (0..n).step_by(spacing).collect();
        if n > 0 && frames.last() != Some(&(n - 1)) {
            frames.push(n - 1);
        }
        let times = frames.iter().map(|&f| time[f]).collect();
        Self {
            spacing,
            frames,
            times,
        }
    }

    /// Checks that the knots' times are finite and increase strictly: [`Knots::new`] takes
    /// them from any `time`, and the weight between two knots at one time is 0 / 0.
    pub(crate) fn check_times(&self) -> Result<(), CorrectError> {
        let t = &self.times;
        if t.iter().any(|t| !t.is_finite()) || t.windows(2).any(|w| w[1] <= w[0]) {
            return Err(CorrectError::InvalidKnots(
                "times must be finite and increasing",
            ));
        }
        Ok(())
    }

    /// Number of knots.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// `true` when there is no knot (empty sequence).
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Frame index of each knot.
    pub fn frames(&self) -> &[usize] {
        &self.frames
    }

    /// Time of each knot, seconds.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// Knot spacing in frames.
    pub fn spacing(&self) -> usize {
        self.spacing
    }

    /// The knot at or before `frame` and the weight of the next knot: the bias at `frame` is
    /// `(1 - w) x[k] + w x[k + 1]` (`w = 0` exactly on a knot, and for the last knot).
    /// `time` is the frame's timestamp. Frames past the last knot are clamped to it.
    #[inline]
    pub fn locate(&self, frame: usize, time: f64) -> (usize, f64) {
        let last = self.frames.len().saturating_sub(1);
        let k = (frame / self.spacing).min(last);
        if k == last || self.frames[k] == frame {
            return (k, 0.0);
        }
        // Only the final knot can sit off the regular grid.
        if self.frames[k + 1] == frame {
            return (k + 1, 0.0);
        }
        let (t0, t1) = (self.times[k], self.times[k + 1]);
        (k, (time - t0) / (t1 - t0))
    }

    /// Index of the last knot whose support contains `frame`: `k` if `frame` is a knot,
    /// else `k + 1`. It depends on indices only, so the sparsity of the system does too.
    #[inline]
    pub(crate) fn upper(&self, frame: usize) -> usize {
        let last = self.frames.len().saturating_sub(1);
        let k = (frame / self.spacing).min(last);
        if self.frames[k] == frame { k } else { k + 1 }
    }
}

/// A piecewise-linear device-frame acceleration bias: one value per knot.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "BiasParts")]
pub struct BiasCurve {
    pub(crate) knots: Knots,
    pub(crate) values: Vec<DeviceVec>,
}

/// [`BiasCurve`] as stored, checked on the way in ([`BiasCurve::new`]).
#[derive(Deserialize)]
struct BiasParts {
    knots: Knots,
    values: Vec<DeviceVec>,
}

impl TryFrom<BiasParts> for BiasCurve {
    type Error = CorrectError;
    fn try_from(p: BiasParts) -> Result<Self, CorrectError> {
        Self::new(p.knots, p.values)
    }
}

impl BiasCurve {
    /// The curve with `values[k]` at knot `k`: one finite value per knot.
    pub fn new(knots: Knots, values: Vec<DeviceVec>) -> Result<Self, CorrectError> {
        if values.len() != knots.len() {
            return Err(CorrectError::BiasLength {
                knots: knots.len(),
                values: values.len(),
            });
        }
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            return Err(CorrectError::NonFinite {
                what: "bias",
                index: knots.frames()[k],
            });
        }
        Ok(Self { knots, values })
    }

    /// Where the values sit.
    pub fn knots(&self) -> &Knots {
        &self.knots
    }

    /// Bias at each knot, device frame, m/s².
    pub fn values(&self) -> &[DeviceVec] {
        &self.values
    }

    /// The zero bias over `knots`.
    pub fn zero(knots: Knots) -> Self {
        let values = vec![DeviceVec::ZERO; knots.len()];
        Self { knots, values }
    }

    /// Bias at `frame` (whose timestamp is `time`). Zero if there is no knot.
    #[inline]
    pub fn at(&self, frame: usize, time: f64) -> DeviceVec {
        if self.values.is_empty() {
            return DeviceVec::ZERO;
        }
        let (k, w) = self.knots.locate(frame, time);
        if w == 0.0 {
            self.values[k]
        } else {
            self.values[k] * (1.0 - w) + self.values[k + 1] * w
        }
    }

    /// Bias at the last knot (the end of the covered frames), zero if there is no knot.
    pub fn last(&self) -> DeviceVec {
        self.values.last().copied().unwrap_or(DeviceVec::ZERO)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn knots_cover_the_tail_and_interpolate_in_time() {
        let time: Vec<f64> = (0..12).map(|i| i as f64 * 0.5).collect();
        let k = Knots::new(&time, 5);
        assert_eq!(k.frames(), &[0, 5, 10, 11]);
        assert_eq!(k.locate(0, 0.0), (0, 0.0));
        assert_eq!(k.locate(5, 2.5), (1, 0.0));
        let (i, w) = k.locate(7, 3.5);
        assert_eq!(i, 1);
        assert!((w - 0.4).abs() < 1e-12);
        assert_eq!(k.locate(11, 5.5), (3, 0.0));
        assert_eq!(k.upper(7), 2);
        assert_eq!(k.upper(10), 2);
        // Aligned length: no extra knot.
        assert_eq!(Knots::new(&time[..11], 5).frames(), &[0, 5, 10]);
    }

    #[test]
    fn curve_is_linear_between_knots() {
        let time: Vec<f64> = (0..11).map(|i| i as f64).collect();
        let knots = Knots::new(&time, 10);
        let curve = BiasCurve::new(
            knots.clone(),
            vec![DeviceVec::new(0.0, 1.0, 2.0), DeviceVec::new(1.0, 1.0, 0.0)],
        )
        .unwrap();
        let mid = curve.at(5, 5.0);
        assert!((mid - DeviceVec::new(0.5, 1.0, 1.0)).norm() < 1e-12);
        assert_eq!(curve.last(), DeviceVec::new(1.0, 1.0, 0.0));
        // One value per knot, finite.
        assert_eq!(
            BiasCurve::new(knots.clone(), vec![DeviceVec::ZERO]),
            Err(CorrectError::BiasLength {
                knots: 2,
                values: 1
            })
        );
        let nan = vec![DeviceVec::ZERO, DeviceVec::new(f64::NAN, 0.0, 0.0)];
        assert_eq!(
            BiasCurve::new(knots, nan),
            Err(CorrectError::NonFinite {
                what: "bias",
                index: 10
            })
        );
    }

    #[test]
    fn every_knots_new_reads_back_and_a_lone_knot_must_be_frame_0() {
        for n in 0..30 {
            let time: Vec<f64> = (0..n).map(|i| f64::from(i) * 0.005).collect();
            for spacing in 1..8 {
                let k = Knots::new(&time, spacing);
                let json = serde_json::to_string(&k).unwrap();
                assert_eq!(serde_json::from_str::<Knots>(&json).unwrap(), k, "{json}");
            }
        }
        let lone = r#"{"spacing":5,"frames":[7],"times":[0.0]}"#;
        assert!(serde_json::from_str::<Knots>(lone).is_err());
    }

    #[test]
    fn stored_knots_and_curves_are_checked_on_the_way_in() {
        let time: Vec<f64> = (0..12).map(|i| i as f64 * 0.5).collect();
        let curve = BiasCurve::zero(Knots::new(&time, 5));
        let json = serde_json::to_string(&curve).unwrap();
        assert_eq!(serde_json::from_str::<BiasCurve>(&json).unwrap(), curve);
        for (from, to) in [
            ("\"spacing\":5", "\"spacing\":0"),
            ("[0,5,10,11]", "[0,5,11,10]"),
            ("[0,5,10,11]", "[0,4,10,11]"),
            ("[0,5,10,11]", "[0,5,10,17]"),
            ("[0.0,2.5,5.0,5.5]", "[0.0,2.5,5.5,5.0]"),
            ("[0.0,0.0,0.0],[0.0,0.0,0.0]]", "[0.0,0.0,0.0]]"),
            ("\"spacing\":5", "\"spacing\":9223372036854775808"),
        ] {
            assert!(json.contains(from), "{json}");
            let bad = json.replacen(from, to, 1);
            let e = serde_json::from_str::<BiasCurve>(&bad).unwrap_err();
            assert!(
                e.to_string().contains("invalid knots")
                    || e.to_string().contains("one value per knot"),
                "{bad}: {e}"
            );
        }
    }
}
