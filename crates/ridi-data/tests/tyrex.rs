//! Tyrex reader on synthetic folders: known motion in, known sequence out, and an error naming
//! file, line and field for each kind of bad input.

use std::f64::consts::FRAC_PI_2;
use std::fmt::Write as _;
use std::path::PathBuf;

use ridi_data::ridi_frames::{DeviceVec, STANDARD_GRAVITY};
use ridi_data::tyrex::{self, TyrexOptions};
use ridi_data::{DataError, OrientationSource};
use ridi_test_support::{
    MatArray, MatWriter, TYREX_OMEGA, TYREX_TIME_DIFF, qtm_take, tyrex_mocap, tyrex_phone_rows, yaw,
};

/// A synthetic run (`ridi_test_support`'s): the phone lies flat, turns about z at
/// `TYREX_OMEGA` rad/s and moves along room x at 1 m/s. Phone samples at 200 Hz from 0.003 s
/// for `phone_s` seconds; `frames` mocap frames at 60 Hz, phone time = mocap time + 2 s.
struct Fixture {
    _tmp: tempfile::TempDir,
    root: PathBuf,
    dir: PathBuf,
    mat: PathBuf,
}

fn phone_rows(phone_s: f64, row: impl Fn(f64) -> String) -> String {
    tyrex_phone_rows(200.0, phone_s, row)
}

impl Fixture {
    fn new(name: &str, phone_s: f64, mocap_frames: usize, lost: &[std::ops::Range<usize>]) -> Self {
        let tmp = tempfile::tempdir().unwrap();
        let root = tmp.path().join("tyrex");
        let dir = root.join("datasets/android").join(name);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::create_dir_all(root.join("datasets/qualisys")).unwrap();
        let w = |f: &str, s: String| std::fs::write(dir.join(f), s).unwrap();
        w(
            "accelerometer.txt",
            phone_rows(phone_s, |t| format!("{t:.9} {} 0.0 9.80665", 0.1 * t.sin())),
        );
        w(
            "gyroscope-calibrated.txt",
            phone_rows(phone_s, |t| {
                format!("{:.9} 0.0 0.0 {TYREX_OMEGA}", t + 0.001)
            }),
        );
        w(
            "rotation-vector.txt",
            phone_rows(phone_s, |t| {
                let [x, y, z, q] = yaw(TYREX_OMEGA * t).to_xyzw();
                format!("{t:.9} {x} {y} {z} {q} 0.17453292")
            }),
        );
        w("timeAlignment.txt", format!("  {TYREX_TIME_DIFF:e}\n"));
        w(
            "record.properties",
            "[Device]\nManufacturer = LGE\nModel = Nexus 5\n[Time]\nStartTime = 1".into(),
        );
        let (p, r) = tyrex_mocap(mocap_frames, lost);
        let vars = qtm_take("Take_1", 60.0, &p, &r);
        let mat = root.join("datasets/qualisys").join(format!("{name}.mat"));
        std::fs::write(&mat, MatWriter::LE.file(&vars, true)).unwrap();
        Fixture {
            _tmp: tmp,
            root,
            dir,
            mat,
        }
    }

    fn standard() -> Self {
        Self::new("Ann_Nexus5_NoDist_Texting", 40.0, 60 * 30, &[])
    }

    fn write(&self, file: &str, content: &str) {
        std::fs::write(self.dir.join(file), content).unwrap();
    }

    fn edit(&self, file: &str, f: impl Fn(&str) -> String) {
        let old = std::fs::read_to_string(self.dir.join(file)).unwrap();
        self.write(file, &f(&old));
    }

    fn err(&self) -> String {
        tyrex::read(&self.dir, &TyrexOptions::default())
            .unwrap_err()
            .to_string()
    }
}

/// `text` with line `n` (1-based) replaced, every line ending in a line break as in the fixture files.
fn replace_line(text: &str, n: usize, new: &str) -> String {
    text.lines()
        .enumerate()
        .map(|(i, l)| if i + 1 == n { new } else { l })
        .map(|l| format!("{l}\n"))
        .collect()
}

