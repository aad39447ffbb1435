//! Pedestrian dead reckoning (PDR) baseline: step detection and step-and-heading integration.
//!
//! The STEP baseline of RIDI's tables: count steps from the accelerometer, advance a fixed
//! stride along the device heading at each step. It needs no training, so it is the yardstick a
//! learned method has to beat.

use serde::{Deserialize, Serialize};

use crate::error::{
    EvalError, Result, check_finite, check_non_empty, check_positive, check_same_len,
};
use crate::metrics::estimate_rate_hz;

/// Settings of [`detect_steps`].
///
/// Thresholds are in m/s² relative to the slowly varying baseline of the acceleration
/// magnitude (gravity plus sensor scale error, about 9.8), after low-pass filtering.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StepDetectorConfig {
    /// Cut-off of the zero-phase low-pass filter, Hz. Walking cadence is 1.5–2.5 steps/s; 3 Hz
    /// keeps it and removes the heel-strike ringing that would split one step into several
    /// peaks.
    pub lowpass_hz: f64,
    /// Width of the centred moving average removed as the baseline, seconds.
    pub baseline_window_s: f64,
    /// A peak starts when the filtered signal rises above this.
    pub rise_threshold: f64,
    /// A peak ends when the filtered signal falls below this (must be ≤ `rise_threshold`); the
    /// gap between the two is the hysteresis that keeps noise near a threshold from producing
    /// extra steps.
    pub fall_threshold: f64,
    /// Minimum time between two steps, seconds. Of two peaks closer than this, the higher one
    /// is kept.
    pub min_step_interval_s: f64,
}

impl Default for StepDetectorConfig {
    fn default() -> Self {
        Self {
            lowpass_hz: 3.0,
            baseline_window_s: 2.0,
            rise_threshold: 0.6,
            fall_threshold: 0.0,
            min_step_interval_s: 0.3,
        }
    }
}

impl StepDetectorConfig {
    fn validate(&self) -> Result<()> {
        check_positive("lowpass_hz", self.lowpass_hz)?;
        check_positive("baseline_window_s", self.baseline_window_s)?;
        for (name, v) in [
            ("rise_threshold", self.rise_threshold),
            ("fall_threshold", self.fall_threshold),
        ] {
            if !v.is_finite() {
                return Err(EvalError::InvalidParameter {
                    name,
                    reason: format!("must be finite, got {v}"),
                });
            }
        }
        if self.fall_threshold > self.rise_threshold {
            return Err(EvalError::InvalidParameter {
                name: "fall_threshold",
                reason: format!(
                    "must not exceed rise_threshold ({} > {})",
                    self.fall_threshold, self.rise_threshold
                ),
            });
        }
        if !(self.min_step_interval_s.is_finite() && self.min_step_interval_s >= 0.0) {
            return Err(EvalError::InvalidParameter {
                name: "min_step_interval_s",
                reason: format!("must be finite and ≥ 0, got {}", self.min_step_interval_s),
            });
        }
        Ok(())
    }
}

/// Detects steps in a 3-axis accelerometer signal (gravity included, any frame): returns the
/// frame index of each step, increasing.
///
/// Works on the magnitude `‖aᵢ‖`, which does not depend on how the phone is held; see
/// [`detect_steps_in_magnitude`].
///
/// # Errors
/// As [`detect_steps_in_magnitude`].
pub fn detect_steps(
    times: &[f64],
    accel: &[[f64; 3]],
    config: &StepDetectorConfig,
) -> Result<Vec<usize>> {
    let magnitude: Vec<f64> = accel
        .iter()
        .map(|a| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt())
        .collect();
    detect_steps_in_magnitude(times, &magnitude, config)
}

