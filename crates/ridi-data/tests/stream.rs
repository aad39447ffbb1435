//! The streaming reader against the whole-file one: the same rows, and for a recording with
//! one fault the same error (file, line, field and message).

use std::io::Write as _;
use std::path::{Path, PathBuf};

use ridi_data::ridi_frames::{DeviceVec, WorldFromDevice, WorldVec};
use ridi_data::{
    GroundTruth, OrientationSource, ReadOptions, RowReader, Sequence, SequenceParts, read_sequence,
    write_ridi_csv, write_ridi_plain,
};

/// A valid walk of `n` frames at 200 Hz, turning slowly, with magnetometer and ground truth.
fn walk(n: usize) -> Sequence {
    let time: Vec<f64> = (0..n)
        .map(|i| (1_000_000_000 + 5_000_000 * i as u64) as f64 / 1e9)
        .collect();
    let orientation: Vec<WorldFromDevice> = (0..n)
        .map(|i| {
            WorldFromDevice::from_scaled_axis(ridi_data::ridi_frames::nalgebra::Vector3::new(
                0.0,
                0.0,
                0.002 * i as f64,
            ))
        })
        .collect();
    let wobble = |i: usize| (i as f64 * 0.1).sin();
    Sequence::new(SequenceParts {
        name: "walk".into(),
        time,
        gyro: (0..n)
            .map(|i| DeviceVec::new(0.01 * wobble(i), 0.02, 0.4))
            .collect(),
        acce: (0..n)
            .map(|i| DeviceVec::new(0.3 * wobble(i), 9.8, 0.1))
            .collect(),
        linacce: (0..n)
            .map(|i| DeviceVec::new(0.3 * wobble(i), 0.0, 0.1))
            .collect(),
        gravity: vec![DeviceVec::new(0.0, 9.8, 0.0); n],
        magnet: Some(vec![DeviceVec::new(20.0, -5.0, 40.0); n]),
        orientation: orientation.clone(),
        orientation_source: Some(OrientationSource::GameRotationVector),
        ground_truth: Some(GroundTruth {
            position: (0..n)
                .map(|i| WorldVec::new(0.005 * i as f64, 0.0, 1.0))
                .collect(),
            orientation,
        }),
        ..Default::default()
    })
    .unwrap()
}

/// The rows of `path` read as a stream, or its error.
fn streamed(path: &Path) -> Result<Vec<ridi_data::Row>, String> {
    let mut rows = RowReader::open(path, &ReadOptions::default()).map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    for row in rows.by_ref() {
        out.push(row.map_err(|e| e.to_string())?);
    }
    rows.finish().map_err(|e| e.to_string())?;
    Ok(out)
}

