//! The iOS layout of the Tyrex reader on runs built in code: the authors' conventions (g and the
//! opposite sign, `BootTime`, the 90-degree heading turn of the Core Motion attitude) come out as
//! the Android ones, the Qualisys file is found regardless of case, Android and iOS runs are
//! listed side by side, and each kind of bad input is an error naming file, line and field.

use std::f64::consts::FRAC_PI_2;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use ridi_data::ridi_frames::nalgebra::Vector3;
use ridi_data::ridi_frames::{
    DeviceVec, Rot, STANDARD_GRAVITY, World, WorldFromDevice, WorldVec, gravity_in_device,
};
use ridi_data::tyrex::{self, Layout, TyrexOptions};
use ridi_data::{Format, OrientationSource, ReadOptions};
use ridi_test_support::{MatWriter, TYREX_OMEGA, TYREX_TIME_DIFF, assert_names_file, qtm_take};

/// Pitch of the phone about its own x axis, rad: gravity is on device y and z.
const TILT: f64 = 0.5;
/// `[Time] BootTime` of the fixtures: the file times are phone clock + this.
const BOOT: f64 = 145_406.917_9;
/// Accelerometer and gyroscope (attitude) intervals of the iPhone 4S, s.
const ACCE_DT: f64 = 1.0 / 90.0;
const GYRO_DT: f64 = 0.0093;
/// Phone-clock start of the accelerometer and the gyroscope (the iPhone logs its accelerometer
/// 0.7 s before its device motion).
const ACCE_T0: f64 = 0.0174;
const GYRO_T0: f64 = 0.72;

/// The true pose: world (east-north-up, and the mocap room) from device.
fn truth(t: f64) -> WorldFromDevice {
    Rot::<World, World>::from_axis_angle(&Vector3::z_axis(), TYREX_OMEGA * t)
        * WorldFromDevice::from_axis_angle(&Vector3::x_axis(), TILT)
}

/// The quarter turn the authors' loader applies to the Core Motion attitude.
fn heading() -> Rot<World, World> {
    Rot::from_axis_angle(&Vector3::z_axis(), FRAC_PI_2)
}

/// What the accelerometer measures in the Android convention (gravity up, m/s^2): gravity and a
/// small acceleration along device x.
fn specific_force(t: f64) -> DeviceVec {
    gravity_in_device(truth(t), STANDARD_GRAVITY) + DeviceVec::new(0.1 * t.sin(), 0.0, 0.0)
}

/// Rows `t` from `t0` every `dt` for `seconds`, with `row(phone_time)`; file times are phone
/// times plus `offset`.
fn rows(t0: f64, dt: f64, seconds: f64, offset: f64, row: impl Fn(f64) -> String) -> String {
    let mut s = String::new();
    let n = (seconds / dt) as usize;
    for k in 0..n {
        let t = t0 + k as f64 * dt;
        writeln!(s, "{:.9} {}", t + offset, row(t)).unwrap();
    }
    s
}

/// A QTM export of the true pose, `frames` at 60 Hz, the room origin moving along x at 1 m/s
/// from mocap time 0; mocap time = phone time + `TYREX_TIME_DIFF`.
fn qualisys(frames: usize) -> Vec<u8> {
    let mut p = Vec::new();
    let mut r = Vec::new();
    for i in 0..frames {
        let m = i as f64 / 60.0;
        p.push([m * 1000.0, 500.0, 1200.0]);
        let matrix = truth(m - TYREX_TIME_DIFF).matrix();
        r.push(matrix.as_slice().try_into().unwrap());
    }
    MatWriter::LE.file(&qtm_take("Take_1", 60.0, &p, &r), true)
}

/// A Tyrex root in a temporary folder.
struct Root {
    _tmp: tempfile::TempDir,
    root: PathBuf,
}

impl Root {
    fn new() -> Self {
        let tmp = tempfile::tempdir().unwrap();
        let root = tmp.path().join("tyrex");
        std::fs::create_dir_all(root.join("datasets/qualisys")).unwrap();
        Root { _tmp: tmp, root }
    }

