//! What `ridi inspect` reports about a sequence or a model.

use ridi_data::{Format, Sequence};
use ridi_features::FeatureChannel;
use ridi_frames::UpAxis;
use ridi_regress::{Cascade, GridRow, Solver, StoredAs};
use serde::Serialize;

use crate::orientation::Orientation;
use crate::track::{RATE_HZ, RATE_TOLERANCE};

/// Summary statistics of a scalar series.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stats {
    /// Mean.
    pub mean: f64,
    /// Standard deviation (population).
    pub std: f64,
    /// Minimum.
    pub min: f64,
    /// Maximum.
    pub max: f64,
}

impl Stats {
    /// Statistics of `values` (all zero when empty).
    pub fn of(values: impl Iterator<Item = f64> + Clone) -> Stats {
        let (mut n, mut sum, mut min, mut max) = (0usize, 0.0, f64::INFINITY, f64::NEG_INFINITY);
        for v in values.clone() {
            n += 1;
            sum += v;
            min = min.min(v);
            max = max.max(v);
        }
        if n == 0 {
            return Stats {
                mean: 0.0,
                std: 0.0,
                min: 0.0,
                max: 0.0,
            };
        }
        let mean = sum / n as f64;
        let var = values.map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64;
        Stats {
            mean,
            std: var.sqrt(),
            min,
            max,
        }
    }
}

/// Everything `ridi inspect` prints, as JSON with `--json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Inspection {
    /// Format detected.
    pub format: String,
    /// Sequence name.
    pub name: String,
    /// The phone's model (`iPhone 4S`), when the source says.
    pub device: Option<String>,
    /// The rate the phone's IMU sampled at before any resampling, Hz, when known
    /// ([`ridi_data::DeviceInfo::imu_rate_hz`]); `rate_hz` is the sequence's.
    pub device_imu_rate_hz: Option<f64>,
    /// Placement label, if known.
    pub placement: Option<String>,
    /// Number of frames.
    pub frames: usize,
    /// First to last frame, seconds.
    pub duration_s: f64,
    /// Mean rate, Hz.
    pub rate_hz: f64,
    /// Longest interval between frames, seconds.
    pub max_gap_s: f64,
    /// Where the device orientation comes from.
    pub orientation_source: Option<String>,
    /// Gravity magnitude, m/s^2.
    pub gravity_norm: Stats,
    /// Fraction of frames with the phone upside down ([`UpAxis::is_upside_down`]), where the
    /// paper's S is ill-conditioned.
    pub upside_down_fraction: f64,
    /// Accelerometer magnitude, m/s^2.
    pub acce_norm: Stats,
    /// Whether a magnetometer stream is present.
    pub has_magnet: bool,
    /// Whether a step counter is present.
    pub has_steps: bool,
    /// Fraction of frames with ground truth (0 or 1: sequences carry it on every frame or not
    /// at all; readers trim or split where it is missing).
    pub ground_truth_coverage: f64,
    /// Horizontal ground-truth path length, metres.
    pub path_length_m: Option<f64>,
    /// Things a user should look at.
    pub warnings: Vec<String>,
}

