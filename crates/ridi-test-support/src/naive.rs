//! Straightforward reference implementations, written for clarity rather than speed: every
//! window rotates its own frames, builds explicit padded channel vectors and smooths in f64.
//! The oracles of `ridi-features`' tests, and the baseline its benchmark reports the speed
//! ratio against.

use ridi_frames::{DeviceVec, align_gravity};

/// Gaussian kernel from the scipy recipe, full length `2r + 1`.
pub fn naive_kernel(sigma: f64, truncate: f64) -> Vec<f64> {
    let r = (truncate * sigma + 0.5) as i64;
    if r == 0 {
        return vec![1.0];
    }
    let w: Vec<f64> = (-r..=r)
        .map(|x| (-0.5 * (x * x) as f64 / (sigma * sigma)).exp())
        .collect();
    let s: f64 = w.iter().sum();
    w.into_iter().map(|v| v / s).collect()
}

/// Position `i` of the reflect extension, found by mirroring step by step at each border
/// (independent of the closed form `ridi-features` uses).
pub fn naive_mirror(mut i: i64, n: i64) -> usize {
    loop {
        if i < 0 {
            i = -i - 1;
        } else if i >= n {
            i = 2 * n - 1 - i;
        } else {
            return i as usize;
        }
    }
}

/// scipy's gaussian_filter1d, mode 'reflect', by explicit padding.
pub fn naive_smooth(x: &[f64], sigma: f64, truncate: f64) -> Vec<f64> {
    let k = naive_kernel(sigma, truncate);
    let r = (k.len() / 2) as i64;
    let n = x.len() as i64;
    if n == 0 {
        return Vec::new();
    }
    let padded: Vec<f64> = (-r..n + r).map(|i| x[naive_mirror(i, n)]).collect();
    (0..x.len())
        .map(|i| k.iter().enumerate().map(|(j, w)| w * padded[i + j]).sum())
        .collect()
}

/// Feature rows for gyro + linear acceleration, window `window` ending before each frame.
pub fn naive_features(
    gyro: &[DeviceVec],
    linacce: &[DeviceVec],
    gravity: &[DeviceVec],
    frames: &[usize],
    window: usize,
    sigma: f64,
    truncate: f64,
) -> Vec<Vec<f32>> {
    frames
        .iter()
        .map(|&f| {
            let mut channels: Vec<Vec<f64>> = vec![Vec::new(); 6];
            for i in f - window..f {
                let r = align_gravity(gravity[i]);
                let a = (r * gyro[i]).to_array();
                let b = (r * linacce[i]).to_array();
                for c in 0..3 {
                    channels[c].push(a[c]);
                    channels[3 + c].push(b[c]);
                }
            }
            let smoothed: Vec<Vec<f64>> = channels
                .iter()
                .map(|c| naive_smooth(c, sigma, truncate))
                .collect();
            let mut row = Vec::with_capacity(window * 6);
            for t in 0..window {
                for c in smoothed.iter() {
                    row.push(c[t] as f32);
                }
            }
            row
        })
        .collect()
}
