//! Bounded per-frame storage of the tracker.
//!
//! Columns are plain vectors holding between `cap` and `2 cap` of the most recent frames;
//! when full, the oldest `cap` are dropped in one move. Any run of up to `cap` recent frames
//! is therefore a contiguous slice (what a regressor and a window solve want) at an amortized
//! cost of one extra copy per frame, and memory stays flat whatever the stream length.

use ridi_frames::{DeviceVec, ImuFrames, WorldFromDevice};

use crate::integrate::Pose;
use crate::regressor::FrameWindow;

pub(crate) struct FrameRing {
    cap: usize,
    /// Stream index of element 0.
    first: u64,
    pub time: Vec<f64>,
    pub gyro: Vec<DeviceVec>,
    pub linacce: Vec<DeviceVec>,
    pub gravity: Vec<DeviceVec>,
    pub orientation: Vec<WorldFromDevice>,
    /// Best estimate of each frame's pose (live, then revised by corrections).
    pub pose: Vec<Pose>,
}

impl FrameRing {
    pub(crate) fn new(cap: usize) -> Self {
        let cap = cap.max(1);
        Self {
            cap,
            first: 0,
            time: Vec::new(),
            gyro: Vec::new(),
            linacce: Vec::new(),
            gravity: Vec::new(),
            orientation: Vec::new(),
            pose: Vec::new(),
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.time.len()
    }

    /// Drops everything; the next pushed frame gets stream index `first`.
    pub(crate) fn clear(&mut self, first: u64) {
        self.first = first;
        self.time.clear();
        self.gyro.clear();
        self.linacce.clear();
        self.gravity.clear();
        self.orientation.clear();
        self.pose.clear();
    }

    pub(crate) fn push(
        &mut self,
        time: f64,
        gyro: DeviceVec,
        linacce: DeviceVec,
        gravity: DeviceVec,
        orientation: WorldFromDevice,
    ) {
        if self.time.len() == 2 * self.cap {
            let c = self.cap;
            self.time.drain(..c);
            self.gyro.drain(..c);
            self.linacce.drain(..c);
            self.gravity.drain(..c);
            self.orientation.drain(..c);
            self.pose.drain(..c);
            self.first += c as u64;
        }
        self.time.push(time);
        self.gyro.push(gyro);
        self.linacce.push(linacce);
        self.gravity.push(gravity);
        self.orientation.push(orientation);
        self.pose.push(Pose::default());
    }

    /// Local index of stream frame `frame`, if it is still held.
    pub(crate) fn index(&self, frame: u64) -> Option<usize> {
        let i = frame.checked_sub(self.first)? as usize;
        (i < self.len()).then_some(i)
    }

    /// The last `n` frames (fewer if fewer are held).
    pub(crate) fn last(&self, n: usize) -> FrameWindow<'_> {
        let a = self.len().saturating_sub(n);
        FrameWindow {
            first_frame: self.first + a as u64,
            imu: self.imu().slice(a..self.len()),
        }
    }

    /// Every frame held (local indices).
    pub(crate) fn imu(&self) -> ImuFrames<'_> {
        ImuFrames {
            time: &self.time,
            gyro: &self.gyro,
            linacce: &self.linacce,
            gravity: &self.gravity,
            orientation: &self.orientation,
        }
    }
}