    /// An iOS run `name` of 40 s with 30 s of motion capture in `<mat>.mat` (`None`: none).
    fn ios(&self, name: &str, mat: Option<&str>) -> PathBuf {
        let dir = self.root.join("datasets/ios").join(name);
        std::fs::create_dir_all(&dir).unwrap();
        let w = |f: &str, s: String| std::fs::write(dir.join(f), s).unwrap();
        w(
            "accelerometer.txt",
            rows(ACCE_T0, ACCE_DT, 40.0, BOOT, |t| {
                // In g, with Core Motion's sign.
                let a = specific_force(t) * (-1.0 / STANDARD_GRAVITY);
                format!("{:.9} {:.9} {:.9}", a.x(), a.y(), a.z())
            }),
        );
        w(
            "gyroscope.txt",
            rows(GYRO_T0, GYRO_DT, 39.0, BOOT, |t| {
                let g = truth(t).inverse() * WorldVec::new(0.0, 0.0, TYREX_OMEGA);
                format!("{:.9} {:.9} {:.9}", g.x(), g.y(), g.z())
            }),
        );
        w(
            "attitude.txt",
            rows(GYRO_T0, GYRO_DT, 39.0, BOOT, |t| {
                // Core Motion's reference frame: x north, so a quarter turn from ENU.
                let [qw, qx, qy, qz] = (heading().inverse() * truth(t)).to_wxyz();
                format!("{qw:.12} {qx:.12} {qy:.12} {qz:.12}")
            }),
        );
        // As in the shared runs: no line break after the last line.
        w("description.txt", format!("[Time]\nBootTime = {BOOT}"));
        w("timeAlignment.txt", format!("  {TYREX_TIME_DIFF:e}\n"));
        if let Some(mat) = mat {
            let file = self.root.join(format!("datasets/qualisys/{mat}.mat"));
            std::fs::write(file, qualisys(60 * 30)).unwrap();
        }
        dir
    }

    /// An Android run of the same motion, in m/s^2 with Android's sign and no time offset.
    fn android(&self, name: &str) -> PathBuf {
        let dir = self.root.join("datasets/android").join(name);
        std::fs::create_dir_all(&dir).unwrap();
        let w = |f: &str, s: String| std::fs::write(dir.join(f), s).unwrap();
        w(
            "accelerometer.txt",
            rows(0.003, 0.005, 40.0, 0.0, |t| {
                let a = specific_force(t);
                format!("{:.9} {:.9} {:.9}", a.x(), a.y(), a.z())
            }),
        );
        w(
            "gyroscope-calibrated.txt",
            rows(0.004, 0.005, 40.0, 0.0, |t| {
                let g = truth(t).inverse() * WorldVec::new(0.0, 0.0, TYREX_OMEGA);
                format!("{:.9} {:.9} {:.9}", g.x(), g.y(), g.z())
            }),
        );
        w(
            "rotation-vector.txt",
            rows(0.003, 0.005, 40.0, 0.0, |t| {
                let [x, y, z, qw] = truth(t).to_xyzw();
                format!("{x} {y} {z} {qw} 0.17453292")
            }),
        );
        w("timeAlignment.txt", format!("  {TYREX_TIME_DIFF:e}\n"));
        w("record.properties", "[Device]\nModel = Nexus 5\n".into());
        let file = self.root.join(format!("datasets/qualisys/{name}.mat"));
        std::fs::write(file, qualisys(60 * 30)).unwrap();
        dir
    }
}

fn replace_line(text: &str, n: usize, new: &str) -> String {
    text.lines()
        .enumerate()
        .map(|(i, l)| if i + 1 == n { new } else { l })
        .map(|l| format!("{l}\n"))
        .collect()
}

fn edit(dir: &Path, file: &str, f: impl Fn(&str) -> String) {
    let path = dir.join(file);
    let old = std::fs::read_to_string(&path).unwrap();
    std::fs::write(path, f(&old)).unwrap();
}

