//! Which orientation a sequence is tracked with: the recorded one (Tango, the Android rotation
//! vector) or one estimated from gyro and accelerometer by `ridi-frames`.
//!
//! The magnetometer-aided Android rotation vector turns with the magnetic field indoors (up to
//! 93 deg/min on the Tyrex runs, docs/bench-orientation.md) while the gyro drifts a few degrees
//! per minute, so the estimate gives straighter tracks wherever the recorded orientation uses the
//! magnetometer. The choice also replaces gravity and linear acceleration, so that the three
//! stay consistent.

use ridi_data::{OrientationSource, Sequence};
use ridi_frames::{FilterConfig, STANDARD_GRAVITY, estimate_orientation, gravity_in_device};
use serde::{Deserialize, Serialize};

use crate::error::{PipelineError, Result};

/// Orientation used for features, correction and integration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Orientation {
    /// As recorded (RIDI: Tango or game rotation vector; Tyrex: Android rotation vector).
    #[default]
    Recorded,
    /// Gyro + accelerometer complementary filter with default settings.
    Estimated,
}

/// `seq` with its orientation replaced by a gyro + accelerometer estimate, gravity by the
/// estimate's gravity (standard magnitude) and linear acceleration by accelerometer minus that
/// gravity.
///
/// # Errors
/// When the estimator rejects the input (non-finite samples) or the result fails validation.
pub fn with_estimated_orientation(seq: &Sequence, filter: &FilterConfig) -> Result<Sequence> {
    let q = estimate_orientation(seq.time(), seq.gyro(), seq.acce(), filter)
        .map_err(|e| PipelineError::sequence(seq.name(), format!("orientation estimate: {e}")))?;
    let mut p = seq.clone().into_parts();
    p.gravity = q
        .iter()
        .map(|&q| gravity_in_device(q, STANDARD_GRAVITY))
        .collect();
    p.linacce = p
        .acce
        .iter()
        .zip(&p.gravity)
        .map(|(&a, &g)| a - g)
        .collect();
    p.orientation = q;
    p.orientation_source = Some(OrientationSource::Estimated);
    Sequence::new(p).map_err(|e| PipelineError::sequence(seq.name(), e.to_string()))
}

impl Orientation {
    /// Applies the choice to every sequence in place.
    ///
    /// # Errors
    /// As [`with_estimated_orientation`].
    pub fn apply(self, seqs: &mut [Sequence]) -> Result<()> {
        if self == Orientation::Estimated {
            for s in seqs.iter_mut() {
                *s = with_estimated_orientation(s, &FilterConfig::default())?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ridi_data::{ReadOptions, load_list};

    #[test]
    fn estimate_replaces_orientation_gravity_and_linear_acceleration_consistently() {
        let list = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../datasets/sample/list_Jakob.txt");
        let mut seqs = load_list(&list, &ReadOptions::default()).unwrap();
        seqs.truncate(1);
        let before = seqs[0].clone();
        Orientation::Recorded.apply(&mut seqs).unwrap();
        assert_eq!(seqs[0], before);
        Orientation::Estimated.apply(&mut seqs).unwrap();
        let after = &seqs[0];
        assert_eq!(
            after.orientation_source(),
            Some(OrientationSource::Estimated)
        );
        assert_eq!(after.len(), before.len());
        assert_eq!(after.acce(), before.acce());
        assert_eq!(after.gyro(), before.gyro());
        for i in (0..after.len()).step_by(97) {
            let g = after.gravity()[i];
            assert!((g.norm() - STANDARD_GRAVITY).abs() < 1e-9);
            assert!((after.linacce()[i] + g - after.acce()[i]).norm() < 1e-9);
            // The estimate's gravity is the world up axis seen from the device.
            assert!(
                (gravity_in_device(after.orientation()[i], STANDARD_GRAVITY) - g).norm() < 1e-9
            );
        }
        // Tilt agrees with the recorded gravity to a few degrees once the filter settled.
        let i = after.len() - 1;
        let cos = after.gravity()[i].dot(before.gravity()[i])
            / (after.gravity()[i].norm() * before.gravity()[i].norm());
        assert!(
            cos > 10f64.to_radians().cos(),
            "tilt differs by {} deg",
            cos.acos().to_degrees()
        );
    }
}
