//! Tracking: regress velocities with a trained cascade, correct the accelerations, integrate.

use std::path::Path;

use ridi_correct::{CorrectionConfig, FrameVelocity, correct};
use ridi_data::{RoundTrip, RowReader, Sequence, write_atomically};
use ridi_features::{
    FeatureConfig, FeatureExtractor, FeatureMatrixRef, Orientation, SampleSchedule,
};
use ridi_frames::{DeviceVec, WorldVec};
use ridi_regress::Cascade;

use crate::error::{PipelineError, Result};
use crate::live::{LiveTracker, SensorReading};
use crate::orientation::oriented;

use crate::track_options::TrackOptions;

/// A tracked sequence: one pose per frame, plus what produced it.
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    /// Timestamps, seconds.
    pub time: Vec<f64>,
    /// Position, world frame of the device orientation, metres, from the origin.
    pub position: Vec<WorldVec>,
    /// Velocity, world frame, m/s.
    pub velocity: Vec<WorldVec>,
    /// The bias correction added to the linear acceleration, device frame, m/s^2 (the
    /// correction's `x` in `R (a + x)`: minus the accelerometer's estimated bias).
    pub bias: Vec<DeviceVec>,
    /// The regressed velocities the correction followed, at their frames.
    pub regressions: Vec<FrameVelocity>,
    /// The placement each of `regressions` was regressed for, an index into
    /// `placement_names`.
    pub placements: Vec<usize>,
    /// Placement names of the model.
    pub placement_names: Vec<String>,
}

impl Track {
    /// The horizontal trajectory, `[x, y]` per frame.
    pub fn horizontal(&self) -> Vec<[f64; 2]> {
        self.position.iter().map(|p| [p.x(), p.y()]).collect()
    }

    /// Writes the trajectory CSV: `time,pos_x,pos_y,pos_z,vel_x,vel_y,vel_z,placement,
    /// bias_x,bias_y,bias_z`, one row per frame (`placement` is the latest regression's, empty
    /// before the first). Written atomically ([`write_atomically`]); [`crate::TrackOutput`]
    /// writes it together with a plot.
    pub fn write_csv(&self, path: impl AsRef<Path>) -> Result<()> {
        // Checked first, so that a missing folder is named as such rather than as the system's
        // error on the temporary file beside the output.
        crate::output::check_output_file(path.as_ref())?;
        write_atomically(path.as_ref(), |w| self.csv(w))?;
        Ok(())
    }

    /// The rows of [`Track::write_csv`], header first.
    pub(crate) fn csv(&self, w: &mut dyn std::io::Write) -> std::io::Result<()> {
        // The fields are public: lengths that do not match are refused before a row is written.
        let frames = self.time.len();
        for (what, len, of, want) in [
            ("positions", self.position.len(), "timestamps", frames),
            ("velocities", self.velocity.len(), "timestamps", frames),
            ("biases", self.bias.len(), "timestamps", frames),
            (
                "placements",
                self.placements.len(),
                "regressions",
                self.regressions.len(),
            ),
        ] {
            if len != want {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    format!("the track has {len} {what} for {want} {of}"),
                ));
            }
        }
        let mut next = 0;
        let mut current: Option<&str> = None;
        csv_header(w)?;
        for i in 0..self.time.len() {
            while next < self.regressions.len() && self.regressions[next].frame <= i {
                current = self
                    .placement_names
                    .get(self.placements[next])
                    .map(String::as_str);
                next += 1;
            }
            let pose = (self.position[i], self.velocity[i]);
            csv_row(w, self.time[i], pose, current, self.bias[i])?;
        }
        Ok(())
    }

    /// Draws the horizontal trajectory of `seq` (tracked into `self`) to `path` (`.svg` or
    /// `.png`), with its ground truth if it has one, the trajectory then aligned to it on the
    /// first 10 s as evaluations do.
    #[cfg(feature = "plot")]
    pub fn plot(&self, seq: &Sequence, path: &Path) -> Result<()> {
        let gt = seq.ground_truth().map(|gt| gt.horizontal());
        plot_track(
            seq.name(),
            seq.time(),
            &self.horizontal(),
            gt.as_deref(),
            path,
        )
    }
}

