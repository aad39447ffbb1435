//! End to end on the bundled sample: train, track (batch and online), evaluate.

use ridi::CascadeRegressor;
use ridi::correct::{PlacementSmoother, Tracker, TrackerConfig};
use ridi::data::{Listed, ReadOptions, Sequence};
use ridi::features::Orientation;
use ridi::frames::nalgebra::Vector3;
use ridi::frames::{DeviceVec, Rot, UpAxis};
use ridi::regress::{Cascade, NoProgress};
use ridi::{
    EvalOptions, GridChoice, LiveTracker, Method, PlacementMap, SensorReading, TrackOptions,
    TrainOptions, apply_orientation,
};
use ridi_test_support::sample_dataset;

fn load(list: &str) -> Vec<Sequence> {
    let mut seqs = Listed::read(&[sample_dataset().join(list)], &ReadOptions::default())
        .unwrap()
        .into_sequences();
    PlacementMap::tyrex4().apply(&mut seqs);
    seqs
}

/// A model on the recorded orientation (the tests below compare frames, S and streams with
/// the recorded ones; the estimated default has its own tests).
fn quick_model(seqs: &[Sequence]) -> ridi::regress::Cascade {
    let mut opts = TrainOptions::default();
    opts.cascade.regressors = GridChoice::None.regressors();
    opts.features.orientation = Orientation::Recorded;
    ridi::train(seqs, &opts, &mut NoProgress).unwrap()
}

/// The batch and the online track of `seq`, without placement smoothing (batch votes over a
/// centred window, streaming over the window before).
fn batch_and_online(seq: &Sequence, model: &ridi::regress::Cascade) -> (ridi::Track, ridi::Track) {
    let unsmoothed = TrackOptions {
        placement_smoothing: None,
        ..TrackOptions::default()
    };
    let batch = ridi::track(seq, model, &unsmoothed).unwrap();
    let online = ridi::track(
        seq,
        model,
        &TrackOptions {
            online: true,
            ..unsmoothed
        },
    )
    .unwrap();
    (batch, online)
}

#[test]
fn train_track_and_evaluate_on_the_sample_dataset() {
    let train = load("list_train.txt");
    let test = load("list_test.txt");
    // The held-out person on the training phone and on one the model never saw.
    assert_eq!((train.len(), test.len()), (16, 10));
    let devices = |seqs: &[Sequence]| -> Vec<String> {
        let mut d: Vec<String> = seqs
            .iter()
            .map(|s| s.device().map_or("-".into(), |d| d.model().to_string()))
            .collect();
        d.dedup();
        d
    };
    assert_eq!(devices(&train), ["Nexus 5"]);
    assert_eq!(devices(&test), ["Nexus 5", "iPhone 4S"]);
    // Each phone's list, as `ridi convert` writes them.
    let iphone = load("list_iphone4s.txt");
    assert_eq!(
        (iphone.len(), devices(&iphone)),
        (2, vec!["iPhone 4S".into()])
    );
    assert_eq!(load("list_nexus5.txt").len(), 24);
    let model = quick_model(&train);
    assert_eq!(
        model.placement_names(),
        ["hand", "pocket", "running", "swing"]
    );

    // The model file round-trips and keeps the feature configuration (with standardization).
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.ridi");
    model.save(&path).unwrap();
    let back = Cascade::load(&path).unwrap();
    assert_eq!(back, model);
    assert!(back.feature_config().standardization.is_some());

    let (report, traces) = ridi::evaluate(&test, &model, &EvalOptions::default()).unwrap();
    // The same figures, to the last bit, whatever order the sequences come in.
    let reversed: Vec<Sequence> = test.iter().rev().cloned().collect();
    let (again, _) = ridi::evaluate(&reversed, &model, &EvalOptions::default()).unwrap();
    assert_eq!(again.summary, report.summary);
    // `ridi inspect` names the model as the report records it.
    assert_eq!(
        ridi::inspect_model(&model).fingerprint,
        report.provenance.as_ref().unwrap().model_fingerprint
    );
    // A model of its own: no warning about the bundled model's training runs.
    assert!(
        !report
            .warnings
            .iter()
            .any(|w| w.contains("the bundled model was trained on")),
        "{:?}",
        report.warnings
    );
    // Cancelled before it starts: no sequence is evaluated, and the error says so.
    let cancel = std::sync::atomic::AtomicBool::new(true);
    let err =
        ridi::evaluate_cancellable(&test, &model, &EvalOptions::default(), &cancel).unwrap_err();
    assert!(
        matches!(err, ridi::PipelineError::Cancelled("evaluation")),
        "{err:?}"
    );
    assert_eq!(err.to_string(), "evaluation cancelled");
    assert_eq!(
        (&again.intervals, &again.ridi_minus),
        (&report.intervals, &report.ridi_minus)
    );
    assert_eq!(
        again.velocity_mse.map(f64::to_bits),
        report.velocity_mse.map(f64::to_bits)
    );
    assert_eq!(report.sequences.len(), 10);
    assert_eq!(traces.len(), 10);
    let ridi = report.summary["ridi"];
    let raw = report.summary["raw"];
    let still = report.summary["still"];
    // What the method is for: far better than double integration and than standing still on
    // short-window drift, with velocities of the right size.
    assert!(
        ridi.rte_5s_m < 0.5 * raw.rte_5s_m,
        "{ridi:?} vs raw {raw:?}"
    );
    assert!(
        ridi.rte_5s_m < still.rte_5s_m,
        "{ridi:?} vs still {still:?}"
    );
    let ratio = ridi.path_length_ratio.unwrap();
    assert!((0.5..1.5).contains(&ratio), "path length ratio {ratio}");
    assert!(
        report.velocity_mse.iter().all(|m| *m < 0.5),
        "{:?}",
        report.velocity_mse
    );
    assert!(report.placement_accuracy.unwrap() > 0.6);

    // Report files: the keys the issue names.
    let written = report.write(dir.path()).unwrap();
    assert_eq!(written.len(), 2);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("report.json")).unwrap())
            .unwrap();
    let seq = &json["sequences"][0];
    for key in [
        "name",
        "placement",
        "path_length_m",
        "alignment_extent_m",
        "placement_accuracy",
        "velocity_mse",
    ] {
        assert!(!seq[key].is_null(), "missing {key}");
    }
    assert_eq!(seq["velocity_mse"].as_array().unwrap().len(), 2);
    for m in Method::ALL {
        let metrics = &seq["methods"][m.key()];
        for key in [
            "mpe_m",
            "mpe_pct",
            "ate_m",
            "rte_m",
            "ate_ronin_m",
            "rte_ronin_m",
            "rte_5s_m",
            "path_length_ratio",
        ] {
            assert!(metrics.get(key).is_some(), "{} lacks {key}", m.key());
        }
        assert!(json["summary"][m.key()]["rte_5s_m"].is_number());
        // Every mean has its 95 % interval, and ridi its paired difference from the others.
        let i = &json["intervals"][m.key()]["rte_5s_m"];
        let (mean, low, high) = (i["mean"].as_f64(), i["low"].as_f64(), i["high"].as_f64());
        assert_eq!(mean, json["summary"][m.key()]["rte_5s_m"].as_f64());
        assert!(low <= mean && mean <= high, "{i}");
        if m.key() != "ridi" {
            assert!(json["ridi_minus"][m.key()]["rte_5s_m"]["mean"].is_number());
        }
    }
    let md = std::fs::read_to_string(dir.path().join("report.md")).unwrap();
    assert!(md.contains("## Per placement") && md.contains("| ridi |"));
    assert!(md.contains("| Nexus 5 | 8 |") && md.contains("| iPhone 4S | 2 |"));
    // Sequences whose ground truth hardly moves while the alignment is fitted are named, with
    // their travel, in the warning and only there.
    let warning = md
        .lines()
        .find(|l| l.starts_with("**Warning**: weakly determined alignment"))
        .unwrap_or("");
    for s in &report.sequences {
        let seq = test.iter().find(|q| q.name() == s.name).unwrap();
        let gt = seq.ground_truth().unwrap().horizontal();
        let frames = ridi::eval::AlignWindow::default()
            .frame_count(seq.time())
            .unwrap();
        assert_eq!(
            s.alignment_extent_m,
            ridi::eval::target_extent(&gt[..frames])
        );
        let named = warning.contains(&format!("{} ({:.2} m)", s.name, s.alignment_extent_m));
        assert_eq!(named, s.alignment_extent_m < 1.0, "{}: {warning}", s.name);
    }
    assert!(
        report.sequences.iter().any(|s| s.alignment_extent_m < 1.0),
        "the sample's test set has a run that starts standing"
    );

    // A gap the readers accept (0.2 s) but double integration does not: named where it is,
    // for batch and streaming tracks and for evaluation.
    let gappy = without_frames(&test[0], |i| (1000..1040).contains(&i));
    for online in [false, true] {
        let opts = TrackOptions {
            online,
            ..TrackOptions::default()
        };
        let err = ridi::track(&gappy, &model, &opts).unwrap_err().to_string();
        assert!(
            err.contains("a gap of 0.205 s between frames 999 and 1000")
                && err.contains(gappy.name()),
            "{err}"
        );
    }
    let err = ridi::evaluate(&[gappy], &model, &EvalOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("a gap of 0.205 s"), "{err}");
    // Every ninth frame dropped: each gap is short enough to track across, but the RTE
    // windows, counted in frames at 200 Hz, would not last 5 s and 1 min.
    let holey = without_frames(&test[0], |i| i % 9 == 4);
    let err = ridi::evaluate(&[holey], &model, &EvalOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(test[0].name())
            && err.contains("averages 177.8 Hz (dropped frames?)")
            && err.contains("ridi convert --rate 200"),
        "{err}"
    );

    // Plots of one sequence.
    #[cfg(feature = "plot")]
    {
        let files = traces[0].plot(dir.path(), "svg").unwrap();
        assert_eq!(files.len(), 2);
        assert!(
            std::fs::read_to_string(&files[0])
                .unwrap()
                .contains("ground truth")
        );
    }
}