/// The error of reading `dir`, checked to name `file` (and returned as text).
#[track_caller]
fn err_naming(dir: &Path, file: &str) -> (String, ridi_test_support::Blame) {
    let e = tyrex::read(dir, &TyrexOptions::default()).unwrap_err();
    let path = dir.join(file);
    let blame = assert_names_file(&e, &path);
    (e.to_string(), blame)
}

#[test]
fn units_sign_boot_time_and_heading_come_out_in_the_android_conventions() {
    let root = Root::new();
    let dir = root.ios(
        "Ann_iPhone4S_NoDist_Texting",
        Some("Ann_iPhone4S_NoDist_Texting"),
    );
    let read = tyrex::read(&dir, &TyrexOptions::default()).unwrap();
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    assert_eq!(read.layout, Layout::Ios);
    assert_eq!(read.time_diff_s, Some(TYREX_TIME_DIFF));
    assert_eq!(read.device_model.as_deref(), Some("iPhone 4S"));
    let [seq] = read.sequences.as_slice() else {
        panic!("{} parts", read.sequences.len())
    };
    assert_eq!(seq.placement(), Some("Texting"));
    assert_eq!(
        seq.orientation_source(),
        Some(OrientationSource::CoreMotionAttitude)
    );
    let device = seq.device().unwrap();
    assert_eq!(device.model(), "iPhone 4S");
    // The slower stream, the accelerometer at 90 Hz.
    assert!(
        (device.imu_rate_hz().unwrap() - 90.0).abs() < 0.01,
        "{device:?}"
    );
    // BootTime is subtracted: the mocap starts at phone time 2 s, and the sequence with it.
    let t = seq.time();
    assert!((t[0] - 2.0).abs() < 1e-9, "{}", t[0]);
    assert!((seq.rate_hz() - 200.0).abs() < 1e-6);
    let gt = seq.ground_truth().unwrap();
    for k in (0..seq.len()).step_by(41) {
        let t = seq.time()[k];
        // Units and sign: m/s^2, gravity up along the device's upward axes.
        let expect = specific_force(t);
        assert!(
            (seq.acce()[k] - expect).norm() < 1e-4,
            "{t}: {:?}",
            seq.acce()[k]
        );
        let g = gravity_in_device(truth(t), STANDARD_GRAVITY);
        assert!(g.y() > 4.0 && g.z() > 8.0, "the fixture's phone is pitched");
        // Heading: the attitude turned by +90 degrees is the true east-north-up pose.
        let q = seq.orientation()[k];
        assert!(
            q.angle_to(&truth(t)) < 1e-6,
            "{t}: {}",
            q.angle_to(&truth(t))
        );
        assert!((seq.gravity()[k] - g).norm() < 1e-6);
        assert!((seq.linacce()[k].x() - 0.1 * t.sin()).abs() < 1e-4);
        // Gyro in rad/s as it is.
        let w = truth(t).inverse() * WorldVec::new(0.0, 0.0, TYREX_OMEGA);
        assert!((seq.gyro()[k].to_array()[0] - w.x()).abs() < 1e-9);
        assert!((seq.gyro()[k].norm() - TYREX_OMEGA).abs() < 1e-9);
        // Mocap time = phone time + timeDiff.
        assert!((gt.position[k].x() - (t + TYREX_TIME_DIFF)).abs() < 1e-9);
        assert!(gt.orientation[k].angle_to(&truth(t)) < 1e-6);
    }
    // The file's own quaternion is a quarter turn off: the turn is what makes it agree.
    let first = std::fs::read_to_string(dir.join("attitude.txt")).unwrap();
    let c: Vec<f64> = first
        .lines()
        .next()
        .unwrap()
        .split(' ')
        .map(|v| v.parse().unwrap())
        .collect();
    let raw = WorldFromDevice::from_wxyz([c[1], c[2], c[3], c[4]]).unwrap();
    assert!((raw.angle_to(&truth(GYRO_T0)) - FRAC_PI_2).abs() < 1e-9);

    // Without ground truth the phone streams' overlap is read: the gyro's first time minus
    // BootTime.
    let opts = TyrexOptions {
        ground_truth: false,
        ..TyrexOptions::default()
    };
    let seq = &tyrex::read(&dir, &opts).unwrap().sequences[0];
    assert!((seq.time()[0] - GYRO_T0).abs() < 1e-9, "{}", seq.time()[0]);
    assert!(seq.ground_truth().is_none());
}

