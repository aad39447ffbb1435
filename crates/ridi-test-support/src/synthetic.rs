//! Deterministic synthetic data: the same numbers on every machine and every run, without a
//! random-number crate.

/// SplitMix64: tiny, deterministic, good enough for test data.
#[derive(Debug, Clone)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [-1, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `n × d` row-major features with smooth structure and a nonlinear target, from `seed`.
pub fn regression_data(n: usize, d: usize, seed: u64) -> (Vec<f32>, Vec<f64>) {
    let mut rng = SplitMix64(seed);
    let mut x = Vec::with_capacity(n * d);
    let mut y = Vec::with_capacity(n);
    for _ in 0..n {
        let a = rng.uniform();
        let b = rng.uniform();
        for j in 0..d {
            let t = j as f64 / d as f64;
            x.push((a * (3.0 * t).sin() + b * (5.0 * t + a).cos() + 0.1 * rng.uniform()) as f32);
        }
        y.push((2.0 * a).sin() + 0.5 * b * b + 0.05 * rng.uniform());
    }
    (x, y)
}

/// One blob per entry of `label_of` in `d` dimensions, `n_per` samples each, spread `spread`
/// about a unit centre; the samples of blob `c` are labelled `label_of[c]`.
pub fn blob_data(
    n_per: usize,
    d: usize,
    label_of: &[usize],
    spread: f64,
    seed: u64,
) -> (Vec<f32>, Vec<usize>) {
    let mut rng = SplitMix64(seed);
    let mut x = Vec::new();
    let mut y = Vec::new();
    for (c, &label) in label_of.iter().enumerate() {
        for _ in 0..n_per {
            for j in 0..d {
                let centre = if j % label_of.len() == c { 1.0 } else { 0.0 };
                x.push((centre + spread * rng.uniform()) as f32);
            }
            y.push(label);
        }
    }
    (x, y)
}

/// `positions` (one per frame of `time`) made straight lines at constant speed between the
/// points every `every` frames and the last, as waypoints interpolated are (the Indoor
/// Location Competition's ground truth).
pub fn straight_between_points<F: ridi_frames::Frame>(
    time: &[f64],
    positions: &mut [ridi_frames::Vec3<F>],
    every: usize,
) {
    let marks: Vec<usize> = (0..time.len())
        .step_by(every)
        .chain([time.len() - 1])
        .collect();
    let truth = positions.to_vec();
    for w in marks.windows(2) {
        let (a, b) = (w[0], w[1]);
        for i in a..=b {
            let share = (time[i] - time[a]) / (time[b] - time[a]);
            positions[i] = truth[a] + (truth[b] - truth[a]) * share;
        }
    }
}
