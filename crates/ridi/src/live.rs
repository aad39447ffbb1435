//! Tracking a live stream: one sample in, its pose out, with the model's orientation.
//!
//! [`LiveTracker`] is the streaming tracker of `ridi-correct` with a trained cascade as its
//! regressor and, for models trained on an orientation estimated from gyro and accelerometer
//! ([`Orientation::Estimated`]), the same estimator running on the stream
//! ([`OrientationFilter`]) with its heading drift corrected by the orientation each sample
//! carries ([`HeadingCorrector`], [`TrackOptions::recorded_heading`]), so a live caller hands
//! over what the phone measures and gets what `ridi track --online` would give for the same
//! recording.

use std::collections::VecDeque;

use ridi_correct::{
    FrameVelocity, FrameWindow, GapPolicy, PlacementSmoother, RegressorOutput, TrackError, Tracker,
    TrackerConfig, TrailingMajority, Update, VelocityRegressor,
};
use ridi_data::{Channel, MedianTest, Sequence, Validation};
use ridi_features::{FeatureExtractor, FeatureMatrixRef, Orientation};
use ridi_frames::{
    DeviceVec, FilterConfig, HeadingCorrector, ImuSample, OrientationFilter, WorldFromDevice,
};
use ridi_regress::Cascade;

use crate::error::{PipelineError, Result};
use crate::track_options::TrackOptions;

/// The cascade as the streaming tracker's regressor: features of the latest window, one query.
///
/// The frames pushed must carry the orientation the model was trained with
/// ([`FeatureConfig::orientation`](ridi_features::FeatureConfig::orientation));
/// [`LiveTracker`] sees to that.
#[derive(Debug)]
pub struct CascadeRegressor<'m> {
    model: &'m Cascade,
    extractor: FeatureExtractor,
    row: Vec<f32>,
    majority: Option<TrailingMajority>,
    /// Every velocity regressed, at its frame, for reports.
    made: Vec<FrameVelocity>,
    /// The placement of each of `made`.
    placements: Vec<usize>,
}

impl<'m> CascadeRegressor<'m> {
    /// Every regression made so far, for reports: the velocities at their frames and the
    /// placement of each, as [`Track::regressions`](crate::Track::regressions) and
    /// [`Track::placements`](crate::Track::placements) hold them.
    pub fn made(&self) -> (&[FrameVelocity], &[usize]) {
        (&self.made, &self.placements)
    }

    /// A regressor over `model`; with `smoothing`, each placement becomes the majority label of
    /// the window's length of regressions before it (the streaming form of the batch vote).
    pub fn new(model: &'m Cascade, smoothing: Option<PlacementSmoother>) -> Result<Self> {
        if let Some(s) = smoothing {
            s.validate()?;
        }
        let extractor = FeatureExtractor::new(model.feature_config().clone())?;
        let row = vec![0.0; extractor.dim()];
        Ok(Self {
            model,
            extractor,
            row,
            majority: smoothing.map(|s| s.trailing(model.placement_names().len())),
            made: Vec::new(),
            placements: Vec::new(),
        })
    }
}

impl VelocityRegressor for CascadeRegressor<'_> {
    fn window_len(&self) -> usize {
        // One more than the feature window: the feature of the regressed (last) frame covers
        // the frames before it, as in batch tracking.
        self.extractor.config().window + 1
    }

    fn up_axis(&self) -> Option<ridi_frames::UpAxis> {
        Some(self.extractor.config().up_axis)
    }

    fn regress(
        &mut self,
        frames: &FrameWindow<'_>,
    ) -> std::result::Result<Option<RegressorOutput>, ridi_correct::RegressorError> {
        let stab = self.extractor.stabilize(&frames.imu)?;
        let len = frames.len();
        self.extractor.row_into(&stab, len - 1, &mut self.row)?;
        let mut p = self.model.predict_one(&self.row)?;
        if let Some(m) = &mut self.majority {
            let label = m.push(frames.imu.time[len - 1], p.placement);
            if label != p.placement {
                let row = FeatureMatrixRef::new(&self.row, self.row.len())?;
                p.velocity = self.model.predict_with_placement(row, label)?[0];
                p.placement = label;
            }
        }
        self.made.push(FrameVelocity {
            frame: frames.last_frame() as usize,
            velocity: p.velocity,
        });
        self.placements.push(p.placement);
        Ok(Some(RegressorOutput {
            velocity: p.velocity,
            placement: Some(p.placement),
        }))
    }
}

