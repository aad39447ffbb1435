//! Streaming tracker: agreement with the batch solve where the math says so, background
//! determinism, bounded memory, bad input.

mod common;

use common::{Walk, max_position_error, walk};
use ridi_correct::{
    CorrectionConfig, CorrectionOutcome, Corrector, FrameVelocity, FrameWindow, GapPolicy,
    InitialVelocity, PlacementFilter, RegressionOutcome, RegressorError, RegressorOutput,
    TrackError, Tracker, TrackerConfig, VelocityRegressor, corrected_acceleration, integrate,
    world_acceleration,
};
use ridi_frames::{DeviceVec, ImuSample, StabHorizontal, WorldVec};

/// Returns the exact S velocity of the walk at the regressed frame; can be told to fail or
/// to flip placement labels.
struct Truth {
    velocity: Vec<StabHorizontal>,
    window: usize,
    fail_every: Option<u64>,
    flip_between: Option<(u64, u64)>,
}

impl Truth {
    fn new(w: &Walk, window: usize) -> Self {
        Self {
            velocity: (0..w.time.len()).map(|f| w.target(f).velocity).collect(),
            window,
            fail_every: None,
            flip_between: None,
        }
    }
}

impl VelocityRegressor for Truth {
    fn window_len(&self) -> usize {
        self.window
    }
    fn regress(
        &mut self,
        frames: &FrameWindow<'_>,
    ) -> Result<Option<RegressorOutput>, RegressorError> {
        assert_eq!(frames.len(), self.window);
        let f = frames.last_frame();
        if self.fail_every.is_some_and(|k| f.is_multiple_of(k)) {
            return Err("model not loaded".into());
        }
        let placement = match self.flip_between {
            Some((a, b)) if f >= a && f <= b => Some(((f / 50) % 2) as usize),
            _ => Some(0),
        };
        Ok(self
            .velocity
            .get(f as usize)
            .map(|&velocity| RegressorOutput {
                velocity,
                placement,
            }))
    }
}

fn samples(w: &Walk) -> Vec<ImuSample> {
    let imu = w.imu();
    (0..imu.len()).map(|f| imu.sample(f)).collect()
}

#[test]
fn a_single_window_over_everything_is_the_batch_solve() {
    let w = walk(801, 50, WorldVec::ZERO, true);
    let config = TrackerConfig {
        window: 1000,
        correct_every: 800,
        ..Default::default()
    };
    // A regressor must look at the frame it regresses at least.
    let err = Tracker::new(config, Truth::new(&w, 0)).unwrap_err();
    assert!(err.to_string().contains("at least 1 frame"), "{err}");
    let mut tracker = Tracker::new(config, Truth::new(&w, 1)).unwrap();
    let (updates, err) = tracker.push_all(&samples(&w));
    assert!(err.is_none());
    match &updates[800].correction {
        Some(CorrectionOutcome::Applied(r)) => {
            assert_eq!((r.first_frame, r.last_frame), (0, 800));
        }
        other => panic!("expected a correction at frame 800, got {other:?}"),
    }
    let batch = Corrector::new(CorrectionConfig::default())
        .unwrap()
        .correct(&w.imu(), &w.targets(0, 50))
        .unwrap();
    for f in 0..801 {
        assert_eq!(tracker.pose(f as u64).unwrap(), batch.poses[f], "frame {f}");
    }
    assert_eq!(tracker.bias(), batch.correction.bias.last());
}