/// [`Track::plot`] of the recording `title`: the horizontal positions `estimate` at `time`,
/// and the ground truth's `gt` if any.
#[cfg(feature = "plot")]
fn plot_track(
    title: &str,
    time: &[f64],
    estimate: &[[f64; 2]],
    gt: Option<&[[f64; 2]]>,
    path: &Path,
) -> Result<()> {
    use crate::plot::{Trajectory, TrajectoryOptions, TrajectoryPlot, plot_trajectories};
    let aligned = match gt {
        Some(gt) => Some(ridi_eval::align_trajectory(time, estimate, gt, Default::default())?.1),
        None => None,
    };
    let estimates = [Trajectory {
        name: "ridi",
        points: aligned.as_deref().unwrap_or(estimate),
    }];
    plot_trajectories(
        path,
        &TrajectoryPlot {
            title,
            ground_truth: gt.map(|points| Trajectory {
                name: "ground truth",
                points,
            }),
            estimates: &estimates,
        },
        &TrajectoryOptions::default(),
    )?;
    Ok(())
}

/// The most frames a streamed track's plot keeps ([`TrackPoints`]): about 22 minutes at
/// 200 Hz, far more than a figure's pixel columns.
pub(crate) const PLOT_FRAMES: usize = 1 << 18;

/// A per-frame series thinned to at most [`PLOT_FRAMES`] values: frame `i` is kept when `i`
/// is a multiple of the stride, which doubles (every other value dropped) whenever one more
/// would exceed the bound. What is kept depends only on how many frames were pushed, so
/// series of the same frames, pushed at different times, keep the same frames.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Thinned<T> {
    kept: Vec<T>,
    stride: usize,
    seen: usize,
}

impl<T> Default for Thinned<T> {
    fn default() -> Self {
        Self {
            kept: Vec::new(),
            stride: 1,
            seen: 0,
        }
    }
}

impl<T> Thinned<T> {
    /// The value of the next frame.
    pub(crate) fn push(&mut self, value: T) {
        if self.seen.is_multiple_of(self.stride) {
            if self.kept.len() == PLOT_FRAMES {
                let mut i = 0;
                self.kept.retain(|_| {
                    i += 1;
                    i % 2 == 1
                });
                self.stride *= 2;
            }
            if self.seen.is_multiple_of(self.stride) {
                self.kept.push(value);
            }
        }
        self.seen += 1;
    }

    /// The values kept.
    #[cfg_attr(not(feature = "plot"), allow(dead_code))]
    pub(crate) fn kept(&self) -> &[T] {
        &self.kept
    }
}

/// What the plot of a track draws ([`Track::plot`]), a small part of what the recording
/// holds: the time and horizontal position of each frame, and the ground truth's position
/// when the recording has ground truth. A streamed track keeps these alone
/// ([`crate::TrackOutput::write_stream`]), thinned to at most [`PLOT_FRAMES`] frames so that
/// memory does not grow with the recording: a recording of up to that many frames is plotted
/// as [`Track::plot`] plots it, byte for byte; a longer one on every second (fourth, ...) frame,
/// the alignment to the ground truth too.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(not(feature = "plot"), allow(dead_code))]
pub(crate) struct TrackPoints {
    time: Thinned<f64>,
    estimate: Thinned<[f64; 2]>,
    /// Empty without ground truth.
    ground_truth: Thinned<[f64; 2]>,
}

#[cfg(feature = "plot")]
impl TrackPoints {
    /// Draws them, the track of the recording `title`, to `path`, as [`Track::plot`] does.
    pub(crate) fn plot(&self, title: &str, path: &Path) -> Result<()> {
        let gt = Some(self.ground_truth.kept()).filter(|gt| !gt.is_empty());
        plot_track(title, self.time.kept(), self.estimate.kept(), gt, path)
    }
}

/// The header of a trajectory CSV ([`Track::write_csv`]).
fn csv_header(w: &mut dyn std::io::Write) -> std::io::Result<()> {
    writeln!(
        w,
        "time,pos_x,pos_y,pos_z,vel_x,vel_y,vel_z,placement,bias_x,bias_y,bias_z"
    )
}

/// One row of a trajectory CSV: a frame's time, position and velocity, placement and bias.
fn csv_row(
    w: &mut dyn std::io::Write,
    time: f64,
    (p, v): (WorldVec, WorldVec),
    placement: Option<&str>,
    b: DeviceVec,
) -> std::io::Result<()> {
    let r = RoundTrip;
    writeln!(
        w,
        "{},{},{},{},{},{},{},{},{},{},{}",
        r(time),
        r(p.x()),
        r(p.y()),
        r(p.z()),
        r(v.x()),
        r(v.y()),
        r(v.z()),
        placement.unwrap_or(""),
        r(b.x()),
        r(b.y()),
        r(b.z())
    )
}

