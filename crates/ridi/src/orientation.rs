//! Which orientation a sequence is tracked with: the recorded one (Tango, the Android rotation
//! vector) or one estimated from gyro and accelerometer by `ridi-frames`.
//!
//! The magnetometer-aided Android rotation vector jumps and bends with the magnetic field indoors
//! (up to 93 deg/min on the Tyrex runs, docs/bench-orientation.md), and Core Motion's attitude
//! loses its tilt while running; the estimate's tilt does not, so gravity, S and the features
//! come from the estimate. The choice also replaces gravity and linear acceleration, so that the
//! three stay consistent.
//!
//! The estimate's heading drifts with the gyro's bias about the vertical (28 deg/min on the
//! Tyrex iPhone 4S). Where the sequence has a recorded orientation, its slow heading corrects
//! that drift ([`ridi_frames::HeadingCorrector`]: resets and magnetic corrections faster than
//! a gyro bias are dropped). The heading enters neither gravity nor S, so the features, and
//! a model, are the same with or without it; only the world frame the tracker integrates in
//! turns.

use std::borrow::Cow;

use ridi_data::{OrientationSource, Sequence};
use ridi_frames::{FilterConfig, HeadingConfig};

use crate::error::{PipelineError, Result};

use ridi_features::Orientation;

/// `seq` with the orientation `choice` asks for: `seq` itself when it has it already (a recorded
/// one, or one estimated before), else a copy with the estimate swapped in, its heading
/// corrected by the recorded one's when `heading` is given
/// ([`TrackOptions::recorded_heading`](crate::TrackOptions::recorded_heading)).
///
/// Models record the orientation they were trained with
/// ([`FeatureConfig::orientation`](ridi_features::FeatureConfig::orientation)); training,
/// tracking and evaluation pass their sequences through this, so that a model never sees the
/// other orientation's gravity.
///
/// # Errors
/// [`Orientation::Recorded`] for a sequence whose orientation was already replaced by an
/// estimate (the recorded one is gone), and as
/// [`Sequence::with_estimated_orientation`].
pub fn oriented<'a>(
    seq: &'a Sequence,
    choice: Orientation,
    heading: Option<&HeadingConfig>,
) -> Result<Cow<'a, Sequence>> {
    let estimated = seq.orientation_source() == Some(OrientationSource::Estimated);
    match (choice, estimated) {
        (Orientation::Recorded, false) | (Orientation::Estimated, true) => Ok(Cow::Borrowed(seq)),
        (Orientation::Estimated, false) => Ok(Cow::Owned(
            seq.with_estimated_orientation(&FilterConfig::default(), heading)
                .map_err(|e| PipelineError::sequence(seq.name(), e.to_string()))?,
        )),
        (Orientation::Recorded, true) => Err(recorded_wanted(seq.name())),
    }
}

/// The error of [`oriented`] for the sequence `name` whose orientation was estimated where the
/// recorded one is wanted.
pub(crate) fn recorded_wanted(name: &str) -> PipelineError {
    PipelineError::sequence(
        name,
        "carries an orientation estimated from gyro and accelerometer, but the model or \
         training options expect the recorded one (train with `--orientation estimated`; in \
         Python `orientation=\"estimated\"`)",
    )
}

/// [`oriented`] for every sequence, in place.
///
/// # Errors
/// As [`oriented`].
pub fn apply_orientation(
    choice: Orientation,
    heading: Option<&HeadingConfig>,
    seqs: &mut [Sequence],
) -> Result<()> {
    for s in seqs.iter_mut() {
        if let Cow::Owned(o) = oriented(s, choice, heading)? {
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
        apply_orientation(Orientation::Recorded, None, &mut seqs).unwrap();
        assert_eq!(seqs[0], before);
        apply_orientation(Orientation::Estimated, None, &mut seqs).unwrap();
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
            oriented(
                after,
                Orientation::Estimated,
                Some(&HeadingConfig::default())
            ),
            Ok(Cow::Borrowed(_))
        ));
        let err = oriented(after, Orientation::Recorded, None)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains(after.name()) && err.contains("recorded"),
            "{err}"
        );
    }

    #[test]
    fn the_recorded_heading_turns_the_estimate_and_leaves_its_gravity() {
        let list = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../datasets/sample/list_iphone4s.txt");
        let seqs = Listed::read(&[list], &ReadOptions::default())
            .unwrap()
            .into_sequences();
        let seq = &seqs[0];
        let filter = FilterConfig::default();
        let gyro_only = seq.with_estimated_orientation(&filter, None).unwrap();
        let corrected = seq
            .with_estimated_orientation(&filter, Some(&HeadingConfig::default()))
            .unwrap();
        assert_eq!(
            corrected.orientation_source(),
            Some(OrientationSource::Estimated)
        );
        // Gravity and linear acceleration, and so the features, are the estimate's exactly.
        assert_eq!(corrected.gravity(), gyro_only.gravity());
        assert_eq!(corrected.linacce(), gyro_only.linacce());
        // Against the recorded (Core Motion) heading the gyro's drifts; the corrected one
        // follows it after a lag of about the time constant.
        let drift = |s: &Sequence| {
            ridi_frames::orientation_errors(s.orientation(), seq.orientation())
                .unwrap()
                .heading_drift_per_minute(seq.time())
                .unwrap()
                .abs()
        };
        let (before, after) = (drift(&gyro_only), drift(&corrected));
        assert!(after < 0.6 * before, "{after} against {before} rad/min");
        // Nor is the ground truth, which would give tracking the answer it is judged by.
        let mut parts = seq.clone().into_parts();
        parts.orientation_source = Some(OrientationSource::GroundTruth);
        let truth_sourced = Sequence::new(parts).unwrap();
        let with_truth = truth_sourced
            .with_estimated_orientation(&filter, Some(&HeadingConfig::default()))
            .unwrap();
        assert_eq!(with_truth.orientation(), gyro_only.orientation());
        // An estimate is never the reference of another.
        let again = gyro_only
            .with_estimated_orientation(&filter, Some(&HeadingConfig::default()))
            .unwrap();
        assert_eq!(again.orientation(), gyro_only.orientation());
    }
}