#[test]
fn each_window_starts_from_raw_data_and_the_earlier_output() {
    let w = walk(3000, 50, WorldVec::ZERO, false);
    let config = TrackerConfig::default();
    let mut tracker = Tracker::new(config, Truth::new(&w, 200)).unwrap();
    let all = samples(&w);
    let mut checked = 0;
    for (f, s) in all.iter().enumerate() {
        let start = (f + 1).saturating_sub(1000);
        let before = tracker.pose(start as u64);
        let u = tracker.push(s).unwrap();
        let Some(CorrectionOutcome::Applied(r)) = u.correction else {
            continue;
        };
        assert_eq!(r.first_frame, start as u64);
        // The window problem, solved from scratch on the raw slice, starting from the pose
        // the tracker had output for the window's first frame.
        let start_pose = before.expect("the window start was pushed earlier");
        let imu = w.imu().slice(start..f + 1);
        let targets: Vec<FrameVelocity> = (200..=f)
            .step_by(50)
            .filter(|&g| g >= start)
            .map(|g| FrameVelocity {
                frame: g - start,
                velocity: w.target(g).velocity,
            })
            .collect();
        let initial = if start == 0 {
            InitialVelocity::Fixed(WorldVec::ZERO)
        } else {
            InitialVelocity::Fixed(start_pose.velocity)
        };
        let c = Corrector::new(CorrectionConfig::default())
            .unwrap()
            .solve_from(&imu, &targets, initial)
            .unwrap();
        let acc = corrected_acceleration(&imu, &c.bias).unwrap();
        let poses = integrate(imu.time, &acc, c.initial_velocity, start_pose.position).unwrap();
        for (i, p) in poses.iter().enumerate() {
            let got = tracker.pose((start + i) as u64).unwrap();
            assert!(
                (got.position - p.position).norm() < 1e-9
                    && (got.velocity - p.velocity).norm() < 1e-9,
                "window ending at {f}, frame {}",
                start + i
            );
        }
        checked += 1;
    }
    assert_eq!(checked, 14);
}

#[test]
fn sliding_windows_remove_the_drift() {
    let w = walk(12_000, 50, WorldVec::ZERO, true);
    let mut tracker = Tracker::new(TrackerConfig::default(), Truth::new(&w, 200)).unwrap();
    let (updates, err) = tracker.push_all(&samples(&w));
    assert!(err.is_none());
    let live: Vec<_> = updates.iter().map(|u| u.pose).collect();
    let e = max_position_error(&live, &w.poses_true);
    let raw = integrate(
        &w.time,
        &world_acceleration(&w.imu()).unwrap(),
        WorldVec::ZERO,
        WorldVec::ZERO,
    )
    .unwrap();
    let e_raw = max_position_error(&raw, &w.poses_true);
    assert!(e < 1.0, "live error {e} m over 60 s");
    assert!(e_raw > 50.0 * e, "raw {e_raw} m vs corrected {e} m");
    let st = tracker.stats();
    assert_eq!(st.corrections, 59);
    // Regressions at multiples of 50 once 200 frames are buffered: 200, 250, ..., 11_950.
    assert_eq!(st.regressions, 236);
}

#[test]
fn background_solver_gives_identical_results() {
    let w = walk(5000, 50, WorldVec::ZERO, true);
    let s = samples(&w);
    for delay in [0, 37] {
        let base = TrackerConfig {
            apply_delay: delay,
            ..Default::default()
        };
        let mut inline = Tracker::new(base, Truth::new(&w, 200)).unwrap();
        let mut bg = Tracker::new(
            TrackerConfig {
                background: true,
                ..base
            },
            Truth::new(&w, 200),
        )
        .unwrap();
        let (a, ea) = inline.push_all(&s);
        let (b, eb) = bg.push_all(&s);
        assert!(ea.is_none() && eb.is_none());
        assert_eq!(a, b, "delay {delay}");
        assert_eq!(inline.stats(), bg.stats());
        let submitted = a
            .iter()
            .filter(|u| u.correction == Some(CorrectionOutcome::Submitted))
            .count();
        assert_eq!(submitted, if delay == 0 { 0 } else { 24 });
    }
}

#[test]
fn memory_stays_flat() {
    let w = walk(2000, 50, WorldVec::ZERO, false);
    let s = samples(&w);
    let mut tracker = Tracker::new(TrackerConfig::default(), Truth::new(&w, 200)).unwrap();
    let mut peak = 0;
    for lap in 0..25u32 {
        for (i, x) in s.iter().enumerate() {
            // Replay the walk lap after lap on a continuous clock.
            let mut x = *x;
            x.time = (f64::from(lap) * 2000.0 + i as f64) * 0.005;
            tracker.push(&x).unwrap();
            peak = peak.max(tracker.buffered_frames());
        }
    }
    assert_eq!(tracker.stats().frames, 50_000);
    assert!(peak <= 2 * 1001, "peak {peak}");
}