/// What the phone's operating system reports besides gyro and accelerometer: its orientation
/// (Android's rotation vector or game rotation vector, Core Motion's attitude) and the gravity
/// and linear acceleration derived from it, all as `ridi_data::Sequence` holds them. Not a
/// ground truth: a model on the estimated orientation takes its slow heading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Recorded {
    /// World-from-device orientation.
    pub orientation: WorldFromDevice,
    /// Gravity (pointing up), device frame, m/s².
    pub gravity: DeviceVec,
    /// Linear acceleration, device frame, m/s².
    pub linacce: DeviceVec,
}

impl Recorded {
    /// Frame `frame` of `seq`'s orientation, gravity and linear acceleration, whatever their
    /// source.
    ///
    /// # Panics
    /// When `frame` is not below `seq.len()`.
    pub fn of_frame(seq: &Sequence, frame: usize) -> Self {
        Self {
            orientation: seq.orientation()[frame],
            gravity: seq.gravity()[frame],
            linacce: seq.linacce()[frame],
        }
    }
}

/// One reading of a phone's sensors, as a live stream delivers it: raw gyro and accelerometer,
/// and the orientation the OS derived where it reports one. [`LiveTracker`] turns readings
/// into the pipeline's frames (`ridi_frames::ImuSample`), estimating the orientation where
/// the model wants that.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorReading {
    /// Timestamp, seconds, increasing.
    pub time: f64,
    /// Angular rate, device frame, rad/s.
    pub gyro: DeviceVec,
    /// Accelerometer (including gravity, reading up at rest), device frame, m/s².
    pub acce: DeviceVec,
    /// The recorded orientation: required by a model trained on it
    /// ([`Orientation::Recorded`]); a model with an estimated orientation estimates its own
    /// from `gyro` and `acce` and takes only the slow part of the recorded heading, to correct
    /// the gyro's drift ([`TrackOptions::recorded_heading`]; a sample without one keeps the
    /// correction reached so far).
    pub recorded: Option<Recorded>,
}

impl SensorReading {
    /// Frame `frame` of a recording, with its recorded orientation: to play a recording back
    /// as a stream. A sequence whose orientation was estimated already has none recorded.
    ///
    /// # Panics
    /// When `frame` is not below `seq.len()`.
    pub fn of_frame(seq: &Sequence, frame: usize) -> Self {
        let recorded = seq.orientation_source() != Some(ridi_data::OrientationSource::Estimated);
        Self {
            time: seq.time()[frame],
            gyro: seq.gyro()[frame],
            acce: seq.acce()[frame],
            recorded: recorded.then(|| Recorded::of_frame(seq, frame)),
        }
    }
}