#[test]
fn placement_smoothing_takes_the_window_majority_and_its_regressors() {
    let model = quick_model(&load("list_Guillaume.txt"));
    let test = load("list_Jakob.txt");
    let mut changed = 0;
    for seq in &test {
        let off = TrackOptions {
            placement_smoothing: None,
            ..TrackOptions::default()
        };
        let on = TrackOptions::default();
        let smoother = on.placement_smoothing.unwrap();
        let (raw, raw_p) = ridi::regress_sequence(seq, &model, &off).unwrap();
        let (smoothed, smoothed_p) = ridi::regress_sequence(seq, &model, &on).unwrap();
        let times: Vec<f64> = raw.iter().map(|r| seq.time()[r.frame]).collect();
        let want = smoother.smooth(&times, &raw_p, model.placement_names().len());
        assert_eq!(raw.len(), smoothed.len());
        assert_eq!((raw.len(), smoothed.len()), (raw_p.len(), smoothed_p.len()));
        assert_eq!(smoothed_p, want);
        for (i, (a, b)) in raw.iter().zip(&smoothed).enumerate() {
            assert_eq!(a.frame, b.frame);
            if raw_p[i] == smoothed_p[i] {
                assert_eq!(a.velocity, b.velocity);
            } else {
                changed += 1;
                assert_ne!(a.velocity, b.velocity);
            }
        }
        // Fewer label changes than before.
        let flips = |p: &[usize]| p.windows(2).filter(|w| w[0] != w[1]).count();
        assert!(flips(&smoothed_p) <= flips(&raw_p), "{}", seq.name());
    }
    // A model of one person mislabels some windows of another: the test must exercise that.
    assert!(changed > 0);
    // A window set through the public field is checked, batch and streaming, before the work.
    for online in [false, true] {
        let bad = TrackOptions {
            online,
            placement_smoothing: Some(PlacementSmoother { window_s: -1.0 }),
            ..TrackOptions::default()
        };
        let e = ridi::track(&test[0], &model, &bad).unwrap_err().to_string();
        assert!(e.contains("window_s must be finite and positive"), "{e}");
    }
}

