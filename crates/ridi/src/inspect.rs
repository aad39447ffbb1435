//! What `ridi inspect` reports about a sequence or a model.

use ridi_data::{Format, Sequence, shown};
use ridi_features::FeatureChannel;
use ridi_frames::UpAxis;
use ridi_regress::{Cascade, GridRow, Solver, StoredAs};
use serde::Serialize;

use crate::convert::RESAMPLE_MAX_GAP_FRAMES;
use crate::track::{TRACK_RATE_HZ, TRACK_RATE_TOLERANCE};
use ridi_features::Orientation;

/// Summary statistics of a scalar series.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SeriesStats {
    /// Mean.
    pub mean: f64,
    /// Standard deviation (population).
    pub std: f64,
    /// Minimum.
    pub min: f64,
    /// Maximum.
    pub max: f64,
}

impl SeriesStats {
    /// Statistics of `values` (all zero when empty), in one pass (the sum, the extremes, and the sums of the
    /// differences from the first value and of their squares).
    pub fn of(values: impl Iterator<Item = f64>) -> SeriesStats {
        let mut sum = StatsSum::default();
        values.for_each(|v| sum.push(v));
        sum.stats()
    }
}

/// [`SeriesStats`] summed one value at a time, so that a stream too long to hold has them: the sum,
/// the extremes, and the sums of the values' differences from the first and of their squares
/// (shifted so that a small spread about a large mean keeps its digits).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct StatsSum {
    n: usize,
    sum: f64,
    min: f64,
    max: f64,
    shift: f64,
    d: f64,
    dd: f64,
}

impl StatsSum {
    fn push(&mut self, v: f64) {
        if self.n == 0 {
            (self.min, self.max, self.shift) = (v, v, v);
        }
        self.n += 1;
        self.sum += v;
        self.min = self.min.min(v);
        self.max = self.max.max(v);
        let d = v - self.shift;
        self.d += d;
        self.dd += d * d;
    }

    fn stats(&self) -> SeriesStats {
        if self.n == 0 {
            return SeriesStats {
                mean: 0.0,
                std: 0.0,
                min: 0.0,
                max: 0.0,
            };
        }
        let n = self.n as f64;
        let var = ((self.dd - self.d * self.d / n) / n).max(0.0);
        SeriesStats {
            mean: self.sum / n,
            std: var.sqrt(),
            min: self.min,
            max: self.max,
        }
    }
}

/// What [`Inspection`] is made of, from a whole sequence or a stream of rows.
struct Summary {
    format: Format,
    name: String,
    device: Option<ridi_data::DeviceInfo>,
    placement: Option<String>,
    frames: usize,
    duration: f64,
    max_gap: f64,
    /// The median rate, when it is off [`TRACK_RATE_HZ`] by more than [`TRACK_RATE_TOLERANCE`].
    rate_off: Option<f64>,
    /// The median rate (one over the median frame interval), which gaps do not lower: what a
    /// gap is counted in frame intervals of. `None`: not known (a stream without a long gap).
    median_rate: Option<f64>,
    orientation_source: Option<ridi_data::OrientationSource>,
    gravity_norm: SeriesStats,
    upside_down: usize,
    acce_norm: SeriesStats,
    has_magnet: bool,
    has_steps: bool,
    has_ground_truth: bool,
    path_length: Option<f64>,
}

/// The horizontal distance between two ground-truth positions, as
/// [`Sequence::path_length`] sums it.
fn horizontal_step(a: ridi_frames::WorldVec, b: ridi_frames::WorldVec) -> f64 {
    ((b.x() - a.x()).powi(2) + (b.y() - a.y()).powi(2)).sqrt()
}