/// Tracks a live stream with a trained model: push samples as they arrive, get each frame's
/// pose (the streaming tracker's [`Update`]).
///
/// With a model trained on the recorded orientation, every push gives its own frame's update.
/// With an estimated orientation, the first frames wait until the estimator knows the initial
/// tilt (its settling pass over the first
/// [`FilterConfig::settle_time`](ridi_frames::FilterConfig::settle_time), 2 s) and then come
/// out together; [`finish`](Self::finish) releases what a stream too short for that leaves.
/// The recorded orientation a sample carries corrects the estimate's heading drift (a sample
/// without one keeps the correction reached; a stream that starts without one stays in the
/// estimate's world frame). Pushing a whole recording gives exactly the poses of `ridi track --online`
/// ([`track`](crate::track()) with [`TrackOptions::online`]), which runs through this type.
///
/// A refused sample (a non-finite field, a value no phone sensor gives as the readers'
/// [`Validation::limit`]s define it, a time not after the previous sample's) leaves the
/// tracking as it was. So does one refused because the stream's last second (its last
/// [`STREAM_CHECK_SAMPLES`]) has a median rate off [`TRACK_RATE_HZ`](crate::TRACK_RATE_HZ) by
/// more than [`TRACK_RATE_TOLERANCE`](crate::TRACK_RATE_TOLERANCE) (a 50 Hz stream, or time
/// in milliseconds), a median |gyro| of a gyro in deg/s, a median |acce| of an
/// accelerometer in g ([`STREAM_ACCE_G`]), or a recorded gravity and linear acceleration that
/// disagree with the samples' orientation and accelerometer as a recording's checks judge them
/// ([`Validation`]: gravity a median of over 45 degrees off the orientation's up axis, negated
/// say; a median |gravity| outside 8.5..11 m/s², in g say; a linear acceleration whose scale
/// against accelerometer minus gravity is outside 0.5..2, the accelerometer itself say): such
/// a stream is refused before its first velocity is regressed. The samples with a new time count towards that second whether they are
/// tracked or refused, so that samples are taken again once most of the last
/// [`STREAM_CHECK_SAMPLES`] are right (a sample given again is refused again). A stream whose
/// gyro turns against the recorded orientation pushed with it (a sign flipped, most
/// quaternions with their components in another order) is refused once
/// consecutive samples with one cover [`STREAM_GYRO_CHECK_S`], and from then on. Pushing after [`finish`](Self::finish) is refused
/// too. A gap longer than the correction integrates across (its `max_dt`, 0.1 s:
/// a dropped sensor buffer, say) starts a new segment ([`GapPolicy::Restart`]): the position is
/// held, velocity and bias start over, and the update says
/// [`restarted`](Update::restarted). (`ridi track` refuses such a gap in a recording instead.)
///
/// ```
/// use ridi::data::{Listed, ReadOptions};
/// use ridi::regress::NoProgress;
/// use ridi::{SensorReading, LiveTracker, PlacementMap, TrackOptions, TrainOptions};
///
/// let sample = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets/sample");
/// let read = |list: &str| Listed::read(&[sample.join(list)], &ReadOptions::default());
/// let mut train = read("list_Guillaume.txt")?.into_sequences();
/// PlacementMap::tyrex4().apply(&mut train);
/// let mut opts = TrainOptions::default();
/// opts.cascade.regressors = ridi::GridChoice::None.regressors();
/// let model = ridi::train(&train, &opts, &mut NoProgress)?;
///
/// // A recording played back as if it arrived live.
/// let test = read("list_Jakob.txt")?;
/// let stream = &test.sequences()[0];
/// let mut live = LiveTracker::new(&model, &TrackOptions::default())?;
/// let mut updates = Vec::new();
/// for i in 0..stream.len() {
///     live.push(&SensorReading::of_frame(stream, i), &mut updates)?;
/// }
/// live.finish(&mut updates)?;
/// assert_eq!(updates.len(), stream.len());
/// let end = updates.last().unwrap().pose.position;
/// println!("walked to ({:.1}, {:.1}) m", end.x(), end.y());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct LiveTracker<'m> {
    tracker: Tracker<CascadeRegressor<'m>>,
    estimator: Option<Estimator>,
    limits: Validation,
    stream: StreamCheck,
    finished: bool,
    /// The last sample taken, and the pause before it when it came more than the readers'
    /// longest gap after the one before: for the error of a sample that goes back after it.
    last: Option<(f64, Option<f64>)>,
}

type Waiting = (f64, DeviceVec, DeviceVec, Option<WorldFromDevice>);

/// The orientation estimate of a stream, and the samples waiting for it.
#[derive(Debug)]
struct Estimator {
    filter: OrientationFilter,
    /// Corrects the estimate's heading by the recorded orientation's, where samples carry one.
    heading: Option<HeadingCorrector>,
    /// Time, gyro, accelerometer and recorded orientation of each sample waiting.
    waiting: VecDeque<Waiting>,
    orientations: Vec<WorldFromDevice>,
}

impl<'m> LiveTracker<'m> {
    /// A tracker with `model`, configured as `opts` configures [`track`](crate::track()) (its
    /// `online` flag aside: this is the online form).
    ///
    /// # Errors
    /// A configuration the tracker refuses, or a model whose features cannot be extracted.
    pub fn new(model: &'m Cascade, opts: &TrackOptions) -> Result<Self> {
        opts.validate()?;
        let config = TrackerConfig {
            correction: opts.correction_for(model),
            regress_every: opts.regress_every,
            gap_policy: GapPolicy::Restart,
            ..TrackerConfig::default()
        };
        let regressor = CascadeRegressor::new(model, opts.placement_smoothing)?;
        let tracker = Tracker::new(config, regressor)?;
        let estimator = match model.feature_config().orientation {
            Orientation::Recorded => None,
            Orientation::Estimated => Some(Estimator {
                filter: OrientationFilter::new(FilterConfig::default())?,
                heading: opts
                    .recorded_heading
                    .map(HeadingCorrector::new)
                    .transpose()?,
                waiting: VecDeque::new(),
                orientations: Vec::new(),
            }),
        };
        Ok(Self {
            tracker,
            estimator,
            limits: Validation::default(),
            stream: StreamCheck::default(),
            finished: false,
            last: None,
        })
    }

