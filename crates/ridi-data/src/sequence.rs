//! The sequence model: one recording on one uniform timeline.

use std::fmt;
use std::ops::Range;

use ridi_frames::{DeviceVec, WorldFromDevice, WorldVec};
use serde::{Deserialize, Serialize};

/// Where the device orientation of a sequence comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OrientationSource {
    /// Android game rotation vector (gyro + accelerometer, no magnetometer): RIDI's `rv`.
    GameRotationVector,
    /// Android rotation vector (uses the magnetometer; heading is magnetic north).
    RotationVector,
    /// Estimated by ridi-frames from gyro and accelerometer.
    Estimated,
    /// Ground-truth orientation (Tango, motion capture) used as the device orientation.
    GroundTruth,
}

impl fmt::Display for OrientationSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            OrientationSource::GameRotationVector => "game rotation vector",
            OrientationSource::RotationVector => "rotation vector",
            OrientationSource::Estimated => "estimated",
            OrientationSource::GroundTruth => "ground truth",
        })
    }
}

/// Ground-truth pose per frame. Its world frame is the ground-truth system's (Tango start of
/// service, mocap room): z up like the device orientation's world, but with its own heading and
/// origin.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroundTruth {
    /// Device position, metres.
    pub position: Vec<WorldVec>,
    /// Device orientation, world-from-device.
    pub orientation: Vec<WorldFromDevice>,
}

impl GroundTruth {
    /// The horizontal path, `[x, y]` per frame: what trajectories are evaluated against.
    pub fn horizontal(&self) -> Vec<[f64; 2]> {
        self.position.iter().map(|p| [p.x(), p.y()]).collect()
    }
}

/// Everything a [`Sequence`] is made of, before validation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SequenceParts {
    /// Sequence name (usually the folder name).
    pub name: String,
    /// Placement label (e.g. `handheld`, `bag`), if known.
    pub placement: Option<String>,
    /// Timestamps, seconds, strictly increasing.
    pub time: Vec<f64>,
    /// Calibrated gyroscope, rad/s, device frame.
    pub gyro: Vec<DeviceVec>,
    /// Accelerometer including gravity, m/s^2, device frame.
    pub acce: Vec<DeviceVec>,
    /// Linear acceleration (accelerometer minus gravity), m/s^2, device frame.
    pub linacce: Vec<DeviceVec>,
    /// Gravity, pointing up (about +9.8 along the upward axis at rest), m/s^2, device frame.
    pub gravity: Vec<DeviceVec>,
    /// Magnetometer, microtesla, device frame, if recorded.
    pub magnet: Option<Vec<DeviceVec>>,
    /// Device orientation, world-from-device.
    pub orientation: Vec<WorldFromDevice>,
    /// Where `orientation` comes from.
    pub orientation_source: Option<OrientationSource>,
    /// Ground-truth pose, if any.
    pub ground_truth: Option<GroundTruth>,
    /// Step counter (steps since start), if recorded.
    pub steps: Option<Vec<f64>>,
}

/// Limits applied when a sequence is built.
#[derive(Debug, Clone, PartialEq)]
pub struct Validation {
    /// Largest accepted interval between two frames, seconds.
    pub max_gap_s: f64,
    /// Accepted range of the mean gravity magnitude, m/s^2 (catches data in g or in mm/s^2).
    pub gravity_range: (f64, f64),
}

impl Default for Validation {
    fn default() -> Self {
        Self {
            max_gap_s: 1.0,
            gravity_range: (8.5, 11.0),
        }
    }
}

/// Why a set of [`SequenceParts`] is not a valid sequence.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SequenceError {
    /// No frames.
    #[error("sequence has no frames")]
    Empty,
    /// A channel's length differs from the timeline's.
    #[error("`{field}` has {found} frames, the timeline has {expected}")]
    LengthMismatch {
        /// The channel.
        field: &'static str,
        /// Length of the timeline.
        expected: usize,
        /// Length of the channel.
        found: usize,
    },
    /// NaN or infinity.
    #[error("`{field}` is not finite at frame {index}")]
    NotFinite {
        /// The channel.
        field: &'static str,
        /// 0-based frame index.
        index: usize,
    },
    /// Time does not strictly increase.
    #[error("time does not increase at frame {index}: {previous} s then {next} s")]
    TimeNotIncreasing {
        /// 0-based index of the later frame.
        index: usize,
        /// Time of the earlier frame.
        previous: f64,
        /// Time of the later frame.
        next: f64,
    },
    /// Two frames are too far apart.
    #[error("gap of {gap_s:.3} s before frame {index} (at {time} s) exceeds {max_gap_s} s")]
    Gap {
        /// 0-based index of the frame after the gap.
        index: usize,
        /// Its time.
        time: f64,
        /// Length of the gap.
        gap_s: f64,
        /// The limit.
        max_gap_s: f64,
    },
    /// Mean gravity magnitude outside the plausible range: wrong units or a wrong column.
    #[error(
        "mean gravity magnitude {mean:.3} m/s^2 is outside {min}..{max}: wrong units or column?"
    )]
    Gravity {
        /// Mean magnitude found.
        mean: f64,
        /// Lower limit.
        min: f64,
        /// Upper limit.
        max: f64,
    },
}

