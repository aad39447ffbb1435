//! The error type of this crate.

/// Why features, targets or a configuration were rejected. Every variant names the offending
/// input so that a caller can point at the bad recording.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FeatureError {
    /// An input has another length than the others, the configuration or the matrix shape
    /// imply (streams of one recording, a feature row, targets per row).
    #[error("length of {what} is {found}, expected {expected}")]
    LengthMismatch {
        /// Which input.
        what: &'static str,
        /// Length it should have.
        expected: usize,
        /// Length found.
        found: usize,
    },
    /// A NaN or infinite value.
    #[error("non-finite {what} at sample {index}")]
    NonFinite {
        /// Which input.
        what: &'static str,
        /// Sample index.
        index: usize,
    },
    /// `time[index] <= time[index - 1]`: velocities need strictly increasing time.
    #[error("time does not increase at sample {index}")]
    TimeNotIncreasing {
        /// Sample index.
        index: usize,
    },
    /// A requested sample frame lies outside `[min, max]`.
    #[error("sample frame {frame} outside the valid range [{min}, {max}]")]
    FrameOutOfRange {
        /// The frame asked for.
        frame: usize,
        /// Smallest valid frame.
        min: usize,
        /// Largest valid frame.
        max: usize,
    },
    /// A configuration value is out of range.
    #[error("invalid feature configuration: {0}")]
    InvalidConfig(String),
}

/// An [`ImuFrames`](ridi_frames::ImuFrames) length error is this crate's `LengthMismatch`, so
/// that a caller matches one spelling for every input of the crate, whichever check found it.
impl From<ridi_frames::ImuError> for FeatureError {
    fn from(e: ridi_frames::ImuError) -> Self {
        let ridi_frames::ImuError::LengthMismatch {
            what,
            expected,
            found,
        } = e;
        FeatureError::LengthMismatch {
            what,
            expected,
            found,
        }
    }
}