/// Inspects the recording `rows` reads, in one pass over its rows (memory that does not grow
/// with its length): what [`inspect`] reports of the sequence the whole-file reader gives.
///
/// # Errors
/// What reading the recording refuses ([`ridi_data::RowReader::finish`]).
pub fn inspect_stream(mut rows: ridi_data::RowReader) -> crate::Result<Inspection> {
    let (mut gravity, mut acce) = (StatsSum::default(), StatsSum::default());
    let (mut upside_down, mut max_gap) = (0usize, 0.0f64);
    let mut rate = ridi_data::MedianTest::default();
    let (mut first, mut last) = (None::<f64>, None::<f64>);
    let mut path = -0.0;
    let mut previous_position = None;
    let mut has_ground_truth = false;
    for row in rows.by_ref() {
        let row = row?;
        if let Some(t) = last {
            max_gap = max_gap.max(row.time - t);
            crate::track::count_rate(&mut rate, row.time - t);
        }
        first.get_or_insert(row.time);
        last = Some(row.time);
        gravity.push(row.gravity.norm());
        acce.push(row.acce.norm());
        upside_down += usize::from(UpAxis::is_upside_down(row.gravity));
        if let Some((p, _)) = row.ground_truth {
            has_ground_truth = true;
            if let Some(q) = previous_position {
                path += horizontal_step(q, p);
            }
            previous_position = Some(p);
        }
    }
    let file = rows.path().to_path_buf();
    let opts = rows.options().clone();
    let summary = Summary {
        format: rows.format(),
        name: rows.name().to_string(),
        device: rows.device().cloned(),
        placement: None,
        frames: rows.rows(),
        duration: last.zip(first).map_or(0.0, |(l, f)| l - f),
        max_gap,
        rate_off: None,
        median_rate: None,
        orientation_source: rows.orientation_source(),
        gravity_norm: gravity.stats(),
        upside_down,
        acce_norm: acce.stats(),
        has_magnet: rows.has_magnet(),
        has_steps: rows.has_steps(),
        has_ground_truth,
        path_length: has_ground_truth.then_some(path),
    };
    rows.finish()?;
    let rate_off = crate::track::rate_off(&rate, &file, &opts)?;
    // The exact median takes another pass over the file: only for a gap the report counts.
    let fastest = TRACK_RATE_HZ * (1.0 + TRACK_RATE_TOLERANCE);
    let median_rate = match rate_off {
        Some(rate) => Some(rate),
        None if summary.max_gap > RESAMPLE_MAX_GAP_FRAMES / fastest => {
            Some(1.0 / ridi_data::median_interval(&file, &opts)?)
        }
        None => None,
    };
    Ok(report(Summary {
        rate_off: rate_off.filter(|_| summary.frames >= 2),
        median_rate: median_rate.filter(|_| summary.frames >= 2),
        ..summary
    }))
}

/// Everything `ridi inspect` prints, as JSON with `--json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Inspection {
    /// Format detected (its [`Format::key`] in JSON, in words in text).
    pub format: Format,
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
    pub longest_gap_s: f64,
    /// Where the device orientation comes from (in JSON by its key, as in files:
    /// `rotation-vector`).
    pub orientation_source: Option<ridi_data::OrientationSource>,
    /// Gravity magnitude, m/s^2.
    pub gravity_norm: SeriesStats,
    /// Fraction of frames with the phone upside down ([`UpAxis::is_upside_down`]), where the
    /// paper's S is ill-conditioned.
    pub upside_down_fraction: f64,
    /// Accelerometer magnitude, m/s^2.
    pub acce_norm: SeriesStats,
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
    let median_rate = seq.median_rate_hz();
    let off = (median_rate - TRACK_RATE_HZ).abs() > TRACK_RATE_TOLERANCE * TRACK_RATE_HZ;
    report(Summary {
        format,
        name: seq.name().to_string(),
        device: seq.device().cloned(),
        placement: seq.placement().map(str::to_string),
        frames: seq.len(),
        duration: seq.duration(),
        max_gap: seq.max_gap(),
        rate_off: (seq.len() >= 2 && off).then_some(median_rate),
        median_rate: (seq.len() >= 2).then_some(median_rate),
        orientation_source: seq.orientation_source(),
        gravity_norm: SeriesStats::of(seq.gravity().iter().map(|g| g.norm())),
        upside_down: seq
            .gravity()
            .iter()
            .filter(|&&g| UpAxis::is_upside_down(g))
            .count(),
        acce_norm: SeriesStats::of(seq.acce().iter().map(|a| a.norm())),
        has_magnet: seq.magnet().is_some(),
        has_steps: seq.steps().is_some(),
        has_ground_truth: seq.ground_truth().is_some(),
        path_length: seq.path_length(),
    })
}

