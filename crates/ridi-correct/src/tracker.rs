//! The streaming tracker: integration every frame, regression every few frames, a windowed
//! correction every few hundred frames, in bounded memory.

use std::collections::VecDeque;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

use ridi_frames::{DeviceVec, ImuFrames, ImuSample, StabHorizontal, WorldFromDevice, WorldVec};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::config::{CorrectionConfig, InitialVelocity};
use crate::error::CorrectError;
use crate::input::FrameVelocity;
use crate::integrate::{Integrator, Pose};
use crate::knots::BiasCurve;
use crate::placement::PlacementFilter;
use crate::regressor::{RegressorOutput, VelocityRegressor};
use crate::ring::FrameRing;
use crate::solve::{Correction, Corrector, Trajectory};

/// Largest number of frames a window, a regressor view or the apply delay may span (about
/// 5.8 hours at 200 Hz): the buffers are allocated up front. It also bounds `regress_every`
/// and the placement filter's radius, whose product counts the targets kept.
pub const MAX_BUFFER: usize = 1 << 22;

/// What to do when the time step to a new sample exceeds `correction.max_dt`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum GapPolicy {
    /// Refuse the sample with [`TrackError::Gap`]; the tracker is unchanged. The caller may
    /// then call [`Tracker::restart`] and push it again.
    #[default]
    Reject,
    /// Restart automatically (see [`Tracker::restart`]) and accept the sample as the first
    /// frame of a new segment.
    Restart,
}

/// Configuration of a [`Tracker`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrackerConfig {
    /// The objective solved in each window (knots, weights, lambda, initial velocity,
    /// largest time step).
    pub correction: CorrectionConfig,
    /// Frames between regressions (paper: 50; original code: 30).
    pub regress_every: usize,
    /// Frames between window corrections (paper: 200).
    pub correct_every: usize,
    /// Frames per correction window (paper: 1000).
    pub window: usize,
    /// Frames between the end of a window and the application of its solution; must be less
    /// than `correct_every`. Gives a background solver time to finish.
    pub apply_delay: usize,
    /// Solve windows on a background thread (bounded queue of one job).
    pub background: bool,
    /// Keep every frame and target for [`Tracker::global_pass`] (memory grows with the
    /// stream; off by default).
    pub keep_history: bool,
    /// Zero regressed velocities around placement flips (off by default).
    pub placement_filter: Option<PlacementFilter>,
    /// Reaction to a time gap.
    pub gap_policy: GapPolicy,
}

impl Default for TrackerConfig {
    /// The paper's online setting: regression every 50 frames, a 1000-frame window solved
    /// every 200 frames, applied at once, inline.
    fn default() -> Self {
        Self {
            correction: CorrectionConfig::default(),
            regress_every: 50,
            correct_every: 200,
            window: 1000,
            apply_delay: 0,
            background: false,
            keep_history: false,
            placement_filter: None,
            gap_policy: GapPolicy::Reject,
        }
    }
}

impl TrackerConfig {
    /// Checks every value's domain.
    pub fn validate(&self) -> Result<(), TrackError> {
        self.correction.validate()?;
        if self.regress_every == 0 || self.correct_every == 0 || self.window < 2 {
            return Err(TrackError::InvalidConfig(
                "regress_every and correct_every must be at least 1, window at least 2",
            ));
        }
        let radius = self.placement_filter.map_or(0, |f| f.radius);
        if [self.window, self.apply_delay, self.regress_every, radius]
            .iter()
            .any(|&n| n > MAX_BUFFER)
        {
            // Also what keeps the count of targets the filter looks back on within u64.
            return Err(TrackError::InvalidConfig(
                "window, apply_delay, regress_every and the placement filter's radius must be \
                 at most 2^22",
            ));
        }
        if self.apply_delay >= self.correct_every {
            return Err(TrackError::InvalidConfig(
                "apply_delay must be less than correct_every",
            ));
        }
        Ok(())
    }
}

