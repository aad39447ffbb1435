//! The interface between the tracker and a velocity regressor.

use ridi_frames::{ImuFrames, StabHorizontal, UpAxis};

/// The most recent frames of the stream, oldest first; the last frame is the one to regress.
#[derive(Debug, Clone, Copy)]
pub struct FrameWindow<'a> {
    /// Stream index of the first frame of the view (frames are counted from 0 since the
    /// tracker was created, across restarts).
    pub first_frame: u64,
    /// The frames.
    pub imu: ImuFrames<'a>,
}

impl FrameWindow<'_> {
    /// Number of frames in the view.
    pub fn len(&self) -> usize {
        self.imu.len()
    }

    /// `true` when the view holds no frame.
    pub fn is_empty(&self) -> bool {
        self.imu.is_empty()
    }

    /// Stream index of the last frame (the one to regress).
    pub fn last_frame(&self) -> u64 {
        self.first_frame + self.len().saturating_sub(1) as u64
    }
}

/// What a [`VelocityRegressor`] gives for one window: the velocity at its last frame, and the
/// placement it was regressed for if the regressor classifies one.
///
/// The same meaning as ridi-regress's `Prediction` (the cascade's output for one window), which
/// always has a placement; this crate does not depend on ridi-regress, and a regressor that
/// does not classify has none, hence `Option`. The tracker stores the velocity as a
/// [`FrameVelocity`](crate::FrameVelocity) at the window's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegressorOutput {
    /// Horizontal velocity in the stabilized frame S, `[S-x, S-z]`, m/s.
    pub velocity: StabHorizontal,
    /// The placement it was regressed for, as an index into the regressor's placement names
    /// (e.g. leg, bag, hand, body), if the regressor classifies; used by the placement-change
    /// filter.
    pub placement: Option<usize>,
}

/// The error type a regressor may return.
pub type RegressorError = Box<dyn std::error::Error + Send + Sync>;

/// A source of regressed velocities for the [`Tracker`](crate::Tracker): the SVR cascade in
/// production (the `ridi` crate's `CascadeRegressor` turns a trained model's windows into
/// features), test doubles in tests, or a model of one's own.
///
/// ```
/// use ridi_correct::{
///     FrameWindow, RegressorError, RegressorOutput, Tracker, TrackerConfig, VelocityRegressor,
/// };
/// use ridi_frames::nalgebra::Vector3;
/// use ridi_frames::{DeviceVec, ImuSample, StabHorizontal, WorldFromDevice};
///
/// /// Says the walker goes forward (S's -z) at 1 m/s, whatever the frames: a stand-in for a
/// /// trained model, which would regress from `frames.imu`.
/// struct Forward;
///
/// impl VelocityRegressor for Forward {
///     fn window_len(&self) -> usize {
///         1
///     }
///     fn regress(
///         &mut self,
///         _frames: &FrameWindow<'_>,
///     ) -> Result<Option<RegressorOutput>, RegressorError> {
///         let velocity = StabHorizontal::new(0.0, -1.0);
///         Ok(Some(RegressorOutput { velocity, placement: None }))
///     }
/// }
///
/// let mut tracker = Tracker::new(TrackerConfig::default(), Forward)?;
/// // Ten seconds at 200 Hz of a phone held upright (device +y up, S's up axis) that measures
/// // no motion: the correction makes the trajectory follow the regressed velocities.
/// let quarter_turn_about_x = Vector3::new(std::f64::consts::FRAC_PI_2, 0.0, 0.0);
/// let upright = WorldFromDevice::from_scaled_axis(quarter_turn_about_x);
/// let mut last = None;
/// for i in 0..2000 {
///     let sample = ImuSample {
///         time: i as f64 * 0.005,
///         gyro: DeviceVec::ZERO,
///         linacce: DeviceVec::ZERO,
///         gravity: DeviceVec::new(0.0, 9.81, 0.0),
///         orientation: upright,
///     };
///     last = Some(tracker.push(&sample)?);
/// }
/// let end = last.unwrap().pose.position;
/// let walked = end.x().hypot(end.y());
/// assert!((8.0..10.5).contains(&walked), "{walked} m");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub trait VelocityRegressor {
    /// How many of the most recent frames [`regress`](Self::regress) needs, at least 1 (the
    /// tracker refuses 0). The tracker only asks for a regression once a segment holds that
    /// many frames, and always passes exactly that many, the last being the frame regressed.
    /// RIDI's features use the 200 frames *before* the sample frame: such a regressor asks for
    /// 201 and ignores the last one.
    fn window_len(&self) -> usize;

    /// The stabilized frame S the regressed velocities are in, when the regressor knows it (a
    /// trained model does). The tracker refuses a correction configured for another
    /// ([`CorrectionConfig::up_axis`](crate::CorrectionConfig::up_axis)): its velocities would
    /// be read in the wrong frame. `None` (the default): the caller vouches for the match.
    fn up_axis(&self) -> Option<UpAxis> {
        None
    }

    /// The velocity at the last frame of `frames`. `Ok(None)` means "no estimate here" (the
    /// frame is skipped silently); an error is reported in the tracker's update and the frame
    /// is skipped too.
    fn regress(
        &mut self,
        frames: &FrameWindow<'_>,
    ) -> Result<Option<RegressorOutput>, RegressorError>;
}

impl<R: VelocityRegressor + ?Sized> VelocityRegressor for Box<R> {
    fn window_len(&self) -> usize {
        (**self).window_len()
    }
    fn up_axis(&self) -> Option<UpAxis> {
        (**self).up_axis()
    }
    fn regress(
        &mut self,
        frames: &FrameWindow<'_>,
    ) -> Result<Option<RegressorOutput>, RegressorError> {
        (**self).regress(frames)
    }
}

impl<R: VelocityRegressor + ?Sized> VelocityRegressor for &mut R {
    fn window_len(&self) -> usize {
        (**self).window_len()
    }
    fn up_axis(&self) -> Option<UpAxis> {
        (**self).up_axis()
    }
    fn regress(
        &mut self,
        frames: &FrameWindow<'_>,
    ) -> Result<Option<RegressorOutput>, RegressorError> {
        (**self).regress(frames)
    }
}