#[test]
fn online_smoothing_takes_the_majority_of_the_labels_before() {
    let model = quick_model(&load("list_Guillaume.txt"));
    let seq = &load("list_Jakob.txt")[6]; // Swinging: many scattered labels
    let online = |smoothing| TrackOptions {
        online: true,
        placement_smoothing: smoothing,
        ..TrackOptions::default()
    };
    let smoother = TrackOptions::default().placement_smoothing.unwrap();
    let raw = ridi::track(seq, &model, &online(None)).unwrap();
    let smoothed = ridi::track(seq, &model, &online(Some(smoother))).unwrap();
    let mut live = smoother.trailing(model.placement_names().len());
    let mut changed = 0;
    assert_eq!(raw.regressions.len(), smoothed.regressions.len());
    assert_eq!(raw.placements.len(), smoothed.placements.len());
    for (i, (a, b)) in raw
        .regressions
        .iter()
        .zip(&smoothed.regressions)
        .enumerate()
    {
        let (pa, pb) = (raw.placements[i], smoothed.placements[i]);
        assert_eq!(a.frame, b.frame);
        assert_eq!(pb, live.push(seq.time()[a.frame], pa));
        if pa == pb {
            assert_eq!(a.velocity, b.velocity);
        } else {
            changed += 1;
        }
    }
    assert!(changed > 0, "the test needs scattered labels");
}

#[test]
fn online_tracking_stays_close_to_batch_tracking() {
    let train = load("list_Guillaume.txt");
    let model = quick_model(&train);
    let seq = &load("list_Jakob.txt")[7]; // Texting
    let (batch, online) = batch_and_online(seq, &model);
    assert_eq!(batch.time.len(), seq.len());
    assert_eq!(online.time.len(), seq.len());
    // Both regress at the same frames with the same features (batched GEMM and single-query
    // kernels differ in f32 rounding only).
    assert_eq!(batch.regressions.len(), online.regressions.len());
    for (a, b) in batch.regressions.iter().zip(&online.regressions) {
        assert_eq!(a.frame, b.frame);
        assert!((a.velocity[0] - b.velocity[0]).abs() < 1e-3, "{a:?} {b:?}");
    }
    assert_eq!(batch.placements, online.placements);
    // The live trajectory differs from the global solve, but not wildly over 24 s.
    let end = seq.len() - 1;
    let gap = (batch.position[end] - online.position[end]).norm();
    assert!(gap < 5.0, "online ends {gap} m from batch");
    assert!(online.position.iter().all(|p| p.is_finite()));

    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("t.csv");
    batch.write_csv(&csv).unwrap();
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("time,pos_x,pos_y,pos_z,vel_x,vel_y,vel_z,placement,bias_x"));
    assert_eq!(text.lines().count(), seq.len() + 1);
    // Tiny biases come out in exponent notation, not as hundreds of digits, and read back.
    let mut tiny = batch.clone();
    tiny.bias[0] = ridi::frames::DeviceVec::new(1.28e-300, -5e-20, 0.0);
    tiny.write_csv(&csv).unwrap();
    let text = std::fs::read_to_string(&csv).unwrap();
    let first = text.lines().nth(1).unwrap();
    assert!(first.ends_with(",1.28e-300,-5e-20,0"), "{first}");
    let longest = text.split([',', '\n']).map(str::len).max().unwrap();
    assert!(longest < 30, "a field of {longest} characters");
    // A track put together with lengths that do not match is refused; the file is kept.
    let mut short = batch.clone();
    short.position.pop();
    let e = format!("{:#}", short.write_csv(&csv).unwrap_err());
    assert!(
        e.contains(&format!("positions for {} timestamps", seq.len())),
        "{e}"
    );
    let mut unlabelled = batch.clone();
    unlabelled.placements.clear();
    assert!(unlabelled.write_csv(&csv).is_err());
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), text);
}

#[test]
fn training_without_labels_or_ground_truth_names_the_sequence() {
    let mut seqs = load("list_Thibaud.txt");
    seqs[2].set_placement(None);
    let name = seqs[2].name().to_string();
    let err = ridi::train(&seqs, &TrainOptions::default(), &mut NoProgress)
        .unwrap_err()
        .to_string();
    assert!(err.contains(&name) && err.contains("placement"), "{err}");

    // A sequence too short for one window gives a clear error, not a panic.
    let short: Vec<Sequence> = load("list_Thibaud.txt")
        .iter()
        .map(|s| s.slice(0..150))
        .collect();
    let err = ridi::train(&short, &TrainOptions::default(), &mut NoProgress)
        .unwrap_err()
        .to_string();
    assert!(err.contains("window"), "{err}");

    // A renamed copy of a recording is the recording: refused by training and evaluation, as
    // a list refuses it, naming the copy and the index of the original.
    let mut seqs = load("list_Thibaud.txt");
    let mut copy = seqs[1].clone();
    copy.set_name("renamed");
    seqs.push(copy);
    let expected = format!(
        "sequence `renamed`: is the same recording as sequence 1, `{}`",
        seqs[1].name()
    );
    let err = ridi::train(&seqs, &TrainOptions::default(), &mut NoProgress)
        .unwrap_err()
        .to_string();
    assert!(err.starts_with(&expected), "{err}");
    let model = quick_model(&load("list_Guillaume.txt"));
    let err = ridi::evaluate(&seqs, &model, &ridi::EvalOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.starts_with(&expected), "{err}");
}

#[test]
fn turned_copies_repeat_labels_and_groups_and_keep_speeds() {
    let seqs = load("list_train.txt");
    let config = ridi::features::FeatureConfig::default();
    let data = ridi::training_data(&seqs[..3], &config).unwrap();
    let n = data.targets.len();
    let turned = data.clone().with_turned_copies(2).unwrap();
    assert_eq!(turned.features.rows(), 3 * n);
    assert_eq!(turned.placement_names, data.placement_names);
    for copy in 0..3 {
        let part = copy * n..(copy + 1) * n;
        assert_eq!(turned.placements[part.clone()], data.placements[..]);
        assert_eq!(turned.groups[part.clone()], data.groups[..]);
        for (a, b) in turned.targets[part].iter().zip(&data.targets) {
            assert!((a[0].hypot(a[1]) - b[0].hypot(b[1])).abs() < 1e-5);
        }
    }
    // The copies are turned: the horizontal components change, the vertical (S-y) do not.
    let (orig, copy) = (data.features.row(5), turned.features.row(n + 5));
    assert!(
        orig.iter()
            .zip(copy)
            .step_by(3)
            .any(|(a, b)| (a - b).abs() > 1e-3)
    );
    assert!(
        orig.iter()
            .zip(copy)
            .skip(1)
            .step_by(3)
            .all(|(a, b)| a == b)
    );
    assert_eq!(data.clone().with_turned_copies(0).unwrap(), data);
}