/// Regresses placement and velocity every `opts.regress_every` frames from the first full
/// window, in one batched pass, then smooths the placements if `opts.placement_smoothing` asks.
/// `seq` is first given the model's orientation ([`oriented`]).
///
/// Returns the velocities at their frames (what the correction follows) and, one per velocity,
/// the placement it was regressed for: a cascade [`Prediction`](ridi_regress::Prediction) at a
/// frame, kept as the two things its users take apart ([`Track::regressions`] and
/// [`Track::placements`]).
///
/// # Errors
/// As [`track`]'s: a sequence at another rate than [`TRACK_RATE_HZ`], shorter than one feature
/// window, or with a gap longer than the correction's `max_dt` (a window across it would mix
/// two stretches of the walk); besides the stages' own.
pub fn regress_sequence(
    seq: &Sequence,
    model: &Cascade,
    opts: &TrackOptions,
) -> Result<(Vec<FrameVelocity>, Vec<usize>)> {
    opts.validate()?;
    // A window across a gap, or counted at another rate, is no window the model knows.
    check_trackable(seq, model.feature_config(), opts.correction.max_dt)?;
    regressed(seq, model, opts)
}

/// [`regress_sequence`] of a sequence [`check_trackable`] passed already (tracking and
/// evaluation check every sequence first).
pub(crate) fn regressed(
    seq: &Sequence,
    model: &Cascade,
    opts: &TrackOptions,
) -> Result<(Vec<FrameVelocity>, Vec<usize>)> {
    let seq = oriented(
        seq,
        model.feature_config().orientation,
        opts.recorded_heading.as_ref(),
    )?;
    let seq = seq.as_ref();
    let fx = FeatureExtractor::new(model.feature_config().clone())?;
    let frames = SampleSchedule::every(fx.config(), opts.regress_every)?.frames(seq.len());
    if frames.is_empty() {
        return Ok((Vec::new(), Vec::new()));
    }
    let features = fx.features(&fx.stabilize(&seq.imu())?, &frames)?;
    let predictions = model.predict(FeatureMatrixRef::try_from(&features)?)?;
    let mut velocities: Vec<FrameVelocity> = frames
        .iter()
        .zip(&predictions)
        .map(|(&frame, p)| FrameVelocity {
            frame,
            velocity: p.velocity,
        })
        .collect();
    let labels: Vec<usize> = predictions.iter().map(|p| p.placement).collect();
    let Some(smoother) = opts.placement_smoothing else {
        return Ok((velocities, labels));
    };
    let times: Vec<f64> = frames.iter().map(|&f| seq.time()[f]).collect();
    let smoothed = smoother.smooth(&times, &labels, model.placement_names().len());
    for p in 0..model.placement_names().len() {
        let moved: Vec<usize> = (0..velocities.len())
            .filter(|&i| smoothed[i] == p && labels[i] != p)
            .collect();
        if moved.is_empty() {
            continue;
        }
        let rows: Vec<f32> = moved
            .iter()
            .flat_map(|&i| features.row(i).iter().copied())
            .collect();
        let moved_velocities =
            model.predict_with_placement(FeatureMatrixRef::new(&rows, features.cols())?, p)?;
        for (&i, v) in moved.iter().zip(moved_velocities) {
            velocities[i].velocity = v;
        }
    }
    Ok((velocities, smoothed))
}

/// Corrects and integrates `seq` so that its velocity follows `regressions` (batch: one
/// global solve), `placements` their placements. `seq` must carry the orientation of the model that regressed them
/// ([`oriented`]), `config` the model's S ([`TrackOptions::correction_for`]).
pub(crate) fn correct_with(
    seq: &Sequence,
    regressions: Vec<FrameVelocity>,
    placements: Vec<usize>,
    config: CorrectionConfig,
    placement_names: &[String],
) -> Result<Track> {
    let traj = correct(config, &seq.imu(), &regressions)?;
    let bias = &traj.correction.bias;
    Ok(Track {
        time: seq.time().to_vec(),
        position: traj.poses.iter().map(|p| p.position).collect(),
        velocity: traj.poses.iter().map(|p| p.velocity).collect(),
        bias: (0..seq.len()).map(|i| bias.at(i, seq.time()[i])).collect(),
        regressions,
        placements,
        placement_names: placement_names.to_vec(),
    })
}

