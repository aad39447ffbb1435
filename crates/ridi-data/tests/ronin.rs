//! The RoNIN reader on small HDF5 files in RoNIN's layout, written by h5py
//! (`tests/ronin/make_fixtures.py`, run by hand, its output committed): reading, the
//! orientation-source choice and the calibration arithmetic against numbers the script computed
//! with numpy as RoNIN's loader does, and bad input.

use std::path::{Path, PathBuf};

use ridi_data::ronin::{self, RoninOptions, RoninOrientation};
use ridi_data::{
    DataError, Format, Hdf5File, OrientationSource, ReadOptions, detect, read_sequence,
    source_files,
};
use ridi_test_support::assert_names_file;
use serde_json::Value;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/ronin")
}

fn expected() -> Value {
    let text = std::fs::read_to_string(fixtures().join("variants/expected.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// A sequence folder `name` in `dir` with the valid data.hdf5 and the info.json `info`.
fn assemble(dir: &Path, name: &str, info: &Path) -> PathBuf {
    let folder = dir.join(name);
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::copy(
        fixtures().join("a000_1/data.hdf5"),
        folder.join("data.hdf5"),
    )
    .unwrap();
    std::fs::copy(info, folder.join("info.json")).unwrap();
    folder
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// Compares a read sequence with what the script computed with numpy.
#[track_caller]
fn check_against_numpy(read: &ronin::RoninSequence, want: &Value) {
    let seq = &read.sequence;
    assert_eq!(read.orientation.name(), want["source"].as_str().unwrap());
    assert_eq!(
        read.orientation_error,
        want["source_error"].as_f64().unwrap()
    );
    assert_eq!(seq.len() as u64, want["len"].as_u64().unwrap());
    let gt = seq.ground_truth().unwrap();
    for f in want["frames"].as_array().unwrap() {
        let i = f["index"].as_u64().unwrap() as usize;
        assert!(close(seq.time()[i], f["time"].as_f64().unwrap(), 1e-15));
        for (got, key, tol) in [
            (seq.gyro()[i].to_array().to_vec(), "gyro", 1e-14),
            (seq.acce()[i].to_array().to_vec(), "acce", 1e-14),
            (gt.position[i].to_array().to_vec(), "position", 1e-14),
            (
                seq.orientation()[i].to_wxyz().to_vec(),
                "orientation_wxyz",
                1e-9,
            ),
        ] {
            let want = numbers(&f[key]);
            assert!(
                got.iter().zip(&want).all(|(&g, &w)| close(g, w, tol)),
                "frame {i} {key}: read {got:?}, numpy {want:?}"
            );
        }
        // The ground-truth orientation is the device orientation aligned to the Tango world.
        assert_eq!(gt.orientation[i], seq.orientation()[i]);
    }
}

#[test]
fn reads_the_sequence_as_ronins_loader_does() {
    let folder = fixtures().join("a000_1");
    let read = ronin::read(&folder, &RoninOptions::default()).unwrap();
    check_against_numpy(&read, &expected()["a000_1"]);
    let seq = &read.sequence;
    assert_eq!(seq.name(), "a000_1");
    assert_eq!(read.start_frame, 20);
    assert_eq!(read.orientation, RoninOrientation::GameRotationVector);
    assert_eq!(
        seq.orientation_source(),
        Some(OrientationSource::GameRotationVector)
    );
    assert_eq!(seq.device().map(|d| d.model()), Some("asus4"));
    assert!(seq.magnet().is_some());
    assert_eq!(seq.placement(), None);
    // Android's gravity and linear acceleration sensors, as RoNIN's RIDI baseline reads them:
    // the accelerometer (calibrated) is their sum.
    for i in [0, seq.len() / 2, seq.len() - 1] {
        let sum = seq.gravity()[i] + seq.linacce()[i];
        assert!((sum - seq.acce()[i]).norm() < 1e-9, "frame {i}");
        // Gravity points up in the aligned orientation's world.
        let up = seq.orientation()[i] * seq.gravity()[i];
        assert!(
            up.z() > 9.8 && up.x().abs() < 1e-6 && up.y().abs() < 1e-6,
            "{up:?}"
        );
    }

    // Detected, and read through the generic entry point, from the folder or its files.
    for path in [
        folder.clone(),
        folder.join("data.hdf5"),
        folder.join("info.json"),
    ] {
        assert_eq!(detect(&path).unwrap(), Format::Ronin, "{}", path.display());
    }
    assert_eq!(
        read_sequence(&folder, &ReadOptions::default()).unwrap(),
        *seq
    );
    assert_eq!(
        source_files(&folder).unwrap(),
        vec![folder.join("data.hdf5"), folder.join("info.json")]
    );
}

#[test]
fn the_orientation_source_is_chosen_as_ronin_chooses_it() {
    let dir = tempfile::tempdir().unwrap();
    let want = expected();
    let variants = fixtures().join("variants");
    for (name, source) in [
        ("info_ekf", OrientationSource::Ekf),
        ("info_gyro", OrientationSource::GyroIntegration),
    ] {
        let folder = assemble(dir.path(), name, &variants.join(format!("{name}.json")));
        let read = ronin::read(&folder, &RoninOptions::default()).unwrap();
        check_against_numpy(&read, &want[name]);
        assert_eq!(read.sequence.orientation_source(), Some(source));
    }
    // grv_only forces the game rotation vector whatever the errors.
    let folder = dir.path().join("info_ekf");
    let opts = RoninOptions {
        grv_only: true,
        ..RoninOptions::default()
    };
    let read = ronin::read(&folder, &opts).unwrap();
    check_against_numpy(&read, &want["info_ekf_grv_only"]);
    // max_ori_error above grv_ori_error (25) does too.
    let opts = RoninOptions {
        max_ori_error: 30.0,
        ..RoninOptions::default()
    };
    let read = ronin::read(&folder, &opts).unwrap();
    assert_eq!(read.orientation, RoninOrientation::GameRotationVector);
}

#[test]
fn python_non_finite_errors_read_as_numpy_compares_them() {
    // json.dump writes NaN: numpy's comparison is false, its argmin picks the NaN.
    let dir = tempfile::tempdir().unwrap();
    let info = std::fs::read_to_string(fixtures().join("variants/info_ekf.json")).unwrap();
    let info = info.replace(
        "\"gyro_integration_error\": 7.5",
        "\"gyro_integration_error\": NaN",
    );
    assert!(info.contains("NaN"));
    let path = dir.path().join("info.json");
    std::fs::write(&path, info).unwrap();
    let folder = assemble(dir.path(), "nan", &path);
    let read = ronin::read(&folder, &RoninOptions::default()).unwrap();
    assert_eq!(read.orientation, RoninOrientation::GyroIntegration);
    assert!(read.orientation_error.is_nan());
}

#[test]
fn the_hdf5_reader_reads_h5pys_latest_format_too() {
    let path = fixtures().join("variants/latest.hdf5");
    let file = Hdf5File::read(&path).unwrap();
    let time = file.read_f64("synced/time").unwrap().unwrap();
    assert_eq!(time.shape, vec![40]);
    assert_eq!(time.data[0], 1234.5);
    assert_eq!(time.data[39], 1234.5 + 39.0 / 200.0);
    let rv = file.read_f64("synced/game_rv").unwrap().unwrap();
    assert_eq!(rv.shape, vec![40, 4]);
    let norm: f64 = rv.data[..4].iter().map(|c| c * c).sum();
    assert!((norm - 1.0).abs() < 1e-12);
    assert!(file.read_f64("synced/nothing").unwrap().is_none());
    assert!(file.read_f64("nothing/at/all").unwrap().is_none());
    let e = file.read_f64("synced").unwrap_err();
    assert!(e.to_string().contains("is a group"), "{e}");
    let pos = file.read_f64("pose/tango_pos").unwrap().unwrap();
    assert_eq!(pos.shape, vec![40, 3]);
    // More than 8 links: dense storage, refused with an error naming the dataset.
    let e = file.read_f64("dense/d0").unwrap_err();
    let blame = assert_names_file(&e, &path);
    assert_eq!(blame.field.as_deref(), Some("dense/d0"));
    assert!(e.to_string().contains("dense storage"), "{e}");
}

/// The error of reading the bad fixture `name`, checked to name `file` of it and `field`.
#[track_caller]
fn bad(name: &str, file: &str, field: &str) -> String {
    let folder = fixtures().join("bad").join(name);
    let e = ronin::read(&folder, &RoninOptions::default()).unwrap_err();
    let blame = assert_names_file(&e, &folder.join(file));
    assert_eq!(blame.field.as_deref(), Some(field), "{e}");
    assert!(matches!(e, DataError::Format { .. }), "{e:?}");
    e.to_string()
}

#[test]
fn bad_input_is_an_error_naming_the_file_and_the_dataset() {
    let e = bad("missing_dataset", "data.hdf5", "synced/acce");
    assert!(e.contains("no dataset synced/acce"), "{e}");
    let e = bad("wrong_shape", "data.hdf5", "synced/acce");
    assert!(e.contains("shape (40, 2), expected (N, 3)"), "{e}");
    let e = bad("wrong_type", "data.hdf5", "synced/gyro_uncalib");
    assert!(e.contains("has type integer of 4 bytes"), "{e}");
    let e = bad("wrong_length", "data.hdf5", "pose/tango_pos");
    assert!(e.contains("39 rows, but synced/time has 40"), "{e}");
    let e = bad("chunked", "data.hdf5", "synced/game_rv");
    assert!(e.contains("compressed"), "{e}");
    let e = bad("info_without_field", "info.json", "imu_acce_bias");
    assert!(e.contains("missing"), "{e}");
}

#[test]
fn a_truncated_file_is_an_error_naming_it_never_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let folder = assemble(dir.path(), "a000_1", &fixtures().join("a000_1/info.json"));
    let full = std::fs::read(fixtures().join("a000_1/data.hdf5")).unwrap();
    let data = folder.join("data.hdf5");
    // Every cut through the headers, then coarser ones through the data.
    let cuts = (0..4096.min(full.len()))
        .step_by(7)
        .chain((4096..full.len()).step_by(997));
    for cut in cuts {
        std::fs::write(&data, &full[..cut]).unwrap();
        let e = ronin::read(&folder, &RoninOptions::default()).unwrap_err();
        let blame = assert_names_file(&e, &data);
        // Past the superblock, the error names the dataset being read.
        assert!(
            cut < 100 || blame.field.as_deref() == Some("synced/time"),
            "cut at {cut}: {e}"
        );
    }
    // Cut inside the data of the datasets: the message says so.
    std::fs::write(&data, &full[..full.len() - 1000]).unwrap();
    let e = ronin::read(&folder, &RoninOptions::default()).unwrap_err();
    assert!(e.to_string().contains("truncated"), "{e}");
}

#[test]
fn corrupt_bytes_give_errors_never_panics() {
    let full = std::fs::read(fixtures().join("a000_1/data.hdf5")).unwrap();
    let info = std::fs::read(fixtures().join("a000_1/info.json")).unwrap();
    let folder = Path::new("a000_1");
    // Flip bytes all through the metadata, a few at a time.
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for round in 0..3000 {
        let mut bytes = full.clone();
        for _ in 0..1 + round % 4 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let at = (state as usize) % 6000.min(bytes.len());
            bytes[at] = (state >> 32) as u8;
        }
        let _ = ronin::parse(bytes, &info, folder, &RoninOptions::default());
    }
}

#[test]
fn info_json_problems_name_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let original = std::fs::read_to_string(fixtures().join("a000_1/info.json")).unwrap();
    let cases: [(&str, &str, &str, &str); 7] = [
        (
            "\"imu_acce_scale\": [",
            "\"imu_acce_scale\": [\"x\", ",
            "imu_acce_scale",
            "expected a list of 3 numbers",
        ),
        // Calibrations far from any phone's, named here, not on the data they would scale.
        (
            "\"imu_acce_scale\": [\n  1.01",
            "\"imu_acce_scale\": [\n  1e308",
            "imu_acce_scale",
            "1e308 is outside 0.5..2: an accelerometer scale near 1",
        ),
        (
            "\"imu_init_gyro_bias\": [\n  0.012",
            "\"imu_init_gyro_bias\": [\n  50",
            "imu_init_gyro_bias",
            "50 is outside -1..1: a gyro bias in rad/s",
        ),
        (
            "\"imu_acce_bias\": [\n  0.11",
            "\"imu_acce_bias\": [\n  9.81",
            "imu_acce_bias",
            "9.81 is outside -5..5: an accelerometer bias in m/s^2",
        ),
        (
            "\"start_frame\": 20",
            "\"start_frame\": 5000",
            "start_frame",
            "leaves fewer than 2",
        ),
        (
            "\"start_frame\": 20",
            "\"start_frame\": -1",
            "start_frame",
            "a frame index",
        ),
        (
            "\"grv_ori_error\": 3.25",
            "\"grv_ori_error\": \"low\"",
            "grv_ori_error",
            "expected a number",
        ),
    ];
    for (i, (from, to, field, says)) in cases.into_iter().enumerate() {
        assert!(original.contains(from), "{from}");
        let path = dir.path().join(format!("info{i}.json"));
        std::fs::write(&path, original.replacen(from, to, 1)).unwrap();
        let folder = assemble(dir.path(), &format!("s{i}"), &path);
        let e = ronin::read(&folder, &RoninOptions::default()).unwrap_err();
        let blame = assert_names_file(&e, &folder.join("info.json"));
        assert_eq!(blame.field.as_deref(), Some(field), "{e}");
        assert!(e.to_string().contains(says), "{e}");
    }
    // Not JSON at all: the line is named.
    let path = dir.path().join("broken.json");
    std::fs::write(&path, "{\n\"a\": [1,\n").unwrap();
    let folder = assemble(dir.path(), "broken", &path);
    let e = ronin::read(&folder, &RoninOptions::default()).unwrap_err();
    let blame = assert_names_file(&e, &folder.join("info.json"));
    assert!(blame.line.is_some(), "{e}");
}