#[test]
fn a_phone_carried_top_down_is_tracked_like_the_upright_one() {
    // The default model builds S on device -y while the phone is upside down. Turning a
    // recording top down about the screen normal (device x and y negated, orientation turned
    // with them) must then change neither regressions nor the track, batch or streaming.
    let model = quick_model(&load("list_Guillaume.txt"));
    assert_eq!(model.feature_config().up_axis, UpAxis::PlusOrMinusY);
    let upright = load("list_Jakob.txt").swap_remove(1);
    assert_eq!(upright.name(), "Jakob_Nexus5_NoDist_BackPocket");
    let turn = |v: &Vec<DeviceVec>| -> Vec<DeviceVec> {
        v.iter()
            .map(|v| DeviceVec::new(-v.x(), -v.y(), v.z()))
            .collect()
    };
    let half_turn = Rot::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI);
    let mut parts = upright.parts().clone();
    parts.gyro = turn(&parts.gyro);
    parts.acce = turn(&parts.acce);
    parts.linacce = turn(&parts.linacce);
    parts.gravity = turn(&parts.gravity);
    parts.magnet = parts.magnet.as_ref().map(turn);
    for q in &mut parts.orientation {
        *q = *q * half_turn;
    }
    let top_down = Sequence::new(parts).unwrap();
    assert!(
        top_down
            .gravity()
            .iter()
            .all(|g| g.y() < UpAxis::FLIP_COSINE * g.norm())
    );
    // PDR's heading too.
    let (a, b) = (
        ridi::device_heading(&upright),
        ridi::device_heading(&top_down),
    );
    for (x, y) in a.iter().zip(&b) {
        let d =
            (x - y + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        assert!(d.abs() < 1e-9, "heading {x} vs {y}");
    }
    for online in [false, true] {
        let opts = TrackOptions {
            online,
            ..TrackOptions::default()
        };
        let a = ridi::track(&upright, &model, &opts).unwrap();
        let b = ridi::track(&top_down, &model, &opts).unwrap();
        assert_eq!(a.placements, b.placements, "online {online}");
        for (x, y) in a.regressions.iter().zip(&b.regressions) {
            let d = (x.velocity[0] - y.velocity[0]).hypot(x.velocity[1] - y.velocity[1]);
            assert!(d < 1e-3, "online {online}: {x:?} vs {y:?}");
        }
        let gap = a
            .position
            .iter()
            .zip(&b.position)
            .map(|(p, q)| (*p - *q).norm())
            .fold(0.0, f64::max);
        assert!(gap < 0.01, "online {online}: tracks {gap} m apart");
    }
}

#[test]
fn a_model_tracks_in_the_orientation_it_was_trained_with() {
    let train = load("list_Guillaume.txt");
    let mut opts = TrainOptions::default();
    opts.cascade.regressors = GridChoice::None.regressors();
    opts.features.orientation = Orientation::Estimated;
    let model = ridi::train(&train, &opts, &mut NoProgress).unwrap();
    assert_eq!(model.feature_config().orientation, Orientation::Estimated);
    // A recorded sequence is tracked with the estimate swapped in, exactly as one whose
    // orientation was estimated before.
    let seq = load("list_Jakob.txt").swap_remove(7);
    let mut pre = vec![seq.clone()];
    apply_orientation(
        Orientation::Estimated,
        TrackOptions::default().recorded_heading.as_ref(),
        &mut pre,
    )
    .unwrap();
    let a = ridi::track(&seq, &model, &TrackOptions::default()).unwrap();
    let b = ridi::track(&pre[0], &model, &TrackOptions::default()).unwrap();
    assert_eq!(a.position, b.position);
    // Online, the live tracker estimates the orientation on the stream: the same poses as the
    // streaming tracker fed the batch estimate.
    let online = TrackOptions {
        online: true,
        ..TrackOptions::default()
    };
    let a = ridi::track(&seq, &model, &online).unwrap();
    let config = TrackerConfig {
        correction: online.correction_for(&model),
        regress_every: online.regress_every,
        ..TrackerConfig::default()
    };
    // The regressor knows its model's S: a correction set up for the paper's (the tracker's
    // default) is refused rather than fed velocities in another frame.
    let regressor = CascadeRegressor::new(&model, online.placement_smoothing).unwrap();
    let err = Tracker::new(TrackerConfig::default(), regressor).unwrap_err();
    assert!(
        err.to_string().contains("another stabilized frame"),
        "{err}"
    );
    let regressor = CascadeRegressor::new(&model, online.placement_smoothing).unwrap();
    let mut tracker = Tracker::new(config, regressor).unwrap();
    let e = &pre[0];
    for i in 0..e.len() {
        let u = tracker.push(&e.imu().sample(i)).unwrap();
        assert_eq!(u.pose.position, a.position[i], "frame {i}");
        assert_eq!(u.bias, a.bias[i], "frame {i}");
    }
    assert_eq!(
        tracker.regressor().made(),
        (a.regressions.as_slice(), a.placements.as_slice())
    );
    // The sequence estimated before streams with its own orientation: the same poses again.
    let b = ridi::track(&pre[0], &model, &online).unwrap();
    assert_eq!(a.position, b.position);
    // The heading correction turns the track, not the features: the same regressions.
    let gyro = TrackOptions {
        recorded_heading: None,
        ..TrackOptions::default()
    };
    assert_eq!(
        ridi::regress_sequence(&seq, &model, &gyro).unwrap(),
        ridi::regress_sequence(&seq, &model, &TrackOptions::default()).unwrap()
    );
    let (report, _) = ridi::evaluate(&pre, &model, &EvalOptions::default()).unwrap();
    assert!(report.summary["ridi"].rte_5s_m.is_finite());
    // Recorded training options on an estimated sequence: an error naming it.
    let mut recorded = TrainOptions::default();
    recorded.features.orientation = Orientation::Recorded;
    let err = ridi::train(&pre, &recorded, &mut NoProgress)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(seq.name()) && err.contains("recorded"),
        "{err}"
    );
}