/// Inspects `seq`, read as `format`.
pub fn inspect(seq: &Sequence, format: Format) -> Inspection {
    let gravity_norm = Stats::of(seq.gravity().iter().map(|g| g.norm()));
    let upside_down = seq
        .gravity()
        .iter()
        .filter(|&&g| UpAxis::is_upside_down(g))
        .count();
    let upside_down_fraction = upside_down as f64 / seq.len().max(1) as f64;
    let acce_norm = Stats::of(seq.acce().iter().map(|a| a.norm()));
    let rate_hz = seq.rate_hz();
    let max_gap_s = seq.max_gap();
    let mut warnings = Vec::new();
    let median_rate = seq.median_rate_hz();
    let window = ridi_features::FeatureConfig::default().window;
    if seq.len() < 2 {
        warnings.push("a single frame: no rate, nothing to train, track or evaluate".into());
    } else if (median_rate - RATE_HZ).abs() > RATE_TOLERANCE * RATE_HZ {
        warnings.push(format!(
            "rate {median_rate:.1} Hz (median frame interval): train, track and eval need \
             {RATE_HZ} Hz (within {:.0} %)",
            RATE_TOLERANCE * 100.0
        ));
    }
    if (2..=window).contains(&seq.len()) {
        warnings.push(format!(
            "{} frames: no whole feature window of the default {window} frames before any of \
             them, nothing to train, track or evaluate with such a model",
            seq.len()
        ));
    }
    if rate_hz > 0.0 && max_gap_s > 5.0 / rate_hz {
        warnings.push(format!(
            "longest gap {:.3} s is {:.0} frame intervals",
            max_gap_s,
            max_gap_s * rate_hz
        ));
    }
    if (gravity_norm.mean - ridi_frames::STANDARD_GRAVITY).abs() > 0.3 {
        warnings.push(format!(
            "mean gravity magnitude {:.3} m/s^2 is far from 9.81: accelerometer scale error?",
            gravity_norm.mean
        ));
    }
    // Reading refuses ratios outside `acce_gravity_ratio` (an accelerometer in g gives 0.1);
    // within it, a mismatch is worth a look (running reaches 1.9).
    if (acce_norm.mean - gravity_norm.mean).abs() > 0.5 {
        let (min, max) = ridi_data::Validation::default().acce_gravity_ratio;
        warnings.push(format!(
            "accelerometer mean magnitude {:.3} m/s^2 is {:.2} times gravity's {:.3}: large \
             accelerations (running) or a scale error? (reading refuses ratios outside \
             {min}..{max})",
            acce_norm.mean,
            acce_norm.mean / gravity_norm.mean,
            gravity_norm.mean
        ));
    }
    if upside_down_fraction > 0.01 {
        warnings.push(format!(
            "phone upside down in {:.0} % of frames: train with the default \
             `--up-axis plus-or-minus-y`, the paper's S (`plus-y`) turns erratically there",
            100.0 * upside_down_fraction
        ));
    }
    if seq.duration() < 10.0 {
        warnings.push("shorter than 10 s: too short for the paper's alignment".into());
    }
    if seq.ground_truth().is_none() {
        warnings.push("no ground truth: usable for tracking, not for training".into());
    }
    Inspection {
        format: format.to_string(),
        name: seq.name().to_string(),
        device: seq.device().map(|d| d.model().to_string()),
        device_imu_rate_hz: seq.device().and_then(|d| d.imu_rate_hz()),
        placement: seq.placement().map(str::to_string),
        frames: seq.len(),
        duration_s: seq.duration(),
        rate_hz,
        max_gap_s,
        orientation_source: seq.orientation_source().map(|s| s.to_string()),
        gravity_norm,
        upside_down_fraction,
        acce_norm,
        has_magnet: seq.magnet().is_some(),
        has_steps: seq.steps().is_some(),
        ground_truth_coverage: if seq.ground_truth().is_some() {
            1.0
        } else {
            0.0
        },
        // `+ 0.0` turns the -0.0 of a path without steps into 0.0 for printing.
        path_length_m: seq.path_length().map(|l| l + 0.0),
        warnings,
    }
}