/// Detects steps in an acceleration magnitude signal, m/s²; returns increasing frame indices.
///
/// 1. Baseline removal: `xᵢ = mᵢ − mean(m over a centred window of baseline_window_s)`.
/// 2. Zero-phase low-pass: a 2nd-order Butterworth filter at `lowpass_hz` run forwards then
///    backwards, so peaks are not delayed.
/// 3. Hysteresis: a candidate peak opens when `x > rise_threshold` and closes when
///    `x < fall_threshold`; the step is the frame of the maximum in between (a peak still open
///    at the end counts).
/// 4. Candidates closer than `min_step_interval_s` to the previous step replace it if higher,
///    and are dropped otherwise.
///
/// The sampling rate is taken from `times` (seconds) as `(N − 1) / (t_last − t₀)`.
///
/// # Errors
/// Fewer than 2 frames, mismatched lengths, non-finite values, decreasing or constant times, an
/// invalid configuration, or a cut-off at or above the Nyquist frequency.
pub fn detect_steps_in_magnitude(
    times: &[f64],
    magnitude: &[f64],
    config: &StepDetectorConfig,
) -> Result<Vec<usize>> {
    config.validate()?;
    check_same_len("times vs acceleration", times.len(), magnitude.len())?;
    check_finite("acceleration magnitude", magnitude)?;
    let rate = estimate_rate_hz(times)?;
    if config.lowpass_hz >= rate / 2.0 {
        return Err(EvalError::InvalidParameter {
            name: "lowpass_hz",
            reason: format!(
                "{} Hz is not below the Nyquist frequency of {} Hz data",
                config.lowpass_hz, rate
            ),
        });
    }

    let half = ((config.baseline_window_s * rate / 2.0).round() as usize).max(1);
    let centred = subtract_moving_average(magnitude, half);
    let filtered = filtfilt(
        &centred,
        &Biquad::butterworth_lowpass(config.lowpass_hz, rate),
    );

    let mut steps: Vec<usize> = Vec::new();
    let accept = |peak: usize, steps: &mut Vec<usize>| match steps.last_mut() {
        Some(last) if times[peak] - times[*last] < config.min_step_interval_s => {
            if filtered[peak] > filtered[*last] {
                *last = peak;
            }
        }
        _ => steps.push(peak),
    };
    let mut open: Option<usize> = None;
    for (i, &x) in filtered.iter().enumerate() {
        match open {
            Some(best) => {
                let best = if x > filtered[best] { i } else { best };
                if x < config.fall_threshold {
                    accept(best, &mut steps);
                    open = None;
                } else {
                    open = Some(best);
                }
            }
            None if x > config.rise_threshold => open = Some(i),
            None => {}
        }
    }
    if let Some(best) = open {
        accept(best, &mut steps);
    }
    Ok(steps)
}

/// `xᵢ − mean(x[i−half ..= i+half])`, the window clipped at the ends.
fn subtract_moving_average(x: &[f64], half: usize) -> Vec<f64> {
    let mut prefix = Vec::with_capacity(x.len() + 1);
    prefix.push(0.0);
    let mut acc = 0.0;
    for &v in x {
        acc += v;
        prefix.push(acc);
    }
    (0..x.len())
        .map(|i| {
            let lo = i.saturating_sub(half);
            // Saturating: a window longer than any recording (half near usize::MAX) is the
            // whole recording, not an overflow.
            let hi = i.saturating_add(half).saturating_add(1).min(x.len());
            x[i] - (prefix[hi] - prefix[lo]) / (hi - lo) as f64
        })
        .collect()
}

/// A second-order IIR section, `a0 = 1`.
struct Biquad {
    b: [f64; 3],
    a: [f64; 2],
}

impl Biquad {
    /// Butterworth low-pass by the bilinear transform with pre-warping.
    fn butterworth_lowpass(cutoff_hz: f64, rate_hz: f64) -> Self {
        let k = (std::f64::consts::PI * cutoff_hz / rate_hz).tan();
        let q = std::f64::consts::SQRT_2;
        let norm = 1.0 / (1.0 + q * k + k * k);
        let b0 = k * k * norm;
        Self {
            b: [b0, 2.0 * b0, b0],
            a: [2.0 * (k * k - 1.0) * norm, (1.0 - q * k + k * k) * norm],
        }
    }