/// Why the tracker refused a sample or an operation.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TrackError {
    /// A sample field is NaN or infinite; the sample was dropped and the tracker is unchanged.
    #[error("sample field {what} is not finite")]
    NonFinite {
        /// The offending field.
        what: &'static str,
    },
    /// The sample is not after the previous one; dropped, tracker unchanged.
    #[error("sample time {time} is not after the previous sample's {previous}")]
    TimeNotIncreasing {
        /// The sample's time.
        time: f64,
        /// The previous accepted sample's time.
        previous: f64,
    },
    /// The time step exceeds `max_dt` and the gap policy is [`GapPolicy::Reject`].
    #[error("gap of {} s exceeds max_dt = {max_dt} s", crate::error::rounded(*dt))]
    Gap {
        /// The step, seconds.
        dt: f64,
        /// The limit, seconds.
        max_dt: f64,
    },
    /// A configuration value is out of its domain.
    #[error("invalid configuration: {0}")]
    InvalidConfig(&'static str),
    /// [`Tracker::global_pass`] needs `keep_history`.
    #[error("the tracker keeps no history (set keep_history)")]
    NoHistory,
    /// The background solver thread stopped (it panicked); the tracker cannot continue.
    #[error("the background solver stopped")]
    SolverStopped,
    /// A correction of the global pass failed.
    #[error(transparent)]
    Correct(#[from] CorrectError),
}

/// What became of a scheduled regression.
#[derive(Debug, Clone, PartialEq)]
pub enum RegressionOutcome {
    /// A velocity was regressed and stored as a target.
    Velocity(RegressorOutput),
    /// The regressor had no estimate for this frame.
    NoEstimate,
    /// The regressor failed (or returned a non-finite velocity): the frame gets no target,
    /// which the windows containing it simply do without.
    Failed(String),
}

/// Frames whose stored poses a correction re-integrated.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Revision {
    /// First frame of the window (its pose is kept, except for an estimated velocity).
    pub first_frame: u64,
    /// Last frame re-integrated (the current frame).
    pub last_frame: u64,
    /// The bias correction now added to new frames' linear acceleration, device frame.
    pub bias: DeviceVec,
}

/// What became of a correction step.
#[derive(Debug, Clone, PartialEq)]
pub enum CorrectionOutcome {
    /// A window solve was started; it is applied `apply_delay` frames later.
    Submitted,
    /// A window solve was applied at this frame.
    Applied(Revision),
    /// The window had no velocity target: nothing to correct, the current bias is kept.
    NoTargets,
    /// The solve failed; the current bias is kept.
    Failed(CorrectError),
}

/// Result of pushing one sample.
#[derive(Debug, Clone, PartialEq)]
pub struct Update {
    /// Stream index of the frame (from 0, across restarts).
    pub frame: u64,
    /// Its pose, as known now (including a revision applied at this frame).
    pub pose: Pose,
    /// The bias applied to new frames from here on, device frame ([`Tracker::bias`] after
    /// this sample).
    pub bias: DeviceVec,
    /// Set when a regression was scheduled at this frame.
    pub regression: Option<RegressionOutcome>,
    /// Set when a correction was started, applied, or skipped at this frame.
    pub correction: Option<CorrectionOutcome>,
    /// `true` when this sample started a new segment after a gap ([`GapPolicy::Restart`]).
    pub restarted: bool,
}

/// Counters of a tracker's life.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct TrackerStats {
    /// Accepted samples.
    pub frames: u64,
    /// Regressions that produced a target.
    pub regressions: u64,
    /// Regressions that failed.
    pub failed_regressions: u64,
    /// Targets zeroed by the placement-change filter (counted per window solve).
    pub zeroed_targets: u64,
    /// Corrections applied.
    pub corrections: u64,
    /// Corrections skipped (no target, or a failed solve).
    pub skipped_corrections: u64,
    /// Restarts (gaps or explicit).
    pub restarts: u64,
}