#[test]
fn known_motion_comes_out_aligned_resampled_and_in_the_right_frames() {
    let fx = Fixture::standard();
    let read = tyrex::read(&fx.dir, &TyrexOptions::default()).unwrap();
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    assert_eq!(read.time_diff_s, Some(TYREX_TIME_DIFF));
    assert_eq!(read.device_model.as_deref(), Some("Nexus 5"));
    let [seq] = read.sequences.as_slice() else {
        panic!("{} parts", read.sequences.len())
    };
    assert_eq!(seq.name(), "Ann_Nexus5_NoDist_Texting");
    assert_eq!(seq.placement(), Some("Texting"));
    assert_eq!(
        seq.orientation_source(),
        Some(OrientationSource::RotationVector)
    );
    // Mocap covers phone time 2.0 .. 2 + 1799/60; phone streams 0.004 .. 39.999.
    let t = seq.time();
    assert!((t[0] - 2.0).abs() < 1e-12, "{}", t[0]);
    assert!((t[t.len() - 1] - (2.0 + 1799.0 / 60.0)).abs() <= 0.005);
    assert!((seq.rate_hz() - 200.0).abs() < 1e-9);
    let gt = seq.ground_truth().unwrap();
    for k in (0..seq.len()).step_by(37) {
        let t = seq.time()[k];
        let mocap_t = t - 2.0;
        let p = gt.position[k];
        assert!(
            (p.x() - mocap_t).abs() < 1e-9 && (p.y() - 0.5).abs() < 1e-12,
            "{t} {p:?}"
        );
        assert!(
            gt.orientation[k].angle_to(&yaw(TYREX_OMEGA * mocap_t)) < 1e-6,
            "{t}"
        );
        assert!(
            seq.orientation()[k].angle_to(&yaw(TYREX_OMEGA * t)) < 1e-6,
            "{t}"
        );
        assert!((seq.gyro()[k] - DeviceVec::new(0.0, 0.0, TYREX_OMEGA)).norm() < 1e-12);
        // Flat phone: gravity is +z in the device frame, whatever the heading.
        assert!((seq.gravity()[k] - DeviceVec::new(0.0, 0.0, STANDARD_GRAVITY)).norm() < 1e-9);
        let lin = seq.linacce()[k];
        assert!(
            (lin.x() - 0.1 * t.sin()).abs() < 1e-5 && lin.z().abs() < 1e-9,
            "{lin:?}"
        );
    }
}

#[test]
fn short_mocap_losses_are_bridged_and_long_ones_split() {
    // 6 lost frames: 7/60 s between tracked frames, bridged. 21 lost: 22/60 s, split.
    let fx = Fixture::new(
        "Bo_Nexus5_NoDist_Swinging",
        40.0,
        60 * 30,
        &[300..306, 900..921],
    );
    let read = tyrex::read(&fx.dir, &TyrexOptions::default()).unwrap();
    let names: Vec<&str> = read.sequences.iter().map(|s| s.name()).collect();
    assert_eq!(
        names,
        [
            "Bo_Nexus5_NoDist_Swinging_part1",
            "Bo_Nexus5_NoDist_Swinging_part2"
        ]
    );
    assert_eq!(read.warnings.len(), 1, "{:?}", read.warnings);
    assert!(
        read.warnings[0].contains("mocap lost the body once (up to 0.367 s; 16.98-17.35 s, phone"),
        "{:?}",
        read.warnings
    );
    let (a, b) = (&read.sequences[0], &read.sequences[1]);
    assert!((a.time()[a.len() - 1] - (2.0 + 899.0 / 60.0)).abs() < 0.005);
    assert!((b.time()[0] - (2.0 + 921.0 / 60.0)).abs() < 1e-12);
    // Across the bridged loss the straight-line motion is interpolated exactly.
    let gt = a.ground_truth().unwrap();
    for (k, &t) in a.time().iter().enumerate() {
        assert!((gt.position[k].x() - (t - 2.0)).abs() < 1e-9);
    }
    // With a larger limit nothing splits.
    let opts = TyrexOptions {
        max_mocap_gap_s: 0.5,
        ..TyrexOptions::default()
    };
    assert_eq!(tyrex::read(&fx.dir, &opts).unwrap().sequences.len(), 1);
    // Parts shorter than min_part_s are dropped with a warning.
    let opts = TyrexOptions {
        min_part_s: 14.8,
        ..TyrexOptions::default()
    };
    // Parts of 14.98 s and 14.63 s: the second goes, the first keeps the plain name.
    let read = tyrex::read(&fx.dir, &opts).unwrap();
    assert_eq!(read.sequences.len(), 1);
    assert_eq!(read.sequences[0].name(), "Bo_Nexus5_NoDist_Swinging");
    assert!(
        read.warnings
            .iter()
            .any(|w| w.contains("Swinging: 1 part shorter than 14.8 s dropped (14.6"))
    );
}