/// The report of a [`Summary`]: its figures and the warnings they call for.
fn report(s: Summary) -> Inspection {
    let gravity_norm = s.gravity_norm;
    let upside_down_fraction = s.upside_down as f64 / s.frames.max(1) as f64;
    let acce_norm = s.acce_norm;
    // As `Sequence::rate_hz`: the mean rate, 0 for a single frame.
    let rate_hz = if s.duration > 0.0 {
        (s.frames - 1) as f64 / s.duration
    } else {
        0.0
    };
    let longest_gap_s = s.max_gap;
    let mut warnings = Vec::new();
    let window = ridi_features::FeatureConfig::default().window;
    if s.frames < 2 {
        warnings.push("a single frame: no rate, nothing to train, track or evaluate".into());
    } else if let Some(median_rate) = s.rate_off {
        warnings.push(format!(
            "rate {median_rate:.1} Hz (median frame interval): train, track and eval need \
             {TRACK_RATE_HZ} Hz (within {:.0} %)",
            TRACK_RATE_TOLERANCE * 100.0
        ));
    }
    if (2..=window).contains(&s.frames) {
        warnings.push(format!(
            "{} frames: no whole feature window of the default {window} frames before any of \
             them, nothing to train, track or evaluate with such a model",
            s.frames
        ));
    }
    // Warned of beyond what `ridi convert --rate` interpolates across.
    let median_rate = s.median_rate.unwrap_or(rate_hz);
    if median_rate > 0.0 && longest_gap_s > RESAMPLE_MAX_GAP_FRAMES / median_rate {
        let mut w = format!(
            "longest gap {:.3} s is {:.0} frame intervals",
            longest_gap_s,
            longest_gap_s * median_rate
        );
        // `ridi inspect` reads pauses the other commands refuse (`inspect_options`).
        let limit = ridi_data::Validation::default().max_gap_s;
        if longest_gap_s > limit {
            w += &format!(
                ", longer than the {limit} s the other commands read across: `ridi convert \
                 --split-at-gaps 0.1` cuts the recording at its gaps"
            );
        }
        warnings.push(w);
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
    if s.duration < 10.0 {
        warnings.push("shorter than 10 s: too short for the paper's alignment".into());
    }
    if !s.has_ground_truth {
        warnings.push("no ground truth: usable for tracking, not for training".into());
    }
    Inspection {
        format: s.format,
        name: s.name,
        device: s.device.as_ref().map(|d| d.model().to_string()),
        device_imu_rate_hz: s.device.as_ref().and_then(|d| d.imu_rate_hz()),
        placement: s.placement,
        frames: s.frames,
        duration_s: s.duration,
        rate_hz,
        longest_gap_s,
        orientation_source: s.orientation_source,
        gravity_norm,
        upside_down_fraction,
        acce_norm,
        has_magnet: s.has_magnet,
        has_steps: s.has_steps,
        ground_truth_coverage: if s.has_ground_truth { 1.0 } else { 0.0 },
        // `+ 0.0` turns the -0.0 of a path without steps into 0.0 for printing.
        path_length_m: s.path_length.map(|l| l + 0.0),
        warnings,
    }
}

impl std::fmt::Display for Inspection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // Names come from file names and list lines: escaped, as every name `ridi` prints.
        writeln!(f, "name:         {}", shown(&self.name))?;
        writeln!(f, "format:       {}", self.format)?;
        match (&self.device, self.device_imu_rate_hz) {
            (Some(d), Some(r)) => writeln!(
                f,
                "device:       {}, IMU at {r:.1} Hz (this sequence: {:.0} Hz)",
                shown(d),
                self.rate_hz
            )?,
            (Some(d), None) => writeln!(f, "device:       {}", shown(d))?,
            (None, _) => writeln!(f, "device:       (unknown)")?,
        }
        writeln!(
            f,
            "placement:    {}",
            self.placement.as_deref().map_or("(none)".into(), shown)
        )?;
        writeln!(
            f,
            "frames:       {} over {:.2} s",
            self.frames, self.duration_s
        )?;
        writeln!(
            f,
            "rate:         {:.2} Hz mean, longest gap {:.4} s",
            self.rate_hz, self.longest_gap_s
        )?;
        writeln!(
            f,
            "orientation:  {}",
            self.orientation_source
                .map_or("(unknown)".to_owned(), |o| o.to_string())
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
            writeln!(f, "warning:      {}", shown(w))?;
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
    /// The model file's fingerprint, as an evaluation report records it
    /// ([`crate::Provenance::model_fingerprint`]): which model a report was made with.
    pub fingerprint: String,
    /// The solver it was trained with, as `ridi train --solver` names it: `exact` or
    /// `nystrom`.
    pub solver: &'static str,
    /// Most landmarks one machine of a Nyström model holds (`None`: exact kernel machines,
    /// [`ridi_regress::Solver`]): the classifier's are drawn from all rows, each placement's
    /// regressors' from its own (its samples).
    pub landmarks: Option<usize>,
    /// Seed of a Nyström model's landmark draw (`ridi train --seed`; `None`: exact).
    pub landmark_seed: Option<u64>,
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
    /// Cross-validation results of the grid search (`ridi train --grid`; empty without a
    /// search); `channel` is 0 for S-x, 1 for S-z and 2 for the speed.
    pub cross_validation: Vec<GridRow>,
}

/// The regressors of one placement ([`ModelInspection::placements`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlacementModel {
    /// Placement name.
    pub name: String,
    /// Training windows it was trained on (turned copies included).
    pub windows: usize,
    /// Training samples the model keeps for it (a Nyström model: its regressors' landmarks).
    pub samples: usize,
    /// The S-x regressor.
    pub s_x: RegressorSummary,
    /// The S-z regressor.
    pub s_z: RegressorSummary,
    /// The speed regressor, if the model has one.
    pub speed: Option<RegressorSummary>,
}