    /// A tracker that takes each sample's `recorded` orientation as it is, whatever the
    /// model's: for a recording whose orientation was estimated before (a sequence whose
    /// [`OrientationSource`](ridi_data::OrientationSource) is `Estimated`), whose heading
    /// correction the estimator could not make again without the recorded orientation.
    pub(crate) fn with_given_orientation(model: &'m Cascade, opts: &TrackOptions) -> Result<Self> {
        Ok(Self {
            estimator: None,
            ..Self::new(model, opts)?
        })
    }

    /// This tracker, not judging the recorded orientation, gravity and linear acceleration
    /// (the gyro against the orientation, gravity against its up axis, the linear
    /// acceleration's scale): for a sequence whose whole recording passed those checks
    /// ([`ridi_data::Validation`]), whose stretches need not each agree as much.
    pub(crate) fn judged_whole(mut self) -> Self {
        self.stream.judged_whole = true;
        self
    }

    /// Adds one sample and appends to `out` the updates of the frames whose pose became known
    /// (one, except while an estimated orientation starts up).
    ///
    /// # Errors
    /// A refused sample ([`TrackError`], [`ridi_frames::EstimateError`]), or a recorded model
    /// given a sample without its recorded orientation; the tracking is unchanged (the
    /// sample still counts towards the stream's last second, as the type's docs say). A
    /// sample whose time falls inside the pause before the last one (a clock that jumped
    /// ahead, taken for a pause) is [`PipelineError::Live`], naming the jump, rather than
    /// [`TrackError::TimeNotIncreasing`].
    pub fn push(&mut self, sample: &SensorReading, out: &mut Vec<Update>) -> Result<()> {
        match self.push_checked(sample, out) {
            Ok(()) => {
                let pause = self
                    .last
                    .map(|(t, _)| sample.time - t)
                    .filter(|dt| *dt > self.limits.max_gap_s);
                self.last = Some((sample.time, pause));
                Ok(())
            }
            // After a clock that jumped ahead (a glitch taken for a pause), every sample
            // would go back: say why, and what to do. Only a sample landing inside the pause
            // before the last one says the pause was a clock's jump (a repeated timestamp says
            // nothing of it).
            Err(PipelineError::Track(TrackError::TimeNotIncreasing { time, previous })) => {
                match self.last {
                    Some((_, Some(pause))) if time < previous && time > previous - pause => {
                        Err(PipelineError::Live(format!(
                            "sample time {time} is not after the previous sample's {previous}, \
                             which came {} s after the one before it (taken for a pause, where a \
                             new segment started): a stream cannot go back in time; if that \
                             timestamp was a glitch, start a new tracker",
                            ridi_data::short(pause)
                        )))
                    }
                    _ => Err(TrackError::TimeNotIncreasing { time, previous }.into()),
                }
            }
            Err(e) => Err(e),
        }
    }

    /// [`Self::push`] but for the pause it remembers.
    fn push_checked(&mut self, sample: &SensorReading, out: &mut Vec<Update>) -> Result<()> {
        if self.finished {
            return Err(PipelineError::Live(
                "the stream was finished: a new stream needs a new tracker".into(),
            ));
        }
        self.check_values(sample)?;
        self.stream.push(sample, &self.limits)?;
        let Some(est) = &mut self.estimator else {
            let r = sample.recorded.ok_or_else(|| {
                PipelineError::Live(
                    "the model was trained on the recorded orientation, but the sample has \
                     none (give `recorded`, or train with `--orientation estimated`; in Python \
                     `orientation=\"estimated\"`)"
                        .into(),
                )
            })?;
            let update = self.tracker.push(&ImuSample {
                time: sample.time,
                gyro: sample.gyro,
                linacce: r.linacce,
                gravity: r.gravity,
                orientation: r.orientation,
            })?;
            out.push(update);
            return Ok(());
        };
        // The tracker's own check, made before the estimator holds the sample: a sample it
        // would refuse later could no longer be taken back.
        if let Some(previous) = est.filter.last_time()
            && sample.time <= previous
        {
            return Err(TrackError::TimeNotIncreasing {
                time: sample.time,
                previous,
            }
            .into());
        }
        est.filter
            .push(sample.time, sample.gyro, sample.acce, &mut est.orientations)?;
        est.waiting.push_back((
            sample.time,
            sample.gyro,
            sample.acce,
            sample.recorded.map(|r| r.orientation),
        ));
        self.drain(out)
    }