impl std::fmt::Display for Inspection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "name:         {}", self.name)?;
        writeln!(f, "format:       {}", self.format)?;
        match (&self.device, self.device_imu_rate_hz) {
            (Some(d), Some(r)) => writeln!(
                f,
                "device:       {d}, IMU at {r:.1} Hz (this sequence: {:.0} Hz)",
                self.rate_hz
            )?,
            (Some(d), None) => writeln!(f, "device:       {d}")?,
            (None, _) => writeln!(f, "device:       (unknown)")?,
        }
        writeln!(
            f,
            "placement:    {}",
            self.placement.as_deref().unwrap_or("(none)")
        )?;
        writeln!(
            f,
            "frames:       {} over {:.2} s",
            self.frames, self.duration_s
        )?;
        writeln!(
            f,
            "rate:         {:.2} Hz mean, worst gap {:.4} s",
            self.rate_hz, self.max_gap_s
        )?;
        writeln!(
            f,
            "orientation:  {}",
            self.orientation_source.as_deref().unwrap_or("(unknown)")
        )?;
        let g = &self.gravity_norm;
        writeln!(
            f,
            "|gravity|:    mean {:.4}, std {:.4}, min {:.4}, max {:.4} m/s^2",
            g.mean, g.std, g.min, g.max
        )?;
        writeln!(
            f,
            "upside down:  {:.1} % of frames",
            100.0 * self.upside_down_fraction
        )?;
        let a = &self.acce_norm;
        writeln!(
            f,
            "|acce|:       mean {:.4}, std {:.4}, min {:.4}, max {:.4} m/s^2",
            a.mean, a.std, a.min, a.max
        )?;
        writeln!(
            f,
            "magnetometer: {}   step counter: {}",
            if self.has_magnet { "yes" } else { "no" },
            if self.has_steps { "yes" } else { "no" }
        )?;
        match self.path_length_m {
            Some(len) => writeln!(
                f,
                "ground truth: {:.0} % of frames, path length {len:.2} m",
                self.ground_truth_coverage * 100.0
            )?,
            None => writeln!(f, "ground truth: none")?,
        }
        for w in &self.warnings {
            writeln!(f, "warning:      {w}")?;
        }
        Ok(())
    }
}

/// What `ridi inspect` reports about a model file (and `ridi train` about the model it
/// trained), as JSON with `--json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelInspection {
    /// Model file format version ([`Cascade::format_version`]: 7 exact, 8 Nyström).
    pub format_version: u32,
    /// Landmarks of a Nyström model (`None`: exact kernel machines,
    /// [`ridi_regress::Solver`]); every placement shares them.
    pub landmarks: Option<usize>,
    /// Frames per feature window.
    pub window: usize,
    /// Frames between training windows.
    pub step: usize,
    /// Gaussian sigma within each window, frames.
    pub feature_sigma: f64,
    /// Gaussian sigma of the velocity targets, frames.
    pub target_sigma: f64,
    /// Feature channels, in row order.
    pub channels: Vec<FeatureChannel>,
    /// Values per feature (`window x 3 x channels`).
    pub dim: usize,
    /// Whether features are z-scored with the training set's statistics.
    pub standardized: bool,
    /// The device axis S is built on.
    pub up_axis: UpAxis,
    /// The orientation features are computed with (track and eval use the same).
    pub orientation: Orientation,
    /// Principal coordinates stored per sample (`None`: every value in half precision).
    pub projected_components: Option<usize>,
    /// Share of the training variance the stored coordinates hold (1 for half precision).
    pub stored_variance: f64,
    /// One entry per placement.
    pub placements: Vec<PlacementModel>,
    /// Cross-validation results of the grid search (empty without a search); `channel` is 0
    /// for S-x, 1 for S-z and 2 for the speed.
    pub grid: Vec<GridRow>,
}

/// The regressors of one placement ([`ModelInspection::placements`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlacementModel {
    /// Placement name.
    pub name: String,
    /// Training samples the model keeps for it.
    pub samples: usize,
    /// The S-x regressor.
    pub s_x: Regressor,
    /// The S-z regressor.
    pub s_z: Regressor,
    /// The speed regressor, if the model has one.
    pub speed: Option<Regressor>,
}

/// Hyper-parameters of one epsilon-SVR ([`PlacementModel`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Regressor {
    /// `C`.
    pub c: f64,
    /// Epsilon, m/s.
    pub epsilon: f64,
}