/// Hyper-parameters of one regressor ([`PlacementModel`]): an epsilon-SVR's, or a Nyström
/// model's kernel ridge regression's, whose `epsilon` is 0 (it has none).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RegressorSummary {
    /// `C`.
    pub c: f64,
    /// Epsilon, m/s.
    pub epsilon: f64,
}

impl From<(f64, f64)> for RegressorSummary {
    fn from((c, epsilon): (f64, f64)) -> Self {
        RegressorSummary { c, epsilon }
    }
}

impl std::fmt::Display for RegressorSummary {
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
        .placement_names()
        .iter()
        .enumerate()
        .map(|(p, name)| {
            let [x, z] = model.regressor_params(p).unwrap_or_default();
            PlacementModel {
                name: name.clone(),
                windows: model.training_windows(p),
                samples: model.stored_samples(p),
                s_x: x.into(),
                s_z: z.into(),
                speed: model.speed_params(p).map(RegressorSummary::from),
            }
        })
        .collect();
    let (solver, landmarks, landmark_seed) = match model.solver() {
        Solver::Exact => ("exact", None, None),
        Solver::Nystrom(n) => ("nystrom", Some(n.landmarks()), Some(n.seed())),
    };
    ModelInspection {
        // A model that cannot be encoded (one serde built alone) has no file to name.
        fingerprint: crate::evaluate::model_fingerprint(model).unwrap_or_else(|_| "-".into()),
        format_version: model.format_version(),
        solver,
        landmarks,
        landmark_seed,
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
        cross_validation: model.grid_results().to_vec(),
    }
}

impl std::fmt::Display for ModelInspection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // Placement labels come from list lines, which may hold any character but a space.
        let names: Vec<String> = self.placements.iter().map(|p| shown(&p.name)).collect();
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
        writeln!(
            f,
            "fingerprint: {} (an evaluation report's model_fingerprint)",
            self.fingerprint
        )?;
        if let Some(m) = self.landmarks {
            let seed = self.landmark_seed.unwrap_or_default();
            writeln!(
                f,
                "solver: Nyström, up to {m} landmarks per machine drawn with seed {seed} (the \
                 classifier's from all rows; each placement's regressors', by kernel ridge, from \
                 its rows: its samples below)"
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
        // A Nyström model's regressors are kernel ridge regressions: no epsilon to show.
        let params = |r: RegressorSummary| match self.landmarks {
            Some(_) => format!("C={}", r.c),
            None => r.to_string(),
        };
        for p in &self.placements {
            let speed = p
                .speed
                .map_or(String::new(), |s| format!("  speed: {}", params(s)));
            writeln!(
                f,
                "  {:<12} {:>6} samples of {:>7} windows  S-x: {}  S-z: {}{speed}",
                shown(&p.name),
                p.samples,
                p.windows,
                params(p.s_x),
                params(p.s_z)
            )?;
        }
        if !self.cross_validation.is_empty() {
            // Kernel ridge regressors (Nyström) have no epsilon: no column of zeros.
            let epsilon = |e: &dyn std::fmt::Display| match self.landmarks {
                Some(_) => String::new(),
                None => format!(" {e:>8}"),
            };
            writeln!(f, "cross-validation (MSE, (m/s)^2, mean over folds):")?;
            writeln!(
                f,
                "  {:<12} {:>7} {:>8}{} {:>10}",
                "placement",
                "channel",
                "C",
                epsilon(&"epsilon"),
                "MSE"
            )?;
            for r in &self.cross_validation {
                writeln!(
                    f,
                    "  {:<12} {:>7} {:>8}{} {:>10.5}",
                    shown(&r.placement),
                    ["S-x", "S-z", "speed"][usize::from(r.channel.min(2))],
                    r.c,
                    epsilon(&r.epsilon),
                    r.mse
                )?;
            }
        }
        Ok(())
    }
}