    /// Ends the stream: appends the updates of frames still waiting for an estimated
    /// orientation.
    ///
    /// # Errors
    /// [`ridi_frames::EstimateError::NoGravity`] when every sample waiting has a zero
    /// accelerometer reading.
    pub fn finish(&mut self, out: &mut Vec<Update>) -> Result<()> {
        self.finished = true;
        if let Some(est) = &mut self.estimator {
            est.filter.finish(&mut est.orientations)?;
        }
        self.drain(out)
    }

    /// Refuses a non-finite time, gyro, accelerometer, recorded gravity or linear acceleration
    /// (the stream's check judges those two, whatever the model uses), and a value no phone
    /// sensor gives (the readers' [`Validation::limit`]s: a corrupt sample, or mm/s^2 for
    /// m/s^2), naming the field, the sample and its time.
    fn check_values(&self, sample: &SensorReading) -> Result<()> {
        let index = self.accepted();
        if !sample.time.is_finite() {
            return Err(PipelineError::Live(format!(
                "`time` of sample {index} is {}, not a finite number",
                sample.time
            )));
        }
        let recorded = sample.recorded.as_ref();
        for (name, v) in [
            ("gyro", Some(sample.gyro)),
            ("acce", Some(sample.acce)),
            ("gravity", recorded.map(|r| r.gravity)),
            ("linacce", recorded.map(|r| r.linacce)),
        ] {
            let Some(v) = v.map(|v| v.to_array()) else {
                continue;
            };
            if let Some(axis) = (0..3).find(|&a| !v[a].is_finite()) {
                return Err(PipelineError::Live(format!(
                    "`{name}.{}` of sample {index} is {}, not a finite number (t = {} s)",
                    ["x", "y", "z"][axis],
                    v[axis],
                    sample.time
                )));
            }
        }
        let vectors = [
            (Channel::Gyro, Some(sample.gyro)),
            (Channel::Acce, Some(sample.acce)),
            (Channel::Gravity, recorded.map(|r| r.gravity)),
            (Channel::Linacce, recorded.map(|r| r.linacce)),
        ];
        for (channel, v) in vectors {
            if let Some(v) = v {
                self.limits
                    .check_value(channel, index, v.to_array())
                    .map_err(|e| PipelineError::Live(format!("{e} (t = {} s)", sample.time)))?;
            }
        }
        Ok(())
    }

    /// Samples accepted so far: in the tracker, or waiting for their orientation.
    fn accepted(&self) -> usize {
        let waiting = self.estimator.as_ref().map_or(0, |e| e.waiting.len());
        self.tracker.stats().frames as usize + waiting
    }

    /// Every regression made so far: the velocities at their frames and the placement of
    /// each ([`CascadeRegressor::made`]).
    pub fn regressions(&self) -> (&[FrameVelocity], &[usize]) {
        self.tracker.regressor().made()
    }

    /// Takes the regressions made since the last call (or the start): the velocities at their
    /// frames and the placement of each. A caller that writes them out as it goes (`ridi track
    /// --online` of a long recording) so keeps none; [`regressions`](Self::regressions) then
    /// holds only those made since.
    pub fn take_regressions(&mut self) -> (Vec<FrameVelocity>, Vec<usize>) {
        let r = self.tracker.regressor_mut();
        (
            std::mem::take(&mut r.made),
            std::mem::take(&mut r.placements),
        )
    }

    /// The streaming tracker underneath (statistics, buffered poses, the current bias).
    pub fn tracker(&self) -> &Tracker<CascadeRegressor<'m>> {
        &self.tracker
    }

    /// Feeds the tracker every waiting sample whose orientation is known.
    fn drain(&mut self, out: &mut Vec<Update>) -> Result<()> {
        let Some(est) = &mut self.estimator else {
            return Ok(());
        };
        // One orientation per sample given, in order: the oldest waiting samples are known.
        let known = est.orientations.len().min(est.waiting.len());
        for (q, (time, gyro, acce, recorded)) in
            est.orientations.drain(..).zip(est.waiting.drain(..known))
        {
            // Gravity from the estimate itself, as batch tracking takes it: the turn about
            // the vertical changes neither.
            let (gravity, linacce) = ridi_frames::gravity_and_linacce(q, acce);
            let q = match (&mut est.heading, recorded) {
                (Some(h), Some(r)) => h.correct(time, q, r)?,
                (Some(h), None) => h.hold(q),
                (None, _) => q,
            };
            out.push(self.tracker.push(&ImuSample {
                time,
                gyro,
                linacce,
                gravity,
                orientation: q,
            })?);
        }
        Ok(())
    }
}

