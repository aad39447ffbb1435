//! A recording's IMU streams on one timeline: the one input type of features, correction and
//! streaming regressors.

use std::ops::Range;

use serde::{Deserialize, Serialize};

use crate::{DeviceVec, WorldFromDevice};

/// Why an [`ImuFrames`] was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ImuError {
    /// A stream has another length than `time`.
    #[error("{what} has {found} frames, time has {expected}")]
    LengthMismatch {
        /// The stream.
        what: &'static str,
        /// Length of `time`.
        expected: usize,
        /// Length of the stream.
        found: usize,
    },
}

/// One stream of [`ImuFrames`] besides `time`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImuStream {
    /// `gyro`.
    Gyro,
    /// `linacce`.
    Linacce,
    /// `gravity`.
    Gravity,
    /// `orientation`.
    Orientation,
}

impl ImuStream {
    /// Every stream, in field order.
    pub const ALL: [ImuStream; 4] = [
        ImuStream::Gyro,
        ImuStream::Linacce,
        ImuStream::Gravity,
        ImuStream::Orientation,
    ];

    /// The field's name, as errors give it.
    pub fn name(self) -> &'static str {
        match self {
            ImuStream::Gyro => "gyro",
            ImuStream::Linacce => "linacce",
            ImuStream::Gravity => "gravity",
            ImuStream::Orientation => "orientation",
        }
    }
}

/// The IMU streams of consecutive frames, borrowed, one entry per frame in every slice. Features
/// read gyro, linear acceleration and gravity; the correction reads time, linear acceleration,
/// orientation and gravity; a streaming regressor gets all of them. One type for all, so that
/// a recording (`Sequence::imu` in ridi-data) or a stream's window is handed to any stage as is.
///
/// [`ImuFrames::new`] checks every length; a value built field by field is checked by every
/// stage that takes it, for the streams it reads ([`ImuFrames::check_streams`]): a stream no
/// stage of a caller reads may be left empty.
#[derive(Debug, Clone, Copy)]
pub struct ImuFrames<'a> {
    /// Timestamps, seconds, increasing.
    pub time: &'a [f64],
    /// Gyroscope, device frame, rad/s.
    pub gyro: &'a [DeviceVec],
    /// Linear acceleration (gravity removed), device frame, m/s².
    pub linacce: &'a [DeviceVec],
    /// Gravity as Android's gravity sensor reports it (pointing up), device frame, m/s²: it
    /// defines each frame's stabilized frame S.
    pub gravity: &'a [DeviceVec],
    /// Device orientation, world-from-device.
    pub orientation: &'a [WorldFromDevice],
}

impl<'a> ImuFrames<'a> {
    /// Bundles the streams; fails naming the first stream whose length differs from `time`'s.
    pub fn new(
        time: &'a [f64],
        gyro: &'a [DeviceVec],
        linacce: &'a [DeviceVec],
        gravity: &'a [DeviceVec],
        orientation: &'a [WorldFromDevice],
    ) -> Result<Self, ImuError> {
        let frames = Self {
            time,
            gyro,
            linacce,
            gravity,
            orientation,
        };
        frames.check_lengths()?;
        Ok(frames)
    }

    /// Checks that every stream has the length of `time`.
    pub fn check_lengths(&self) -> Result<(), ImuError> {
        self.check_streams(&ImuStream::ALL)
    }

    /// Checks that `streams` have the length of `time`: what a stage that reads only those
    /// checks, so that a caller may leave the others empty (the correction never reads the
    /// gyro, features never read the orientation).
    pub fn check_streams(&self, streams: &[ImuStream]) -> Result<(), ImuError> {
        let expected = self.time.len();
        for &stream in streams {
            let found = match stream {
                ImuStream::Gyro => self.gyro.len(),
                ImuStream::Linacce => self.linacce.len(),
                ImuStream::Gravity => self.gravity.len(),
                ImuStream::Orientation => self.orientation.len(),
            };
            if found != expected {
                return Err(ImuError::LengthMismatch {
                    what: stream.name(),
                    expected,
                    found,
                });
            }
        }
        Ok(())
    }

    /// Number of frames (of `time`).
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// `true` without frames.
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// Frame `i` of every stream, owned: as a stream delivers it (to play frames back through
    /// a streaming tracker).
    ///
    /// # Panics
    /// When `i` is out of bounds of a stream, as indexing does.
    pub fn sample(&self, i: usize) -> ImuSample {
        ImuSample {
            time: self.time[i],
            gyro: self.gyro[i],
            linacce: self.linacce[i],
            gravity: self.gravity[i],
            orientation: self.orientation[i],
        }
    }

    /// Frames `range` of every stream.
    ///
    /// # Panics
    /// When `range` is out of bounds of a stream, as slicing does.
    pub fn slice(&self, range: Range<usize>) -> ImuFrames<'a> {
        ImuFrames {
            time: &self.time[range.clone()],
            gyro: &self.gyro[range.clone()],
            linacce: &self.linacce[range.clone()],
            gravity: &self.gravity[range.clone()],
            orientation: &self.orientation[range],
        }
    }
}

/// One frame of [`ImuFrames`], owned: what a stream delivers at a time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ImuSample {
    /// Timestamp, seconds.
    pub time: f64,
    /// Gyroscope, device frame, rad/s.
    pub gyro: DeviceVec,
    /// Linear acceleration (gravity removed), device frame, m/s².
    pub linacce: DeviceVec,
    /// Gravity (pointing up), device frame, m/s².
    pub gravity: DeviceVec,
    /// Device orientation, world-from-device.
    pub orientation: WorldFromDevice,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths_are_checked_against_time_and_named() {
        let t = [0.0, 0.005];
        let v = [DeviceVec::ZERO; 2];
        let q = [WorldFromDevice::identity(); 2];
        let frames = ImuFrames::new(&t, &v, &v, &v, &q).unwrap();
        assert_eq!((frames.len(), frames.slice(1..2).len()), (2, 1));
        let e = ImuFrames::new(&t, &v, &v[..1], &v, &q).unwrap_err();
        assert_eq!(e.to_string(), "linacce has 1 frames, time has 2");
        let correction = ImuFrames {
            gyro: &[],
            ..frames
        };
        correction
            .check_streams(&[ImuStream::Linacce, ImuStream::Orientation])
            .unwrap();
        assert!(correction.check_lengths().is_err());
        let e = ImuFrames::new(&t, &v, &v, &v, &q[..0]).unwrap_err();
        assert_eq!(
            e,
            ImuError::LengthMismatch {
                what: "orientation",
                expected: 2,
                found: 0
            }
        );
    }
}