/// A piece of the global pass: the frames of one segment (between restarts).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// Stream index of the segment's first frame.
    pub first_frame: u64,
    /// Corrected trajectory, positions continuing from the previous segment's end.
    pub trajectory: Trajectory,
}

#[derive(Debug, Clone, Copy)]
struct StoredTarget {
    frame: u64,
    velocity: StabHorizontal,
    placement: Option<usize>,
}

/// A window's inputs, owned so that a background thread can solve them.
#[derive(Default)]
struct Job {
    time: Vec<f64>,
    linacce: Vec<DeviceVec>,
    orientation: Vec<WorldFromDevice>,
    gravity: Vec<DeviceVec>,
    targets: Vec<FrameVelocity>,
    initial: Option<InitialVelocity>,
}

impl Job {
    fn imu(&self) -> ImuFrames<'_> {
        // The correction reads no gyro.
        ImuFrames {
            time: &self.time,
            gyro: &[],
            linacce: &self.linacce,
            gravity: &self.gravity,
            orientation: &self.orientation,
        }
    }
}

type JobResult = (Job, Result<Correction, CorrectError>);

enum Solver {
    Inline(Box<Corrector>),
    Background {
        jobs: Option<SyncSender<Job>>,
        results: Receiver<JobResult>,
        thread: Option<JoinHandle<()>>,
    },
}

impl Drop for Solver {
    fn drop(&mut self) {
        if let Solver::Background { jobs, thread, .. } = self {
            // Closing the queue ends the worker's loop.
            jobs.take();
            if let Some(t) = thread.take() {
                let _ = t.join();
            }
        }
    }
}

/// A solve waiting to be applied.
struct Pending {
    apply_at: u64,
    first: u64,
    last: u64,
    /// Result of an inline solve (a background one arrives through the channel).
    result: Option<Result<Correction, CorrectError>>,
}

struct History {
    time: Vec<f64>,
    linacce: Vec<DeviceVec>,
    orientation: Vec<WorldFromDevice>,
    gravity: Vec<DeviceVec>,
    targets: Vec<StoredTarget>,
    /// Index of each segment's first frame (history starts at stream frame 0, so the index
    /// is the stream frame).
    segments: Vec<usize>,
}

/// The streaming RIDI tracker.
///
/// # What a window correction means
///
/// At frame `e` (every `correct_every` frames of a segment) the tracker solves the batch
/// objective over the window `W = [s, e]` of the latest `window` frames, with
///
/// - the **raw** accelerations of `W` (never accelerations corrected by an earlier window, so
///   overlapping windows do not stack their corrections: the original's bug),
/// - the velocity targets regressed inside `W`,
/// - the initial velocity fixed to the tracker's current estimate at `s` (the output of the
///   previous windows), or, for a window starting at the segment start, the configured
///   initial velocity (fixed or estimated).
///
/// The solution revises the stored poses of `W`: they are re-integrated from the current
/// estimate of the pose at `s` with the window's bias. Frames after `e` use the bias at the
/// end of the window (held constant) until the next correction. The result of a solve is
/// applied `apply_delay` frames after `e` (frames `(e, e + apply_delay]` are then
/// re-integrated too), in both the inline and the background mode, which makes the two
/// produce bit-identical trajectories.
///
/// Each frame's pose in an [`Update`] is the live estimate at that moment; later revisions
/// can be read back with [`Tracker::pose`] while the frame is still buffered.
///
/// Consequences: a window covering the whole stream reproduces the batch solve exactly, and
/// [`Tracker::global_pass`] *is* the batch solve over the stored history (both are tested).
///
/// # Schedule
///
/// Frame `f` of a segment (counted from the segment's first frame) is regressed when `f` is a
/// multiple of `regress_every` and the segment holds the regressor's window; a correction is
/// started when `f > 0` is a multiple of `correct_every`. Align the two (the defaults do) so
/// that each window ends on a target and its final bias, carried forward, is well determined.
///
/// # Bad input and recovery
///
/// - A sample with a NaN or infinite field, or not after the previous one: refused with an
///   error, the tracker unchanged; pushing the next good sample continues the stream.
/// - A gap longer than `max_dt`: refused ([`GapPolicy::Reject`]) or a restart
///   ([`GapPolicy::Restart`], or [`Tracker::restart`] by hand): position held, velocity and
///   bias reset, window emptied. Nothing is integrated across the gap.
/// - A regression that fails, or returns a non-finite velocity: reported in the update,
///   counted, and left out; windows do without it. A window without any target is skipped and
///   the current bias kept, as is a window whose solve fails.
/// - The placement-change filter, when enabled, re-evaluates the labels at every window with
///   the labels known by then (the ±radius neighbourhood of the newest targets is one-sided
///   until later labels arrive); the global pass sees them all.
pub struct Tracker<R: VelocityRegressor> {
    config: TrackerConfig,
    regressor: R,
    ring: FrameRing,
    targets: VecDeque<StoredTarget>,
    next_frame: u64,
    last_time: Option<f64>,
    segment_start: u64,
    /// Position held across a restart.
    hold_position: WorldVec,
    integrator: Option<Integrator>,
    bias: DeviceVec,
    solver: Solver,
    pending: Option<Pending>,
    spare: Option<Job>,
    history: Option<History>,
    stats: TrackerStats,
}