/// Refuses a sequence with a gap longer than the correction integrates across, naming where
/// it is. Readers accept gaps up to a second (features and training live with them); double
/// integration does not. Called once per sequence by [`track`] and the evaluation, before
/// the corrections (which would refuse the gap too, by frame only).
fn check_gaps(seq: &Sequence, max_dt: f64) -> Result<()> {
    let t = seq.time();
    match t.windows(2).position(|w| w[1] - w[0] > max_dt) {
        None => Ok(()),
        Some(i) => Err(gap_error(seq.name(), i, (t[i], t[i + 1]), t[0], max_dt)),
    }
}

/// The error of [`check_gaps`] for the gap from frame `i` (times `t`, the first frame's `t0`).
fn gap_error(name: &str, i: usize, t: (f64, f64), t0: f64, max_dt: f64) -> PipelineError {
    PipelineError::sequence(
        name,
        format!(
            "a gap of {:.3} s between frames {i} and {} ({:.3} s and {:.3} s from the \
             start) is longer than the {max_dt} s the correction integrates across; split \
             the recording at its gaps (`ridi convert --split-at-gaps {max_dt}`; in Python \
             `Sequence.split_at_gaps`)",
            t.1 - t.0,
            i + 1,
            t.0 - t0,
            t.1 - t0,
            max_dt = ridi_data::short(max_dt),
        ),
    )
}

/// The IMU rate every model assumes: feature windows, sample steps, regressions and
/// correction knots are all counted in frames of a 200 Hz stream.
pub const TRACK_RATE_HZ: f64 = 200.0;

/// How far a sequence's mean rate may be from [`TRACK_RATE_HZ`], as a fraction, for training,
/// tracking and evaluation (Android's fastest sensor rate varies by a few percent between
/// phones; half or twice the rate would make a one-second window half or two seconds long).
pub const TRACK_RATE_TOLERANCE: f64 = 0.1;

/// Refuses a sequence whose frames do not fit the model's frame counts: a rate (one over the
/// median frame interval, so that gaps do not count) outside [`TRACK_RATE_HZ`] ± [`TRACK_RATE_TOLERANCE`],
/// or no frame with a whole feature window before it (the trajectory would be plain double
/// integration, and its metrics meaningless).
pub(crate) fn check_frames(seq: &Sequence, config: &FeatureConfig) -> Result<()> {
    let n = seq.len();
    if n <= config.window {
        return Err(too_short(seq.name(), n, seq.duration(), config));
    }
    let rate = seq.median_rate_hz();
    if (rate - TRACK_RATE_HZ).abs() > TRACK_RATE_TOLERANCE * TRACK_RATE_HZ {
        return Err(wrong_rate(seq.name(), rate));
    }
    Ok(())
}

/// The error of [`check_frames`] for `n` frames over `duration` seconds.
fn too_short(name: &str, n: usize, duration: f64, config: &FeatureConfig) -> PipelineError {
    PipelineError::sequence(
        name,
        format!(
            "has {n} frames ({duration:.2} s): the first velocity is regressed after a whole \
             feature window of {} frames ({:.1} s at {TRACK_RATE_HZ} Hz), at frame {}, so \
             at least {} frames are needed",
            config.window,
            config.window as f64 / TRACK_RATE_HZ,
            config.window,
            config.window + 1
        ),
    )
}

/// The error of [`check_frames`] for a median `rate`.
fn wrong_rate(name: &str, rate: f64) -> PipelineError {
    PipelineError::sequence(
        name,
        format!(
            "has {}: resample it (`ridi convert <recording> --out <folder> --rate \
             {TRACK_RATE_HZ}`, or the sequence's `resampled` in Rust and Python)",
            rate_text(rate)
        ),
    )
}

/// What is wrong with a median `rate` off [`TRACK_RATE_HZ`], for a recording's error and a
/// live stream's.
pub(crate) fn rate_text(rate: f64) -> String {
    format!(
        "a rate of {rate:.1} Hz (median frame interval); models count windows and knots in \
         frames of a {TRACK_RATE_HZ} Hz stream (within {:.0} %)",
        TRACK_RATE_TOLERANCE * 100.0
    )
}