/// One recording: IMU channels, device orientation and optional ground truth on one timeline.
///
/// Built only through [`Sequence::new`] (or [`Sequence::with_validation`]), so every
/// `Sequence` has equal channel lengths, finite values, strictly increasing time without long
/// gaps and a plausible gravity magnitude.
#[derive(Debug, Clone, PartialEq)]
pub struct Sequence {
    parts: SequenceParts,
}

fn check_len(field: &'static str, expected: usize, found: usize) -> Result<(), SequenceError> {
    if expected == found {
        Ok(())
    } else {
        Err(SequenceError::LengthMismatch {
            field,
            expected,
            found,
        })
    }
}

fn check_vecs(field: &'static str, n: usize, v: &[DeviceVec]) -> Result<(), SequenceError> {
    check_len(field, n, v.len())?;
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(SequenceError::NotFinite { field, index }),
        None => Ok(()),
    }
}

impl Sequence {
    /// Validates `parts` with the default [`Validation`].
    pub fn new(parts: SequenceParts) -> Result<Self, SequenceError> {
        Self::with_validation(parts, &Validation::default())
    }

    /// Validates `parts` with explicit limits.
    pub fn with_validation(
        parts: SequenceParts,
        limits: &Validation,
    ) -> Result<Self, SequenceError> {
        let n = parts.time.len();
        if n == 0 {
            return Err(SequenceError::Empty);
        }
        if let Some(index) = parts.time.iter().position(|t| !t.is_finite()) {
            return Err(SequenceError::NotFinite {
                field: "time",
                index,
            });
        }
        for (i, w) in parts.time.windows(2).enumerate() {
            let gap = w[1] - w[0];
            if gap <= 0.0 {
                return Err(SequenceError::TimeNotIncreasing {
                    index: i + 1,
                    previous: w[0],
                    next: w[1],
                });
            }
            if gap > limits.max_gap_s {
                return Err(SequenceError::Gap {
                    index: i + 1,
                    time: w[1],
                    gap_s: gap,
                    max_gap_s: limits.max_gap_s,
                });
            }
        }
        check_vecs("gyro", n, &parts.gyro)?;
        check_vecs("acce", n, &parts.acce)?;
        check_vecs("linacce", n, &parts.linacce)?;
        check_vecs("gravity", n, &parts.gravity)?;
        if let Some(m) = &parts.magnet {
            check_vecs("magnet", n, m)?;
        }
        // Rot values are unit quaternions by construction; only the length can be wrong.
        check_len("orientation", n, parts.orientation.len())?;
        if let Some(gt) = &parts.ground_truth {
            check_len("ground_truth.orientation", n, gt.orientation.len())?;
            check_len("ground_truth.position", n, gt.position.len())?;
            if let Some(index) = gt.position.iter().position(|p| !p.is_finite()) {
                return Err(SequenceError::NotFinite {
                    field: "ground_truth.position",
                    index,
                });
            }
        }
        if let Some(steps) = &parts.steps {
            check_len("steps", n, steps.len())?;
            if let Some(index) = steps.iter().position(|s| !s.is_finite()) {
                return Err(SequenceError::NotFinite {
                    field: "steps",
                    index,
                });
            }
        }
        let mean = parts.gravity.iter().map(|g| g.norm()).sum::<f64>() / n as f64;
        let (min, max) = limits.gravity_range;
        if !(min..=max).contains(&mean) {
            return Err(SequenceError::Gravity { mean, min, max });
        }
        Ok(Self { parts })
    }

    /// Gives the parts back (to edit and re-validate).
    pub fn into_parts(self) -> SequenceParts {
        self.parts
    }

    /// All parts, read-only.
    pub fn parts(&self) -> &SequenceParts {
        &self.parts
    }

