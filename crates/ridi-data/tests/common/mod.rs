//! Fixtures shared by the integration tests: small valid sequences and files built in code.
//! They are built from ridi-data's own types, so they stay here; what needs nothing of
//! ridi-data (error assertions, cell edits, file writing, the shared data) is in
//! `ridi-test-support`.

#![allow(dead_code)]

use std::fmt::Write as _;

use ridi_data::ridi_frames::nalgebra::Vector3;
use ridi_data::ridi_frames::{
    Device, DeviceVec, Rot, WorldFromDevice, WorldVec, gravity_in_device,
};
use ridi_data::{
    GroundTruth, OrientationSource, ReadOptions, Row, RowReader, Sequence, SequenceParts, ridi_raw,
};
use ridi_test_support::write_files;

/// First timestamp of the fixtures, ns (a plausible boot-clock value).
pub(crate) const T0_NS: i64 = 172_364_832_413_231;

/// A valid sequence at 200 Hz whose values have many significant digits, so that round trips
/// test float formatting for real. Times are whole nanoseconds, as files store them.
pub(crate) fn sample_sequence(name: &str, n: usize, ground_truth: bool, magnet: bool) -> Sequence {
    let time: Vec<f64> = (0..n)
        .map(|i| (T0_NS + 5_000_000 * i as i64 + (i as i64 * 7919) % 1000) as f64 / 1e9)
        .collect();
    let orientation: Vec<WorldFromDevice> = (0..n)
        .map(|i| {
            let t = i as f64 / 200.0;
            WorldFromDevice::from_scaled_axis(Vector3::new(0.3 * t.sin(), 0.2, 0.7 * t))
        })
        .collect();
    let gravity: Vec<DeviceVec> = orientation
        .iter()
        .map(|q| gravity_in_device(*q, 9.80665))
        .collect();
    let wave = |i: usize, k: f64| {
        DeviceVec::new(
            (k * i as f64).sin() / 3.0,
            (k * i as f64).cos() * 0.7,
            k / 7.0,
        )
    };
    let linacce: Vec<DeviceVec> = (0..n).map(|i| wave(i, 0.11)).collect();
    Sequence::new(SequenceParts {
        name: name.to_owned(),
        placement: None,
        // The orientation's own rotation rate (the readers check the gyro against it), with a
        // wave on top so that no two channels are alike.
        gyro: (0..n)
            .map(|i| {
                let (a, b) = if i + 1 < n { (i, i + 1) } else { (i - 1, i) };
                let step = orientation[a].inverse() * orientation[b];
                let rate = step.quaternion().scaled_axis() * 200.0;
                DeviceVec::new(rate.x, rate.y, rate.z) + wave(i, 0.37) * 0.2
            })
            .collect(),
        acce: linacce.iter().zip(&gravity).map(|(a, g)| *a + *g).collect(),
        linacce,
        gravity,
        magnet: magnet.then(|| (0..n).map(|i| wave(i, 0.05) * 40.0).collect()),
        ground_truth: ground_truth.then(|| GroundTruth {
            position: (0..n)
                .map(|i| WorldVec::new(i as f64 * 0.0071, (i as f64 * 0.01).sin(), 1.234567))
                .collect(),
            orientation: orientation
                .iter()
                .map(|q| *q * Rot::<Device, Device>::from_scaled_axis(Vector3::new(0.0, 0.0, 0.1)))
                .collect(),
        }),
        orientation,
        orientation_source: Some(OrientationSource::GameRotationVector),
        steps: None,
        device: None,
        time,
    })
    .expect("fixture sequence is valid")
}

/// The bytes of a valid RIDI `data.csv` with ground truth and magnet.
pub(crate) fn valid_csv(n: usize) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("data.csv");
    ridi_data::write_ridi_csv(&sample_sequence("s", n, true, true), &path).unwrap();
    std::fs::read(path).unwrap()
}

/// The bytes of a valid `data_plain.txt`.
pub(crate) fn valid_plain(n: usize) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("data_plain.txt");
    ridi_data::write_ridi_plain(&sample_sequence("s", n, true, true), &path).unwrap();
    std::fs::read(path).unwrap()
}

/// Options for the small raw fixtures: fewer pose records trimmed than the original's 800.
pub(crate) fn raw_options() -> ReadOptions {
    ReadOptions {
        pose_trim: 5,
        ..ReadOptions::default()
    }
}