/// The mocap solves the body turned by half a turn about the vertical for half a second: the
/// tilt agrees with the phone's, so only the gyro can tell. The reader cuts the stretch out as a
/// mocap loss, splitting the run, and says when; told to trust the mocap, it keeps the flip.
#[test]
fn a_mocap_flip_the_gyro_contradicts_is_cut_out_with_a_warning() {
    let fx = Fixture::standard();
    let (p, mut r) = tyrex_mocap(60 * 30, &[]);
    for (i, rot) in r.iter_mut().enumerate().take(930).skip(900) {
        let m = yaw(TYREX_OMEGA * i as f64 / 60.0 + std::f64::consts::PI).matrix();
        *rot = m.as_slice().try_into().unwrap();
    }
    std::fs::write(
        &fx.mat,
        MatWriter::LE.file(&qtm_take("Take_1", 60.0, &p, &r), true),
    )
    .unwrap();
    let read = tyrex::read(&fx.dir, &TyrexOptions::default()).unwrap();
    let flips: Vec<&String> = read
        .warnings
        .iter()
        .filter(|w| w.contains("the rigid body was solved flipped there"))
        .collect();
    assert_eq!(flips.len(), 1, "{:?}", read.warnings);
    // Mocap frames 900..930 are at 17.0-17.483 s on the phone clock: suspect windows from a
    // window (0.1 s) before the first to a window after the last, then 0.25 s margins.
    assert!(flips[0].contains("(16.65-17.83 s"), "{}", flips[0]);
    assert!(
        flips[0].contains(&format!("{}", fx.mat.display())),
        "{}",
        flips[0]
    );
    assert_eq!(read.sequences.len(), 2, "{:?}", read.warnings);
    for seq in &read.sequences {
        let gt = seq.ground_truth().unwrap();
        for (k, &t) in seq.time().iter().enumerate() {
            let expected = yaw(TYREX_OMEGA * (t - 2.0));
            assert!(gt.orientation[k].angle_to(&expected) < 1e-6, "{t}");
            assert!(!(16.65..=17.83).contains(&t), "{t}");
        }
    }
    let trusting = TyrexOptions {
        max_mocap_gyro_rad: f64::INFINITY,
        ..TyrexOptions::default()
    };
    let read = tyrex::read(&fx.dir, &trusting).unwrap();
    assert_eq!(read.sequences.len(), 1);
    assert!(
        read.warnings.iter().all(|w| !w.contains("flipped")),
        "{:?}",
        read.warnings
    );
}

#[test]
fn warnings_escape_control_characters_in_the_paths_they_name() {
    let fx = Fixture::standard();
    // The run's folder under a root whose name holds a line break and a terminal escape.
    let root = fx.root.with_file_name("ty\nrex\u{1b}[2J");
    std::fs::rename(&fx.root, &root).unwrap();
    let dir = root.join(fx.dir.strip_prefix(&fx.root).unwrap());
    let path = dir.join("gyroscope-calibrated.txt");
    let text = std::fs::read_to_string(&path).unwrap();
    let kept: String = text
        .lines()
        .filter(|l| !l.starts_with("20."))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&path, kept).unwrap();
    let read = tyrex::read(&dir, &TyrexOptions::default()).unwrap();
    let gap = read
        .warnings
        .iter()
        .find(|w| w.contains("gap of"))
        .expect("a gap warning");
    assert!(!gap.chars().any(char::is_control), "{gap:?}");
    assert!(gap.contains("ty\\nrex\\u{1b}[2J/"), "{gap}");
}

#[test]
fn a_gap_in_a_phone_stream_splits_and_names_its_line() {
    let fx = Fixture::standard();
    // Drop 1 s of gyro samples around phone time 20 s.
    fx.edit("gyroscope-calibrated.txt", |s| {
        s.lines()
            .filter(|l| {
                let t: f64 = l.split(' ').next().unwrap().parse().unwrap();
                !(19.5..20.5).contains(&t)
            })
            .map(|l| format!("{l}\n"))
            .collect()
    });
    let read = tyrex::read(&fx.dir, &TyrexOptions::default()).unwrap();
    assert_eq!(read.sequences.len(), 2);
    assert!(
        read.warnings[0]
            .contains("gyroscope-calibrated.txt:3901: gap of 1.005 s in the samples at 19.499 s"),
        "{:?}",
        read.warnings
    );
}

#[test]
fn without_a_mat_file_there_is_no_ground_truth() {
    let fx = Fixture::standard();
    let read = tyrex::read(
        &fx.dir,
        &TyrexOptions {
            ground_truth: false,
            ..TyrexOptions::default()
        },
    )
    .unwrap();
    assert!(read.sequences[0].ground_truth().is_none() && read.time_diff_s.is_none());
    std::fs::remove_file(&fx.mat).unwrap();
    // timeAlignment.txt is only needed with ground truth.
    std::fs::remove_file(fx.dir.join("timeAlignment.txt")).unwrap();
    let read = tyrex::read(&fx.dir, &TyrexOptions::default()).unwrap();
    let seq = &read.sequences[0];
    assert!(seq.ground_truth().is_none());
    // The overlap of the phone streams: gyro starts 1 ms late.
    assert!((seq.time()[0] - 0.004).abs() < 1e-12);
    assert!(seq.duration() > 39.9);
}