impl<R: VelocityRegressor> std::fmt::Debug for Tracker<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Tracker")
            .field("config", &self.config)
            .field("next_frame", &self.next_frame)
            .field("stats", &self.stats)
            .finish_non_exhaustive()
    }
}

impl<R: VelocityRegressor> Tracker<R> {
    /// A tracker with `config` (validated) and `regressor`. Starts at the origin with the
    /// configured initial velocity (zero when it is to be estimated, until a window estimates
    /// it).
    pub fn new(config: TrackerConfig, regressor: R) -> Result<Self, TrackError> {
        config.validate()?;
        if regressor.window_len() > MAX_BUFFER {
            return Err(TrackError::InvalidConfig(
                "the regressor's window must be at most 2^22 frames",
            ));
        }
        if regressor.window_len() == 0 {
            return Err(TrackError::InvalidConfig(
                "the regressor's window must be at least 1 frame (the frame regressed)",
            ));
        }
        if regressor
            .up_axis()
            .is_some_and(|a| a != config.correction.up_axis)
        {
            return Err(TrackError::InvalidConfig(
                "the regressor's velocities are in another stabilized frame than the \
                 correction's: set the correction's up_axis to the model's",
            ));
        }
        let cap = config
            .window
            .max(regressor.window_len().max(1))
            .saturating_add(config.apply_delay + 1);
        let solver = if config.background {
            let corrector = Corrector::new(config.correction)?;
            let (jobs, job_rx) = sync_channel::<Job>(1);
            let (res_tx, results) = sync_channel::<JobResult>(1);
            let thread = std::thread::Builder::new()
                .name("ridi-correct-solver".into())
                .spawn(move || {
                    let mut corrector = corrector;
                    while let Ok(job) = job_rx.recv() {
                        let r = solve_job(&mut corrector, &job);
                        if res_tx.send((job, r)).is_err() {
                            break;
                        }
                    }
                })
                .map_err(|_| TrackError::SolverStopped)?;
            Solver::Background {
                jobs: Some(jobs),
                results,
                thread: Some(thread),
            }
        } else {
            Solver::Inline(Box::new(Corrector::new(config.correction)?))
        };
        let history = config.keep_history.then(|| History {
            time: Vec::new(),
            linacce: Vec::new(),
            orientation: Vec::new(),
            gravity: Vec::new(),
            targets: Vec::new(),
            segments: vec![0],
        });
        Ok(Self {
            config,
            regressor,
            ring: FrameRing::new(cap),
            targets: VecDeque::new(),
            next_frame: 0,
            last_time: None,
            segment_start: 0,
            hold_position: WorldVec::ZERO,
            integrator: None,
            bias: DeviceVec::ZERO,
            solver,
            pending: None,
            spare: None,
            history,
            stats: TrackerStats::default(),
        })
    }

