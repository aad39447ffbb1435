//! The methods every evaluation compares: RIDI and its baselines.
//!
//! | method | key | trajectory |
//! | --- | --- | --- |
//! | RIDI | `ridi` | regressed velocities, bias correction (lambda 0.1), double integration |
//! | RAW | `raw` | plain double integration of the linear acceleration from rest |
//! | PDR | `pdr` | steps from the accelerometer magnitude; step length = the sequence's mean ground-truth step length (as in the paper); heading = the device's forward direction (S -z) in the world |
//! | RIDI-MAG | `ridi_mag` | RIDI with only the *magnitude* of each regressed velocity, pointed along the device's forward direction (S -z), as the original code's `mag_only` preset |
//! | RIDI-ORI | `ridi_ori` | RIDI with only the *direction* of each regressed velocity, at a constant speed (the sequence's mean ground-truth speed), as the original's `ori_only` preset |
//! | VELOCITY | `velocity` | the regressed velocities followed closely (lambda 1e-6: the bias absorbs any mismatch) |
//! | STILL | `still` | stays at the start point: on short runs in a small room it can beat real methods on ATE, and a report must show that |
//!
//! PDR, RIDI-MAG and RIDI-ORI use ground truth (mean step length or speed), which flatters
//! them; they are references, not competitors.

use std::fmt;
use std::str::FromStr;

use ridi_correct::{CorrectionConfig, FrameVelocity, correct, integrate, world_acceleration};
use ridi_data::Sequence;
use ridi_eval::{StepDetectorConfig, detect_steps, pdr_trajectory};
use ridi_frames::{StabHorizontal, UpAxis, WorldVec};
use serde::{Deserialize, Serialize};

use crate::error::{PipelineError, Result};

/// A trajectory method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// RIDI itself.
    Ridi,
    /// Plain double integration.
    Raw,
    /// Step counting.
    Pdr,
    /// Regressed speed, device heading.
    RidiMag,
    /// Regressed direction, constant speed.
    RidiOri,
    /// Regressed velocities followed closely.
    Velocity,
    /// Standing still: one point, which the alignment puts at the ground truth's mean
    /// position over the alignment window.
    Still,
}

impl Method {
    /// Every method, in report order.
    pub const ALL: [Method; 7] = [
        Method::Ridi,
        Method::Raw,
        Method::Pdr,
        Method::RidiMag,
        Method::RidiOri,
        Method::Velocity,
        Method::Still,
    ];

    /// The report key (`ridi`, `raw`, `pdr`, `ridi_mag`, `ridi_ori`, `velocity`, `still`).
    pub fn key(self) -> &'static str {
        match self {
            Method::Ridi => "ridi",
            Method::Raw => "raw",
            Method::Pdr => "pdr",
            Method::RidiMag => "ridi_mag",
            Method::RidiOri => "ridi_ori",
            Method::Velocity => "velocity",
            Method::Still => "still",
        }
    }

    /// What the method's trajectory is, as report.md's definitions say it.
    pub fn definition(self) -> &'static str {
        match self {
            Method::Ridi => {
                "RIDI: the regressed velocities, a bias correction solved to follow \
                 them, integrated"
            }
            Method::Raw => "the linear acceleration integrated twice in the world frame",
            Method::Pdr => {
                "steps detected in the accelerometer, every step as long as the \
                 ground truth's path length over the number of steps (an oracle for the \
                 total length; no step detected, it stays put), along the device's forward \
                 heading"
            }
            Method::RidiMag => {
                "each regressed velocity's size along S's forward axis, then \
                 corrected as ridi"
            }
            Method::RidiOri => {
                "each regressed velocity's direction at the ground truth's mean \
                 speed (an oracle), then corrected as ridi"
            }
            Method::Velocity => {
                "the regressed velocities, corrected as ridi with a bias prior \
                 (lambda) of 1e-6 instead of ridi's: followed closely"
            }
            Method::Still => {
                "one point, aligned as the others: the ground truth's mean \
                 position over the alignment window"
            }
        }
    }

    /// Whether the method needs the regression model.
    pub fn needs_model(self) -> bool {
        matches!(
            self,
            Method::Ridi | Method::RidiMag | Method::RidiOri | Method::Velocity
        )
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.key())
    }
}