#[test]
fn an_ios_run_is_detected_and_read_as_tyrex() {
    let root = Root::new();
    let dir = root.ios("Ann_iPhone4S_NoDist_AR", Some("Ann_iPhone4S_NoDist_AR"));
    assert_eq!(ridi_data::detect(&dir).unwrap(), Format::Tyrex);
    assert_eq!(tyrex::layout_of(&dir).unwrap(), Layout::Ios);
    let seq = ridi_data::read_sequence(&dir, &ReadOptions::default()).unwrap();
    assert_eq!(seq.device().unwrap().model(), "iPhone 4S");
    assert!(seq.ground_truth().is_some());
    let files = ridi_data::source_files(&dir).unwrap();
    for f in ["attitude.txt", "description.txt", "gyroscope.txt"] {
        assert!(files.contains(&dir.join(f)), "{f}: {files:?}");
    }
    assert!(
        files
            .iter()
            .any(|f| f.ends_with("qualisys/Ann_iPhone4S_NoDist_AR.mat"))
    );
    // A folder of only the iOS files but the accelerometer is still one: reading it names what
    // it lacks.
    std::fs::remove_file(dir.join("gyroscope.txt")).unwrap();
    let (e, _) = err_naming(&dir, "gyroscope.txt");
    assert!(e.ends_with(": no such file or folder"), "{e}");
    std::fs::remove_file(dir.join("accelerometer.txt")).unwrap();
    assert_eq!(ridi_data::detect(&dir).unwrap(), Format::Tyrex);
}

#[test]
fn the_qualisys_file_is_found_regardless_of_case() {
    let root = Root::new();
    // The source's spelling: the run `..._Backpocket`, its mocap `..._BackPocket.mat`.
    let dir = root.ios(
        "Jo_iPhone4S_NoDist_Backpocket",
        Some("Jo_iPhone4S_NoDist_BackPocket"),
    );
    let mat = root
        .root
        .join("datasets/qualisys/Jo_iPhone4S_NoDist_BackPocket.mat");
    assert_eq!(tyrex::mat_path(&dir), Some(mat.clone()));
    let listed = tyrex::list_sequences(&root.root).unwrap();
    assert_eq!(listed.runs, std::slice::from_ref(&dir));
    let read = tyrex::read(&dir, &TyrexOptions::default()).unwrap();
    let seq = &read.sequences[0];
    assert!(seq.ground_truth().is_some());
    assert_eq!(seq.name(), "Jo_iPhone4S_NoDist_Backpocket");
    assert_eq!(seq.placement(), Some("BackPocket"));
    assert!(ridi_data::source_files(&dir).unwrap().contains(&mat));

    // Two files that match but for case: which one is meant? An error naming both.
    let other = root
        .root
        .join("datasets/qualisys/Jo_iPhone4S_NoDist_backpocket.mat");
    std::fs::copy(&mat, &other).unwrap();
    if std::fs::read_dir(mat.parent().unwrap()).unwrap().count() == 2 {
        let e = tyrex::read(&dir, &TyrexOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(
                "2 Qualisys files match the run `Jo_iPhone4S_NoDist_Backpocket` but for case"
            ),
            "{e}"
        );
        assert_names_file(&e, &mat);
        // Still listed as a run with motion capture: the reader says what is wrong.
        assert_eq!(
            tyrex::list_sequences(&root.root).unwrap().runs,
            std::slice::from_ref(&dir)
        );
    }
    std::fs::remove_file(&other).unwrap();
    // A Qualisys "file" that is a folder is an error, not a run without ground truth.
    std::fs::remove_file(&mat).unwrap();
    std::fs::create_dir(&mat).unwrap();
    let e = tyrex::read(&dir, &TyrexOptions::default()).unwrap_err();
    assert!(e.to_string().ends_with("is not a regular file"), "{e}");
    assert_names_file(&e, &mat);
}