    /// The configuration.
    pub fn config(&self) -> &TrackerConfig {
        &self.config
    }

    /// Counters.
    pub fn stats(&self) -> TrackerStats {
        self.stats
    }

    /// The regressor.
    pub fn regressor(&self) -> &R {
        &self.regressor
    }

    /// The regressor, to take what it kept for reports (the tracker relies on no state of it).
    pub fn regressor_mut(&mut self) -> &mut R {
        &mut self.regressor
    }

    /// The bias currently applied to new frames, device frame.
    pub fn bias(&self) -> DeviceVec {
        self.bias
    }

    /// Number of frames currently buffered (at most about twice the window): the tracker's
    /// memory does not grow with the stream unless `keep_history` is set.
    pub fn buffered_frames(&self) -> usize {
        self.ring.len()
    }

    /// The current estimate of the pose of stream frame `frame`, if still buffered.
    pub fn pose(&self, frame: u64) -> Option<Pose> {
        self.ring.index(frame).map(|i| self.ring.pose[i])
    }

    /// Feeds a chunk of samples; stops at the first refused sample and returns its error
    /// together with the updates of the samples accepted before it.
    pub fn push_all(&mut self, samples: &[ImuSample]) -> (Vec<Update>, Option<TrackError>) {
        let mut out = Vec::with_capacity(samples.len());
        for s in samples {
            match self.push(s) {
                Ok(u) => out.push(u),
                Err(e) => return (out, Some(e)),
            }
        }
        (out, None)
    }

    /// Feeds one sample and returns its frame's pose plus what happened at this frame.
    pub fn push(&mut self, sample: &ImuSample) -> Result<Update, TrackError> {
        check_sample(sample)?;
        let mut restarted = false;
        // Time must increase even across a restart: the history and the stream indices would
        // otherwise stop meaning anything.
        if let Some(prev) = self.last_time {
            let dt = sample.time - prev;
            if dt <= 0.0 {
                return Err(TrackError::TimeNotIncreasing {
                    time: sample.time,
                    previous: prev,
                });
            }
            // Right after a restart there is nothing to bridge.
            if dt > self.config.correction.max_dt && self.integrator.is_some() {
                match self.config.gap_policy {
                    GapPolicy::Reject => {
                        return Err(TrackError::Gap {
                            dt,
                            max_dt: self.config.correction.max_dt,
                        });
                    }
                    GapPolicy::Restart => {
                        self.restart()?;
                        restarted = true;
                    }
                }
            }
        }
        let frame = self.next_frame;
        self.next_frame += 1;
        self.last_time = Some(sample.time);
        self.stats.frames += 1;
        self.ring.push(
            sample.time,
            sample.gyro,
            sample.linacce,
            sample.gravity,
            sample.orientation,
        );
        if let Some(h) = &mut self.history {
            h.time.push(sample.time);
            h.linacce.push(sample.linacce);
            h.orientation.push(sample.orientation);
            h.gravity.push(sample.gravity);
        }
        let acc = corrected_world(sample.orientation, sample.linacce, self.bias);
        let pose = match &mut self.integrator {
            Some(it) => it.step(sample.time, acc),
            None => {
                let v0 = match self.config.correction.initial_velocity {
                    InitialVelocity::Fixed(v) => v,
                    InitialVelocity::Estimate => WorldVec::ZERO,
                };
                let it = Integrator::new(sample.time, acc, v0, self.hold_position);
                self.integrator = Some(it);
                it.pose()
            }
        };
        let last = self.ring.len() - 1;
        self.ring.pose[last] = pose;

        let in_segment = frame - self.segment_start;
        let regression = if in_segment.is_multiple_of(self.config.regress_every as u64)
            && in_segment + 1 >= self.regressor.window_len().max(1) as u64
        {
            Some(self.regress(frame))
        } else {
            None
        };

        let mut correction = None;
        if self.pending.as_ref().is_some_and(|p| p.apply_at == frame) {
            correction = Some(self.apply_pending()?);
        }
        if in_segment > 0 && in_segment.is_multiple_of(self.config.correct_every as u64) {
            correction = Some(self.submit(frame)?);
        }
        let pose = self.ring.pose[self.ring.len() - 1];
        Ok(Update {
            frame,
            pose,
            bias: self.bias,
            regression,
            correction,
            restarted,
        })
    }