#[test]
fn lists_sequence_folders_from_the_root() {
    let fx = Fixture::standard();
    std::fs::create_dir_all(fx.root.join("datasets/android/not_a_sequence")).unwrap();
    let found = tyrex::list_sequences(&fx.root).unwrap();
    assert_eq!(found.runs, std::slice::from_ref(&fx.dir));
    assert!(found.without_mocap.is_empty() && found.warning().is_none());
    assert_eq!(
        tyrex::list_sequences(fx.root.join("datasets/android")).unwrap(),
        found
    );
    // An earlier take kept without motion capture is listed apart, with one warning.
    let old = fx
        .root
        .join("datasets/android/Ann_Nexus5_NoDist_Texting_old");
    std::fs::create_dir_all(&old).unwrap();
    std::fs::copy(
        fx.dir.join("accelerometer.txt"),
        old.join("accelerometer.txt"),
    )
    .unwrap();
    let found = tyrex::list_sequences(&fx.root).unwrap();
    assert_eq!(found.runs, std::slice::from_ref(&fx.dir));
    assert_eq!(found.without_mocap, std::slice::from_ref(&old));
    let warning = found.warning().unwrap();
    assert!(
        warning.starts_with("1 run folder without a Qualisys file")
            && warning.ends_with(&format!("skipped: {}", old.display())),
        "{warning}"
    );
    let e = tyrex::list_sequences(fx.root.join("datasets/qualisys")).unwrap_err();
    assert!(e.to_string().contains("no Tyrex sequence folder"), "{e}");
    let e = tyrex::list_sequences(fx.root.join("nowhere")).unwrap_err();
    assert!(
        e.to_string()
            .contains("nowhere: not a Tyrex run or root (no such file or folder)"),
        "{e}"
    );
}

#[test]
fn unknown_motion_means_no_placement_and_a_warning() {
    let fx = Fixture::new("Ann_Nexus5_NoDist_Dancing", 40.0, 900, &[]);
    let read = tyrex::read(&fx.dir, &TyrexOptions::default()).unwrap();
    assert_eq!(read.sequences[0].placement(), None);
    assert!(
        read.warnings[0].contains("known motion"),
        "{:?}",
        read.warnings
    );
}

#[test]
fn rotation_vector_without_w_or_accuracy_is_accepted() {
    let fx = Fixture::standard();
    fx.edit("rotation-vector.txt", |s| {
        s.lines()
            .map(|l| {
                let c: Vec<f64> = l.split(' ').map(|x| x.parse().unwrap()).collect();
                // Without w, Android implies w >= 0: write the sign that makes it so.
                let s = if c[4] < 0.0 { -1.0 } else { 1.0 };
                format!("{} {} {} {}\n", c[0], s * c[1], s * c[2], s * c[3])
            })
            .collect()
    });
    let read = tyrex::read(&fx.dir, &TyrexOptions::default()).unwrap();
    let seq = &read.sequences[0];
    let k = seq.len() / 2;
    assert!(seq.orientation()[k].angle_to(&yaw(TYREX_OMEGA * seq.time()[k])) < 1e-6);
}

fn assert_err(fx: &Fixture, expect: &[&str]) {
    let e = fx.err();
    for part in expect {
        assert!(e.contains(part), "`{part}` not in: {e}");
    }
}

#[test]
fn text_errors_name_file_line_and_field() {
    let fx = Fixture::standard();
    fx.edit("accelerometer.txt", |s| {
        replace_line(s, 3, "0.013 0.1 abc 9.8")
    });
    assert_err(
        &fx,
        &["accelerometer.txt:3: field `ay`: `abc` is not a number"],
    );

    let fx = Fixture::standard();
    fx.edit("gyroscope-calibrated.txt", |s| {
        replace_line(s, 2, "0.009 0.0 0.0")
    });
    assert_err(
        &fx,
        &["gyroscope-calibrated.txt:2: 3 fields, expected 4 (t wx wy wz)"],
    );

    let fx = Fixture::standard();
    fx.edit("rotation-vector.txt", |s| {
        replace_line(s, 5, "0.001 0 0 0 1 0.1")
    });
    assert_err(
        &fx,
        &["rotation-vector.txt:5: field `t`: timestamp goes back"],
    );

    let fx = Fixture::standard();
    fx.edit("rotation-vector.txt", |s| {
        replace_line(s, 4, "0.0181 0 0 0 1 0.1")
    });
    fx.edit("rotation-vector.txt", |s| {
        replace_line(s, 5, "0.0181 0 0 0 1 0.1")
    });
    assert_err(
        &fx,
        &["rotation-vector.txt:5: field `t`: duplicate timestamp"],
    );

    let fx = Fixture::standard();
    fx.edit("rotation-vector.txt", |s| {
        replace_line(s, 7, "0.033 0.5 0.5 0.5 0.9 0.1")
    });
    assert_err(
        &fx,
        &["rotation-vector.txt:7: field `qw`: quaternion x,y,z,w has norm 1.2"],
    );

    let fx = Fixture::standard();
    fx.edit("accelerometer.txt", |s| {
        replace_line(s, 9, "0.043 0.1 NaN 9.8")
    });
    assert_err(&fx, &["accelerometer.txt:9: field `ay`"]);

    let fx = Fixture::standard();
    fx.write("accelerometer.txt", "\n\n");
    assert_err(&fx, &["accelerometer.txt: no samples: the file is empty"]);

    let fx = Fixture::standard();
    fx.write("timeAlignment.txt", "");
    assert_err(&fx, &["timeAlignment.txt: empty"]);

    let fx = Fixture::standard();
    fx.write("timeAlignment.txt", "-3.7 s\n");
    assert_err(&fx, &["timeAlignment.txt:1: unexpected `s` after timeDiff"]);

    let fx = Fixture::standard();
    fx.write("timeAlignment.txt", "minus three\n");
    assert_err(
        &fx,
        &["timeAlignment.txt:1: field `timeDiff`: `minus` is not a number"],
    );

    let fx = Fixture::standard();
    std::fs::remove_file(fx.dir.join("gyroscope-calibrated.txt")).unwrap();
    let e = tyrex::read(&fx.dir, &TyrexOptions::default()).unwrap_err();
    assert!(
        matches!(&e, DataError::Io { path, .. } if path.ends_with("gyroscope-calibrated.txt")),
        "{e}"
    );
}