/// Samples over which [`LiveTracker`] judges a stream's rate and units: a second at
/// [`TRACK_RATE_HZ`](crate::TRACK_RATE_HZ), the length of a feature window, so that a stream
/// at a wrong rate or in a wrong unit is refused by the time its first velocity would be
/// regressed.
pub const STREAM_CHECK_SAMPLES: usize = 200;

/// Seconds covered by pairs of consecutive samples pushed with a recorded orientation after
/// which [`LiveTracker`] judges the direction of the gyro against it, over all of them ([`ridi_data::GyroFit::agreement`]
/// against [`STREAM_MIN_GYRO_AGREEMENT`]): a gyro with its sign flipped, or most quaternions
/// given in another component order, are refused from then on. (Samples pushed with a
/// recorded orientation only every other time give no pair of consecutive ones to judge.)
/// A stream's gyro is judged by its direction alone: not axis by axis (a dead axis,
/// [`ridi_data::MIN_GYRO_AXIS_SCALE`]), nor against an orientation that stays put, as a
/// recording's is when read.
pub const STREAM_GYRO_CHECK_S: f64 = 10.0;

/// The least agreement [`LiveTracker`] accepts from [`STREAM_GYRO_CHECK_S`] on: 0, below the
/// whole recordings' [`ridi_data::MIN_GYRO_AGREEMENT`], since a stream may start anywhere.
/// Over the 127 shared sequences started every 2 s (`benchmarks/gyro_direction.py --stream`),
/// the agreement from the start is at least 0.25 once 10 s have passed (-0.06 after 5 s): a
/// flipped gyro gives its negation, at most -0.25; a quaternion in another component order is
/// refused in 60 % of the streams.
pub const STREAM_MIN_GYRO_AGREEMENT: f64 = 0.0;

/// Accepted range of the median |acce| over a stream's last [`STREAM_CHECK_SAMPLES`], in
/// standard gravities: 0.35..10. Over every second of the shared Tyrex runs (both phones), the
/// twelve Indoor Location Competition walks and the bundled sample it lies within 0.50..2.40
/// (the upper end running with the phone in the hand; `benchmarks/stream_bounds.py`); an
/// accelerometer in g gives at most 0.25, one in mm/s^2 a thousand times too much. Wider than the readers' whole-recording
/// bounds ([`Validation::acce_gravity_ratio`]): a second varies more than a recording.
pub const STREAM_ACCE_G: (f64, f64) = (0.35, 10.0);

/// One sample as [`StreamCheck`] judges it: the interval from the one before (seconds), |gyro|,
/// |acce| and, when it came with a recorded orientation, gravity and linear acceleration, how
/// those agree.
#[derive(Debug, Clone, Copy)]
struct Judged {
    interval: f64,
    gyro: f64,
    acce: f64,
    recorded: Option<JudgedRecorded>,
}

/// How a sample's recorded orientation, gravity and linear acceleration agree: gravity's angle
/// from the orientation's up axis (degrees), |gravity|, and the linear acceleration's terms of
/// [`Validation::linacce_scale_verdict`] (with `d = acce - gravity`: `d.l`, `l.l`, `d.d`).
#[derive(Debug, Clone, Copy)]
struct JudgedRecorded {
    up_deg: f64,
    gravity: f64,
    linacce_terms: [f64; 3],
}

impl Judged {
    /// Quantity `column` of [`StreamCheck::properties`]' order; `None` for a recorded
    /// quantity of a sample without one.
    fn value(&self, column: usize) -> Option<f64> {
        match column {
            0 => Some(self.interval),
            1 => Some(self.gyro),
            2 => Some(self.acce),
            3 => self.recorded.map(|r| r.up_deg),
            _ => self.recorded.map(|r| r.gravity),
        }
    }
}