/// Counts a frame `interval` (seconds) towards the median rate [`check_frames`] judges:
/// `low`, a rate above [`TRACK_RATE_HZ`] beyond the tolerance, holds for short intervals, `high` for
/// long ones.
pub(crate) fn count_rate(test: &mut ridi_data::MedianTest, interval: f64) {
    let (fast, slow) = rate_beyond(interval);
    test.push(fast, slow);
}

/// Whether a frame `interval` (seconds) is that of a rate above [`TRACK_RATE_HZ`] beyond
/// [`TRACK_RATE_TOLERANCE`], and whether of one below.
pub(crate) fn rate_beyond(interval: f64) -> (bool, bool) {
    let off = 1.0 / interval - TRACK_RATE_HZ;
    let tolerance = TRACK_RATE_TOLERANCE * TRACK_RATE_HZ;
    (off > tolerance, -off > tolerance)
}

/// The median rate of the recording at `path` when [`count_rate`] says it is off, Hz.
pub(crate) fn rate_off(
    test: &ridi_data::MedianTest,
    path: &Path,
    opts: &ridi_data::ReadOptions,
) -> Result<Option<f64>> {
    if !(test.median_low() || test.median_high()) {
        return Ok(None);
    }
    Ok(Some(1.0 / ridi_data::median_interval(path, opts)?))
}

/// [`check_gaps`] and [`check_frames`]: what tracking and evaluation need of a sequence.
pub(crate) fn check_trackable(seq: &Sequence, config: &FeatureConfig, max_dt: f64) -> Result<()> {
    check_gaps(seq, max_dt)?;
    check_frames(seq, config)
}

/// Tracks `seq` with `model`, in the orientation the model was trained with ([`oriented`]).
///
/// # Errors
/// Besides the stages' own: a sequence at another rate than [`TRACK_RATE_HZ`] (± [`TRACK_RATE_TOLERANCE`]),
/// shorter than one feature window, or with a gap longer than the correction's `max_dt`.
pub fn track(seq: &Sequence, model: &Cascade, opts: &TrackOptions) -> Result<Track> {
    opts.validate()?;
    check_trackable(seq, model.feature_config(), opts.correction.max_dt)?;
    if opts.online {
        // The live tracker estimates an estimated orientation on the stream itself; a
        // recorded one must still be there.
        if model.feature_config().orientation == Orientation::Recorded {
            oriented(seq, Orientation::Recorded, None)?;
        }
        return track_online(seq, model, opts);
    }
    let seq = oriented(
        seq,
        model.feature_config().orientation,
        opts.recorded_heading.as_ref(),
    )?;
    let seq = seq.as_ref();
    let (regressions, placements) = regressed(seq, model, opts)?;
    correct_with(
        seq,
        regressions,
        placements,
        opts.correction_for(model),
        model.placement_names(),
    )
}

/// The live tracker [`track`] streams the frames of a recording whose orientation comes from
/// `source` into: one that takes an orientation estimated before as it is (the estimator could
/// not make its heading correction again), else one that estimates it, correcting its heading
/// only by an orientation the phone recorded.
fn live_for<'m>(
    model: &'m Cascade,
    opts: &TrackOptions,
    source: Option<ridi_data::OrientationSource>,
) -> Result<LiveTracker<'m>> {
    if source == Some(ridi_data::OrientationSource::Estimated) {
        LiveTracker::with_given_orientation(model, opts)
    } else if ridi_data::heading_reference(source) {
        LiveTracker::new(model, opts)
    } else {
        let opts = TrackOptions {
            recorded_heading: None,
            ..*opts
        };
        LiveTracker::new(model, &opts)
    }
}

fn track_online(seq: &Sequence, model: &Cascade, opts: &TrackOptions) -> Result<Track> {
    let mut live = live_for(model, opts, seq.orientation_source())?.judged_whole();
    let mut updates = Vec::with_capacity(seq.len());
    for i in 0..seq.len() {
        // The recorded orientation whatever its source: `live_for` chose what it is used for.
        let reading = SensorReading {
            time: seq.time()[i],
            gyro: seq.gyro()[i],
            acce: seq.acce()[i],
            recorded: Some(crate::live::Recorded::of_frame(seq, i)),
        };
        live.push(&reading, &mut updates)
            .map_err(|e| PipelineError::sequence(seq.name(), format!("frame {i}: {e}")))?;
    }
    live.finish(&mut updates)
        .map_err(|e| PipelineError::sequence(seq.name(), e.to_string()))?;
    Ok(Track {
        time: seq.time().to_vec(),
        position: updates.iter().map(|u| u.pose.position).collect(),
        velocity: updates.iter().map(|u| u.pose.velocity).collect(),
        bias: updates.iter().map(|u| u.bias).collect(),
        regressions: live.regressions().0.to_vec(),
        placements: live.regressions().1.to_vec(),
        placement_names: model.placement_names().to_vec(),
    })
}