impl FromStr for Method {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let key = s.trim().to_ascii_lowercase().replace('-', "_");
        Method::ALL
            .into_iter()
            .find(|m| m.key() == key)
            .ok_or_else(|| {
                let keys: Vec<&str> = Method::ALL.iter().map(|m| m.key()).collect();
                format!("unknown method `{s}` (known: {})", keys.join(", "))
            })
    }
}

/// Heading (yaw, radians counter-clockwise from world +x) of the device's forward direction,
/// S -z, at every frame. S is built on device -y while the phone is upside down
/// ([`UpAxis::PlusOrMinusY`]), where the paper's S, and so its yaw, turns erratically.
pub fn device_heading(seq: &Sequence) -> Vec<f64> {
    seq.orientation()
        .iter()
        .zip(seq.gravity())
        .map(|(&q, &g)| UpAxis::PlusOrMinusY.forward_heading(q, g))
        .collect()
}

/// Mean horizontal ground-truth speed, m/s.
fn mean_speed(seq: &Sequence) -> Result<f64> {
    let len = seq
        .path_length()
        .ok_or_else(|| PipelineError::sequence(seq.name(), "has no ground truth"))?;
    Ok(len / seq.duration().max(f64::EPSILON))
}

/// The horizontal trajectory of `method` on `seq`, starting at the origin. `regressions` are
/// the cascade's velocities at their frames (needed by the model-based methods); `config` is
/// RIDI's correction.
pub fn baseline_trajectory(
    method: Method,
    seq: &Sequence,
    regressions: &[FrameVelocity],
    config: CorrectionConfig,
) -> Result<Vec<[f64; 2]>> {
    let with = |regs: Vec<FrameVelocity>, config: CorrectionConfig| -> Result<Vec<[f64; 2]>> {
        let traj = correct(config, &seq.imu(), &regs)?;
        Ok(traj
            .poses
            .iter()
            .map(|p| [p.position.x(), p.position.y()])
            .collect())
    };
    match method {
        Method::Ridi => with(regressions.to_vec(), config),
        Method::Velocity => with(
            regressions.to_vec(),
            CorrectionConfig {
                lambda: 1e-6,
                ..config
            },
        ),
        Method::RidiMag => with(
            regressions
                .iter()
                .map(|r| FrameVelocity {
                    velocity: StabHorizontal::new(0.0, -r.velocity.norm()),
                    ..*r
                })
                .collect(),
            config,
        ),
        Method::RidiOri => {
            let speed = mean_speed(seq)?;
            with(
                regressions
                    .iter()
                    .map(|r| {
                        let n = r.velocity.norm();
                        let v = if n > 1e-9 {
                            r.velocity * (speed / n)
                        } else {
                            StabHorizontal::ZERO
                        };
                        FrameVelocity { velocity: v, ..*r }
                    })
                    .collect(),
                config,
            )
        }
        Method::Raw => {
            let acc = world_acceleration(&seq.imu())?;
            let poses = integrate(seq.time(), &acc, WorldVec::ZERO, WorldVec::ZERO)?;
            Ok(poses
                .iter()
                .map(|p| [p.position.x(), p.position.y()])
                .collect())
        }
        Method::Pdr => {
            let acce: Vec<[f64; 3]> = seq.acce().iter().map(|a| a.to_array()).collect();
            let steps = detect_steps(seq.time(), &acce, &StepDetectorConfig::default())?;
            let gt = seq
                .ground_truth()
                .ok_or_else(|| PipelineError::sequence(seq.name(), "has no ground truth"))?;
            let path = ridi_eval::path_length(&gt.horizontal())?;
            let step_length = if steps.is_empty() {
                0.0
            } else {
                path / steps.len() as f64
            };
            Ok(pdr_trajectory(
                [0.0, 0.0],
                &steps,
                step_length,
                &device_heading(seq),
            )?)
        }
        Method::Still => Ok(vec![[0.0, 0.0]; seq.len()]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_keys_round_trip() {
        for m in Method::ALL {
            assert_eq!(m.key().parse::<Method>(), Ok(m));
        }
        assert_eq!("RIDI-MAG".parse::<Method>(), Ok(Method::RidiMag));
        assert!("nope".parse::<Method>().unwrap_err().contains("ridi_ori"));
    }
}