/// The last [`STREAM_CHECK_SAMPLES`] of a stream, and whether the median of each quantity
/// lies beyond its bounds, from counts ([`MedianTest`], as the readers judge a recording), so
/// that a median is judged in constant time per sample; the linear acceleration's scale from
/// sums over the same samples.
#[derive(Debug, Default)]
struct StreamCheck {
    last_time: Option<f64>,
    /// The last sample's time, gyro and recorded orientation, when it had one.
    last_recorded: Option<(f64, DeviceVec, WorldFromDevice)>,
    /// The gyro against the recorded orientation, over the pairs of consecutive samples with
    /// one, and the seconds those pairs cover.
    gyro_fit: ridi_data::GyroFit,
    gyro_covered: f64,
    /// Why the gyro was refused, once it was: it stays so.
    gyro_refused: Option<String>,
    /// The recorded orientation is not judged: a recording validated whole streamed
    /// ([`crate::track`]).
    judged_whole: bool,
    recent: VecDeque<Judged>,
    /// Each quantity's properties: low, a rate too fast, a gyro (none), an accelerometer too
    /// weak, (none), a gravity too weak; high, a rate too slow, a gyro too fast, an
    /// accelerometer too strong, a gravity far from the orientation's up axis, a gravity too
    /// strong.
    medians: [MedianTest; 5],
    /// Why the last sample judged was refused, while the stream stays refused: a sample given
    /// again (its time not after the last one) gets the same answer.
    refused: Option<String>,
}

impl StreamCheck {
    /// The (low, high) properties of each of `sample`'s quantities (interval, |gyro|, |acce|,
    /// gravity's angle from up, |gravity|).
    fn properties(sample: &Judged, limits: &Validation) -> [(bool, bool); 5] {
        let g = ridi_frames::STANDARD_GRAVITY;
        let (up, gravity) = match sample.recorded {
            Some(r) => (
                (false, r.up_deg > limits.max_orientation_gravity_deg),
                (
                    r.gravity < limits.gravity_range.0,
                    r.gravity > limits.gravity_range.1,
                ),
            ),
            None => ((false, false), (false, false)),
        };
        [
            crate::track::rate_beyond(sample.interval),
            (false, sample.gyro > limits.max_median_gyro),
            (
                sample.acce < STREAM_ACCE_G.0 * g,
                sample.acce > STREAM_ACCE_G.1 * g,
            ),
            up,
            gravity,
        ]
    }

    /// `sample`'s recorded orientation, gravity and linear acceleration as judged.
    fn judge_recorded(sample: &SensorReading) -> Option<JudgedRecorded> {
        let r = sample.recorded?;
        let d = sample.acce - r.gravity;
        Some(JudgedRecorded {
            // A zero gravity has no direction: never beyond the angle.
            up_deg: ridi_data::up_angle_deg(r.orientation, r.gravity).unwrap_or(0.0),
            gravity: r.gravity.norm(),
            linacce_terms: [d.dot(r.linacce), r.linacce.dot(r.linacce), d.dot(d)],
        })
    }

    /// Counts `sample` and judges the last second. A sample whose time is not after the last
    /// one's is no new interval: the tracker refuses it, or this check again when the last one
    /// judged was refused (a sample retried is no way round it).
    fn push(&mut self, sample: &SensorReading, limits: &Validation) -> Result<()> {
        let previous = self.last_time;
        if previous.is_some_and(|t| sample.time <= t) {
            return match &self.refused {
                Some(why) => Err(PipelineError::Live(why.clone())),
                None => Ok(()),
            };
        }
        self.last_time = Some(sample.time);
        if !self.judged_whole {
            let recorded = sample
                .recorded
                .map(|r| (sample.time, sample.gyro, r.orientation));
            if let (Some((t0, g0, q0)), Some((t1, g1, q1))) = (self.last_recorded, recorded) {
                self.gyro_fit.add_steps(&[t0, t1], &[g0, g1], &[q0, q1]);
                self.gyro_covered += t1 - t0;
            }
            self.last_recorded = recorded;
        }
        let Some(previous) = previous else {
            return Ok(());
        };
        let entry = Judged {
            interval: sample.time - previous,
            gyro: sample.gyro.norm(),
            acce: sample.acce.norm(),
            recorded: if self.judged_whole {
                None
            } else {
                Self::judge_recorded(sample)
            },
        };
        self.count(&entry, limits, true);
        self.recent.push_back(entry);
        if self.recent.len() > STREAM_CHECK_SAMPLES
            && let Some(old) = self.recent.pop_front()
        {
            self.count(&old, limits, false);
        }
        if self.gyro_refused.is_none() {
            self.gyro_refused = self.gyro_refusal();
        }
        self.refused = self
            .gyro_refused
            .clone()
            .or_else(|| self.median_refusal(limits))
            .or_else(|| self.linacce_refusal(limits));
        match &self.refused {
            Some(why) => Err(PipelineError::Live(why.clone())),
            None => Ok(()),
        }
    }