#[test]
fn a_live_stream_gets_its_poses_sample_by_sample_dataset() {
    let seq = load("list_Jakob.txt").swap_remove(7);
    let sample = |i: usize, recorded: bool| SensorReading {
        recorded: SensorReading::of_frame(&seq, i)
            .recorded
            .filter(|_| recorded),
        ..SensorReading::of_frame(&seq, i)
    };
    let opts = TrackOptions {
        online: true,
        ..TrackOptions::default()
    };
    let train = load("list_Guillaume.txt");

    // Recorded orientation: one update per sample, the poses of `ridi track --online`; a
    // sample without the recorded orientation is refused, naming what is missing.
    let model = quick_model(&train);
    let whole = ridi::track(&seq, &model, &opts).unwrap();
    let mut live = LiveTracker::new(&model, &opts).unwrap();
    let mut updates = Vec::new();
    let err = live
        .push(&sample(0, false), &mut updates)
        .unwrap_err()
        .to_string();
    assert!(err.contains("recorded orientation"), "{err}");
    for i in 0..seq.len() {
        updates.clear();
        live.push(&sample(i, true), &mut updates).unwrap();
        assert_eq!(updates.len(), 1);
        assert_eq!(updates[0].pose.position, whole.position[i]);
    }
    updates.clear();
    live.finish(&mut updates).unwrap();
    assert!(updates.is_empty());
    assert_eq!(
        live.regressions(),
        (whole.regressions.as_slice(), whole.placements.as_slice())
    );

    // Estimated orientation: the frames of the settling pass wait for the initial tilt, then
    // the stream gives one pose per sample; refused samples (time going back, NaN) change
    // nothing.
    let settle = ridi::frames::FilterConfig::default().settle_time;
    let held = seq
        .time()
        .iter()
        .position(|&t| t - seq.time()[0] >= settle)
        .unwrap();
    assert!(
        held < 500,
        "the refused samples below come after the release"
    );
    let mut opts_est = TrainOptions::default();
    opts_est.cascade.regressors = GridChoice::None.regressors();
    opts_est.features.orientation = Orientation::Estimated;
    let model = ridi::train(&train, &opts_est, &mut NoProgress).unwrap();
    let whole = ridi::track(&seq, &model, &opts).unwrap();
    let mut live = LiveTracker::new(&model, &opts).unwrap();
    let mut positions = Vec::new();
    let mut updates = Vec::new();
    for i in 0..seq.len() {
        if i == 500 {
            let mut back = sample(i, false);
            back.time = seq.time()[i - 1];
            let err = live.push(&back, &mut updates).unwrap_err().to_string();
            assert!(err.contains("not after"), "{err}");
            let mut nan = sample(i, false);
            nan.gyro = DeviceVec::new(f64::NAN, 0.0, 0.0);
            let err = live.push(&nan, &mut updates).unwrap_err().to_string();
            assert!(err.contains("`gyro.x` of sample 500 is NaN"), "{err}");
            nan.gyro = sample(i, false).gyro;
            nan.time = f64::NAN;
            let err = live.push(&nan, &mut updates).unwrap_err().to_string();
            assert!(err.contains("`time` of sample 500 is NaN"), "{err}");
            let mut mm = sample(i, false);
            mm.acce = mm.acce * 1000.0;
            let err = live.push(&mm, &mut updates).unwrap_err().to_string();
            assert!(
                err.contains("`acce.z` at frame 500")
                    && err.contains("beyond any phone accelerometer"),
                "{err}"
            );
        }
        updates.clear();
        live.push(&sample(i, true), &mut updates).unwrap();
        let expected = match i {
            _ if i < held => 0,
            _ if i == held => held + 1,
            _ => 1,
        };
        assert_eq!(updates.len(), expected, "sample {i}");
        positions.extend(updates.iter().map(|u| u.pose.position));
    }
    assert_eq!(positions, whole.position);
    // A dropped second: a new segment from the position reached, nothing integrated across.
    let mut late = sample(seq.len() - 1, false);
    late.time += 1.0;
    updates.clear();
    live.push(&late, &mut updates).unwrap();
    assert!(updates[0].restarted);
    assert_eq!(updates[0].pose.position, *whole.position.last().unwrap());
    updates.clear();
    live.finish(&mut updates).unwrap();
    assert!(updates.is_empty());
    // A finished stream takes no more samples.
    late.time += 0.005;
    let err = live.push(&late, &mut updates).unwrap_err().to_string();
    assert!(err.contains("finished"), "{err}");
    // Without the recorded orientation the heading stays the gyro's: the poses of tracking
    // without `recorded_heading`, which differ.
    let gyro_heading = TrackOptions {
        recorded_heading: None,
        ..opts
    };
    let whole_gyro = ridi::track(&seq, &model, &gyro_heading).unwrap();
    assert_ne!(whole_gyro.position, whole.position);
    let mut bare = LiveTracker::new(&model, &opts).unwrap();
    let mut bare_positions = Vec::new();
    for i in 0..seq.len() {
        updates.clear();
        bare.push(&sample(i, false), &mut updates).unwrap();
        bare_positions.extend(updates.iter().map(|u| u.pose.position));
    }
    updates.clear();
    bare.finish(&mut updates).unwrap();
    assert_eq!(bare_positions, whole_gyro.position);

    // A stream shorter than the initial tilt needs comes out at the end.
    let mut live = LiveTracker::new(&model, &opts).unwrap();
    updates.clear();
    for i in 0..10 {
        live.push(&sample(i, false), &mut updates).unwrap();
    }
    assert!(updates.is_empty());
    live.finish(&mut updates).unwrap();
    assert_eq!(updates.len(), 10);
    assert!(updates.iter().all(|u| u.pose.position.is_finite()));
}