#[test]
fn bad_samples_are_refused_without_harm() {
    let w = walk(600, 50, WorldVec::ZERO, false);
    let s = samples(&w);
    let mut tracker = Tracker::new(TrackerConfig::default(), Truth::new(&w, 200)).unwrap();
    let mut reference = Tracker::new(TrackerConfig::default(), Truth::new(&w, 200)).unwrap();
    for x in &s[..300] {
        tracker.push(x).unwrap();
        reference.push(x).unwrap();
    }
    let mut nan = s[300];
    nan.linacce = DeviceVec::new(0.0, f64::NAN, 0.0);
    assert_eq!(
        tracker.push(&nan),
        Err(TrackError::NonFinite { what: "linacce" })
    );
    let mut nan = s[300];
    nan.time = f64::INFINITY;
    assert_eq!(
        tracker.push(&nan),
        Err(TrackError::NonFinite { what: "time" })
    );
    assert!(matches!(
        tracker.push(&s[100]),
        Err(TrackError::TimeNotIncreasing { .. })
    ));
    let mut late = s[300];
    late.time += 4.4;
    assert!(matches!(tracker.push(&late), Err(TrackError::Gap { .. })));
    // Refused samples left no trace: the rest of the stream gives the same poses.
    for x in &s[300..] {
        assert_eq!(tracker.push(x).unwrap(), reference.push(x).unwrap());
    }

    // Recovery after a gap: an explicit restart holds the position.
    let before = tracker.pose(599).unwrap();
    tracker.restart().unwrap();
    // Even after a restart, time may not go backwards.
    assert!(matches!(
        tracker.push(&s[10]),
        Err(TrackError::TimeNotIncreasing { .. })
    ));
    let u = tracker.push(&late_sample(&s[0], 100.0)).unwrap();
    assert_eq!(u.pose.position, before.position);
    assert_eq!(u.pose.velocity, WorldVec::ZERO);
    assert_eq!(tracker.stats().restarts, 1);
}

fn late_sample(s: &ImuSample, dt: f64) -> ImuSample {
    ImuSample {
        time: s.time + dt,
        ..*s
    }
}

#[test]
fn gap_policy_restart_starts_a_new_segment() {
    let w = walk(1500, 50, WorldVec::ZERO, false);
    let mut s = samples(&w);
    for x in &mut s[700..] {
        x.time += 4.4;
    }
    let config = TrackerConfig {
        gap_policy: GapPolicy::Restart,
        keep_history: true,
        ..Default::default()
    };
    let mut tracker = Tracker::new(config, Truth::new(&w, 200)).unwrap();
    let (u, err) = tracker.push_all(&s);
    assert!(err.is_none());
    assert!(u[700].restarted);
    assert_eq!(u[700].pose.position, u[699].pose.position);
    assert_eq!(u[700].pose.velocity, WorldVec::ZERO);
    // RegressorOutput waits for a full window in the new segment: the first is at 700 + 200.
    assert!(u[900].regression.is_some() && u[850].regression.is_none());
    let segments = tracker.global_pass().unwrap();
    assert_eq!(segments.len(), 2);
    assert_eq!(segments[1].first_frame, 700);
    assert_eq!(
        segments[1].trajectory.poses[0].position,
        segments[0].trajectory.poses.last().unwrap().position
    );
}

#[test]
fn failing_regressions_are_reported_and_skipped() {
    let w = walk(2000, 50, WorldVec::ZERO, false);
    let mut reg = Truth::new(&w, 200);
    reg.fail_every = Some(3);
    let mut tracker = Tracker::new(TrackerConfig::default(), reg).unwrap();
    let (u, err) = tracker.push_all(&samples(&w));
    assert!(err.is_none());
    let failed = u
        .iter()
        .filter(|x| matches!(&x.regression, Some(RegressionOutcome::Failed(m)) if m == "model not loaded"))
        .count();
    assert!(failed > 0);
    let st = tracker.stats();
    assert_eq!(st.failed_regressions, failed as u64);
    assert!(st.corrections > 0);
    assert!(u.iter().all(|x| x.pose.position.is_finite()));

    // A regressor that answers NaN is treated as failing, not trusted.
    struct Nan;
    impl VelocityRegressor for Nan {
        fn window_len(&self) -> usize {
            10
        }
        fn regress(
            &mut self,
            _: &FrameWindow<'_>,
        ) -> Result<Option<RegressorOutput>, RegressorError> {
            Ok(Some(RegressorOutput {
                velocity: StabHorizontal::new(f64::NAN, 0.0),
                placement: None,
            }))
        }
    }
    let mut tracker = Tracker::new(TrackerConfig::default(), Nan).unwrap();
    let (u, _) = tracker.push_all(&samples(&w)[..500]);
    assert!(matches!(
        u[50].regression,
        Some(RegressionOutcome::Failed(_))
    ));
    assert_eq!(u[200].correction, Some(CorrectionOutcome::NoTargets));
    assert!(u.iter().all(|x| x.pose.position.is_finite()));
}