#[test]
fn android_and_ios_runs_are_listed_side_by_side() {
    let root = Root::new();
    let android = root.android("Ann_Nexus5_NoDist_Texting");
    let ios = root.ios(
        "Ann_iPhone4S_NoDist_Texting",
        Some("Ann_iPhone4S_NoDist_Texting"),
    );
    let old = root.ios("Ann_iPhone4S_NoDist_Texting_old", None);
    let listed = tyrex::list_sequences(&root.root).unwrap();
    assert_eq!(listed.runs, [android.clone(), ios.clone()]);
    assert_eq!(listed.without_mocap, std::slice::from_ref(&old));
    assert_eq!(
        tyrex::list_sequences(root.root.join("datasets")).unwrap(),
        listed
    );
    let only_ios = tyrex::list_sequences(root.root.join("datasets/ios")).unwrap();
    assert_eq!(only_ios.runs, std::slice::from_ref(&ios));
    // Both read, in their own layout, into the same frames: the same motion gives the same
    // accelerometer, gravity and orientation.
    let a = tyrex::read(&android, &TyrexOptions::default()).unwrap();
    let i = tyrex::read(&ios, &TyrexOptions::default()).unwrap();
    assert_eq!((a.layout, i.layout), (Layout::Android, Layout::Ios));
    assert_eq!(a.device_model.as_deref(), Some("Nexus 5"));
    let (a, i) = (&a.sequences[0], &i.sequences[0]);
    assert_eq!(a.len(), i.len());
    for k in (0..a.len()).step_by(97) {
        assert!((a.acce()[k] - i.acce()[k]).norm() < 1e-4);
        assert!((a.gravity()[k] - i.gravity()[k]).norm() < 1e-6);
        assert!(a.orientation()[k].angle_to(&i.orientation()[k]) < 1e-6);
        assert!((a.gyro()[k] - i.gyro()[k]).norm() < 1e-6);
    }
    // A folder with files of both layouts is neither.
    std::fs::copy(
        android.join("rotation-vector.txt"),
        ios.join("rotation-vector.txt"),
    )
    .unwrap();
    let e = tyrex::read(&ios, &TyrexOptions::default()).unwrap_err();
    assert!(
        e.to_string().contains("holds files of both Tyrex layouts: rotation-vector.txt (Android) and attitude.txt (iOS)"),
        "{e}"
    );
    assert_names_file(&e, &ios);
}

#[test]
fn a_model_in_description_txt_names_the_device_and_an_unusable_one_is_a_warning() {
    let root = Root::new();
    let dir = root.ios("Ann_iPhone4S_NoDist_AR", None);
    std::fs::write(
        dir.join("description.txt"),
        format!("[Device]\nModel = iPhone 4S (A1387)\n[Time]\nBootTime = {BOOT}\n"),
    )
    .unwrap();
    let read = tyrex::read(&dir, &TyrexOptions::default()).unwrap();
    assert_eq!(read.device_model.as_deref(), Some("iPhone 4S (A1387)"));
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    std::fs::write(
        dir.join("description.txt"),
        format!("[Device]\nModel = ???\n[Time]\nBootTime = {BOOT}\n"),
    )
    .unwrap();
    let read = tyrex::read(&dir, &TyrexOptions::default()).unwrap();
    assert_eq!(read.device_model.as_deref(), Some("iPhone 4S"));
    assert_eq!(read.warnings.len(), 1, "{:?}", read.warnings);
    assert!(
        read.warnings[0].ends_with(
            "description.txt:2: field `Model`: device model `???` has no ASCII letter or digit \
             to name its list file after: the device is taken from the run's name"
        ),
        "{}",
        read.warnings[0]
    );
}

