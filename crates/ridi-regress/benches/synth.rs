//! Synthetic IMU-like training data of realistic structure, shared by the benchmarks and the
//! timing example: each sample is a 200-frame window of 6 smooth channels (gait oscillation at a
//! per-sequence cadence, placement-dependent channel gains and harmonics, noise), the target is
//! a nonlinear function of the latent walking speed and heading, sequences are groups.
#![allow(dead_code)]

use ridi_features::ridi_frames::StabHorizontal;
use ridi_test_support::SplitMix64;

pub(crate) struct Synth {
    pub x: Vec<f32>,
    pub y: Vec<StabHorizontal>,
    pub placement: Vec<usize>,
    pub group: Vec<u64>,
    pub dim: usize,
}

/// `n` samples over `placements` classes, sequences of `per_seq` samples (10-frame steps).
pub(crate) fn generate(n: usize, placements: usize, per_seq: usize, seed: u64) -> Synth {
    const FRAMES: usize = 200;
    const CH: usize = 6;
    let dim = FRAMES * CH;
    let mut rng = SplitMix64(seed);
    let mut s = Synth {
        x: Vec::with_capacity(n * dim),
        y: Vec::with_capacity(n),
        placement: Vec::with_capacity(n),
        group: Vec::with_capacity(n),
        dim,
    };
    // Placement signatures: gain and second-harmonic weight per channel.
    let sig: Vec<[(f64, f64); CH]> = (0..placements)
        .map(|_| std::array::from_fn(|_| (0.3 + 1.2 * rng.unit(), rng.unit())))
        .collect();
    let mut seq = 0u64;
    while s.y.len() < n {
        let p = (seq as usize) % placements;
        let cadence = 1.5 + 0.7 * rng.unit();
        let phase0 = std::f64::consts::TAU * rng.unit();
        let heading = 0.6 * (rng.unit() - 0.5);
        let speed0 = 0.8 + 0.8 * rng.unit();
        let phases: [f64; CH] = std::array::from_fn(|_| std::f64::consts::TAU * rng.unit());
        // Per-sequence gain jitter (phone, person): placements overlap as in real data.
        let jitter: [f64; CH] = std::array::from_fn(|_| 0.6 + 0.8 * rng.unit());
        for k in 0..per_seq {
            if s.y.len() >= n {
                break;
            }
            let t0 = k as f64 * 10.0 / 200.0;
            let speed = speed0 * (1.0 + 0.3 * (t0 / 3.0 + phase0).sin());
            let turn = heading + 0.3 * (t0 / 5.0).sin();
            for f in 0..FRAMES {
                let t = t0 + f as f64 / 200.0;
                let w = std::f64::consts::TAU * cadence * t;
                for c in 0..CH {
                    let (g, h) = sig[p][c];
                    let g = g * jitter[c];
                    let base = (w + phases[c]).sin() + h * (2.0 * w + phases[c]).sin();
                    let v = g * speed * base
                        + 0.2 * turn * (c as f64 - 2.5)
                        + 0.05 * (rng.unit() - 0.5);
                    s.x.push(v as f32);
                }
            }
            s.y.push(StabHorizontal::new(speed * turn.sin(), -speed * turn.cos()));
            s.placement.push(p);
            s.group.push(seq);
        }
        seq += 1;
    }
    s
}