    /// Starts a new segment: the next sample is integrated from the current position (held)
    /// with the configured initial velocity and zero bias; buffered frames, targets and any
    /// pending solve are dropped, and regressions wait for a full regressor window again.
    /// Meant for recovery after a gap, when nothing is known about the motion in between.
    pub fn restart(&mut self) -> Result<(), TrackError> {
        if let Some(it) = &self.integrator {
            self.hold_position = it.pose().position;
        }
        if let Some(p) = self.pending.take()
            && p.result.is_none()
        {
            // A background solve is in flight: collect (and discard) it so the queue stays in
            // step.
            let _discarded = self.receive()?;
        }
        self.integrator = None;
        self.bias = DeviceVec::ZERO;
        self.targets.clear();
        self.segment_start = self.next_frame;
        self.ring.clear(self.next_frame);
        self.stats.restarts += 1;
        if let Some(h) = &mut self.history
            && h.segments.last() != Some(&h.time.len())
        {
            h.segments.push(h.time.len());
        }
        Ok(())
    }

    /// Offline finish: solves the batch objective over every stored frame (each segment on its
    /// own, positions chained across restarts), with the configured initial velocity. Needs
    /// `keep_history`.
    pub fn global_pass(&self) -> Result<Vec<Segment>, TrackError> {
        let h = self.history.as_ref().ok_or(TrackError::NoHistory)?;
        let mut corrector = Corrector::new(self.config.correction)?;
        let mut out = Vec::with_capacity(h.segments.len());
        let mut p0 = WorldVec::ZERO;
        for (i, &a) in h.segments.iter().enumerate() {
            let b = h.segments.get(i + 1).copied().unwrap_or(h.time.len());
            if a == b {
                continue;
            }
            let first_frame = a as u64;
            let imu = ImuFrames {
                time: &h.time[a..b],
                gyro: &[],
                linacce: &h.linacce[a..b],
                gravity: &h.gravity[a..b],
                orientation: &h.orientation[a..b],
            };
            let stored: Vec<&StoredTarget> = h
                .targets
                .iter()
                .filter(|t| t.frame >= first_frame && t.frame < first_frame + (b - a) as u64)
                .collect();
            let labels: Vec<Option<usize>> = stored.iter().map(|t| t.placement).collect();
            let zero = self.filter_flags(&labels);
            let targets: Vec<FrameVelocity> = stored
                .iter()
                .zip(&zero)
                .map(|(t, &z)| FrameVelocity {
                    frame: (t.frame - first_frame) as usize,
                    velocity: if z { StabHorizontal::ZERO } else { t.velocity },
                })
                .collect();
            let mut trajectory = if targets.is_empty()
                && self.config.correction.initial_velocity == InitialVelocity::Estimate
            {
                // Nothing to estimate the start from: integrate from rest, uncorrected.
                Corrector::new(CorrectionConfig {
                    initial_velocity: InitialVelocity::Fixed(WorldVec::ZERO),
                    ..self.config.correction
                })?
                .correct(&imu, &targets)?
            } else {
                corrector.correct(&imu, &targets)?
            };
            for p in &mut trajectory.poses {
                p.position += p0;
            }
            if let Some(last) = trajectory.poses.last() {
                p0 = last.position;
            }
            out.push(Segment {
                first_frame,
                trajectory,
            });
        }
        Ok(out)
    }