#[test]
fn a_clipped_accelerometer_is_a_warning() {
    let root = Root::new();
    let dir = root.ios("Ann_iPhone4S_NoDist_RunningHand", None);
    // 5 % of the samples pile up near -2.04 g on x (+20 m/s^2 once the sign is turned), with a
    // little spread, as the iPhone 4S's do.
    edit(&dir, "accelerometer.txt", |s| {
        s.lines()
            .enumerate()
            .map(|(i, l)| {
                let c: Vec<&str> = l.split(' ').collect();
                let x = if i % 20 == 0 {
                    format!("{}", -2.04 - 0.001 * (i % 7) as f64)
                } else {
                    c[1].to_owned()
                };
                format!("{} {x} {} {}\n", c[0], c[2], c[3])
            })
            .collect()
    });
    let read = tyrex::read(&dir, &TyrexOptions::default()).unwrap();
    let clipped: Vec<&String> = read
        .warnings
        .iter()
        .filter(|w| w.contains("clipped"))
        .collect();
    assert_eq!(clipped.len(), 1, "{:?}", read.warnings);
    assert!(
        clipped[0].contains("accelerometer.txt: 5.0 % of the samples are clipped near the largest \
             reading of their axis (+x 20.06 m/s^2, within 3 %): the accelerometer range was exceeded"),
        "{}",
        clipped[0]
    );
    let clean = root.ios("Ann_iPhone4S_NoDist_RunningPocket", None);
    let read = tyrex::read(&clean, &TyrexOptions::default()).unwrap();
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
}

#[test]
fn a_last_record_cut_off_is_left_out_with_a_warning() {
    let root = Root::new();
    let dir = root.ios("Ann_iPhone4S_NoDist_AR", None);
    let text = std::fs::read_to_string(dir.join("attitude.txt")).unwrap();
    let lines = text.lines().count();
    // As `Thibaud_iPhone4S_NoDist_RunningHand/attitude.txt` ends: the last record cut short.
    std::fs::write(dir.join("attitude.txt"), &text[..text.len() - 6]).unwrap();
    let read = tyrex::read(&dir, &TyrexOptions::default()).unwrap();
    assert_eq!(read.warnings.len(), 1, "{:?}", read.warnings);
    let expect = format!(
        "attitude.txt:{lines}: the file ends inside this record, without a line break (cut off \
         while being written): the record is left out"
    );
    assert!(read.warnings[0].ends_with(&expect), "{}", read.warnings[0]);
    // Nothing but a cut record: no samples.
    std::fs::write(dir.join("gyroscope.txt"), "145407.1 0.1 0.2").unwrap();
    let (e, _) = err_naming(&dir, "gyroscope.txt");
    assert!(e.ends_with("no samples: the file is empty"), "{e}");
}

