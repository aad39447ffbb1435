//! The `ridi` binary as a user runs it: outputs, exit codes and one-line errors.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use ridi::frames::UpAxis;
use ridi_test_support::{assert_names_file, file_names, sample_dataset, stderr};

mod common;

use common::{ridi, s};

#[test]
fn inspect_prints_text_and_json() {
    let seq = sample_dataset().join("Jakob_Nexus5_NoDist_Texting");
    let out = ridi(&["inspect", s(&seq)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("RIDI processed csv") && text.contains("200.00 Hz"),
        "{text}"
    );
    let out = ridi(&["inspect", s(&seq), "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["frames"], 4800);
    // The format by the name `--from` and Python take; the longest gap between frames.
    assert_eq!(json["format"], "ridi-csv");
    assert!(json["longest_gap_s"].as_f64().unwrap() < 0.01, "{json}");
    assert_eq!(json["placement"], serde_json::Value::Null);
    assert!(json["path_length_m"].as_f64().unwrap() > 5.0);
    assert_eq!(json["upside_down_fraction"], 0.0);
    // Its result is stdout: a write that fails there fails the command (a full disk under
    // `> out.json`); a reader that stops reading (`| head`) does not.
    #[cfg(target_os = "linux")]
    {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_ridi"))
            .args(["inspect", s(&seq), "--json"])
            .stdout(full)
            .output()
            .unwrap();
        assert!(
            !out.status.success()
                && stderr(&out).contains("cannot write the result to stdout: No space left"),
            "{}",
            stderr(&out)
        );
        let mut child = Command::new(env!("CARGO_BIN_EXE_ridi"))
            .args(["inspect", s(&seq)])
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
    }

    // Guillaume swings the phone top down: inspect says so.
    let seq = sample_dataset().join("Guillaume_Nexus5_NoDist_Swinging");
    let out = ridi(&["inspect", s(&seq), "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(
        json["upside_down_fraction"].as_f64().unwrap() > 0.9,
        "{json}"
    );
    let warnings = json["warnings"].to_string();
    assert!(warnings.contains("upside down"), "{warnings}");

    // The reader's own warnings are in the report too (here: a Tyrex run of an unknown
    // motion, 20 s of a phone lying still), in text and JSON alike.
    let dir = tempfile::tempdir().unwrap();
    let run = still_tyrex_run(dir.path(), "Ann_Nexus5_NoDist_Dancing", 4000, None);
    let out = ridi(&["inspect", s(&run), "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let warnings = json["warnings"].to_string();
    assert!(
        warnings.contains("does not end in a known motion"),
        "{warnings}"
    );
    let out = ridi(&["inspect", s(&run)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        text.matches("does not end in a known motion").count(),
        1,
        "{text}"
    );

    // A run split at a sensor gap: JSON gives an array of the parts, text the reader's
    // warnings once.
    let split = still_tyrex_run(dir.path(), "Ann_Nexus5_NoDist_Texting", 6000, Some(3000));
    let out = ridi(&["inspect", s(&split), "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let parts = json.as_array().expect("an array of parts");
    assert_eq!(parts.len(), 2, "{json}");
    assert!(parts[1]["warnings"].to_string().contains("split"), "{json}");
    let out = ridi(&["inspect", s(&split)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.matches("name:").count(), 2, "{text}");
    assert_eq!(
        text.matches("accelerometer.txt:3001: gap").count(),
        1,
        "{text}"
    );
    // Tracked, it names its parts and the command that writes each as a recording.
    let out = ridi(&["track", s(&split), "--out", s(&dir.path().join("t.csv"))]);
    let err = stderr(&out);
    assert!(
        !out.status.success()
            && err.contains(
                "holds 2 sequences (cut at gaps in the recording: \
                 Ann_Nexus5_NoDist_Texting_part1, Ann_Nexus5_NoDist_Texting_part2): \
                 `ridi convert "
            )
            && err.contains("--out <folder>` writes each as a recording of its own"),
        "{err}"
    );

    // One frame: no rate to speak of, and nothing to do with it.
    let one = dir.path().join("one.csv");
    let seq = ridi::data::read_sequence(
        sample_dataset().join("Jakob_Nexus5_NoDist_Texting"),
        &ridi::data::ReadOptions::default(),
    )
    .unwrap();
    ridi::data::write_ridi_csv(&seq.slice(0..1), &one).unwrap();
    let out = ridi(&["inspect", s(&one)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("a single frame: no rate, nothing to train"),
        "{text}{}",
        stderr(&out)
    );
    assert!(!text.contains("-0.00"), "{text}");
    // Less than a feature window: readable, but nothing to train, track or evaluate with
    // the default window.
    let short = dir.path().join("short.csv");
    ridi::data::write_ridi_csv(&seq.slice(0..150), &short).unwrap();
    let out = ridi(&["inspect", s(&short)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success()
            && text.contains("150 frames: no whole feature window of the default 200 frames"),
        "{text}"
    );
}

#[test]
fn training_on_ground_truth_between_waypoints_is_warned_about_first() {
    // A run whose ground truth is straight lines between points 5 s apart (the competition's
    // waypoints, interpolated) beside one with motion capture.
    let dir = tempfile::tempdir().unwrap();
    let read = |name: &str| {
        ridi::data::read_sequence(
            sample_dataset().join(name),
            &ridi::data::ReadOptions::default(),
        )
        .unwrap()
    };
    let mut parts = read("Jakob_Nexus5_NoDist_Texting").into_parts();
    let gt = parts.ground_truth.as_mut().unwrap();
    ridi_test_support::straight_between_points(&parts.time, &mut gt.position, 1000);
    parts.name = "straight".into();
    let straight = ridi::data::Sequence::new(parts).unwrap();
    ridi::data::write_ridi_csv(&straight, dir.path().join("straight.csv")).unwrap();
    let pocket = read("Jakob_Nexus5_NoDist_FrontPocket");
    ridi::data::write_ridi_csv(&pocket, dir.path().join("pocket.csv")).unwrap();
    let list = dir.path().join("list.txt");
    std::fs::write(&list, "straight.csv,Texting\npocket.csv,FrontPocket\n").unwrap();
    let model = dir.path().join("m.ridi");
    let out = ridi(&[
        "train",
        "--list",
        s(&list),
        "--out",
        s(&model),
        "--grid",
        "none",
        "--placement-map",
        "tyrex4",
    ]);
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(
        err.starts_with(
            "warning: 1 of 2 training sequences (straight (0.2 a second)) has a ground truth \
             that moves in straight lines at constant speed between a few points"
        ),
        "{err}"
    );
}

/// A Tyrex run `name` in `dir` of a phone lying still for `frames` frames at 200 Hz, with a
/// 3-s gap in every stream before frame `gap_at` if given.
fn still_tyrex_run(dir: &Path, name: &str, frames: usize, gap_at: Option<usize>) -> PathBuf {
    let run = dir.join(name);
    std::fs::create_dir_all(&run).unwrap();
    for (file, values) in [
        ("accelerometer.txt", "0.0 0.0 9.80665"),
        ("gyroscope-calibrated.txt", "0.0 0.0 0.0"),
        ("rotation-vector.txt", "0.0 0.0 0.0 1.0 0.17"),
    ] {
        let rows: String = (0..frames)
            .map(|k| {
                let gap = if gap_at.is_some_and(|g| k >= g) {
                    3.0
                } else {
                    0.0
                };
                format!("{:.9} {values}\n", 0.003 + k as f64 * 0.005 + gap)
            })
            .collect();
        std::fs::write(run.join(file), rows).unwrap();
    }
    run
}

/// A Tyrex run's Qualisys file that is a folder or a link to a device is an error naming the
/// file, for every command that reads the run; a missing one is no error (the run has no
/// ground truth).
#[test]
fn a_qualisys_file_that_is_not_a_file_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let android = dir.path().join("datasets/android");
    let run = still_tyrex_run(&android, "Ann_Nexus5_NoDist_Texting", 4000, None);
    let qualisys = dir.path().join("datasets/qualisys");
    std::fs::create_dir_all(&qualisys).unwrap();
    let mat = qualisys.join("Ann_Nexus5_NoDist_Texting.mat");
    let out = ridi(&["inspect", s(&run)]);
    assert!(out.status.success(), "{}", stderr(&out));
    for make in [
        (|m: &Path| std::fs::create_dir(m).unwrap()) as fn(&Path),
        |m: &Path| std::os::unix::fs::symlink("/dev/zero", m).unwrap(),
    ] {
        make(&mat);
        for args in [
            vec!["inspect", s(&run)],
            vec![
                "convert",
                s(dir.path()),
                "--out",
                s(&dir.path().join("conv")),
            ],
        ] {
            let out = ridi(&args);
            let err = stderr(&out);
            assert!(
                out.status.code() == Some(1)
                    && err.contains(&format!("{}: ", s(&mat)))
                    && err.contains("not a regular file"),
                "{args:?}: {err}"
            );
        }
        let _ = std::fs::remove_dir(&mat).or_else(|_| std::fs::remove_file(&mat));
    }
}

#[test]
fn errors_are_one_line_with_a_non_zero_exit() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nope");
    let out = ridi(&["inspect", s(&missing)]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with("error: ") && err.contains("nope"), "{err}");

    // A corrupt csv names file, line and field.
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, ",time,gyro_x\n0,1,x\n").unwrap();
    let out = ridi(&["inspect", s(&bad)]);
    let err = stderr(&out);
    assert!(!out.status.success() && err.contains("bad.csv"), "{err}");

    // A model file that is not one.
    let model = dir.path().join("m.ridi");
    std::fs::write(&model, b"not a model").unwrap();
    let seq = sample_dataset().join("Jakob_Nexus5_NoDist_Texting");
    let csv = dir.path().join("t.csv");
    let out = ridi(&["track", s(&seq), "--model", s(&model), "--out", s(&csv)]);
    let err = stderr(&out);
    assert!(!out.status.success() && err.contains("m.ridi"), "{err}");
    assert!(!csv.exists(), "no output on failure");
    // Inspected, a `.ridi` file is judged as a model, whatever its bytes; each way a model file
    // can be damaged (magic, length, version, checksum, payload) is an error naming the file.
    let header = |version: u32, len: u64, crc: u32| {
        let mut h = b"RIDIREG\0".to_vec();
        h.extend(version.to_le_bytes());
        h.extend(len.to_le_bytes());
        h.extend(crc.to_le_bytes());
        h
    };
    for bytes in [
        b"not a model".to_vec(),
        Vec::new(),
        b"RIDIR".to_vec(),
        header(7, 0, 0)[..20].to_vec(),
        header(99, 0, 0),
        header(7, 100, 0),
        [header(7, 4, 0), b"abcd".to_vec()].concat(),
        header(7, 0, 0),
    ] {
        std::fs::write(&model, &bytes).unwrap();
        let err = error(&ridi(&["inspect", s(&model)]));
        assert!(err.starts_with("error: cannot load model"), "{err}");
        assert_names_file(&err, &model);
    }
    // Something that exists but is neither file nor folder is not called missing.
    if cfg!(unix) {
        let err = stderr(&ridi(&["inspect", "/dev/null"]));
        assert!(err.contains("neither a regular file nor a folder"), "{err}");
    }
    // Converting into a file, not a folder.
    let out = ridi(&["convert", s(&seq), "--out", s(&bad)]);
    let err = stderr(&out);
    assert!(
        !out.status.success() && err.contains("it is a file, not a folder"),
        "{err}"
    );
}

#[test]
fn a_closed_stdout_is_no_panic() {
    // `ridi inspect ... | head -0`: the reader is gone before ridi writes.
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let seq = sample_dataset().join("Jakob_Nexus5_NoDist_Texting");
    let out = Command::new(env!("CARGO_BIN_EXE_ridi"))
        .args(["inspect", s(&seq)])
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("panicked"), "{}", stderr(&out));
}

#[test]
fn the_nystrom_solver_keeps_its_own_share_of_the_variance() {
    // Its kernel is computed on the principal coordinates: `projected` keeps 90 % for it
    // (`Storage::NYSTROM_DEFAULT`), not the exact solver's 99.99 %; `half` stays half.
    let dir = tempfile::tempdir().unwrap();
    let list = sample_dataset().join("list_Guillaume.txt");
    let model = dir.path().join("m.ridi");
    let stored = |storage: &str| {
        let out = ridi(&[
            "train",
            "--list",
            s(&list),
            "--grid",
            "none",
            "--placement-map",
            "tyrex4",
            "--solver",
            "nystrom",
            "--landmarks",
            "64",
            "--seed",
            "7",
            "--storage",
            storage,
            "--out",
            s(&model),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        let out = ridi(&["inspect", s(&model), "--json"]);
        assert!(out.status.success(), "{}", stderr(&out));
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        // Two trainings differing in the draw alone are told apart.
        assert_eq!(
            (&json["solver"], &json["landmark_seed"]),
            (&"nystrom".into(), &7.into())
        );
        let text = String::from_utf8(ridi(&["inspect", s(&model)]).stdout).unwrap();
        assert!(
            text.contains("landmarks per machine drawn with seed 7"),
            "{text}"
        );
        // Kernel ridge regressors: a C and no epsilon.
        assert!(
            text.contains("S-x: C=10  S-z: C=10") && !text.contains("eps="),
            "{text}"
        );
        let variance = json["stored_variance"].as_f64().unwrap();
        (json["projected_components"].as_u64(), variance)
    };
    let (components, variance) = stored("projected");
    // The exact solver's 99.99 % keeps 272 coordinates of these rows.
    assert_eq!(components, Some(64));
    assert!((0.9..0.9999).contains(&variance), "{variance}");
    assert_eq!(stored("half"), (None, 1.0));
}

#[test]
fn bad_flags_and_outputs_fail_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let list = sample_dataset().join("list_Guillaume.txt");
    let model = dir.path().join("m.ridi");
    let train = |list: &Path, extra: &[&str]| {
        let mut args = vec!["train", "--list", s(list), "--grid", "none"];
        args.extend_from_slice(extra);
        ridi(&args)
    };
    for (flag, value, says) in [
        ("--turned-copies", "100000", "from 0 to 32"),
        ("--step", "0", "from 1 to 12000"),
        ("--window", "10", "from 20 to 600"),
        ("--classifier-c", "0", "above 0"),
        ("--classifier-c", "NaN", "above 0"),
        ("--jobs", "0", "from 1 to 4096"),
    ] {
        let out = train(&list, &["--out", s(&model), flag, value]);
        let err = stderr(&out);
        assert!(!out.status.success(), "{flag} {value}");
        assert!(err.contains(flag) && err.contains(says), "{err}");
    }
    // The model's folder is checked before training, not after.
    let nowhere = dir.path().join("missing/m.ridi");
    let out = train(&list, &["--out", s(&nowhere)]);
    let err = stderr(&out);
    assert!(
        !out.status.success() && err.contains("does not exist"),
        "{err}"
    );
    let printed = String::from_utf8_lossy(&out.stdout);
    assert!(!printed.contains("placements:"), "trained first: {printed}");
    // A label the placement map does not know is named with its list file and line.
    let typo = dir.path().join("typo.txt");
    let swing = sample_dataset().join("Guillaume_Nexus5_NoDist_Swinging");
    let texting = sample_dataset().join("Guillaume_Nexus5_NoDist_Texting");
    std::fs::write(
        &typo,
        format!("{},Texting\n{},Swingin\n", s(&texting), s(&swing)),
    )
    .unwrap();
    let out = train(&typo, &["--out", s(&model), "--placement-map", "tyrex4"]);
    let err = stderr(&out);
    assert!(
        !out.status.success() && err.contains("typo.txt:2: field `placement`: placement `Swingin`"),
        "{err}"
    );

    // One recording of a placement cannot be cross-validated: the error says what to do.
    let single = dir.path().join("single.txt");
    std::fs::write(&single, format!("{},Texting\n", s(&texting))).unwrap();
    let out = ridi(&["train", "--list", s(&single), "--out", s(&model)]);
    let err = stderr(&out);
    assert!(
        !out.status.success() && err.contains("`--grid none` trains without it"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");

    let seq = sample_dataset().join("Jakob_Nexus5_NoDist_Texting");
    let csv = dir.path().join("t.csv");
    let track = |extra: &[&str]| {
        let mut args = vec!["track", s(&seq), "--model", s(&model), "--out", s(&csv)];
        args.extend_from_slice(extra);
        ridi(&args)
    };
    for (flag, value, says) in [
        ("--regress-every", "0", "from 1 to 12000"),
        ("--lambda", "NaN", "above 0"),
        ("--lambda", "inf", "above 0"),
        ("--lambda", "0", "above 0"),
    ] {
        let out = track(&[flag, value]);
        let err = stderr(&out);
        assert!(!out.status.success(), "{flag} {value}");
        assert!(err.contains(flag) && err.contains(says), "{err}");
    }
    // A plot path that cannot be drawn to fails before the trajectory is written (the model
    // does not even exist: the outputs are checked first).
    let jpg = dir.path().join("t.jpg");
    let out = track(&["--plot", s(&jpg)]);
    let err = stderr(&out);
    assert!(
        !out.status.success() && err.contains("expected .svg or .png"),
        "{err}"
    );
    assert!(!csv.exists());
}

#[test]
fn convert_train_track_and_eval() {
    let dir = tempfile::tempdir().unwrap();
    let conv = dir.path().join("conv");
    let seq = sample_dataset().join("Guillaume_Nexus5_NoDist_Swinging");
    let out = ridi(&["convert", s(&seq), "--out", s(&conv)]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        conv.join("Guillaume_Nexus5_NoDist_Swinging/processed/data.csv")
            .is_file()
    );
    assert!(conv.join("list_all.txt").is_file());

    let model = dir.path().join("m.ridi");
    let list = sample_dataset().join("list_Guillaume.txt");
    // Guillaume's runs in 4 groups, without grid search, and `extra`.
    let train = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "train",
            "--list",
            s(&list),
            "--out",
            s(out),
            "--grid",
            "none",
            "--placement-map",
            "tyrex4",
        ];
        args.extend_from_slice(extra);
        ridi(&args)
    };
    let out = train(&model, &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let printed = String::from_utf8_lossy(&out.stdout);
    assert!(printed.contains("placements: hand, pocket, running, swing"));
    // Default training has a speed regressor per placement; the paper's has none.
    assert!(printed.contains("speed: C=10 eps=0.01"), "{printed}");
    let paper = dir.path().join("paper.ridi");
    let out = train(
        &paper,
        &[
            "--turned-copies",
            "0",
            "--no-speed",
            "--up-axis",
            "plus-y",
            "--orientation",
            "recorded",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let printed = String::from_utf8_lossy(&out.stdout);
    assert!(!printed.contains("speed:"), "{printed}");
    assert!(printed.contains("S built on: device +y\n"), "{printed}");
    assert!(printed.contains("orientation: as recorded"), "{printed}");
    let paper_model = ridi::regress::Cascade::load(&paper).unwrap();
    let default_model = ridi::regress::Cascade::load(&model).unwrap();
    assert_eq!(paper_model.feature_config().step, 10);
    assert_eq!(default_model.feature_config().step, 20);
    assert_eq!(paper_model.feature_config().up_axis, UpAxis::PlusY);
    assert_eq!(default_model.feature_config().up_axis, UpAxis::PlusOrMinusY);

    // `ridi inspect` describes a model file as `ridi train` did, or as JSON.
    let out = ridi(&["inspect", s(&paper)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let described = String::from_utf8_lossy(&out.stdout);
    assert!(printed.starts_with(described.as_ref()), "{described}");
    assert!(
        printed.contains(
            "feature window: 200 frames (sigma 2), a training window every 10 frames, standardized"
        ),
        "{printed}"
    );
    let out = ridi(&["inspect", s(&model), "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["window"], 200);
    assert_eq!(json["step"], 20);
    assert_eq!(json["up_axis"], "plus-or-minus-y");
    assert_eq!(json["placements"][0]["name"], "hand");
    assert_eq!(
        json["placements"][0]["speed"],
        serde_json::json!({"c": 10.0, "epsilon": 0.01})
    );
    assert_eq!(json["placements"][3]["s_z"]["c"], 10.0);
    // A model file cut short, even within its magic number, is an error naming it.
    let cut = dir.path().join("cut.ridi");
    for len in [100, 5] {
        std::fs::write(&cut, &std::fs::read(&model).unwrap()[..len]).unwrap();
        let out = ridi(&["inspect", s(&cut)]);
        assert!(!out.status.success());
        assert!(
            stderr(&out).contains("cannot load model") && stderr(&out).contains("cut.ridi"),
            "{}",
            stderr(&out)
        );
    }
    // Another feature window is the model's, and shown.
    let short = dir.path().join("short.ridi");
    let out = train(&short, &["--window", "100"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = ridi(&["inspect", s(&short), "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        (json["window"].clone(), json["dim"].clone()),
        (100.into(), 600.into())
    );

    let csv = dir.path().join("t.csv");
    let png = dir.path().join("t.png");
    let test_seq = sample_dataset().join("Jakob_Nexus5_NoDist_Texting");
    let track_to = |input: &Path, out: &Path, extra: &[&str]| {
        let mut args = vec!["track", s(input), "--model", s(&model), "--out", s(out)];
        args.extend_from_slice(extra);
        ridi(&args)
    };
    let out = track_to(&test_seq, &csv, &["--online", "--plot", s(&png)]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(std::fs::read_to_string(&csv).unwrap().lines().count(), 4801);
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    // The trajectory's temporary name is gone once it is in place.
    let hidden: Vec<_> = file_names(dir.path())
        .into_iter()
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");

    let report = dir.path().join("report");
    let test_list = sample_dataset().join("list_Jakob.txt");
    // `ridi eval` of Jakob's runs with `model` into `out`, and `extra` flags.
    let eval_jakob = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "eval",
            "--list",
            s(&test_list),
            "--model",
            s(&model),
            "--out",
            s(out),
            "--placement-map",
            "tyrex4",
        ];
        args.extend_from_slice(extra);
        ridi(&args)
    };
    let out = eval_jakob(&report, &["--methods", "ridi,raw,still", "--plots", "svg"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("report.json")).unwrap())
            .unwrap();
    assert_eq!(json["methods"], serde_json::json!(["ridi", "raw", "still"]));
    assert!(
        report
            .join("plots/Jakob_Nexus5_NoDist_Texting.trajectory.svg")
            .is_file()
    );

    // The same sequences evaluated otherwise, compared sequence by sequence: what differs is
    // named, and each figure's paired difference listed.
    let other = dir.path().join("report-other");
    let out = eval_jakob(
        &other,
        &[
            "--methods",
            "ridi,still",
            "--placement-window",
            "0",
            "--plots",
            "none",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let out = ridi(&["compare", s(&report), s(&other.join("report.json"))]);
    assert!(out.status.success(), "{}", stderr(&out));
    let md = String::from_utf8_lossy(&out.stdout);
    assert!(
        md.contains("- placement: 10 s against per regression")
            && md.contains("- methods: raw, ridi, still against ridi, still")
            && md.contains("| ridi | RTE 5 s (m) | ")
            && md.contains("| still | RTE 5 s (m) | ")
            && !md.contains("| raw |"),
        "{md}"
    );
    let out = ridi(&["compare", s(&report), s(&report), "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let compared: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(compared["settings"], serde_json::json!([]));
    let figures = compared["figures"].as_array().unwrap();
    assert!(
        figures.iter().all(|f| f["difference"] == 0.0),
        "{figures:?}"
    );
    let out = ridi(&["compare", s(&report), s(&report.join("report.md"))]);
    assert!(
        stderr(&out).contains("report.md: not a report.json of `ridi eval`"),
        "{}",
        stderr(&out)
    );

    let out = ridi(&[
        "eval",
        "--list",
        s(&test_list),
        "--model",
        s(&model),
        "--out",
        s(&report),
        "--methods",
        "ridi,magic",
    ]);
    // A usage error, as for any bad flag value: clap's message and exit code 2.
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("invalid value 'magic' for '--methods <METHODS>'"),
        "{}",
        stderr(&out)
    );

    // Evaluating again into the same folder: the plots of sequences no longer evaluated go,
    // a method given twice is evaluated once, and --plots none leaves no plots/ behind.
    let one = dir.path().join("one.txt");
    std::fs::write(&one, format!("{},Texting\n", s(&test_seq))).unwrap();
    let eval_one = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "eval",
            "--list",
            s(&one),
            "--model",
            s(&model),
            "--out",
            s(out),
        ];
        args.extend_from_slice(extra);
        ridi(&args)
    };
    let methods = ["--methods", "ridi,ridi,still", "--placement-map", "tyrex4"];
    let before = std::fs::read_dir(report.join("plots")).unwrap().count();
    // A file of the user's named like a plot, but of no evaluated sequence, stays.
    let mine = report.join("plots/mine.trajectory.png");
    std::fs::write(&mine, "not a plot of ridi's").unwrap();
    let out = eval_one(&report, &[&methods[..], &["--plots", "svg"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let printed = String::from_utf8_lossy(&out.stdout);
    assert!(
        printed.contains(&format!(
            "removed {} plots of an earlier evaluation",
            before - 2
        )),
        "{printed}"
    );
    assert_eq!(std::fs::read_dir(report.join("plots")).unwrap().count(), 3);
    assert_eq!(std::fs::read(&mine).unwrap(), b"not a plot of ridi's");
    std::fs::remove_file(&mine).unwrap();
    let json_one: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("report.json")).unwrap())
            .unwrap();
    assert_eq!(json_one["methods"], serde_json::json!(["ridi", "still"]));
    let out = eval_one(&report, &[&methods[..], &["--plots", "none"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!report.join("plots").exists());
    // An output folder that is a file fails before any work.
    let out = eval_one(&csv, &[]);
    assert!(
        !out.status.success() && stderr(&out).contains("it is a file, not a folder"),
        "{}",
        stderr(&out)
    );

    // An evaluation is written all or nothing: one output it cannot replace (report.md made
    // a folder) leaves the earlier report.json, and no plots/ or staging folder behind.
    let json_before = std::fs::read(report.join("report.json")).unwrap();
    std::fs::remove_file(report.join("report.md")).unwrap();
    std::fs::create_dir(report.join("report.md")).unwrap();
    let out = eval_one(&report, &[&methods[..], &["--plots", "svg"]].concat());
    assert!(!out.status.success());
    assert_eq!(
        std::fs::read(report.join("report.json")).unwrap(),
        json_before
    );
    assert_eq!(file_names(&report), ["report.json", "report.md"]);
    std::fs::remove_dir(report.join("report.md")).unwrap();
    // A file where the plots go is named before the evaluation.
    std::fs::write(report.join("plots"), "mine").unwrap();
    let out = eval_one(&report, &[&methods[..], &["--plots", "png"]].concat());
    let err = stderr(&out);
    assert!(
        !out.status.success() && err.contains("plots: it is a file, not a folder"),
        "{err}"
    );
    std::fs::remove_file(report.join("plots")).unwrap();

    // A recording listed twice, also through another path, and two recordings of one name
    // are refused at their list line; so is, after loading, a recording too short to track.
    let twice = dir.path().join("twice.txt");
    let same = dir.path().join("same.txt");
    let short_list = dir.path().join("short.txt");
    // Two recordings of one name (copies of one recording would be refused as such).
    for (name, from) in [
        ("a", &test_seq),
        ("b", &sample_dataset().join("Jakob_Nexus5_NoDist_Phoning")),
    ] {
        let run = dir.path().join(name).join("run/processed");
        std::fs::create_dir_all(&run).unwrap();
        std::fs::copy(from.join("processed/data.csv.gz"), run.join("data.csv.gz")).unwrap();
    }
    std::fs::write(
        &twice,
        format!(
            "{}\n{}\n",
            s(&test_seq),
            s(&test_seq.join("processed/data.csv.gz"))
        ),
    )
    .unwrap();
    std::fs::write(&same, "a/run\nb/run\n").unwrap();
    let seq = ridi::data::read_sequence(&test_seq, &Default::default()).unwrap();
    let short_run = dir.path().join("short/processed");
    std::fs::create_dir_all(&short_run).unwrap();
    ridi::data::write_ridi_csv(&seq.slice(0..150), short_run.join("data.csv")).unwrap();
    std::fs::write(&short_list, format!("{}\nshort\n", s(&test_seq))).unwrap();
    let new_report = dir.path().join("new-report");
    for (list, says) in [
        (&twice, "twice.txt:2: field `path`"),
        (
            &same,
            "same.txt:2: field `path`: a sequence named `run` is already listed at",
        ),
        (&short_list, "short.txt:2: sequence `short`: has 150 frames"),
    ] {
        let out = ridi(&[
            "eval",
            "--list",
            s(list),
            "--model",
            s(&model),
            "--out",
            s(&new_report),
        ]);
        let err = stderr(&out);
        assert!(!out.status.success() && err.contains(says), "{err}");
        assert!(!new_report.exists(), "{err}");
    }

    // An output folder that cannot be written fails before the work (procfs refuses new
    // files even to root, who may write anywhere else).
    if cfg!(target_os = "linux") {
        let tracked = std::fs::read(&csv).unwrap();
        let unwritable = Path::new("/proc/ridi-test.png");
        let out = track_to(&test_seq, &csv, &["--plot", s(unwritable)]);
        let err = stderr(&out);
        assert!(
            !out.status.success() && err.contains("cannot create files in /proc"),
            "{err}"
        );
        assert!(!err.contains(".tmp"), "{err}");
        assert_eq!(std::fs::read(&csv).unwrap(), tracked);
    }

    // No output may overwrite an input: the recording, the model, a list, or a file a
    // sequence folder is read from; the inputs stay as they were.
    let recording = dir.path().join("v.csv.gz");
    std::fs::copy(test_seq.join("processed/data.csv.gz"), &recording).unwrap();
    let folder = dir.path().join("seq");
    std::fs::create_dir_all(folder.join("processed")).unwrap();
    std::fs::copy(&recording, folder.join("processed/data.csv.gz")).unwrap();
    let model_bytes = std::fs::read(&model).unwrap();
    let recording_bytes = std::fs::read(&recording).unwrap();
    for (input, output) in [
        (&recording, &recording),
        (&recording, &model),
        (&folder, &folder.join("processed/data.csv.gz")),
    ] {
        let out = track_to(input, output, &[]);
        assert!(
            !out.status.success() && stderr(&out).contains("the command reads it"),
            "{}",
            stderr(&out)
        );
    }
    // An input that does not exist is that error, not the output's, and nothing is written.
    let missing = dir.path().join("missing.csv");
    let out = track_to(&missing, &missing, &[]);
    let err = stderr(&out);
    assert!(
        !out.status.success()
            && err.contains("missing.csv")
            && err.contains("no such file or folder")
            && !err.contains("reads it"),
        "{err}"
    );
    assert!(!missing.exists());
    let out = ridi(&[
        "train",
        "--list",
        s(&one),
        "--out",
        s(&one),
        "--grid",
        "none",
    ]);
    assert!(
        !out.status.success() && stderr(&out).contains("the command reads it"),
        "{}",
        stderr(&out)
    );
    // Nor the placement map it reads.
    let map = dir.path().join("map.txt");
    std::fs::write(&map, "AR,hand\n").unwrap();
    let out = ridi(&[
        "train",
        "--list",
        s(&one),
        "--out",
        s(&map),
        "--grid",
        "none",
        "--placement-map",
        s(&map),
    ]);
    assert!(
        !out.status.success() && stderr(&out).contains("the command reads it"),
        "{}",
        stderr(&out)
    );
    assert_eq!(std::fs::read(&map).unwrap(), b"AR,hand\n");
    // A pipe (or a device) is no output: the rename would replace it with a regular file.
    // (A pipe, not /dev/null: were the check to fail, a test run as root would replace it.)
    #[cfg(unix)]
    {
        let fifo = dir.path().join("pipe.csv");
        ridi_test_support::make_fifo(&fifo);
        let out = track_to(&recording, &fifo, &[]);
        assert!(
            !out.status.success() && stderr(&out).contains("is a device, a pipe or a socket"),
            "{}",
            stderr(&out)
        );
        assert!(ridi_test_support::is_fifo(&fifo));
    }
    // The model at a name the evaluation writes inside --out: refused before anything moves.
    let inside = dir.path().join("eval-into-model");
    std::fs::create_dir_all(&inside).unwrap();
    let model_inside = inside.join("report.json");
    std::fs::copy(&model, &model_inside).unwrap();
    let out = ridi(&[
        "eval",
        "--list",
        s(&test_list),
        "--model",
        s(&model_inside),
        "--out",
        s(&inside),
        "--methods",
        "ridi",
        "--plots",
        "none",
    ]);
    assert!(
        !out.status.success() && stderr(&out).contains("the command reads it"),
        "{}",
        stderr(&out)
    );
    assert_eq!(std::fs::read(&model_inside).unwrap(), model_bytes);
    assert!(!inside.join("report.md").exists());
    assert_eq!(std::fs::read(&model).unwrap(), model_bytes);
    assert_eq!(std::fs::read(&recording).unwrap(), recording_bytes);
    assert!(
        std::fs::read_to_string(&one)
            .unwrap()
            .ends_with(",Texting\n")
    );
    // A trajectory and its plot in the same file would overwrite each other.
    let both = dir.path().join("both.svg");
    std::fs::write(&both, "").unwrap();
    let out = track_to(&folder, &both, &["--plot", s(&both)]);
    assert!(
        !out.status.success() && stderr(&out).contains("it is given as two outputs"),
        "{}",
        stderr(&out)
    );
    // Beside a recording is fine, whatever the extension, and so is a second run over its
    // own output.
    let beside = folder.join("trajectory.txt");
    for run in ["first", "second"] {
        let out = track_to(&folder, &beside, &[]);
        assert!(out.status.success(), "{run}: {}", stderr(&out));
    }

    // --align: the paper's first 10 s by default, the whole run on request; the ground truth's
    // travel within the window is reported per sequence.
    let ten = json["sequences"][0]["alignment_extent_m"].as_f64().unwrap();
    assert_eq!(
        json["config"]["align"],
        serde_json::json!({"seconds": 10.0})
    );
    let whole = dir.path().join("report-whole");
    let eval_aligned = |align: &str| {
        let align = format!("--align={align}");
        ridi(&[
            "eval",
            "--list",
            s(&test_list),
            "--model",
            s(&model),
            "--out",
            s(&whole),
            "--methods",
            "ridi",
            "--plots",
            "none",
            &align,
        ])
    };
    let out = eval_aligned("all");
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(whole.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["config"]["align"], serde_json::json!("all"));
    let all = json["sequences"][0]["alignment_extent_m"].as_f64().unwrap();
    assert!(ten > 0.0 && all > ten, "{ten} {all}");
    for bad in ["0", "-3", "ten"] {
        let out = eval_aligned(bad);
        assert!(!out.status.success());
        assert!(
            stderr(&out).contains("neither a positive number of seconds nor `all`"),
            "{}",
            stderr(&out)
        );
    }

    // The placement majority window: off with 0, refused when negative. The orientation is
    // the model's: track no longer takes --orientation.
    let plain = dir.path().join("plain.csv");
    let out = track_to(&test_seq, &plain, &["--placement-window", "0"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let unsmoothed = std::fs::read_to_string(&plain).unwrap();
    assert_eq!(unsmoothed.lines().count(), 4801);
    assert_ne!(unsmoothed, std::fs::read_to_string(&csv).unwrap());
    let out = track_to(&test_seq, &plain, &["--orientation", "estimated"]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("--orientation"), "{}", stderr(&out));
    // A bad value is a usage error like any other flag's (exit code 2), for each command.
    for bad in ["-1", "nan", "inf"] {
        let out = track_to(&test_seq, &plain, &[&format!("--placement-window={bad}")]);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        assert!(
            stderr(&out).contains(&format!("invalid value '{bad}' for '--placement-window")),
            "{}",
            stderr(&out)
        );
    }
}

// ---- bad input: one-line errors naming the file, nothing partly written ------------------

/// The one-line error of a failed run.
fn error(o: &Output) -> String {
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(err.lines().count(), 1, "{err}");
    err
}

/// A RIDI raw folder of 2000 frames at 200 Hz (more than the 800 pose records dropped at each
/// end), the phone still and upright, with gravity `g` m/s^2; `skip` files left out.
fn raw_folder(dir: &Path, g: f64, skip: &[&str]) {
    std::fs::create_dir_all(dir).unwrap();
    let rows = |header: &str, values: &str| {
        let mut text = format!("# {header}\n");
        for i in 0..2000i64 {
            let _ = writeln!(text, "{} {values}", 1_000_000_000_000 + 5_000_000 * i);
        }
        text
    };
    let files = [
        ("gyro.txt", rows("t x y z", "0 0 0")),
        ("acce.txt", rows("t x y z", &format!("0 {g} 0"))),
        ("linacce.txt", rows("t x y z", "0 0 0")),
        ("gravity.txt", rows("t x y z", &format!("0 {g} 0"))),
        // Upright: a turn by 90 degrees about x takes the y axis, along gravity, up.
        (
            "orientation.txt",
            rows(
                "t x y z w",
                &format!("{r} 0 0 {r}", r = std::f64::consts::FRAC_1_SQRT_2),
            ),
        ),
        ("pose.txt", rows("t tx ty tz qx qy qz qw", "0 0 0 0 0 0 1")),
    ];
    for (name, text) in files {
        if !skip.contains(&name) {
            std::fs::write(dir.join(name), text).unwrap();
        }
    }
}

#[test]
fn raw_folders_name_the_file_to_blame() {
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("raw");
    raw_folder(&raw, 9.81, &[]);
    let out = ridi(&["inspect", s(&raw)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    std::fs::remove_file(raw.join("gyro.txt")).unwrap();
    let conv = dir.path().join("conv");
    for args in [
        vec!["inspect", s(&raw)],
        vec!["convert", s(&raw), "--from", "ridi-raw", "--out", s(&conv)],
    ] {
        let err = error(&ridi(&args));
        assert!(
            err.contains(&format!(
                "{}: RIDI raw folder without gyro.txt",
                raw.display()
            )),
            "{err}"
        );
    }
    assert!(!dir.path().join("conv").exists());

    let in_g = dir.path().join("in_g");
    raw_folder(&in_g, 1.0, &[]);
    let err = error(&ridi(&["inspect", s(&in_g)]));
    assert!(
        err.contains(&format!(
            "{}: mean gravity magnitude 1.000 m/s^2 is outside 8.5..11",
            in_g.join("gravity.txt").display()
        )) && !err.contains("pose.txt"),
        "{err}"
    );
}

#[test]
fn convert_writes_all_or_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path().join("src");
    let texting = sample_dataset().join("Thibaud_Nexus5_NoDist_Texting");
    for name in ["a_seq", "b_seq", "c_seq"] {
        let out = ridi(&["convert", s(&texting), "--out", s(&dir.path().join("tmp"))]);
        assert!(out.status.success());
        let from = dir
            .path()
            .join("tmp/Thibaud_Nexus5_NoDist_Texting/processed/data.csv");
        std::fs::create_dir_all(src.join(name).join("processed")).unwrap();
        let mut text = std::fs::read_to_string(&from).unwrap();
        if name == "b_seq" {
            let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
            let mut cells: Vec<&str> = lines[300].split(',').collect();
            cells[3] = "NaN";
            lines[300] = cells.join(",");
            text = lines.join("\n") + "\n";
        }
        std::fs::write(src.join(name).join("processed/data.csv"), text).unwrap();
    }
    let conv = dir.path().join("conv");
    let err = error(&ridi(&["convert", s(&src), "--out", s(&conv)]));
    assert!(
        err.contains("b_seq/processed/data.csv:301: field `gyro_y`"),
        "{err}"
    );
    assert!(!conv.exists());
    // A rate no phone records at is the flag's error, not the recording's: also 1 Hz and
    // 10 kHz, whose frames the readers would refuse (a step of 1 s is a gap, one of 0.1 ms
    // below the shortest step, once rounded).
    for rate in ["0.5", "1", "10000", "100000", "1e300"] {
        let out = ridi(&["convert", s(&texting), "--out", s(&conv), "--rate", rate]);
        let err = stderr(&out);
        assert!(
            out.status.code() == Some(2)
                && err.contains("--rate")
                && err.contains("from 1.001 to 9990 Hz"),
            "{err}"
        );
    }
    // Its bounds themselves convert, and the results read back.
    for rate in ["1.001", "9990"] {
        let out_dir = dir.path().join(format!("rate-{rate}"));
        let out = ridi(&["convert", s(&texting), "--out", s(&out_dir), "--rate", rate]);
        assert!(out.status.success(), "{rate}: {}", stderr(&out));
        let seq = out_dir.join("Thibaud_Nexus5_NoDist_Texting");
        let out = ridi(&["inspect", s(&seq)]);
        assert!(out.status.success(), "{rate}: {}", stderr(&out));
    }

    // The source of another format than --from says what it is and what was expected.
    let csv = dir
        .path()
        .join("tmp/Thibaud_Nexus5_NoDist_Texting/processed/data.csv");
    let err = error(&ridi(&[
        "convert",
        s(&csv),
        "--from",
        "tyrex",
        "--out",
        s(&conv),
    ]));
    assert!(
        err.contains(
            "data.csv: not a Tyrex folder (it is a RIDI processed csv): a Tyrex run is a folder"
        ) && !err.contains("entity not found"),
        "{err}"
    );
    assert!(!conv.exists());
}

#[test]
fn from_ridi_plain_converts_the_data_plain_txt_of_a_folder_with_both() {
    // Detection and `--from ridi-csv` prefer a folder's data.csv; `--from ridi-plain` (the
    // Python package's name too) takes its data_plain.txt.
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus");
    let dir = tempfile::tempdir().unwrap();
    let both = dir.path().join("both/processed");
    std::fs::create_dir_all(&both).unwrap();
    std::fs::copy(corpus.join("ok/processed/data.csv"), both.join("data.csv")).unwrap();
    std::fs::copy(
        corpus.join("plain/ok/data_plain.txt"),
        both.join("data_plain.txt"),
    )
    .unwrap();
    let source = dir.path().join("both");
    for (from, frames) in [
        (None, 240),
        (Some("ridi-csv"), 240),
        (Some("ridi-plain"), 24),
    ] {
        let out_dir = dir
            .path()
            .join(format!("out-{}", from.unwrap_or("detected")));
        let mut args = vec!["convert", s(&source), "--out", s(&out_dir)];
        args.extend(from.iter().flat_map(|f| ["--from", f]));
        let out = ridi(&args);
        assert!(out.status.success(), "{from:?}: {}", stderr(&out));
        let out = ridi(&["inspect", s(&out_dir.join("both")), "--json"]);
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(json["frames"], frames, "{from:?}");
    }
    // A folder without a data_plain.txt is no `ridi-plain` source (its data.csv is not read
    // instead), nor is a data.csv.
    std::fs::remove_file(both.join("data_plain.txt")).unwrap();
    for source in [source.clone(), both.join("data.csv")] {
        let out = ridi(&["convert", s(&source), "--out", "y", "--from", "ridi-plain"]);
        assert_eq!(out.status.code(), Some(1));
        assert!(
            stderr(&out).contains("not a RIDI data_plain.txt (it is a RIDI processed csv)"),
            "{}",
            stderr(&out)
        );
    }
    // The keys, each with what convert takes of it; another name is clap's usage error.
    let help = String::from_utf8(ridi(&["convert", "--help"]).stdout).unwrap();
    assert!(
        help.contains("- ridi-plain: RIDI processed data_plain.txt (also of a folder that has"),
        "{help}"
    );
    let out = ridi(&["convert", s(&source), "--out", "x", "--from", "csv"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out)
            .contains("[possible values: ridi-csv, ridi-plain, ridi-raw, tyrex, ilc, ronin]"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn rayon_num_threads_out_of_range_is_a_warning_and_jobs_outranks_it() {
    // rayon would start what RAYON_NUM_THREADS asks for at its first parallel call, without a
    // bound, and panic if the system refused: the command starts them first, checked.
    let seq = sample_dataset().join("Jakob_Nexus5_NoDist_Texting");
    let dir = tempfile::tempdir().unwrap();
    let with = |name: &str, value: &str, args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_ridi"))
            .args(args)
            .env_remove("RAYON_NUM_THREADS")
            .env_remove("RAYON_RS_NUM_CPUS")
            .env(name, value)
            .output()
            .unwrap()
    };
    let with_env = |value: &str, args: &[&str]| with("RAYON_NUM_THREADS", value, args);
    let csv = dir.path().join("t.csv");
    let track = ["track", s(&seq), "--out", s(&csv)];
    let out = with_env("100000", &track);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).starts_with(
            "warning: RAYON_NUM_THREADS=100000 is over 4096 threads: using one worker thread \
             per core ("
        ),
        "{}",
        stderr(&out)
    );
    let out = with_env("2", &track);
    let err = stderr(&out);
    assert!(
        out.status.success() && !err.contains("RAYON_NUM_THREADS"),
        "{err}"
    );
    // rayon's older variable, read where the first is not set, is checked the same way.
    let out = with("RAYON_RS_NUM_CPUS", "lots", &track);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).starts_with("warning: RAYON_RS_NUM_CPUS=lots is not a whole number"),
        "{}",
        stderr(&out)
    );
    // --jobs outranks it: no warning before the missing list's error.
    let (missing, model) = (dir.path().join("missing.txt"), dir.path().join("m.ridi"));
    let out = with_env(
        "100000",
        &[
            "train",
            "--list",
            s(&missing),
            "--out",
            s(&model),
            "--jobs",
            "1",
        ],
    );
    let err = stderr(&out);
    assert!(
        !err.contains("RAYON_NUM_THREADS") && err.contains("missing.txt"),
        "{err}"
    );
}

#[test]
fn empty_lists_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let list = dir.path().join("empty.txt");
    std::fs::write(&list, "# nothing here yet\n").unwrap();
    let model = dir.path().join("m.ridi");
    let err = error(&ridi(&[
        "train",
        "--list",
        s(&list),
        "--out",
        s(&model),
        "--grid",
        "none",
    ]));
    assert!(
        err.contains(&format!("{}: no sequences listed", list.display())),
        "{err}"
    );
    assert!(!model.exists());
}

#[test]
fn demo_writes_model_reports_and_plots_all_or_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    std::fs::create_dir_all(&data).unwrap();
    let line = |name: &str, label: &str| format!("{},{label}\n", s(&sample_dataset().join(name)));
    std::fs::write(
        data.join("list_train.txt"),
        line("Guillaume_Nexus5_NoDist_Texting", "Texting")
            + &line("Guillaume_Nexus5_NoDist_Swinging", "Swinging"),
    )
    .unwrap();
    // The held-out runs span two phones, as the bundled sample's do: the iPhone run's device
    // comes from its sidecar.
    let test = line("Jakob_Nexus5_NoDist_Texting", "Texting")
        + &line("Thibaud_iPhone4S_NoDist_Texting", "Texting");
    std::fs::write(data.join("list_test.txt"), &test).unwrap();
    let out = dir.path().join("demo");
    let demo = || {
        ridi(&[
            "demo",
            "--data",
            s(&data),
            "--out",
            s(&out),
            "--plots",
            "svg",
        ])
    };
    let run = demo();
    assert!(run.status.success(), "{}", stderr(&run));
    let printed = String::from_utf8_lossy(&run.stdout);
    for says in [
        "RTE 5 s per device (m):",
        "  Nexus 5 (1 sequence): ridi ",
        "  iPhone 4S (1 sequence): ridi ",
    ] {
        assert!(printed.contains(says), "{says:?} not in {printed}");
    }
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("| iPhone 4S | 1 |"), "{md}");
    // The header names the correction the evaluation used.
    assert!(
        md.contains(
            "; correction lambda 0.1, a knot every 50 frames, weights 1 / 1 (horizontal / \
             vertical), initial velocity at rest; ridi "
        ),
        "{md}"
    );
    let report = std::fs::read(out.join("report.json")).unwrap();
    let model = std::fs::read(out.join("model.ridi")).unwrap();
    ridi::regress::Cascade::from_bytes(&model).unwrap();
    assert!(
        out.join("plots/Jakob_Nexus5_NoDist_Texting.trajectory.svg")
            .is_file()
    );

    // A held-out recording too short to track fails the demo at its list line, before
    // training, and the earlier demo's files stay as they were (none added, no staging left).
    let seq = ridi::data::read_sequence(
        sample_dataset().join("Jakob_Nexus5_NoDist_Swinging"),
        &Default::default(),
    )
    .unwrap();
    std::fs::create_dir_all(data.join("short/processed")).unwrap();
    ridi::data::write_ridi_csv(&seq.slice(0..150), data.join("short/processed/data.csv")).unwrap();
    std::fs::write(data.join("list_test.txt"), test + "short,Swinging\n").unwrap();
    let before: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    // Failed, saying each of `says`, without training first.
    let fails_before_training = |run: std::process::Output, says: &[&str]| {
        let err = stderr(&run);
        assert!(
            !run.status.success() && says.iter().all(|s| err.contains(s)),
            "{err}"
        );
        let out = String::from_utf8_lossy(&run.stdout);
        assert!(!out.contains("trained"), "trained first: {out}");
    };
    fails_before_training(
        demo(),
        &["list_test.txt:3: sequence `short`: has 150 frames"],
    );
    let after: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(before, after);
    assert_eq!(std::fs::read(out.join("report.json")).unwrap(), report);
    assert_eq!(std::fs::read(out.join("model.ridi")).unwrap(), model);
    // Into a folder that cannot be made, it fails before training.
    let run = ridi(&[
        "demo",
        "--data",
        s(&data),
        "--out",
        s(&out.join("report.json/x")),
    ]);
    fails_before_training(run, &["cannot write into"]);
    // A held-out recording that is also a training one is refused before training.
    std::fs::write(
        data.join("list_test.txt"),
        line("Guillaume_Nexus5_NoDist_Swinging", "Swinging"),
    )
    .unwrap();
    fails_before_training(
        demo(),
        &[
            "list_test.txt:1: field `path`",
            "already listed at",
            "list_train.txt:2",
        ],
    );
    // So is a copy of one in another folder.
    let copy = data.join("copy/processed");
    std::fs::create_dir_all(&copy).unwrap();
    let swinging = ridi::data::read_sequence(
        sample_dataset().join("Guillaume_Nexus5_NoDist_Swinging"),
        &Default::default(),
    )
    .unwrap();
    ridi::data::write_ridi_csv(&swinging, copy.join("data.csv")).unwrap();
    std::fs::write(data.join("list_test.txt"), "copy,Swinging\n").unwrap();
    fails_before_training(
        demo(),
        &[
            "list_test.txt:1: field `path`",
            "holds the same recording as",
            "list_train.txt:2",
        ],
    );
}

#[test]
fn track_and_eval_without_a_model_use_the_bundled_one_and_say_so() {
    let dir = tempfile::tempdir().unwrap();
    let seq = sample_dataset().join("Thibaud_Nexus5_NoDist_Texting");
    let csv = dir.path().join("t.csv");
    let out = ridi(&["track", s(&seq), "--out", s(&csv)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let said = stderr(&out);
    assert_eq!(
        said.lines().filter(|l| l.contains("bundled model")).count(),
        1,
        "{said}"
    );
    assert!(said.contains("no --model"), "{said}");
    // The same trajectory as with the bundled model's bytes written to a file.
    let file = dir.path().join("bundled.ridi");
    ridi::bundled_model().unwrap().save(&file).unwrap();
    let csv2 = dir.path().join("t2.csv");
    let out = ridi(&["track", s(&seq), "--model", s(&file), "--out", s(&csv2)]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("bundled"));
    assert!(std::fs::read(&csv).unwrap() == std::fs::read(&csv2).unwrap());
    // `ridi eval` likewise.
    let list = sample_dataset().join("list_test.txt");
    let eval = dir.path().join("eval");
    let out = ridi(&[
        "eval",
        "--list",
        s(&list),
        "--out",
        s(&eval),
        "--placement-map",
        "tyrex4",
        "--plots",
        "none",
        "--methods",
        "ridi",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("no --model: using the bundled model"));
    assert!(eval.join("report.json").is_file());
    // A stderr nobody reads any more (`2>&1 | head -1`, a closed terminal) neither stops the
    // run before its file is written nor changes its exit status.
    let csv3 = dir.path().join("t3.csv");
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let status = Command::new(env!("CARGO_BIN_EXE_ridi"))
        .args(["track", s(&seq), "--out", s(&csv3)])
        .stderr(writer)
        .status()
        .unwrap();
    assert!(status.success());
    assert!(std::fs::read(&csv3).unwrap() == std::fs::read(&csv).unwrap());
}

#[test]
fn the_heading_is_the_corrected_gyros_unless_asked_for_the_gyros_alone() {
    // The bundled model is on the estimated orientation: its heading drifts with the gyro,
    // which the recorded orientation corrects by default.
    let dir = tempfile::tempdir().unwrap();
    let seq = sample_dataset().join("Thibaud_iPhone4S_NoDist_Texting");
    let track = |name: &str, extra: &[&str]| {
        let csv = dir.path().join(name);
        let mut args = vec!["track", s(&seq), "--out", s(&csv)];
        args.extend_from_slice(extra);
        let out = ridi(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        std::fs::read_to_string(csv).unwrap()
    };
    let default = track("default.csv", &[]);
    assert_eq!(default, track("corrected.csv", &["--heading", "corrected"]));
    let gyro = track("gyro.csv", &["--heading", "gyro"]);
    assert_eq!(gyro.lines().count(), default.lines().count());
    assert_ne!(gyro, default);
    // Online as in batch.
    assert_ne!(
        track("gyro-online.csv", &["--heading", "gyro", "--online"]),
        track("online.csv", &["--online"])
    );
    let out = ridi(&[
        "track",
        s(&seq),
        "--out",
        s(&dir.path().join("bad.csv")),
        "--heading",
        "magnetic",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("--heading"), "{}", stderr(&out));
    assert!(!dir.path().join("bad.csv").exists());
}

/// A recording paused for 3 s: `ridi inspect` describes a data.csv and `convert
/// --split-at-gaps` cuts it; a RIDI raw folder, whose sensors are interpolated onto the pose's
/// times, keeps the readers' limit of 1 s for both.
#[test]
fn a_recording_paused_for_seconds_is_inspected_and_split_where_its_format_allows() {
    let dir = tempfile::tempdir().unwrap();
    // The sample is gzip-compressed: a plain copy by convert's own writer.
    let plain = dir.path().join("plain");
    let out = ridi(&[
        "convert",
        s(&sample_dataset().join("Jakob_Nexus5_NoDist_Texting")),
        "--out",
        s(&plain),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let csv = plain.join("Jakob_Nexus5_NoDist_Texting/processed/data.csv");
    let lines: Vec<String> = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    let time = lines[0].split(',').position(|c| c == "time").unwrap();
    let mut paused = String::new();
    for (i, l) in lines.iter().enumerate() {
        let mut cells: Vec<String> = l.split(',').map(String::from).collect();
        if i > 2000 {
            let t: i64 = cells[time].parse().unwrap();
            cells[time] = (t + 3_000_000_000).to_string();
        }
        paused += &(cells.join(",") + "\n");
    }
    let walk = dir.path().join("src/walk");
    std::fs::create_dir_all(&walk).unwrap();
    std::fs::write(walk.join("data.csv"), paused).unwrap();
    let out = ridi(&["inspect", s(&walk)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("longest gap 3.005 s") && text.contains("--split-at-gaps 0.1` cuts"),
        "{text}"
    );
    let out = ridi(&["track", s(&walk), "--out", s(&dir.path().join("t.csv"))]);
    let err = stderr(&out);
    assert!(
        !out.status.success() && err.contains("data.csv:2002: field `time`: gap of 3.005 s"),
        "{err}"
    );
    let conv = dir.path().join("conv");
    let out = ridi(&[
        "convert",
        s(&dir.path().join("src")),
        "--out",
        s(&conv),
        "--split-at-gaps",
        "0.1",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(conv.join("walk_part1").is_dir() && conv.join("walk_part2").is_dir());

    let raw = dir.path().join("raw");
    raw_folder(&raw, 9.81, &[]);
    for entry in std::fs::read_dir(&raw).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let shifted: String = text
            .lines()
            .enumerate()
            .map(|(i, l)| match l.split_once(' ') {
                Some((t, rest)) if i > 1000 => {
                    format!("{} {rest}\n", t.parse::<i64>().unwrap() + 3_000_000_000)
                }
                _ => format!("{l}\n"),
            })
            .collect();
        std::fs::write(&path, shifted).unwrap();
    }
    let conv = dir.path().join("conv_raw");
    for args in [
        vec!["inspect", s(&raw)],
        vec![
            "convert",
            s(&raw),
            "--out",
            s(&conv),
            "--split-at-gaps",
            "0.1",
        ],
    ] {
        let err = error(&ridi(&args));
        // The first file checked: gyro.txt.
        assert!(
            err.contains("gyro.txt:1002: field `t`: gap of 3.005 s"),
            "{err}"
        );
    }
    assert!(!conv.exists());
}