/// A stream at another rate, with time in milliseconds, a gyro in deg/s or an accelerometer in
/// g is refused by the time its first velocity would be regressed, by what is wrong; the
/// samples refused count towards the stream's last second, so a stream that comes right is
/// taken again, in a new segment.
#[test]
fn a_live_stream_at_a_wrong_rate_or_unit_is_refused_by_its_first_window() {
    let seq = load("list_Jakob.txt").swap_remove(7);
    let model = quick_model(&load("list_Guillaume.txt"));
    let opts = TrackOptions::default();
    // Pushes frames 0.. of `seq`, each changed by `edit`, until one is refused: its index and
    // the error.
    let first_refused = |live: &mut LiveTracker, edit: &dyn Fn(usize, &mut SensorReading)| {
        let mut updates = Vec::new();
        for i in 0..seq.len() {
            let mut s = SensorReading::of_frame(&seq, i);
            edit(i, &mut s);
            if let Err(e) = live.push(&s, &mut updates) {
                return (i, e.to_string());
            }
        }
        panic!("no sample refused");
    };
    let t0 = seq.time()[0];
    type Edit<'a> = &'a dyn Fn(usize, &mut SensorReading);
    fn recorded(s: &mut SensorReading) -> &mut ridi::Recorded {
        s.recorded.as_mut().unwrap()
    }
    let cases: [(Edit, &[&str]); 7] = [
        // 100 Hz: the frames' times stretched twofold.
        (
            &|i, s| s.time = t0 + 2.0 * (seq.time()[i] - t0),
            &["100.0 Hz", "resample"],
        ),
        (
            &|_, s| s.time *= 1000.0,
            &["milliseconds instead of seconds"],
        ),
        (
            &|_, s| s.gyro = DeviceVec::new(0.3, -0.2, 0.1) * (180.0 / std::f64::consts::PI),
            &["deg/s instead of rad/s"],
        ),
        (
            &|_, s| s.acce = s.acce / ridi::frames::STANDARD_GRAVITY,
            &["g instead of m/s^2"],
        ),
        // The recorded orientation, gravity and linear acceleration disagreeing as the
        // sequence's own checks would find: gravity negated, in g, not taken out of the
        // linear acceleration.
        (
            &|_, s| recorded(s).gravity = recorded(s).gravity * -1.0,
            &["gravity is 180 degrees from the up axis"],
        ),
        (
            &|_, s| recorded(s).gravity = recorded(s).gravity / ridi::frames::STANDARD_GRAVITY,
            &["median |gravity| 1", "gravity in g instead of m/s^2"],
        ),
        (
            &|_, s| recorded(s).linacce = s.acce,
            &[
                "accelerometer minus gravity is -0.0",
                "times the linear acceleration",
            ],
        ),
    ];
    for (edit, words) in cases {
        let mut live = LiveTracker::new(&model, &opts).unwrap();
        let (i, err) = first_refused(&mut live, edit);
        assert_eq!(i, ridi::STREAM_CHECK_SAMPLES, "{err}");
        assert!(live.regressions().0.is_empty());
        assert!(err.contains("last 200 samples"), "{err}");
        for w in words {
            assert!(err.contains(w), "{w}: {err}");
        }
    }

    // A gyro with its sign flipped turns against the recorded orientation pushed with it:
    // refused once the stream is STREAM_GYRO_CHECK_S long, and from then on; the stream as
    // recorded is not.
    let mut live = LiveTracker::new(&model, &opts).unwrap();
    let (i, err) = first_refused(&mut live, &|_, s| s.gyro = s.gyro * -1.0);
    assert!(
        (seq.time()[i] - t0 - ridi::STREAM_GYRO_CHECK_S).abs() < 0.01,
        "{i}: {err}"
    );
    assert!(
        err.contains("the stream's 10")
            && err.contains("with a recorded orientation: the gyro")
            && err.contains("sign flipped"),
        "{err}"
    );
    let mut updates = Vec::new();
    let flipped = |i| {
        let mut s = SensorReading::of_frame(&seq, i);
        s.gyro = s.gyro * -1.0;
        s
    };
    assert!(live.push(&flipped(i + 1), &mut updates).is_err());
    // Stays so, also through the rest of the recording as recorded and the whole of it again,
    // which take the agreement over the whole stream back above 0 (the fit the check keeps,
    // made here apart).
    let again = seq.time()[seq.len() - 1] - t0 + 0.005;
    let passes = (i + 2..seq.len()).map(|j| (j, 0.0));
    for (j, shift) in passes.chain((0..seq.len()).map(|j| (j, again))) {
        let mut s = SensorReading::of_frame(&seq, j);
        s.time += shift;
        let e = live.push(&s, &mut updates).unwrap_err().to_string();
        assert_eq!(e, err, "sample {j} + {shift} s");
    }
    let mut gyro: Vec<DeviceVec> = seq.gyro().to_vec();
    for g in &mut gyro[..=i + 1] {
        *g = *g * -1.0;
    }
    let mut fit = ridi::data::GyroFit::default();
    fit.add_steps(seq.time(), &gyro, seq.orientation());
    fit.add_steps(seq.time(), seq.gyro(), seq.orientation());
    assert!(fit.agreement().unwrap() > 0.0, "{:?}", fit.agreement());
    let mut live = LiveTracker::new(&model, &opts).unwrap();
    for i in 0..seq.len() {
        live.push(&SensorReading::of_frame(&seq, i), &mut updates)
            .unwrap();
    }
    // A phone lying still after 2 s of walking: accelerometer and gravity equal, the linear
    // acceleration zero, exactly; no scale to judge (the walk's sums leave no residue).
    let mut live = LiveTracker::new(&model, &opts).unwrap();
    for i in 0..1000 {
        let mut s = SensorReading::of_frame(&seq, i);
        if i >= 400 {
            let r = recorded(&mut s);
            r.linacce = DeviceVec::ZERO;
            s.acce = r.gravity;
        }
        live.push(&s, &mut updates).unwrap();
    }
    // A non-finite recorded linear acceleration or gravity is refused on its own sample, by
    // name, and the stream goes on.
    let mut live = LiveTracker::new(&model, &opts).unwrap();
    for i in 0..600 {
        let mut s = SensorReading::of_frame(&seq, i);
        if i == 300 {
            recorded(&mut s).linacce = DeviceVec::new(f64::NAN, 0.0, 0.0);
            let e = live.push(&s, &mut updates).unwrap_err().to_string();
            assert!(e.contains("`linacce.x` of sample 300 is NaN"), "{e}");
            recorded(&mut s).linacce = DeviceVec::ZERO;
            recorded(&mut s).gravity = DeviceVec::new(0.0, f64::INFINITY, 0.0);
            let e = live.push(&s, &mut updates).unwrap_err().to_string();
            assert!(e.contains("`gravity.y` of sample 300 is inf"), "{e}");
            continue;
        }
        live.push(&s, &mut updates).unwrap();
    }

    // Two seconds at 100 Hz (frames 0-399 stretched twofold), then 200 Hz again: refused
    // until most of the last second is right (at most 101 samples later), then taken in a new
    // segment; a refused sample given again is refused again.
    let mut live = LiveTracker::new(&model, &opts).unwrap();
    let mut updates = Vec::new();
    let (mut refused, mut taken) = (0, 0);
    for i in 0..1000 {
        // Frames 0-399 at 100 Hz (stretched), the rest at 200 Hz after them.
        let mut s = SensorReading::of_frame(&seq, i);
        s.time = t0
            + if i < 400 {
                2.0 * (seq.time()[i] - t0)
            } else {
                seq.time()[i] - seq.time()[400] + 2.0 * (seq.time()[400] - t0)
            };
        updates.clear();
        match live.push(&s, &mut updates) {
            Err(e) => {
                refused += 1;
                let again = live.push(&s, &mut updates).unwrap_err().to_string();
                assert_eq!(again, e.to_string());
            }
            Ok(()) if refused > 0 && taken == 0 => {
                taken += 1;
                assert!(i > 400 && i <= 400 + 101, "sample {i}");
                assert!(updates[0].restarted, "sample {i}");
            }
            Ok(()) => {}
        }
    }
    assert!(refused > 0 && taken == 1, "{refused} refused");
}