    /// Counts `entry` into the medians (`add`), or out of them.
    fn count(&mut self, entry: &Judged, limits: &Validation, add: bool) {
        for (m, (low, high)) in self.medians.iter_mut().zip(Self::properties(entry, limits)) {
            if add {
                m.push(low, high);
            } else {
                m.pop(low, high);
            }
        }
    }

    /// Why the last [`STREAM_CHECK_SAMPLES`] are refused, once there are that many and most
    /// came with a recorded linear acceleration: its scale against accelerometer minus gravity
    /// over those that did ([`Validation::linacce_scale_verdict`]). The sums are added up
    /// afresh each time (600 products): kept by adding and taking away, they would leave a
    /// residue of round-off that a still phone's zero sums cannot absorb.
    fn linacce_refusal(&self, limits: &Validation) -> Option<String> {
        if self.recent.len() < STREAM_CHECK_SAMPLES {
            return None;
        }
        let (mut sums, mut count) = ([0.0; 3], 0);
        for r in self.recent.iter().filter_map(|e| e.recorded) {
            for (sum, term) in sums.iter_mut().zip(r.linacce_terms) {
                *sum += term;
            }
            count += 1;
        }
        if count * 2 < self.recent.len() {
            return None;
        }
        let [dl, ll, dd] = sums;
        let e = limits.linacce_scale_verdict(dl, ll, dd, count).err()?;
        Some(format!("the stream's last {count} samples with one: {e}"))
    }

    /// Why the gyro is refused: it turns against the recorded orientation, judged once the
    /// pairs of consecutive samples with one cover [`STREAM_GYRO_CHECK_S`].
    fn gyro_refusal(&self) -> Option<String> {
        let covered = self.gyro_covered;
        let agreement = self.gyro_fit.agreement()?;
        (covered >= STREAM_GYRO_CHECK_S && agreement < STREAM_MIN_GYRO_AGREEMENT).then(|| {
            let e = ridi_data::SequenceError::GyroDirection {
                agreement,
                min: STREAM_MIN_GYRO_AGREEMENT,
            };
            format!(
                "the stream's {} s with a recorded orientation: {e}",
                ridi_data::short(covered)
            )
        })
    }

    /// Why the last [`STREAM_CHECK_SAMPLES`] are refused, once there are that many: a median
    /// beyond its bounds.
    fn median_refusal(&self, limits: &Validation) -> Option<String> {
        if self.recent.len() < STREAM_CHECK_SAMPLES {
            return None;
        }
        let column = self
            .medians
            .iter()
            .position(|m| m.median_low() || m.median_high())?;
        Some(self.verdict(column, limits))
    }

    /// Why the last second's median of quantity `column` ([`Self::properties`]' order) lies
    /// beyond its bounds.
    fn verdict(&self, column: usize, limits: &Validation) -> String {
        let mut values: Vec<f64> = self.recent.iter().filter_map(|e| e.value(column)).collect();
        values.sort_by(f64::total_cmp);
        let median = values[values.len() / 2];
        let n = self.recent.len();
        let g = ridi_frames::STANDARD_GRAVITY;
        let why = match column {
            0 => {
                let (min, max) = limits.time_step_range;
                if (min..=max).contains(&median) {
                    format!(
                        "{}: resample the stream",
                        crate::track::rate_text(1.0 / median)
                    )
                } else {
                    ridi_data::SequenceError::TimeStep { median, min, max }.to_string()
                }
            }
            1 => ridi_data::SequenceError::GyroUnits {
                median,
                max: limits.max_median_gyro,
            }
            .to_string(),
            3 => ridi_data::SequenceError::OrientationGravity {
                median_deg: median,
                max_deg: limits.max_orientation_gravity_deg,
            }
            .to_string(),
            4 => {
                let (min, max) = limits.gravity_range;
                format!(
                    "median |gravity| {} m/s^2 is outside {min}..{max} m/s^2: gravity in {}?",
                    ridi_data::short(median),
                    if median < min {
                        "g instead of m/s^2"
                    } else {
                        "another unit than m/s^2, or another column"
                    }
                )
            }
            _ => format!(
                "median |acce| {} m/s^2 is {} g, outside {}..{} g: accelerometer in {}?",
                ridi_data::short(median),
                ridi_data::short(median / g),
                STREAM_ACCE_G.0,
                STREAM_ACCE_G.1,
                if median < g {
                    "g instead of m/s^2"
                } else {
                    "another unit than m/s^2"
                }
            ),
        };
        format!("the stream's last {n} samples: {why}")
    }
}