/// What [`crate::TrackOutput::write_stream`] tracked.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StreamedTrack {
    /// The sequence's name.
    pub name: String,
    /// Frames tracked (rows written).
    pub frames: usize,
    /// Regressions made.
    pub regressions: usize,
}

/// `ridi track --online` of a recording read as a stream ([`RowReader`]): each row is
/// pushed into a [`LiveTracker`] as it is read and each pose written to `out` as a row of the
/// trajectory CSV ([`Track::write_csv`]) as it becomes known, so that memory does not grow with
/// the recording. The rows and the checks are those of [`track`] with
/// [`TrackOptions::online`] on the sequence the whole-file reader gives: the same CSV, bit for
/// bit; an error (also one found at the end, such as a recording's rate) leaves `out` partly
/// written, for the caller to discard ([`crate::TrackOutput::write_stream`]). With `points`,
/// what a plot of the track needs is kept there as the rows and poses come.
///
/// The outer error is a failed write of `out`; the inner one what reading the recording
/// refuses ([`RowReader`], [`RowReader::finish`]) and what [`track`] refuses of it.
pub(crate) fn track_stream(
    rows: RowReader,
    model: &Cascade,
    opts: &TrackOptions,
    out: &mut dyn std::io::Write,
    points: Option<&mut TrackPoints>,
) -> std::io::Result<Result<StreamedTrack>> {
    let mut failed = None;
    let tracked = track_rows(rows, model, opts, out, points, &mut failed);
    match failed {
        Some(e) => Err(e),
        None => Ok(tracked),
    }
}