#[test]
fn global_pass_is_the_batch_solve() {
    let w = walk(3000, 50, WorldVec::ZERO, true);
    let config = TrackerConfig {
        keep_history: true,
        ..Default::default()
    };
    let mut tracker = Tracker::new(config, Truth::new(&w, 200)).unwrap();
    tracker.push_all(&samples(&w));
    let global = tracker.global_pass().unwrap();
    let targets: Vec<FrameVelocity> = (200..3000).step_by(50).map(|f| w.target(f)).collect();
    let batch = Corrector::new(CorrectionConfig::default())
        .unwrap()
        .correct(&w.imu(), &targets)
        .unwrap();
    assert_eq!(global.len(), 1);
    assert!(
        global[0].trajectory == batch,
        "global pass differs from the batch solve"
    );

    let plain = Tracker::new(TrackerConfig::default(), Truth::new(&w, 200)).unwrap();
    assert_eq!(plain.global_pass().unwrap_err(), TrackError::NoHistory);
}

#[test]
fn placement_filter_zeroes_velocities_around_flips() {
    let w = walk(3000, 50, WorldVec::ZERO, false);
    let run = |filter: Option<PlacementFilter>| {
        let mut reg = Truth::new(&w, 200);
        reg.flip_between = Some((1000, 1500));
        let config = TrackerConfig {
            placement_filter: filter,
            ..Default::default()
        };
        let mut tracker = Tracker::new(config, reg).unwrap();
        tracker.push_all(&samples(&w));
        tracker.stats().zeroed_targets
    };
    assert_eq!(run(None), 0);
    assert!(run(Some(PlacementFilter::default())) > 0);
}

#[test]
fn estimated_initial_velocity_in_the_stream() {
    let v0 = WorldVec::new(1.0, 0.5, 0.0);
    let w = walk(2000, 50, v0, false);
    let config = TrackerConfig {
        correction: CorrectionConfig {
            initial_velocity: InitialVelocity::Estimate,
            lambda: 1e-9,
            ..Default::default()
        },
        // More targets than unknowns: the start velocity is determined by the data.
        regress_every: 10,
        ..Default::default()
    };
    let mut tracker = Tracker::new(config, Truth::new(&w, 1)).unwrap();
    let s = samples(&w);
    let (u, _) = tracker.push_all(&s[..200]);
    // Until the first window is solved the tracker can only assume rest.
    assert_eq!(u[0].pose.velocity, WorldVec::ZERO);
    tracker.push(&s[200]).unwrap();
    let est = tracker.pose(0).unwrap().velocity;
    assert!((est - v0).norm() < 1e-5, "estimated {est:?}");
    tracker.push_all(&s[201..]);
    // Exact right after the last correction (frame 1800), then 200 frames on a held bias.
    let err =
        |f: usize| (tracker.pose(f as u64).unwrap().position - w.poses_true[f].position).norm();
    assert!(err(1800) < 1e-5, "{}", err(1800));
    assert!(err(1999) < 0.02, "{}", err(1999));
}

#[test]
fn invalid_configurations_are_refused() {
    let w = walk(10, 50, WorldVec::ZERO, false);
    for bad in [
        TrackerConfig {
            apply_delay: 200,
            ..Default::default()
        },
        TrackerConfig {
            regress_every: 0,
            ..Default::default()
        },
        TrackerConfig {
            window: 1,
            ..Default::default()
        },
        // Counts that would overflow what the tracker keeps for the placement filter.
        TrackerConfig {
            placement_filter: Some(PlacementFilter {
                radius: usize::MAX,
                max_changes: 0,
            }),
            ..Default::default()
        },
        TrackerConfig {
            regress_every: usize::MAX,
            ..Default::default()
        },
        TrackerConfig {
            correction: CorrectionConfig {
                lambda: -1.0,
                ..Default::default()
            },
            ..Default::default()
        },
    ] {
        assert!(Tracker::new(bad, Truth::new(&w, 1)).is_err());
    }
}