#[test]
fn bad_input_names_file_line_and_field() {
    let root = Root::new();
    let dir = root.ios(
        "Ann_iPhone4S_NoDist_Phoning",
        Some("Ann_iPhone4S_NoDist_Phoning"),
    );
    let fresh = |f: &str| {
        let clean = root.ios("Bo_iPhone4S_NoDist_Phoning", None);
        std::fs::copy(clean.join(f), dir.join(f)).unwrap();
    };
    // (file, edit, expected line and field, words of the message)
    type Edit = Box<dyn Fn(&str) -> String>;
    type Case = (
        &'static str,
        Edit,
        (Option<usize>, Option<&'static str>),
        &'static str,
    );
    let cases: Vec<Case> = vec![
        (
            "accelerometer.txt",
            Box::new(|s| replace_line(s, 3, "145406.96 0.1 abc -0.9")),
            (Some(3), Some("ay")),
            "`abc` is not a number",
        ),
        (
            "attitude.txt",
            Box::new(|s| replace_line(s, 2, "145407.65 1 0 0")),
            (Some(2), None),
            "4 fields, expected 5 (t qw qx qy qz)",
        ),
        (
            "attitude.txt",
            Box::new(|s| {
                replace_line(
                    s,
                    7,
                    &format!("{:.9} 0.9 0.5 0.5 0.5", BOOT + GYRO_T0 + 6.0 * GYRO_DT),
                )
            }),
            (Some(7), Some("qw")),
            "quaternion w,x,y,z has norm 1.2",
        ),
        (
            "gyroscope.txt",
            Box::new(|s| replace_line(s, 5, "145407.0 0 0 0.3")),
            (Some(5), Some("t")),
            "timestamp goes back",
        ),
        (
            "gyroscope.txt",
            Box::new(|s| replace_line(s, 4, "145407.67 0 -1e300 0.3")),
            (Some(4), Some("wy")),
            "-1e300 rad/s is beyond any phone gyroscope",
        ),
        (
            // 1e3 g is beyond any accelerometer once in m/s^2.
            "accelerometer.txt",
            Box::new(|s| {
                replace_line(
                    s,
                    6,
                    &format!("{:.9} 1000 0 -1", BOOT + ACCE_T0 + 5.0 * ACCE_DT),
                )
            }),
            (Some(6), Some("ax")),
            "-9806.65 m/s^2 is beyond any phone accelerometer",
        ),
        (
            // Already in m/s^2: 9.8 times too large.
            "accelerometer.txt",
            Box::new(|s| {
                s.lines()
                    .map(|l| {
                        let c: Vec<f64> = l.split(' ').map(|v| v.parse().unwrap()).collect();
                        let g = STANDARD_GRAVITY;
                        format!("{:.9} {} {} {}\n", c[0], c[1] * g, c[2] * g, c[3] * g)
                    })
                    .collect()
            }),
            (None, Some("ax..az")),
            "times mean |gravity|",
        ),
        (
            "gyroscope.txt",
            Box::new(|s| {
                s.lines()
                    .map(|l| {
                        let c: Vec<f64> = l.split(' ').map(|v| v.parse().unwrap()).collect();
                        let d = f64::to_degrees;
                        format!("{:.9} {} {} {}\n", c[0], d(c[1]), d(c[2]), d(c[3]))
                    })
                    .collect()
            }),
            (None, Some("wx..wz")),
            "gyroscope in deg/s instead of rad/s?",
        ),
        (
            "description.txt",
            Box::new(|_| "[Time]\nStartTime = 3\n".into()),
            (None, Some("BootTime")),
            "no `BootTime = <seconds>` in its `[Time]` section",
        ),
        (
            "description.txt",
            Box::new(|_| "[Other]\nBootTime = 3\n".into()),
            (None, Some("BootTime")),
            "no `BootTime = <seconds>` in its `[Time]` section",
        ),
        (
            "description.txt",
            Box::new(|_| "[Time]\nBootTime = soon".into()),
            (Some(2), Some("BootTime")),
            "`soon` is not a number",
        ),
        (
            "description.txt",
            Box::new(|_| "[Time]\nBootTime = 1e300".into()),
            (None, Some("BootTime")),
            "so far from the time column that subtracting it merges or overflows timestamps",
        ),
        (
            "timeAlignment.txt",
            Box::new(|_| "-2.0 s\n".into()),
            (Some(1), None),
            "unexpected `s` after timeDiff",
        ),
    ];
    for (file, change, (line, field), words) in cases {
        edit(&dir, file, &*change);
        let (e, blame) = err_naming(&dir, file);
        assert!(e.contains(words), "{file}: `{words}` not in: {e}");
        assert_eq!((blame.line, blame.field.as_deref()), (line, field), "{e}");
        if blame.line.is_some() {
            blame.assert_line_in(&std::fs::read(dir.join(file)).unwrap());
        }
        fresh(file);
    }
    tyrex::read(&dir, &TyrexOptions::default()).expect("restored");
    for file in ["description.txt", "attitude.txt"] {
        std::fs::remove_file(dir.join(file)).unwrap();
        let (e, _) = err_naming(&dir, file);
        assert!(e.ends_with(": no such file or folder"), "{e}");
        fresh(file);
    }
}