/// Writes `text` as `name` in `dir`.
fn file(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_valid_recording_streams_as_the_sequence_it_reads_as() {
    let dir = tempfile::tempdir().unwrap();
    let seq = walk(600);
    let csv = dir.path().join("walk.csv");
    write_ridi_csv(&seq, &csv).unwrap();
    let plain = dir.path().join("walk_plain.txt");
    write_ridi_plain(&seq, &plain).unwrap();
    // The same file gzip-compressed.
    let gz = dir.path().join("walk.csv.gz");
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    enc.write_all(&std::fs::read(&csv).unwrap()).unwrap();
    std::fs::write(&gz, enc.finish().unwrap()).unwrap();
    for path in [&csv, &plain, &gz] {
        let read = read_sequence(path, &ReadOptions::default()).unwrap();
        let rows = streamed(path).unwrap();
        assert_eq!(rows.len(), read.len(), "{}", path.display());
        let gt = read.ground_truth().unwrap();
        for (i, r) in rows.iter().enumerate() {
            assert_eq!(r.time, read.time()[i]);
            assert_eq!(r.gyro, read.gyro()[i]);
            assert_eq!(r.acce, read.acce()[i]);
            assert_eq!(r.linacce, read.linacce()[i]);
            assert_eq!(r.gravity, read.gravity()[i]);
            assert_eq!(r.orientation, read.orientation()[i]);
            assert_eq!(Some(r.magnet.unwrap()), read.magnet().map(|m| m[i]));
            let (p, o) = r.ground_truth.unwrap();
            assert_eq!((p, o), (gt.position[i], gt.orientation[i]));
        }
        let reader = RowReader::open(path, &ReadOptions::default()).unwrap();
        assert_eq!(reader.name(), read.name());
        assert_eq!(reader.orientation_source(), read.orientation_source());
    }
}

#[test]
fn a_recording_with_one_fault_gets_the_whole_file_readers_error() {
    let dir = tempfile::tempdir().unwrap();
    let seq = walk(400);
    let good = dir.path().join("good.csv");
    write_ridi_csv(&seq, &good).unwrap();
    let text = std::fs::read_to_string(&good).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    let column = |name: &str| header.iter().position(|&h| h == name).unwrap();
    // `text` with `f` applied to the cells of data line `row` (from 0).
    let edit = |rows: &[usize], f: &dyn Fn(&mut Vec<String>)| -> String {
        let mut out = String::new();
        for (i, l) in lines.iter().enumerate() {
            let mut cells: Vec<String> = l.split(',').map(String::from).collect();
            if i > 0 && rows.contains(&(i - 1)) {
                f(&mut cells);
            }
            out.push_str(&cells.join(","));
            out.push('\n');
        }
        out
    };
    let all: Vec<usize> = (0..400).collect();
    let scale = |name: &'static str, by: f64| {
        let c = column(name);
        move |cells: &mut Vec<String>| {
            let v: f64 = cells[c].parse().unwrap();
            cells[c] = format!("{}", v * by);
        }
    };
    let set = |name: &'static str, value: &'static str| {
        let c = column(name);
        move |cells: &mut Vec<String>| cells[c] = value.to_string()
    };
    let deg = scale("gyro_z", 57.3);
    let big = set("gyro_y", "150");
    let cases: Vec<(&str, String)> = vec![
        (
            "value beyond its bound",
            edit(&[123], &set("acce_x", "5000")),
        ),
        ("gyro in deg/s, one value also too large", {
            let both = |c: &mut Vec<String>| {
                deg(c);
                if c[1] == "7" {
                    big(c);
                }
            };
            edit(&all, &both)
        }),
        ("gravity in g", {
            let g = [
                scale("grav_x", 0.102),
                scale("grav_y", 0.102),
                scale("grav_z", 0.102),
            ];
            edit(&all, &|c| g.iter().for_each(|f| f(c)))
        }),
        ("duplicate timestamp", {
            let t = lines[51]
                .split(',')
                .nth(column("time"))
                .unwrap()
                .to_string();
            let c = column("time");
            edit(&[51], &move |cells| cells[c] = t.clone())
        }),
        ("time in microseconds", edit(&all, &scale("time", 1e-3))),
        (
            "ground truth NaN on one row",
            edit(&[200], &set("pos_x", "NaN")),
        ),
        ("ground truth jump", edit(&[300], &set("pos_y", "900"))),
        ("not a number", edit(&[17], &set("linacce_y", "x1"))),
        ("not a rotation", edit(&[9], &set("rv_w", "3"))),
        ("cut off", text.trim_end().to_string()),
        ("header only", format!("{}\n", lines[0])),
        ("empty", String::new()),
    ];
    for (what, content) in cases {
        let path = file(dir.path(), "bad.csv", &content);
        let whole = read_sequence(&path, &ReadOptions::default())
            .map(|_| ())
            .map_err(|e| e.to_string());
        let stream = streamed(&path).map(|_| ());
        assert!(whole.is_err(), "{what}: the whole-file reader accepts it");
        assert_eq!(stream, whole, "{what}");
    }
    // data_plain.txt: fewer rows than announced.
    let plain = dir.path().join("p_plain.txt");
    write_ridi_plain(&seq, &plain).unwrap();
    let text = std::fs::read_to_string(&plain).unwrap();
    let cut: Vec<&str> = text.lines().take(300).collect();
    let path = file(dir.path(), "q_plain.txt", &format!("{}\n", cut.join("\n")));
    let whole = read_sequence(&path, &ReadOptions::default()).map_err(|e| e.to_string());
    assert_eq!(streamed(&path).map(|_| ()), whole.map(|_| ()));
}

#[test]
fn formats_that_do_not_stream_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("raw");
    std::fs::create_dir(&raw).unwrap();
    std::fs::write(raw.join("gyro.txt"), "").unwrap();
    let e = RowReader::open(&raw, &ReadOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .contains("RIDI raw folder cannot be read as a stream"),
        "{e}"
    );
}