impl From<(f64, f64)> for Regressor {
    fn from((c, epsilon): (f64, f64)) -> Self {
        Regressor { c, epsilon }
    }
}

impl std::fmt::Display for Regressor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "C={} eps={}", self.c, self.epsilon)
    }
}

/// Describes a trained model.
pub fn inspect_model(model: &Cascade) -> ModelInspection {
    let config = model.feature_config();
    let (projected_components, stored_variance) = match model.stored_as() {
        StoredAs::Half => (None, 1.0),
        StoredAs::Projected { components, energy } => (Some(components), energy),
    };
    let placements = model
        .placements()
        .iter()
        .enumerate()
        .map(|(p, name)| {
            let [x, z] = model.regressor_params(p).unwrap_or_default();
            PlacementModel {
                name: name.clone(),
                samples: model.stored_samples(p),
                s_x: x.into(),
                s_z: z.into(),
                speed: model.speed_params(p).map(Regressor::from),
            }
        })
        .collect();
    ModelInspection {
        format_version: model.format_version(),
        landmarks: match model.solver() {
            Solver::Exact => None,
            Solver::Nystrom(n) => Some(n.landmarks()),
        },
        window: config.window,
        step: config.step,
        feature_sigma: config.feature_sigma,
        target_sigma: config.target_sigma,
        channels: config.channels.clone(),
        dim: model.dim(),
        standardized: config.standardization.is_some(),
        up_axis: config.up_axis,
        orientation: config.orientation,
        projected_components,
        stored_variance,
        placements,
        grid: model.grid_results().to_vec(),
    }
}

impl std::fmt::Display for ModelInspection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let names: Vec<&str> = self.placements.iter().map(|p| p.name.as_str()).collect();
        writeln!(f, "placements: {}", names.join(", "))?;
        writeln!(
            f,
            "feature window: {} frames (sigma {}), a training window every {} frames, {}",
            self.window,
            self.feature_sigma,
            self.step,
            if self.standardized {
                "standardized"
            } else {
                "raw (not standardized)"
            }
        )?;
        let up = match self.up_axis {
            UpAxis::PlusY => "device +y",
            UpAxis::PlusOrMinusY => "device +y, or -y while upside down",
        };
        writeln!(f, "stabilized frame S built on: {up}")?;
        let orientation = match self.orientation {
            Orientation::Recorded => "as recorded",
            Orientation::Estimated => "estimated from gyro + accelerometer",
        };
        writeln!(
            f,
            "orientation: {orientation} (track and eval use the same)"
        )?;
        if let Some(m) = self.landmarks {
            writeln!(
                f,
                "solver: Nyström, {m} landmarks shared by every placement (their samples below)"
            )?;
        }
        match self.projected_components {
            None => writeln!(f, "samples stored: {} values in half precision", self.dim)?,
            Some(components) => writeln!(
                f,
                "samples stored: {components} principal coordinates of {} ({:.3} % of the \
                 variance)",
                self.dim,
                100.0 * self.stored_variance
            )?,
        }
        for p in &self.placements {
            let speed = p.speed.map_or(String::new(), |s| format!("  speed: {s}"));
            writeln!(
                f,
                "  {:<12} {:>6} samples  S-x: {}  S-z: {}{speed}",
                p.name, p.samples, p.s_x, p.s_z
            )?;
        }
        if !self.grid.is_empty() {
            writeln!(f, "cross-validation (MSE, (m/s)^2, mean over folds):")?;
            writeln!(
                f,
                "  {:<12} {:>7} {:>8} {:>8} {:>10}",
                "placement", "channel", "C", "epsilon", "MSE"
            )?;
            for r in &self.grid {
                writeln!(
                    f,
                    "  {:<12} {:>7} {:>8} {:>8} {:>10.5}",
                    r.placement,
                    ["S-x", "S-z", "speed"][usize::from(r.channel.min(2))],
                    r.c,
                    r.epsilon,
                    r.mse
                )?;
            }
        }
        Ok(())
    }
}