    /// Sequence name.
    pub fn name(&self) -> &str {
        &self.parts.name
    }
    /// Placement label, if known.
    pub fn placement(&self) -> Option<&str> {
        self.parts.placement.as_deref()
    }
    /// Sets the placement label (e.g. from a list file).
    pub fn set_placement(&mut self, placement: Option<String>) {
        self.parts.placement = placement;
    }
    /// Renames the sequence.
    pub fn set_name(&mut self, name: impl Into<String>) {
        self.parts.name = name.into();
    }
    /// Number of frames (at least 1).
    pub fn len(&self) -> usize {
        self.parts.time.len()
    }
    /// Always `false`: a valid sequence has frames.
    pub fn is_empty(&self) -> bool {
        false
    }
    /// Timestamps, seconds.
    pub fn time(&self) -> &[f64] {
        &self.parts.time
    }
    /// Gyroscope, rad/s, device frame.
    pub fn gyro(&self) -> &[DeviceVec] {
        &self.parts.gyro
    }
    /// Accelerometer with gravity, m/s^2, device frame.
    pub fn acce(&self) -> &[DeviceVec] {
        &self.parts.acce
    }
    /// Linear acceleration, m/s^2, device frame.
    pub fn linacce(&self) -> &[DeviceVec] {
        &self.parts.linacce
    }
    /// Gravity (pointing up), m/s^2, device frame.
    pub fn gravity(&self) -> &[DeviceVec] {
        &self.parts.gravity
    }
    /// Magnetometer, if recorded.
    pub fn magnet(&self) -> Option<&[DeviceVec]> {
        self.parts.magnet.as_deref()
    }
    /// Device orientation, world-from-device.
    pub fn orientation(&self) -> &[WorldFromDevice] {
        &self.parts.orientation
    }
    /// Where the device orientation comes from.
    pub fn orientation_source(&self) -> Option<OrientationSource> {
        self.parts.orientation_source
    }
    /// Ground truth, if any.
    pub fn ground_truth(&self) -> Option<&GroundTruth> {
        self.parts.ground_truth.as_ref()
    }
    /// Step counter, if recorded.
    pub fn steps(&self) -> Option<&[f64]> {
        self.parts.steps.as_deref()
    }

    /// Duration from first to last frame, seconds.
    pub fn duration(&self) -> f64 {
        self.parts.time[self.len() - 1] - self.parts.time[0]
    }

    /// Measured mean rate, Hz (0 for a single frame).
    pub fn rate_hz(&self) -> f64 {
        let d = self.duration();
        if d > 0.0 {
            (self.len() - 1) as f64 / d
        } else {
            0.0
        }
    }

    /// Longest interval between two frames, seconds (0 for a single frame).
    pub fn max_gap(&self) -> f64 {
        self.parts
            .time
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(0.0, f64::max)
    }

    /// Horizontal path length of the ground truth, metres.
    pub fn path_length(&self) -> Option<f64> {
        let gt = self.ground_truth()?;
        Some(
            gt.position
                .windows(2)
                .map(|w| ((w[1].x() - w[0].x()).powi(2) + (w[1].y() - w[0].y()).powi(2)).sqrt())
                .sum(),
        )
    }

    /// The frames in `range`, as a new sequence with the same name and labels.
    ///
    /// # Panics
    /// When `range` is empty or out of bounds.
    pub fn slice(&self, range: Range<usize>) -> Sequence {
        assert!(
            range.start < range.end && range.end <= self.len(),
            "slice {range:?} of a {}-frame sequence",
            self.len()
        );
        let p = &self.parts;
        let r = || range.clone();
        Sequence {
            parts: SequenceParts {
                name: p.name.clone(),
                placement: p.placement.clone(),
                time: p.time[r()].to_vec(),
                gyro: p.gyro[r()].to_vec(),
                acce: p.acce[r()].to_vec(),
                linacce: p.linacce[r()].to_vec(),
                gravity: p.gravity[r()].to_vec(),
                magnet: p.magnet.as_ref().map(|m| m[r()].to_vec()),
                orientation: p.orientation[r()].to_vec(),
                orientation_source: p.orientation_source,
                ground_truth: p.ground_truth.as_ref().map(|gt| GroundTruth {
                    position: gt.position[r()].to_vec(),
                    orientation: gt.orientation[r()].to_vec(),
                }),
                steps: p.steps.as_ref().map(|s| s[r()].to_vec()),
            },
        }
    }
}