    fn filter_flags(&self, labels: &[Option<usize>]) -> Vec<bool> {
        match &self.config.placement_filter {
            Some(f) => f.flags(labels),
            None => vec![false; labels.len()],
        }
    }

    fn regress(&mut self, frame: u64) -> RegressionOutcome {
        let n = self.regressor.window_len().max(1);
        let view = self.ring.last(n);
        match self.regressor.regress(&view) {
            Ok(Some(r)) if r.velocity.is_finite() => {
                let t = StoredTarget {
                    frame,
                    velocity: r.velocity,
                    placement: r.placement,
                };
                self.targets.push_back(t);
                if let Some(h) = &mut self.history {
                    h.targets.push(t);
                }
                // Keep what the next windows and the placement filter can still look at.
                let radius = self.config.placement_filter.map_or(0, |f| f.radius);
                let keep = self.config.window as u64
                    + (radius as u64 + 1) * self.config.regress_every as u64;
                while self.targets.front().is_some_and(|t| t.frame + keep < frame) {
                    self.targets.pop_front();
                }
                self.stats.regressions += 1;
                RegressionOutcome::Velocity(r)
            }
            Ok(Some(_)) => {
                self.stats.failed_regressions += 1;
                RegressionOutcome::Failed("regressor returned a non-finite velocity".into())
            }
            Ok(None) => RegressionOutcome::NoEstimate,
            Err(e) => {
                self.stats.failed_regressions += 1;
                RegressionOutcome::Failed(e.to_string())
            }
        }
    }

    /// Starts the solve of the window ending at `frame`.
    fn submit(&mut self, frame: u64) -> Result<CorrectionOutcome, TrackError> {
        let len = (frame - self.segment_start + 1).min(self.config.window as u64);
        let first = frame + 1 - len;
        let (Some(a), Some(b)) = (self.ring.index(first), self.ring.index(frame)) else {
            return Ok(CorrectionOutcome::NoTargets);
        };
        let mut job = self.spare.take().unwrap_or_default();
        job.targets.clear();
        let labels: Vec<Option<usize>> = self.targets.iter().map(|t| t.placement).collect();
        let zero = self.filter_flags(&labels);
        for (t, z) in self.targets.iter().zip(zero) {
            if t.frame >= first && t.frame <= frame {
                if z {
                    self.stats.zeroed_targets += 1;
                }
                job.targets.push(FrameVelocity {
                    frame: (t.frame - first) as usize,
                    velocity: if z { StabHorizontal::ZERO } else { t.velocity },
                });
            }
        }
        if job.targets.is_empty() {
            self.spare = Some(job);
            self.stats.skipped_corrections += 1;
            return Ok(CorrectionOutcome::NoTargets);
        }
        job.initial = Some(if first == self.segment_start {
            self.config.correction.initial_velocity
        } else {
            InitialVelocity::Fixed(self.ring.pose[a].velocity)
        });
        let mut pending = Pending {
            apply_at: frame + self.config.apply_delay as u64,
            first,
            last: frame,
            result: None,
        };
        match &mut self.solver {
            Solver::Inline(corrector) => {
                let imu = self.ring.imu().slice(a..b + 1);
                let initial = job.initial.unwrap_or_default();
                pending.result = Some(corrector.solve_validated(&imu, &job.targets, initial));
                self.spare = Some(job);
            }
            Solver::Background { jobs, .. } => {
                job.time.clear();
                job.time.extend_from_slice(&self.ring.time[a..=b]);
                job.linacce.clear();
                job.linacce.extend_from_slice(&self.ring.linacce[a..=b]);
                job.orientation.clear();
                job.orientation
                    .extend_from_slice(&self.ring.orientation[a..=b]);
                job.gravity.clear();
                job.gravity.extend_from_slice(&self.ring.gravity[a..=b]);
                let tx = jobs.as_ref().ok_or(TrackError::SolverStopped)?;
                tx.send(job).map_err(|_| TrackError::SolverStopped)?;
            }
        }
        self.pending = Some(pending);
        if self.config.apply_delay == 0 {
            self.apply_pending()
        } else {
            Ok(CorrectionOutcome::Submitted)
        }
    }