/// [`track_stream`], with a failed write of `out` in `failed`.
fn track_rows(
    mut rows: RowReader,
    model: &Cascade,
    opts: &TrackOptions,
    out: &mut dyn std::io::Write,
    mut points: Option<&mut TrackPoints>,
    failed: &mut Option<std::io::Error>,
) -> Result<StreamedTrack> {
    let name = rows.name().to_string();
    if model.feature_config().orientation == Orientation::Recorded
        && rows.orientation_source() == Some(ridi_data::OrientationSource::Estimated)
    {
        return Err(crate::orientation::recorded_wanted(&name));
    }
    let mut written = |e: std::io::Error| {
        let message = e.to_string();
        *failed = Some(e);
        PipelineError::Live(message)
    };
    let written = &mut written;
    let names = model.placement_names();
    let mut live = live_for(model, opts, rows.orientation_source())?;
    csv_header(out).map_err(&mut *written)?;
    let max_dt = opts.correction.max_dt;
    let mut rate = ridi_data::MedianTest::default();
    // Times of the frames pushed whose pose is not out yet, and the regressions made whose
    // frame has no row yet.
    let mut times = std::collections::VecDeque::new();
    let mut made = std::collections::VecDeque::new();
    let mut placement: Option<&str> = None;
    let mut updates = Vec::new();
    let (mut frames, mut regressions) = (0usize, 0usize);
    let (mut first, mut previous) = (None::<f64>, None::<f64>);
    // The ground truth's points, for the plot, while `write` holds `points`.
    let (mut truth, plotted) = (Thinned::default(), points.is_some());
    let mut write = |updates: &mut Vec<ridi_correct::Update>,
                     live: &mut LiveTracker<'_>,
                     times: &mut std::collections::VecDeque<f64>|
     -> std::io::Result<()> {
        let (velocities, placements) = live.take_regressions();
        regressions += velocities.len();
        made.extend(velocities.iter().map(|v| v.frame).zip(placements));
        for u in updates.drain(..) {
            let frame = u.frame as usize;
            while made.front().is_some_and(|&(f, _)| f <= frame) {
                let (_, p) = made.pop_front().unwrap_or_default();
                placement = names.get(p).map(String::as_str);
            }
            let time = times.pop_front().unwrap_or(f64::NAN);
            if let Some(p) = points.as_deref_mut() {
                p.time.push(time);
                p.estimate.push([u.pose.position.x(), u.pose.position.y()]);
            }
            csv_row(
                out,
                time,
                (u.pose.position, u.pose.velocity),
                placement,
                u.bias,
            )?;
            frames += 1;
        }
        Ok(())
    };
    let mut i = 0usize;
    while let Some(row) = rows.next() {
        let row = row?;
        if rows.refused() {
            break;
        }
        let t0 = *first.get_or_insert(row.time);
        if let Some(p) = previous {
            if row.time - p > max_dt {
                rows.finish()?;
                return Err(gap_error(&name, i - 1, (p, row.time), t0, max_dt));
            }
            count_rate(&mut rate, row.time - p);
        }
        previous = Some(row.time);
        if let Some((p, _)) = row.ground_truth.filter(|_| plotted) {
            truth.push([p.x(), p.y()]);
        }
        let reading = SensorReading {
            time: row.time,
            gyro: row.gyro,
            acce: row.acce,
            recorded: Some(crate::live::Recorded {
                orientation: row.orientation,
                gravity: row.gravity,
                linacce: row.linacce,
            }),
        };
        times.push_back(row.time);
        if let Err(e) = live.push(&reading, &mut updates) {
            let (path, read_opts) = (rows.path().to_path_buf(), rows.options().clone());
            // What reading refuses comes first, as when the recording is read whole; then a
            // rate off as `track` words it (the live tracker's check of its last second
            // refuses such a stream by its 201st frame).
            rows.finish()?;
            if let Some(r) = rate_off(&rate, &path, &read_opts)? {
                return Err(wrong_rate(&name, r));
            }
            return Err(PipelineError::sequence(&name, format!("frame {i}: {e}")));
        }
        write(&mut updates, &mut live, &mut times).map_err(&mut *written)?;
        i += 1;
    }
    let path = rows.path().to_path_buf();
    let read_opts = rows.options().clone();
    rows.finish()?;
    let config = model.feature_config();
    if i <= config.window {
        let duration = previous.zip(first).map_or(0.0, |(l, f)| l - f);
        return Err(too_short(&name, i, duration, config));
    }
    if let Some(r) = rate_off(&rate, &path, &read_opts)? {
        return Err(wrong_rate(&name, r));
    }
    live.finish(&mut updates)
        .map_err(|e| PipelineError::sequence(&name, e.to_string()))?;
    write(&mut updates, &mut live, &mut times).map_err(written)?;
    if let Some(p) = points {
        p.ground_truth = truth;
    }
    Ok(StreamedTrack {
        name,
        frames,
        regressions,
    })
}

#[cfg(test)]
mod tests {
    use super::{PLOT_FRAMES, Thinned};

    fn thinned(n: usize) -> Vec<usize> {
        let mut t = Thinned::default();
        (0..n).for_each(|i| t.push(i));
        t.kept().to_vec()
    }

    #[test]
    fn plot_points_are_every_frame_up_to_the_bound_then_every_other() {
        assert_eq!(thinned(PLOT_FRAMES), (0..PLOT_FRAMES).collect::<Vec<_>>());
        // One more frame halves them: every second frame, the new one included.
        let kept = thinned(PLOT_FRAMES + 1);
        assert_eq!(kept, (0..=PLOT_FRAMES).step_by(2).collect::<Vec<_>>());
        // Far beyond: every fourth frame, never more than the bound.
        let n = 3 * PLOT_FRAMES + 5;
        let kept = thinned(n);
        assert_eq!(kept, (0..n).step_by(4).collect::<Vec<_>>());
        assert!(kept.len() <= PLOT_FRAMES);
    }

    #[test]
    fn plot_series_pushed_at_different_times_keep_the_same_frames() {
        // The ground truth is pushed as rows are read, the estimate as poses come out, a
        // tracker's delay later; the recording may end between two halvings of either.
        for n in [PLOT_FRAMES - 1, PLOT_FRAMES + 1, 2 * PLOT_FRAMES + 3] {
            let (mut truth, mut estimate) = (Thinned::default(), Thinned::default());
            let lag = 1000;
            for i in 0..n + lag {
                if i < n {
                    truth.push(i);
                }
                if i >= lag {
                    estimate.push(i - lag);
                }
            }
            assert_eq!(truth.kept(), estimate.kept(), "{n} frames");
        }
    }
}