    /// Runs the filter over `x` (transposed direct form II), starting in the steady state of
    /// the first sample so that a non-zero start does not ring like a step input.
    fn run(&self, x: &[f64]) -> Vec<f64> {
        let [b0, b1, b2] = self.b;
        let [a1, a2] = self.a;
        let x0 = x.first().copied().unwrap_or(0.0);
        // Unity DC gain: constant input x0 gives output x0.
        let mut z2 = (b2 - a2) * x0;
        let mut z1 = (b1 - a1) * x0 + z2;
        x.iter()
            .map(|&v| {
                let y = b0 * v + z1;
                z1 = b1 * v - a1 * y + z2;
                z2 = b2 * v - a2 * y;
                y
            })
            .collect()
    }
}

/// Forward-backward filtering: zero phase, squared magnitude response.
fn filtfilt(x: &[f64], f: &Biquad) -> Vec<f64> {
    let mut y = f.run(x);
    y.reverse();
    let mut z = f.run(&y);
    z.reverse();
    z
}

/// Builds a PDR trajectory: one horizontal position per frame.
///
/// `heading[f]` is the walking direction at frame `f`, radians, counter-clockwise from the world
/// +x axis about world up (so a step moves by `L · (cos h, sin h)`); for a phone carried facing
/// forward, its S frame's forward direction (`ridi_frames::UpAxis::forward_heading`, which the
/// `ridi` crate's PDR baseline takes). The position is piecewise
/// constant, jumping at each step frame:
///
/// ```text
/// p(f) = start + Σ_{s ∈ steps, s ≤ f} L · (cos heading[s], sin heading[s])
/// ```
///
/// The number of frames is `heading.len()`.
///
/// # Errors
/// Empty or non-finite heading, a step length that is negative or non-finite, or step indices
/// that are not strictly increasing or are `≥ heading.len()`.
pub fn pdr_trajectory(
    start: [f64; 2],
    steps: &[usize],
    step_length: f64,
    heading: &[f64],
) -> Result<Vec<[f64; 2]>> {
    check_non_empty("heading", heading.len())?;
    check_finite("heading", heading)?;
    if !(start[0].is_finite() && start[1].is_finite()) {
        return Err(EvalError::NonFinite {
            what: "start position",
            index: 0,
        });
    }
    if !(step_length.is_finite() && step_length >= 0.0) {
        return Err(EvalError::InvalidParameter {
            name: "step_length",
            reason: format!("must be finite and ≥ 0, got {step_length}"),
        });
    }
    for (position, &step) in steps.iter().enumerate() {
        let ordered = position == 0 || steps[position - 1] < step;
        if step >= heading.len() || !ordered {
            return Err(EvalError::BadStepIndex { position, step });
        }
    }

    let mut positions = Vec::with_capacity(heading.len());
    let mut p = start;
    let mut next = steps.iter().peekable();
    for (f, &h) in heading.iter().enumerate() {
        if next.next_if(|&&s| s == f).is_some() {
            let (s, c) = h.sin_cos();
            p = [p[0] + step_length * c, p[1] + step_length * s];
        }
        positions.push(p);
    }
    Ok(positions)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic standard normal samples (xorshift + Box–Muller), so tests need no RNG
    /// crate and never flake.
    struct Noise(u64);

    impl Noise {
        fn uniform(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }

        fn normal(&mut self) -> f64 {
            let (u, v) = (self.uniform(), self.uniform());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        }
    }

    fn timeline(seconds: f64, rate: f64) -> Vec<f64> {
        (0..(seconds * rate) as usize)
            .map(|i| i as f64 / rate)
            .collect()
    }

    #[test]
    fn counts_steps_of_a_noisy_2hz_walk() {
        let times = timeline(30.0, 200.0);
        let mut noise = Noise(0x9e37_79b9_7f4a_7c15);
        let w = std::f64::consts::TAU * 2.0;
        let magnitude: Vec<f64> = times
            .iter()
            .map(|&t| 9.81 + 2.0 * (w * t).sin() + 0.3 * noise.normal())
            .collect();
        let steps =
            detect_steps_in_magnitude(&times, &magnitude, &StepDetectorConfig::default()).unwrap();
        assert!(steps.len().abs_diff(60) <= 1, "{} steps", steps.len());
        // Each detection sits on a sine crest (t = 0.125 + k/2 s), within a few samples.
        for &s in &steps {
            let phase = (times[s] - 0.125).rem_euclid(0.5);
            let off = phase.min(0.5 - phase);
            assert!(off < 0.03, "step at {} s is {off} s off a crest", times[s]);
        }
        // A baseline window longer than the recording is its mean: the same walk, no overflow.
        let whole = StepDetectorConfig {
            baseline_window_s: 1e18,
            ..StepDetectorConfig::default()
        };
        let steps = detect_steps_in_magnitude(&times, &magnitude, &whole).unwrap();
        assert!(steps.len().abs_diff(60) <= 1, "{} steps", steps.len());
    }

    #[test]
    fn magnitude_ignores_phone_orientation() {
        // Gravity turns slowly from device z to device y while walking at 1.8 Hz.
        let times = timeline(20.0, 100.0);
        let w = std::f64::consts::TAU * 1.8;
        let accel: Vec<[f64; 3]> = times
            .iter()
            .map(|&t| {
                let m = 9.81 + 1.5 * (w * t).sin();
                let tilt = t / 20.0 * std::f64::consts::FRAC_PI_2;
                [0.0, m * tilt.sin(), m * tilt.cos()]
            })
            .collect();
        let steps = detect_steps(&times, &accel, &StepDetectorConfig::default()).unwrap();
        assert!(steps.len().abs_diff(36) <= 1, "{} steps", steps.len());
    }

    #[test]
    fn standing_still_gives_no_steps() {
        let times = timeline(10.0, 200.0);
        let mut noise = Noise(42);
        let magnitude: Vec<f64> = times.iter().map(|_| 9.81 + 0.1 * noise.normal()).collect();
        let steps =
            detect_steps_in_magnitude(&times, &magnitude, &StepDetectorConfig::default()).unwrap();
        assert!(steps.is_empty(), "{steps:?}");
    }

    #[test]
    fn close_double_peaks_merge_to_the_higher() {
        // Each step is a heel strike (3 m/s²) followed 0.1 s later by a smaller bump (2 m/s²),
        // with a light filter so both bumps survive as separate candidates.
        let times = timeline(10.0, 200.0);
        let bump = |t: f64, c: f64| (-((t - c) / 0.015).powi(2)).exp();
        let strikes: Vec<f64> = (0..10).map(|k| 0.5 + f64::from(k) * 0.9).collect();
        let magnitude: Vec<f64> = times
            .iter()
            .map(|&t| {
                9.81 + strikes
                    .iter()
                    .map(|&c| 3.0 * bump(t, c) + 2.0 * bump(t, c + 0.1))
                    .sum::<f64>()
            })
            .collect();
        let config = StepDetectorConfig {
            lowpass_hz: 30.0,
            rise_threshold: 0.5,
            fall_threshold: 0.2,
            ..StepDetectorConfig::default()
        };
        let steps = detect_steps_in_magnitude(&times, &magnitude, &config).unwrap();
        assert_eq!(steps.len(), 10, "{steps:?}");
        for (s, c) in steps.iter().zip(&strikes) {
            assert!((times[*s] - c).abs() < 0.011, "{} vs {c}", times[*s]);
        }
        // Without the minimum interval both bumps count.
        let unmerged = StepDetectorConfig {
            min_step_interval_s: 0.0,
            ..config
        };
        assert_eq!(
            detect_steps_in_magnitude(&times, &magnitude, &unmerged)
                .unwrap()
                .len(),
            20
        );
    }

    #[test]
    fn detector_rejects_bad_input() {
        let cfg = StepDetectorConfig::default();
        assert!(detect_steps_in_magnitude(&[], &[], &cfg).is_err());
        assert!(detect_steps_in_magnitude(&[0.0], &[9.8], &cfg).is_err());
        assert!(detect_steps_in_magnitude(&[0.0, 0.01], &[9.8], &cfg).is_err());
        assert!(detect_steps_in_magnitude(&[0.0, 0.01], &[9.8, f64::NAN], &cfg).is_err());
        assert!(detect_steps_in_magnitude(&[0.0, 0.0], &[9.8, 9.8], &cfg).is_err());
        // 3 Hz cut-off on 5 Hz data is above Nyquist.
        let times = timeline(2.0, 5.0);
        let mags = vec![9.8; times.len()];
        assert!(detect_steps_in_magnitude(&times, &mags, &cfg).is_err());
        let inverted = StepDetectorConfig {
            fall_threshold: 1.0,
            rise_threshold: 0.5,
            ..cfg
        };
        let times = timeline(2.0, 200.0);
        let mags = vec![9.8; times.len()];
        assert!(detect_steps_in_magnitude(&times, &mags, &inverted).is_err());
        let negative_gap = StepDetectorConfig {
            min_step_interval_s: -1.0,
            ..cfg
        };
        assert!(detect_steps_in_magnitude(&times, &mags, &negative_gap).is_err());
    }

    #[test]
    fn pdr_walks_a_square() {
        use std::f64::consts::FRAC_PI_2;
        // Four steps of 0.7 m turning left 90° each time: back to the start.
        let heading: Vec<f64> = (0..8).map(|f| f64::from(f / 2) * FRAC_PI_2).collect();
        let p = pdr_trajectory([1.0, 2.0], &[1, 3, 5, 7], 0.7, &heading).unwrap();
        assert_eq!(p.len(), 8);
        assert_eq!(p[0], [1.0, 2.0]);
        assert!((p[1][0] - 1.7).abs() < 1e-12 && (p[1][1] - 2.0).abs() < 1e-12);
        assert_eq!(p[2], p[1]);
        assert!((p[3][0] - 1.7).abs() < 1e-12 && (p[3][1] - 2.7).abs() < 1e-12);
        assert!((p[7][0] - 1.0).abs() < 1e-12 && (p[7][1] - 2.0).abs() < 1e-12);
    }

    #[test]
    fn pdr_rejects_bad_steps() {
        let h = [0.0; 5];
        assert!(matches!(
            pdr_trajectory([0.0; 2], &[2, 2], 0.7, &h),
            Err(EvalError::BadStepIndex { position: 1, .. })
        ));
        assert!(matches!(
            pdr_trajectory([0.0; 2], &[5], 0.7, &h),
            Err(EvalError::BadStepIndex {
                position: 0,
                step: 5
            })
        ));
        assert!(pdr_trajectory([0.0; 2], &[3, 1], 0.7, &h).is_err());
        assert!(pdr_trajectory([0.0; 2], &[], 0.7, &[]).is_err());
        assert!(pdr_trajectory([0.0; 2], &[1], -0.7, &h).is_err());
        assert!(pdr_trajectory([f64::NAN, 0.0], &[1], 0.7, &h).is_err());
        assert!(pdr_trajectory([0.0; 2], &[1], 0.7, &[0.0, f64::NAN]).is_err());
        assert_eq!(
            pdr_trajectory([3.0, 4.0], &[], 0.7, &h).unwrap(),
            vec![[3.0, 4.0]; 5]
        );
    }

    #[test]
    fn detected_steps_drive_pdr() {
        // End to end: 10 s walking due north (heading π/2) at 2 steps/s with 0.7 m strides.
        let times = timeline(10.0, 200.0);
        let w = std::f64::consts::TAU * 2.0;
        let magnitude: Vec<f64> = times.iter().map(|&t| 9.81 + 2.0 * (w * t).sin()).collect();
        let steps =
            detect_steps_in_magnitude(&times, &magnitude, &StepDetectorConfig::default()).unwrap();
        let heading = vec![std::f64::consts::FRAC_PI_2; times.len()];
        let p = pdr_trajectory([0.0, 0.0], &steps, 0.7, &heading).unwrap();
        let end = p[p.len() - 1];
        assert!(end[0].abs() < 1e-9);
        assert!((end[1] - 0.7 * steps.len() as f64).abs() < 1e-9);
        assert!(steps.len().abs_diff(20) <= 1);
    }
}