#[test]
fn phone_files_cut_before_their_last_line_break_are_refused() {
    let fx = Fixture::standard();
    let text = std::fs::read_to_string(fx.dir.join("accelerometer.txt")).unwrap();
    let last = text.lines().count();
    // `... 9.80665` cut to `... 9.806`: still a number, so only the missing break tells.
    fx.write("accelerometer.txt", &text[..text.len() - 3]);
    assert_err(
        &fx,
        &[&format!(
            "accelerometer.txt:{last}: the file ends inside this record, without a line break"
        )],
    );

    // The one-number `timeAlignment.txt` is exempt: a real one lacks its final break.
    let fx = Fixture::standard();
    fx.write("timeAlignment.txt", &format!("  {TYREX_TIME_DIFF:e}"));
    tyrex::read(&fx.dir, &TyrexOptions::default()).unwrap();
}

/// `f` applied to the columns `cols` of every row of a phone file.
fn scale_columns(text: &str, cols: std::ops::Range<usize>, f: impl Fn(f64) -> f64) -> String {
    let mut out = String::new();
    for l in text.lines() {
        let mut c: Vec<String> = l.split(' ').map(str::to_owned).collect();
        for v in &mut c[cols.clone()] {
            *v = f(v.parse().unwrap()).to_string();
        }
        writeln!(out, "{}", c.join(" ")).unwrap();
    }
    out
}

#[test]
fn implausible_values_and_units_name_file_line_and_field() {
    let fx = Fixture::standard();
    fx.edit("gyroscope-calibrated.txt", |s| {
        scale_columns(s, 1..4, f64::to_degrees)
    });
    assert_err(
        &fx,
        &[
            "gyroscope-calibrated.txt: field `wx..wz`: median |gyro| 17.189 rad/s is above 10 rad/s: \
           gyroscope in deg/s instead of rad/s?",
        ],
    );

    let fx = Fixture::standard();
    fx.edit("accelerometer.txt", |s| {
        scale_columns(s, 1..4, |v| v / STANDARD_GRAVITY)
    });
    assert_err(
        &fx,
        &[
            "accelerometer.txt: field `ax..az`: mean |acce| 1 m/s^2 is 0.102 times mean |gravity|",
            "accelerometer in g instead of m/s^2?",
        ],
    );

    // Milliseconds where seconds are expected.
    let fx = Fixture::standard();
    fx.edit("accelerometer.txt", |s| {
        scale_columns(s, 0..1, |t| t * 1000.0)
    });
    assert_err(
        &fx,
        &[
            "accelerometer.txt: field `t`: timestamps step by 5 s (median), outside 1e-4..1 s: \
           time in milliseconds instead of seconds (divide by 1000)? (this format expects \
           seconds)",
        ],
    );

    let fx = Fixture::standard();
    fx.edit("accelerometer.txt", |s| {
        replace_line(s, 3, "0.013 1e308 0.0 9.8")
    });
    assert_err(
        &fx,
        &[
            "accelerometer.txt:3: field `ax`: 1e308 m/s^2 is beyond any phone accelerometer \
           (|value| <= 2000 m/s^2)",
        ],
    );

    let fx = Fixture::standard();
    fx.edit("gyroscope-calibrated.txt", |s| {
        replace_line(s, 4, "0.019 0.0 -1e300 0.3")
    });
    assert_err(
        &fx,
        &["gyroscope-calibrated.txt:4: field `wy`: -1e300 rad/s is beyond any phone gyroscope"],
    );
}