    fn receive(&mut self) -> Result<Result<Correction, CorrectError>, TrackError> {
        match &self.solver {
            Solver::Background { results, .. } => {
                let (job, r) = results.recv().map_err(|_| TrackError::SolverStopped)?;
                self.spare = Some(job);
                Ok(r)
            }
            Solver::Inline(_) => Err(TrackError::SolverStopped),
        }
    }

    fn apply_pending(&mut self) -> Result<CorrectionOutcome, TrackError> {
        let Some(p) = self.pending.take() else {
            return Ok(CorrectionOutcome::NoTargets);
        };
        let result = match p.result {
            Some(r) => r,
            None => self.receive()?,
        };
        let correction = match result {
            Ok(c) => c,
            Err(e) => {
                self.stats.skipped_corrections += 1;
                return Ok(CorrectionOutcome::Failed(e));
            }
        };
        let (Some(a), Some(end)) = (self.ring.index(p.first), self.ring.index(p.last)) else {
            // Only a restart drops frames under a pending solve, and it drops the solve too.
            self.stats.skipped_corrections += 1;
            return Ok(CorrectionOutcome::NoTargets);
        };
        let ring = &mut self.ring;
        let bias_at = |curve: &BiasCurve, i: usize, t: f64| {
            if i <= end {
                curve.at(i - a, t)
            } else {
                curve.last()
            }
        };
        let start = ring.pose[a];
        let acc0 = corrected_world(
            ring.orientation[a],
            ring.linacce[a],
            bias_at(&correction.bias, a, ring.time[a]),
        );
        let mut it = Integrator::new(
            start.time,
            acc0,
            correction.initial_velocity,
            start.position,
        );
        ring.pose[a] = it.pose();
        for i in a + 1..ring.len() {
            let t = ring.time[i];
            let acc = corrected_world(
                ring.orientation[i],
                ring.linacce[i],
                bias_at(&correction.bias, i, t),
            );
            ring.pose[i] = it.step(t, acc);
        }
        self.integrator = Some(it);
        self.bias = correction.bias.last();
        self.stats.corrections += 1;
        Ok(CorrectionOutcome::Applied(Revision {
            first_frame: p.first,
            last_frame: self.next_frame - 1,
            bias: self.bias,
        }))
    }
}

fn solve_job(corrector: &mut Corrector, job: &Job) -> Result<Correction, CorrectError> {
    corrector.solve_validated(&job.imu(), &job.targets, job.initial.unwrap_or_default())
}

#[inline]
fn corrected_world(q: WorldFromDevice, lin: DeviceVec, bias: DeviceVec) -> WorldVec {
    q * (lin + bias)
}

fn check_sample(s: &ImuSample) -> Result<(), TrackError> {
    let bad = |what| Err(TrackError::NonFinite { what });
    if !s.time.is_finite() {
        return bad("time");
    }
    if !s.gyro.is_finite() {
        return bad("gyro");
    }
    if !s.linacce.is_finite() {
        return bad("linacce");
    }
    if !s.gravity.is_finite() {
        return bad("gravity");
    }
    if !s
        .orientation
        .quaternion()
        .coords
        .iter()
        .all(|c| c.is_finite())
    {
        return bad("orientation");
    }
    Ok(())
}
