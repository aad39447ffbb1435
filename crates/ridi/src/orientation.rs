//! Which orientation a sequence is tracked with: the recorded one (Tango, the Android rotation
//! vector) or one estimated from gyro and accelerometer by `ridi-frames`.
//!
//! The magnetometer-aided Android rotation vector turns with the magnetic field indoors (up to
//! 93 deg/min on the Tyrex runs, docs/bench-orientation.md) while the gyro drifts a few degrees
//! per minute, so the estimate gives straighter tracks wherever the recorded orientation uses the
//! magnetometer. The choice also replaces gravity and linear acceleration, so that the three
//! stay consistent.

use std::borrow::Cow;

use ridi_data::{OrientationSource, Sequence};
use ridi_frames::{FilterConfig, estimate_orientation, gravity_and_linacce};

use crate::error::{PipelineError, Result};

use ridi_features::Orientation;

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
    (p.gravity, p.linacce) = q
        .iter()
        .zip(&p.acce)
        .map(|(&q, &a)| gravity_and_linacce(q, a))
        .unzip();
    p.orientation = q;
    p.orientation_source = Some(OrientationSource::Estimated);
    Sequence::new(p).map_err(|e| PipelineError::sequence(seq.name(), e.to_string()))
}

/// `seq` with the orientation `choice` asks for: `seq` itself when it has it already (a recorded
/// one, or one estimated before), else a copy with the estimate swapped in.
///
/// Models record the orientation they were trained with
/// ([`FeatureConfig::orientation`](ridi_features::FeatureConfig::orientation)); training,
/// tracking and evaluation pass their sequences through this, so that a model never sees the
/// other orientation's gravity.
///
/// # Errors
/// [`Orientation::Recorded`] for a sequence whose orientation was already replaced by an
/// estimate (the recorded one is gone), and as [`with_estimated_orientation`].
pub fn oriented(seq: &Sequence, choice: Orientation) -> Result<Cow<'_, Sequence>> {
    let estimated = seq.orientation_source() == Some(OrientationSource::Estimated);
    match (choice, estimated) {
        (Orientation::Recorded, false) | (Orientation::Estimated, true) => Ok(Cow::Borrowed(seq)),
        (Orientation::Estimated, false) => Ok(Cow::Owned(with_estimated_orientation(
            seq,
            &FilterConfig::default(),
        )?)),
        (Orientation::Recorded, true) => Err(recorded_wanted(seq.name())),
    }
}

/// The error of [`oriented`] for the sequence `name` whose orientation was estimated where the
/// recorded one is wanted.
pub(crate) fn recorded_wanted(name: &str) -> PipelineError {
    PipelineError::sequence(
        name,
        "carries an orientation estimated from gyro and accelerometer, but the model or \
         training options expect the recorded one (train with --orientation estimated)",
    )
}

/// [`oriented`] for every sequence, in place.
///
/// # Errors
/// As [`oriented`].
pub fn apply_orientation(choice: Orientation, seqs: &mut [Sequence]) -> Result<()> {
    for s in seqs.iter_mut() {
        if let Cow::Owned(o) = oriented(s, choice)? {
            *s = o;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use ridi_data::{Listed, ReadOptions};
    use ridi_frames::{STANDARD_GRAVITY, gravity_in_device};

    #[test]
    fn estimate_replaces_orientation_gravity_and_linear_acceleration_consistently() {
        let list = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../datasets/sample/list_Jakob.txt");
        let mut seqs = Listed::read(&[list], &ReadOptions::default())
            .unwrap()
            .into_sequences();
        seqs.truncate(1);
        let before = seqs[0].clone();
        apply_orientation(Orientation::Recorded, &mut seqs).unwrap();
        assert_eq!(seqs[0], before);
        apply_orientation(Orientation::Estimated, &mut seqs).unwrap();
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
        // Estimated twice is estimated once; the recorded orientation cannot be asked back.
        assert!(matches!(
            oriented(after, Orientation::Estimated),
            Ok(Cow::Borrowed(_))
        ));
        let err = oriented(after, Orientation::Recorded)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(after.name()) && err.contains("recorded"),
            "{err}"
        );
    }
}
