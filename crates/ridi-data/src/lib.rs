//! IMU sequences and the dataset formats they come in.
//!
//! A [`Sequence`] is one recording on one timeline: device-frame gyro, accelerometer, linear
//! acceleration and gravity, the device orientation (world-from-device, see `ridi-frames`),
//! and optional ground truth and step counter. It is validated when built, so code that takes
//! a `Sequence` can rely on equal lengths, finite values and increasing time.
//!
//! Readers and writers turn files into sequences and back; every error names the file, and
//! parse errors the line and field too.

mod error;
pub mod resample;
mod sequence;

pub use error::{DataError, Location, Result};
pub use sequence::{
    GroundTruth, OrientationSource, Sequence, SequenceError, SequenceParts, Validation,
};
pub use ridi_frames;