/// The files of a valid raw folder: sensors at 200 Hz starting slightly before the pose, pose
/// at 200 Hz with a 1 ms offset, each file with a `#` header. Channels are linear in time
/// (value = seconds since start times a per-channel factor) so interpolation is checkable.
pub(crate) fn raw_files(n: usize, with_pose: bool) -> Vec<(&'static str, String)> {
    let sensor = |name: &'static str, factor: f64, base: [f64; 3]| {
        let mut s = String::from("# t_ns x y z\n");
        for i in 0..n + 20 {
            let t_ns = T0_NS + 5_000_000 * i as i64;
            let t = (5_000_000 * i as i64) as f64 / 1e9;
            let _ = writeln!(
                s,
                "{t_ns} {} {} {}",
                base[0] + factor * t,
                base[1],
                base[2] - factor * t
            );
        }
        (name, s)
    };
    let mut files = vec![
        // About the rate and axis the rotation vector below turns at (0.4 rad/s about y, slowly
        // drifting), as the readers check.
        sensor("gyro.txt", 0.005, [0.0, 0.4, 0.0]),
        sensor("acce.txt", 0.2, [0.0, 9.9, 0.3]),
        sensor("linacce.txt", 0.2, [0.0, 0.1, 0.3]),
        sensor("gravity.txt", 0.0, [0.0, 9.8, 0.0]),
        sensor("magnet.txt", 1.0, [20.0, -30.0, 5.0]),
    ];
    let mut rv = String::from("# t_ns x y z w\n");
    let mut steps = String::from("# t_ns count\n");
    for i in 0..n + 20 {
        let t_ns = T0_NS + 5_000_000 * i as i64;
        // The phone upright (its y axis up, along gravity) and turning about the vertical:
        // Rz(2 * half) * Rx(90 degrees), as x y z w.
        let half = 0.001 * i as f64;
        let (c, s) = (half.cos(), half.sin());
        let r = std::f64::consts::FRAC_1_SQRT_2;
        let _ = writeln!(rv, "{t_ns} {} {} {} {}", r * c, r * s, r * s, r * c);
        if i % 100 == 0 {
            let _ = writeln!(steps, "{t_ns} {}", i / 100);
        }
    }
    files.push(("orientation.txt", rv));
    files.push(("step.txt", steps));
    if with_pose {
        let mut pose = String::from("# t_ns tx ty tz qx qy qz qw\n");
        for i in 0..n {
            let t_ns = T0_NS + 1_000_000 + 5_000_000 * i as i64;
            let _ = writeln!(pose, "{t_ns} {} 0.5 1.5 0 0 0 1", 0.01 * i as f64);
        }
        files.push(("pose.txt", pose));
    }
    files
}

/// Reads a raw folder of `raw_files(60, true)` after `edit`, and checks that it streams as it
/// reads ([`assert_streams_as_read`]).
pub(crate) fn raw_with(
    edit: impl FnOnce(&mut Vec<(&'static str, String)>),
) -> (tempfile::TempDir, ridi_data::Result<Sequence>) {
    let dir = tempfile::tempdir().unwrap();
    let mut files = raw_files(60, true);
    edit(&mut files);
    write_files(dir.path(), &files);
    let r = ridi_raw::read(dir.path(), &raw_options());
    assert_streams_as_read(dir.path(), &raw_options(), &r);
    (dir, r)
}

/// The rows of the recording at `path` read as a stream, finished, or the error.
pub(crate) fn streamed(path: &std::path::Path, opts: &ReadOptions) -> Result<Vec<Row>, String> {
    drain(RowReader::open(path, opts).map_err(|e| e.to_string())?)
}

/// The rows of `rows` to its end, finished, or the error.
fn drain(mut rows: RowReader) -> Result<Vec<Row>, String> {
    let mut out = Vec::new();
    for row in rows.by_ref() {
        out.push(row.map_err(|e| e.to_string())?);
    }
    rows.finish().map_err(|e| e.to_string())?;
    Ok(out)
}

/// The bits of every value of `row`, in one order.
fn row_bits(row: &Row) -> Vec<u64> {
    let mut v = vec![row.time];
    for x in [row.gyro, row.acce, row.linacce, row.gravity] {
        v.extend(x.to_array());
    }
    v.extend(row.magnet.map(|m| m.to_array()).into_iter().flatten());
    v.extend(row.orientation.to_wxyz());
    if let Some((p, o)) = row.ground_truth {
        v.extend(p.to_array());
        v.extend(o.to_wxyz());
    }
    v.extend(row.steps);
    v.into_iter().map(f64::to_bits).collect()
}

/// Frame `i` of `seq` as the [`Row`] a stream of it gives.
pub(crate) fn frame(seq: &Sequence, i: usize) -> Row {
    Row {
        time: seq.time()[i],
        gyro: seq.gyro()[i],
        acce: seq.acce()[i],
        linacce: seq.linacce()[i],
        gravity: seq.gravity()[i],
        magnet: seq.magnet().map(|m| m[i]),
        orientation: seq.orientation()[i],
        ground_truth: seq
            .ground_truth()
            .map(|gt| (gt.position[i], gt.orientation[i])),
        steps: seq.steps().map(|s| s[i]),
    }
}

/// Asserts that the recording at `path` read as a stream ([`RowReader`]) gives the frames of
/// `whole`, what the whole-file reader read, bit for bit, with its name and flags; or the
/// same error (file, line, field, message).
pub(crate) fn assert_streams_as_read(
    path: &std::path::Path,
    opts: &ReadOptions,
    whole: &ridi_data::Result<Sequence>,
) {
    // Opened once: its name and flags are checked before it streams its rows.
    let reader = RowReader::open(path, opts).map_err(|e| e.to_string());
    let (seq, reader) = match (whole, reader) {
        (Err(e), reader) => {
            let stream = reader.and_then(drain);
            assert_eq!(stream.map(|_| ()), Err(e.to_string()), "{}", path.display());
            return;
        }
        (Ok(_), Err(e)) => panic!("{}: streams as an error: {e}", path.display()),
        (Ok(seq), Ok(reader)) => (seq, reader),
    };
    assert_eq!(reader.name(), seq.name());
    assert_eq!(reader.orientation_source(), seq.orientation_source());
    assert_eq!(reader.has_magnet(), seq.magnet().is_some());
    assert_eq!(reader.has_steps(), seq.steps().is_some());
    let rows =
        drain(reader).unwrap_or_else(|e| panic!("{}: streams as an error: {e}", path.display()));
    assert_eq!(rows.len(), seq.len(), "{}", path.display());
    for (i, row) in rows.iter().enumerate() {
        let expected = frame(seq, i);
        assert_eq!(row_bits(row), row_bits(&expected), "frame {i}: {row:?}");
    }
}