fn with_mat(vars: Vec<(String, MatArray)>) -> Fixture {
    let fx = Fixture::standard();
    std::fs::write(&fx.mat, MatWriter::LE.file(&vars, false)).unwrap();
    fx
}

fn mat_file_name(fx: &Fixture) -> String {
    fx.mat.file_name().unwrap().to_string_lossy().into_owned()
}

#[test]
fn mat_errors_name_the_file_and_field() {
    let (p, r) = tyrex_mocap(600, &[]);

    let fx = with_mat(vec![(
        "Take_1".into(),
        MatArray::Struct(vec![(
            "FrameRate".into(),
            MatArray::Num(vec![1, 1], vec![60.0]),
        )]),
    )]);
    assert_err(
        &fx,
        &[
            &mat_file_name(&fx),
            "field `RigidBodies`",
            "variables: Take_1",
        ],
    );

    let mut vars = qtm_take("Take_1", 60.0, &p, &r);
    if let MatArray::Struct(fields) = &mut vars[0].1
        && let Some((_, MatArray::Struct(rb))) = fields.iter_mut().find(|(n, _)| n == "RigidBodies")
    {
        rb.retain(|(n, _)| n != "Positions");
    }
    let fx = with_mat(vars);
    assert_err(
        &fx,
        &[
            &mat_file_name(&fx),
            "field `Take_1.RigidBodies.Positions`: no field `Positions` in `Take_1.RigidBodies`",
        ],
    );

    let fx = with_mat(qtm_take("Take_1", 60.0, &p, &r[..599]));
    assert_err(
        &fx,
        &["field `Take_1.RigidBodies.Rotations`: 599 frames, but Positions has 600"],
    );

    let fx = with_mat(qtm_take("Take_1", 0.0, &p, &r));
    assert_err(
        &fx,
        &["field `Take_1.FrameRate`: expected one positive number"],
    );

    let mut bad = r.clone();
    bad[42][0] = 2.0;
    let fx = with_mat(qtm_take("Take_1", 60.0, &p, &bad));
    assert_err(
        &fx,
        &["field `Take_1.RigidBodies.Rotations`: frame 43 is not a rotation matrix"],
    );

    // A reflection is orthonormal but not a rotation.
    let mut bad = r.clone();
    bad[7] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0];
    let fx = with_mat(qtm_take("Take_1", 60.0, &p, &bad));
    assert_err(&fx, &["frame 8 is not a rotation matrix", "det = -1"]);

    let lost = vec![[f64::NAN; 3]; 600];
    let fx = with_mat(qtm_take("Take_1", 60.0, &lost, &r));
    assert_err(&fx, &["every frame is NaN"]);
}