/// Every other frame: the same walk recorded at half the rate.
fn every_other_frame(seq: &Sequence) -> Sequence {
    fn keep<T: Clone>(v: &[T]) -> Vec<T> {
        v.iter().step_by(2).cloned().collect()
    }
    let mut p = seq.parts().clone();
    p.time = keep(&p.time);
    p.gyro = keep(&p.gyro);
    p.acce = keep(&p.acce);
    p.linacce = keep(&p.linacce);
    p.gravity = keep(&p.gravity);
    p.magnet = p.magnet.as_deref().map(keep);
    p.orientation = keep(&p.orientation);
    if let Some(gt) = &mut p.ground_truth {
        gt.position = keep(&gt.position);
        gt.orientation = keep(&gt.orientation);
    }
    Sequence::new(p).unwrap()
}

#[test]
fn another_rate_or_less_than_a_window_is_refused_by_name() {
    let model = quick_model(&load("list_Guillaume.txt"));
    let seq = load("list_Thibaud.txt").remove(0);
    let name = seq.name().to_string();
    let opts = TrackOptions::default();
    let eval = EvalOptions::default();

    // 200 frames: not one frame has a whole window before it.
    let short = seq.slice(0..200);
    let err = ridi::track(&short, &model, &opts).unwrap_err().to_string();
    assert!(
        err.contains(&name) && err.contains("has 200 frames") && err.contains("feature window"),
        "{err}"
    );
    let err = ridi::evaluate(std::slice::from_ref(&short), &model, &eval)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(&name) && err.contains("has 200 frames"),
        "{err}"
    );
    let online = TrackOptions {
        online: true,
        ..opts
    };
    let err = ridi::track(&short, &model, &online)
        .unwrap_err()
        .to_string();
    assert!(err.contains("has 200 frames"), "{err}");
    assert!(ridi::track(&seq.slice(0..201), &model, &opts).is_ok());

    // Phones differ by a few percent: 190 and 210 Hz pass, 179 and 221 Hz do not.
    let at_rate = |hz: f64| {
        let mut p = seq.parts().clone();
        let t0 = p.time[0];
        for t in &mut p.time {
            *t = t0 + (*t - t0) * 200.0 / hz;
        }
        Sequence::new(p).unwrap()
    };
    for hz in [190.0, 210.0] {
        assert!(ridi::track(&at_rate(hz), &model, &opts).is_ok(), "{hz} Hz");
    }
    for hz in [179.0, 221.0] {
        let err = ridi::track(&at_rate(hz), &model, &opts)
            .unwrap_err()
            .to_string();
        assert!(err.contains(&format!("{hz:.1} Hz")), "{err}");
    }

    // Gaps do not lower the rate: a 200 Hz recording with 0.9 s gaps trains, and tracking
    // names the gap, which the correction cannot integrate across.
    let keep: Vec<usize> = (0..seq.len()).filter(|i| i % 800 >= 180).collect();
    fn pick<T: Copy>(v: &[T], keep: &[usize]) -> Vec<T> {
        keep.iter().map(|&i| v[i]).collect()
    }
    let mut p = seq.parts().clone();
    p.time = pick(&p.time, &keep);
    p.gyro = pick(&p.gyro, &keep);
    p.acce = pick(&p.acce, &keep);
    p.linacce = pick(&p.linacce, &keep);
    p.gravity = pick(&p.gravity, &keep);
    p.orientation = pick(&p.orientation, &keep);
    p.magnet = p.magnet.as_deref().map(|m| pick(m, &keep));
    if let Some(gt) = &mut p.ground_truth {
        gt.position = pick(&gt.position, &keep);
        gt.orientation = pick(&gt.orientation, &keep);
    }
    let gappy = Sequence::new(p).unwrap();
    assert!(gappy.rate_hz() < 170.0 && (gappy.median_rate_hz() - 200.0).abs() < 0.1);
    let features = TrainOptions::default().features;
    assert!(ridi::training_data(std::slice::from_ref(&gappy), &features).is_ok());
    let err = ridi::track(&gappy, &model, &opts).unwrap_err().to_string();
    assert!(err.contains("a gap of 0.905 s"), "{err}");

    // 100 Hz: each 200-frame window would be two seconds long.
    let half = every_other_frame(&seq);
    assert!((half.rate_hz() - 100.0).abs() < 0.1, "{}", half.rate_hz());
    for err in [
        ridi::track(&half, &model, &opts).unwrap_err().to_string(),
        ridi::evaluate(std::slice::from_ref(&half), &model, &eval)
            .unwrap_err()
            .to_string(),
        ridi::train(
            std::slice::from_ref(&half),
            &TrainOptions::default(),
            &mut NoProgress,
        )
        .unwrap_err()
        .to_string(),
    ] {
        assert!(
            err.contains(&name) && err.contains("100.0 Hz") && err.contains("resample"),
            "{err}"
        );
    }
}