/// Mocap rotations go through `Rot::from_matrix`: a scaled matrix or a reflection is an error
/// naming the file, the field and the frame; the rounding of a real export is accepted and
/// gives the nearest rotation.
#[test]
fn mocap_matrices_that_are_not_rotations_name_file_field_and_frame() {
    let (p, r) = tyrex_mocap(600, &[]);

    // 2 I: the unchecked conversion made it a "unit" quaternion with w = 1.32.
    let mut bad = r.clone();
    bad[99] = [2.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0];
    let fx = with_mat(qtm_take("Take_1", 60.0, &p, &bad));
    assert_err(
        &fx,
        &[
            &mat_file_name(&fx),
            "field `Take_1.RigidBodies.Rotations`: frame 100 is not a rotation matrix",
            "|R'R - I| = 3.00e0",
            "at most 1e-3",
            "det = 8.000",
        ],
    );
    let e = tyrex::read_ground_truth(&fx.mat).unwrap_err();
    assert!(matches!(e, DataError::Format { .. }), "{e:?}");

    // diag(-1, 1, 1): orthonormal, but a reflection.
    let mut bad = r.clone();
    bad[0] = [-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    let fx = with_mat(qtm_take("Take_1", 60.0, &p, &bad));
    assert_err(
        &fx,
        &[
            "field `Take_1.RigidBodies.Rotations`: frame 1 is not a rotation matrix",
            "|R'R - I| = 0.00e0",
            "det = -1.000",
        ],
    );

    // Perturbed by 1e-6 (the Tyrex exports are within 1e-7 of orthonormal): accepted, unit,
    // and within a few microradians of the true rotation. The standard fixture's 30 s of mocap,
    // so that the whole run can be read too.
    let (p, r) = tyrex_mocap(60 * 30, &[]);
    let mut noisy = r.clone();
    for (k, m) in noisy.iter_mut().enumerate() {
        for (j, v) in m.iter_mut().enumerate() {
            *v += 1e-6 * if (k + j) % 3 == 0 { 1.0 } else { -0.5 };
        }
    }
    let fx = with_mat(qtm_take("Take_1", 60.0, &p, &noisy));
    let track = tyrex::read_ground_truth(&fx.mat).unwrap();
    assert_eq!(track.valid_count(), 60 * 30);
    for (i, pose) in track.pose.iter().enumerate() {
        let q = pose.unwrap().orientation;
        assert!((q.quaternion().norm() - 1.0).abs() < 1e-14);
        let truth = yaw(TYREX_OMEGA * i as f64 / 60.0);
        assert!(
            q.angle_to(&truth) < 1e-5,
            "frame {i}: {}",
            q.angle_to(&truth)
        );
    }
    assert_eq!(
        tyrex::read(&fx.dir, &TyrexOptions::default())
            .unwrap()
            .sequences
            .len(),
        1
    );
}

#[test]
fn truncated_or_mangled_mat_is_an_error_naming_it() {
    let fx = Fixture::standard();
    let bytes = std::fs::read(&fx.mat).unwrap();
    std::fs::write(&fx.mat, &bytes[..bytes.len() / 2]).unwrap();
    assert_err(
        &fx,
        &[
            &mat_file_name(&fx),
            "field `Take_1.RigidBodies.Rotations`",
            "truncated",
            "of the compressed element at byte 128",
        ],
    );

    let fx = with_mat(qtm_take(
        "Take_1",
        60.0,
        &tyrex_mocap(600, &[]).0,
        &tyrex_mocap(600, &[]).1,
    ));
    let bytes = std::fs::read(&fx.mat).unwrap();
    std::fs::write(&fx.mat, &bytes[..bytes.len() - 1000]).unwrap();
    assert_err(
        &fx,
        &[
            &mat_file_name(&fx),
            "field `Take_1.RigidBodies.Rotations`",
            "truncated",
        ],
    );

    let fx = Fixture::standard();
    std::fs::write(&fx.mat, b"").unwrap();
    assert_err(&fx, &[&mat_file_name(&fx), "the file is empty"]);
}

#[test]
fn bad_options_are_rejected() {
    let fx = Fixture::standard();
    let e = tyrex::read(
        &fx.dir,
        &TyrexOptions {
            rate_hz: 0.0,
            ..TyrexOptions::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("rate_hz"), "{e}");
    // A rate that would make a timeline of billions of frames is refused before it is built.
    let e = tyrex::read(
        &fx.dir,
        &TyrexOptions {
            rate_hz: 1e12,
            ..TyrexOptions::default()
        },
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("expected from 1.001 to 9990 Hz"),
        "{e}"
    );
    let with = |edit: fn(&mut TyrexOptions)| {
        let mut o = TyrexOptions::default();
        edit(&mut o);
        tyrex::read(&fx.dir, &o).unwrap_err().to_string()
    };
    for (e, field) in [
        (with(|o| o.max_sensor_gap_s = f64::NAN), "max_sensor_gap_s"),
        (
            with(|o| o.max_sensor_gap_s = f64::INFINITY),
            "max_sensor_gap_s",
        ),
        (with(|o| o.max_mocap_gap_s = f64::NAN), "max_mocap_gap_s"),
        (
            with(|o| o.max_mocap_tilt_deg = f64::NAN),
            "max_mocap_tilt_deg",
        ),
        (with(|o| o.min_part_s = -1.0), "min_part_s"),
        (with(|o| o.gravity = 0.0), "gravity"),
        (
            with(|o| o.extra_time_diff_s = f64::NAN),
            "extra_time_diff_s",
        ),
    ] {
        assert!(e.contains(&format!("field `{field}`")), "{e}");
    }
    for bad in [0.0, -1.0, f64::NAN] {
        let e = tyrex::read(
            &fx.dir,
            &TyrexOptions {
                max_mocap_gyro_rad: bad,
                ..TyrexOptions::default()
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("max_mocap_gyro_rad"), "{e}");
    }
    let e = tyrex::read(
        &fx.dir,
        &TyrexOptions {
            min_part_s: 1000.0,
            ..TyrexOptions::default()
        },
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("no stretch of at least 1000 s"),
        "{e}"
    );
}

#[test]
fn read_ground_truth_gives_mocap_rate_frames() {
    let fx = Fixture::new(
        "Ann_Nexus5_NoDist_AR",
        20.0,
        120,
        std::slice::from_ref(&(10..12)),
    );
    let track = tyrex::read_ground_truth(&fx.mat).unwrap();
    assert_eq!(
        (track.rate_hz, track.pose.len(), track.valid_count()),
        (60.0, 120, 118)
    );
    assert_eq!(track.variable, "Take_1");
    assert!((track.time[90] - 1.5).abs() < 1e-12);
    let p = track.pose[90].unwrap();
    assert!((p.position.x() - 1.5).abs() < 1e-12 && (p.position.z() - 1.2).abs() < 1e-12);
    assert!(p.orientation.angle_to(&yaw(TYREX_OMEGA * 1.5)) < 1e-9);
    // Column-major 3x3: a quarter turn about z maps device x to room y.
    let q = yaw(FRAC_PI_2);
    let v = q * DeviceVec::new(1.0, 0.0, 0.0);
    assert!((v.y() - 1.0).abs() < 1e-12);
    assert!(track.pose[10].is_none() && track.pose[11].is_none());
}

#[test]
fn source_files_of_a_run_include_its_ground_truth_beside_the_android_folder() {
    let fx = Fixture::standard();
    let files = ridi_data::source_files(&fx.dir).unwrap();
    assert!(files.contains(&fx.mat), "{files:?}");
    assert!(
        files.contains(&fx.dir.join("accelerometer.txt")),
        "{files:?}"
    );
    assert!(
        files.contains(&fx.dir.join("rotation-vector.txt")),
        "{files:?}"
    );
}

/// The OS orientation of a real run (`Jakob_Nexus5_Dist_BackPocket`) jumps for a few frames at
/// hundreds of rad/s; one least-squares fit over all frames took that for a gyro in another
/// unit. The run reads, with one warning giving the jumps' times; bridging them by the gyro is
/// an option.
#[test]
fn os_orientation_jumps_are_a_warning_not_a_gyro_unit_error() {
    let fx = Fixture::standard();
    // Three jumps: the rotation vector turns by 1.5 rad for 4 frames (300 rad/s) and back.
    fx.edit("rotation-vector.txt", |old| {
        old.lines()
            .enumerate()
            .map(|(i, l)| {
                let c: Vec<f64> = l.split(' ').map(|v| v.parse().unwrap()).collect();
                let glitch = [1000..1004, 3000..3004, 5000..5004]
                    .iter()
                    .any(|r| r.contains(&i));
                let q = yaw(TYREX_OMEGA * c[0] + if glitch { 1.5 } else { 0.0 });
                let [x, y, z, w] = q.to_xyzw();
                format!("{} {x} {y} {z} {w} {}\n", c[0], c[5])
            })
            .collect()
    });
    let read = tyrex::read(&fx.dir, &TyrexOptions::default()).unwrap();
    let [seq] = read.sequences.as_slice() else {
        panic!("{} parts", read.sequences.len())
    };
    let jumps = seq.orientation_jumps();
    assert_eq!(jumps.len(), 3, "{jumps:?}");
    // Phone time 0.003 + 0.005 i; the jump spans the frames around the glitch.
    for (j, i) in jumps.iter().zip([1000, 3000, 5000]) {
        let t = 0.003 + 0.005 * i as f64;
        assert!(j.time.0 <= t && j.time.1 >= t + 0.015, "{j:?} vs {t}");
        assert!(j.peak_rate > 100.0, "{j:?}");
        // Out by 1.5 rad and back.
        assert!((j.excess_angle - 3.0).abs() < 0.2, "{j:?}");
    }
    let warning: Vec<&String> = read
        .warnings
        .iter()
        .filter(|w| w.contains("orientation jumps"))
        .collect();
    assert_eq!(warning.len(), 1, "{:?}", read.warnings);
    assert!(
        warning[0].contains("rotation-vector.txt: the orientation jumps 3 times")
            && warning[0].contains("at 5.00-5.03 s, 14.99-15.03 s, 25.00-25.02 s (phone clock)")
            && warning[0].contains("left out of the gyro check"),
        "{}",
        warning[0]
    );
    assert!(!warning[0].contains("bridged"), "{}", warning[0]);
    // Asked to, the reader bridges them by the gyro: the same warning says so, and the
    // orientation turns with the gyro throughout (here, back to the recorded heading).
    let bridging = TyrexOptions {
        bridge_orientation_jumps: true,
        ..TyrexOptions::default()
    };
    let bridged = tyrex::read(&fx.dir, &bridging).unwrap();
    let warning = bridged
        .warnings
        .iter()
        .find(|w| w.contains("orientation jumps"))
        .unwrap();
    assert!(
        warning.ends_with("; bridged by the gyro, the heading kept across them"),
        "{warning}"
    );
    let b = &bridged.sequences[0];
    assert!(b.orientation_jumps().is_empty());
    let in_jump = |t: f64| jumps.iter().any(|j| (j.time.0..=j.time.1).contains(&t));
    let worst = b
        .orientation()
        .iter()
        .zip(seq.orientation())
        .zip(b.time())
        .filter(|(_, t)| !in_jump(**t))
        .map(|((a, r), _)| a.angle_to(r))
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-6,
        "{worst} rad from the recorded orientation away from the glitches"
    );
    // A clean run has none, and reads the same either way.
    let clean = Fixture::standard();
    let read = tyrex::read(&clean.dir, &TyrexOptions::default()).unwrap();
    assert!(read.sequences[0].orientation_jumps().is_empty());
    let raw = tyrex::read(&clean.dir, &bridging).unwrap();
    assert_eq!(read.sequences, raw.sequences);
}