/// A model trained with another feature window than the paper's regresses from that window
/// on, batch and online alike, and a recording is judged by its window.
#[test]
fn a_shorter_feature_window_is_the_models_own() {
    let mut opts = TrainOptions::default();
    opts.cascade.regressors = GridChoice::None.regressors();
    opts.features.window = 100;
    let model = ridi::train(&load("list_Guillaume.txt"), &opts, &mut NoProgress).unwrap();
    assert_eq!(model.feature_config().window, 100);
    assert_eq!(model.dim(), 600);
    let seq = &load("list_Jakob.txt")[7];
    let (batch, online) = batch_and_online(seq, &model);
    // The first regression has the 100 frames before it, then one every 50 frames.
    assert_eq!(batch.regressions[0].frame, 100);
    assert_eq!(batch.regressions[1].frame, 150);
    assert_eq!(batch.regressions.len(), online.regressions.len());
    assert_eq!(batch.placements, online.placements);
    for (a, b) in batch.regressions.iter().zip(&online.regressions) {
        assert_eq!(a.frame, b.frame);
        assert!((a.velocity[1] - b.velocity[1]).abs() < 1e-3, "{a:?} {b:?}");
    }
    // 150 frames: too short for the paper's window, enough for this one.
    let opts = TrackOptions::default();
    assert!(ridi::track(&seq.slice(0..150), &model, &opts).is_ok());
    let err = ridi::track(&seq.slice(0..100), &model, &opts)
        .unwrap_err()
        .to_string();
    assert!(err.contains("feature window of 100 frames"), "{err}");
}

/// `seq` without the frames `drop` picks, in every per-frame stream.
fn without_frames(seq: &Sequence, drop: impl Fn(usize) -> bool) -> Sequence {
    fn keep<T>(v: &mut Vec<T>, drop: &dyn Fn(usize) -> bool) {
        let mut i = 0;
        v.retain(|_| {
            i += 1;
            !drop(i - 1)
        });
    }
    let mut parts = seq.clone().into_parts();
    keep(&mut parts.time, &drop);
    keep(&mut parts.gyro, &drop);
    keep(&mut parts.acce, &drop);
    keep(&mut parts.linacce, &drop);
    keep(&mut parts.gravity, &drop);
    keep(&mut parts.orientation, &drop);
    if let Some(m) = parts.magnet.as_mut() {
        keep(m, &drop);
    }
    if let Some(gt) = parts.ground_truth.as_mut() {
        keep(&mut gt.position, &drop);
        keep(&mut gt.orientation, &drop);
    }
    if let Some(steps) = parts.steps.as_mut() {
        keep(steps, &drop);
    }
    Sequence::new(parts).unwrap()
}

#[test]
fn training_windows_counts_the_rows_training_builds() {
    let seqs = load("list_Guillaume.txt");
    for (step, copies) in [(20, 1), (7, 0), (33, 3)] {
        let mut opts = TrainOptions {
            turned_copies: copies,
            ..TrainOptions::default()
        };
        opts.features.step = step;
        let built = ridi::training_data(&seqs, &opts.features)
            .unwrap()
            .with_turned_copies(copies)
            .unwrap()
            .targets
            .len();
        assert_eq!(
            ridi::training_windows(&seqs, &opts).unwrap(),
            built,
            "{step} {copies}"
        );
    }
}

#[test]
fn training_windows_refuses_a_count_it_cannot_hold() {
    let seqs = load("list_Guillaume.txt");
    let opts = TrainOptions {
        turned_copies: usize::MAX,
        ..TrainOptions::default()
    };
    let e = ridi::training_windows(&seqs, &opts).unwrap_err();
    assert!(e.to_string().contains("too many rows"), "{e}");
}

#[test]
fn the_order_sequences_are_given_in_does_not_change_the_model() {
    use ridi::regress::{Nystrom, Solver};
    let seqs = load("list_train.txt");
    let mut turned = seqs.clone();
    turned.reverse();
    turned.rotate_left(2);
    let mut opts = TrainOptions::default();
    opts.features.step = 60;
    // The Nyström landmark draw and the grid's folds are the order-sensitive parts.
    opts.cascade.solver = Solver::Nystrom(Nystrom::new(64, 0).unwrap());
    opts.cascade.regressors = GridChoice::Small.regressors();
    let bytes = |seqs: &[Sequence]| {
        ridi::train(seqs, &opts, &mut NoProgress)
            .unwrap()
            .to_bytes()
            .unwrap()
    };
    let a = bytes(&seqs);
    assert!(a == bytes(&turned), "another model from the same sequences");
    // ...and the model does depend on what is in them.
    assert!(a != bytes(&seqs[1..]));
    // Sequences alike in name (Python's default name, or one folder listed twice) are told
    // apart by what they hold.
    let unnamed = |seqs: &[Sequence]| -> Vec<Sequence> {
        let mut seqs = seqs.to_vec();
        seqs.iter_mut().for_each(|s| s.set_name("sequence"));
        seqs
    };
    assert!(bytes(&unnamed(&seqs)) == bytes(&unnamed(&turned)));
}

#[test]
fn ground_truth_in_straight_lines_between_waypoints_is_warned_about_at_training() {
    let seqs = load("list_test.txt");
    assert!(ridi::training_warnings(&seqs).is_empty());
    // One run's ground truth as the competition's: straight lines between a point every 5 s.
    let mut parts = seqs[0].clone().into_parts();
    let gt = parts.ground_truth.as_mut().unwrap();
    ridi_test_support::straight_between_points(&parts.time, &mut gt.position, 1000);
    let straight = Sequence::new(parts).unwrap();
    // One line from start to end never changes velocity: nothing tells it from a walk in one
    // straight line, and it is not named.
    let mut parts = seqs[1].clone().into_parts();
    let gt = parts.ground_truth.as_mut().unwrap();
    ridi_test_support::straight_between_points(&parts.time, &mut gt.position, usize::MAX);
    assert!(ridi::training_warnings(&[Sequence::new(parts).unwrap()]).is_empty());
    let warnings = ridi::training_warnings(&[straight, seqs[1].clone()]);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].starts_with(&format!(
            "1 of 2 training sequences ({} (0.",
            seqs[0].name()
        )) && warnings[0].contains(
            " a second)) has a ground truth that moves in straight lines at constant speed \
                 between a few points, its velocity changing under 2 times a second"
        ),
        "{}",
        warnings[0]
    );
}
