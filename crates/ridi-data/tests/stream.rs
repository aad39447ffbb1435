//! The streaming reader against the whole-file one: the same rows, and for a recording with
//! one fault the same error (file, line, field and message). Raw folders are held to it here
//! and wherever a test reads one through `common::raw_with`.

mod common;

use std::io::Write as _;
use std::path::{Path, PathBuf};

use common::{assert_streams_as_read, raw_files, raw_options, streamed};
use ridi_data::ridi_frames::{DeviceVec, WorldFromDevice, WorldVec};
use ridi_data::{
    GroundTruth, OrientationSource, ReadOptions, RowReader, Sequence, SequenceParts, read_sequence,
    ridi_raw, write_ridi_csv, write_ridi_plain,
};
use ridi_test_support::{edit_cells, edit_file, write_files};

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
        // Flat, turning about its z axis: gravity along z, the orientation's up.
        acce: (0..n)
            .map(|i| DeviceVec::new(0.3 * wobble(i), 0.0, 9.9))
            .collect(),
        linacce: (0..n)
            .map(|i| DeviceVec::new(0.3 * wobble(i), 0.0, 0.1))
            .collect(),
        gravity: vec![DeviceVec::new(0.0, 0.0, 9.8); n],
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

/// A phone of `n` frames rocking about its x axis and turning about z at 0.25 rad/s (a sixth
/// of its squared rate), its gyro's z axis `gyro_z` times the true rate (built with the
/// per-axis check off).
fn rocking(n: usize, gyro_z: f64) -> Sequence {
    use ridi_data::ridi_frames::nalgebra::Vector3;
    let time: Vec<f64> = (0..n).map(|i| 1.0 + 0.005 * i as f64).collect();
    let rate = |t: f64| Vector3::new(0.8 * (3.0 * t).cos(), 0.0, 0.25);
    let mut orientation = vec![WorldFromDevice::identity()];
    for w in time.windows(2) {
        let step = ridi_data::ridi_frames::Rot::from_scaled_axis(rate(w[0]) * (w[1] - w[0]));
        orientation.push(*orientation.last().unwrap() * step);
    }
    let gravity: Vec<DeviceVec> = orientation
        .iter()
        .map(|q| q.inverse() * WorldVec::new(0.0, 0.0, 9.8))
        .collect();
    let parts = SequenceParts {
        name: "rocking".into(),
        gyro: time
            .iter()
            .map(|&t| {
                let g = rate(t);
                DeviceVec::new(g.x, g.y, gyro_z * g.z)
            })
            .collect(),
        acce: gravity.clone(),
        linacce: vec![DeviceVec::ZERO; n],
        gravity,
        orientation,
        orientation_source: Some(OrientationSource::GameRotationVector),
        time,
        ..Default::default()
    };
    let off = ridi_data::Validation {
        min_gyro_axis_scale: 0.0,
        ..Default::default()
    };
    Sequence::with_validation(parts, &off).unwrap()
}

/// `bytes` gzip-compressed.
fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    enc.write_all(bytes).unwrap();
    enc.finish().unwrap()
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
    std::fs::write(&gz, gzip(&std::fs::read(&csv).unwrap())).unwrap();
    for path in [&csv, &plain, &gz] {
        let read = read_sequence(path, &ReadOptions::default()).unwrap();
        let rows = streamed(path, &ReadOptions::default()).unwrap();
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
        ("gyro turning against the orientation", {
            let flip = [
                scale("gyro_x", -1.0),
                scale("gyro_y", -1.0),
                scale("gyro_z", -1.0),
            ];
            edit(&all, &|c| flip.iter().for_each(|f| f(c)))
        }),
        (
            "ground truth NaN on one row",
            edit(&[200], &set("pos_x", "NaN")),
        ),
        ("ground truth jump", edit(&[300], &set("pos_y", "900"))),
        ("not a number", edit(&[17], &set("linacce_y", "x1"))),
        ("not a rotation", edit(&[9], &set("rv_w", "3"))),
        ("an orientation that stays put", {
            let identity = [
                set("rv_w", "1"),
                set("rv_x", "0"),
                set("rv_y", "0"),
                set("rv_z", "0"),
            ];
            edit(&all, &|c| identity.iter().for_each(|f| f(c)))
        }),
        ("cut off", text.trim_end().to_string()),
        ("carriage returns alone", text.replace('\n', "\r")),
        ("header only", format!("{}\n", lines[0])),
        ("empty", String::new()),
    ];
    for (what, content) in cases {
        let path = file(dir.path(), "bad.csv", &content);
        let whole = read_sequence(&path, &ReadOptions::default())
            .map(|_| ())
            .map_err(|e| e.to_string());
        let stream = streamed(&path, &ReadOptions::default()).map(|_| ());
        assert!(whole.is_err(), "{what}: the whole-file reader accepts it");
        assert_eq!(stream, whole, "{what}");
        let e = whole.unwrap_err();
        let expected: &[&str] = match what {
            "gyro turning against the orientation" => &["gyro_x..gyro_z", "sign flipped"],
            "an orientation that stays put" => &["an orientation that stays put"],
            "carriage returns alone" => &["bad.csv:1: ", "classic Mac OS line endings"],
            _ => &[],
        };
        for part in expected {
            assert!(e.contains(part), "{what}: {e}");
        }
    }
    // A gyro axis dead or reversed, on a phone turning about two axes (the walk turns about
    // one, where either is a wrong scale or direction).
    for (what, gyro_z, expected) in [
        (
            "dead",
            0.0,
            "reads 0 times the orientation's rotation rate about it",
        ),
        (
            "reversed",
            -1.0,
            "reads -1 times the orientation's rotation rate about it",
        ),
    ] {
        let path = dir.path().join(format!("{what}.csv"));
        write_ridi_csv(&rocking(600, gyro_z), &path).unwrap();
        let whole = read_sequence(&path, &ReadOptions::default()).map_err(|e| e.to_string());
        let e = whole.clone().unwrap_err();
        assert!(
            e.contains("field `gyro_z`") && e.contains(expected),
            "{what}: {e}"
        );
        let stream = streamed(&path, &ReadOptions::default()).map(|_| ());
        assert_eq!(stream, whole.map(|_| ()), "{what}");
    }
    // data_plain.txt: fewer rows than announced.
    let plain = dir.path().join("p_plain.txt");
    write_ridi_plain(&seq, &plain).unwrap();
    let text = std::fs::read_to_string(&plain).unwrap();
    let cut: Vec<&str> = text.lines().take(300).collect();
    let path = file(dir.path(), "q_plain.txt", &format!("{}\n", cut.join("\n")));
    let whole = read_sequence(&path, &ReadOptions::default()).map_err(|e| e.to_string());
    assert_eq!(
        streamed(&path, &ReadOptions::default()).map(|_| ()),
        whole.map(|_| ())
    );
}

#[test]
fn formats_that_do_not_stream_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("Ann_Nexus5_NoDist_Texting");
    write_files(&run, &[("accelerometer.txt", "0 0 0 9.8\n".into())]);
    let e = RowReader::open(&run, &ReadOptions::default()).unwrap_err();
    assert!(
        e.to_string().contains(
            "Tyrex folder cannot be read as a stream of rows (only a RIDI data.csv, \
             data_plain.txt or raw folder can)"
        ),
        "{e}"
    );
}

/// Writes `files` as a raw folder `name` in `dir` and checks that it streams as it reads
/// with `opts`; the whole read.
fn raw_case(
    dir: &Path,
    name: &str,
    files: &[(&'static str, String)],
    opts: &ReadOptions,
) -> ridi_data::Result<Sequence> {
    let folder = dir.join(name);
    write_files(&folder, files);
    let whole = ridi_raw::read(&folder, opts);
    assert_streams_as_read(&folder, opts, &whole);
    whole
}

/// `text` with the data line `n` (from 1, header included) edited by `f` (cells split at
/// spaces).
fn edit_line(n: usize, f: impl Fn(&mut Vec<String>)) -> impl FnOnce(&str) -> String {
    move |text| {
        edit_cells(text, ' ', |i, cells| {
            if i == n {
                f(cells);
            }
        })
    }
}

#[test]
fn raw_folders_stream_as_they_read() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let opts = raw_options();
    // With the pose as the clock, and without (a uniform timeline), with every optional file
    // and without.
    let seq = raw_case(dir, "pose", &raw_files(100, true), &opts).unwrap();
    assert!(seq.ground_truth().is_some() && seq.steps().is_some() && seq.magnet().is_some());
    let seq = raw_case(dir, "uniform", &raw_files(50, false), &opts).unwrap();
    assert!(seq.ground_truth().is_none());
    let mut bare = raw_files(80, true);
    bare.retain(|(n, _)| !["magnet.txt", "step.txt"].contains(n));
    let seq = raw_case(dir, "bare", &bare, &opts).unwrap();
    assert!(seq.magnet().is_none() && seq.steps().is_none());
    // Repeated timestamps keep their first record; comments and blank lines anywhere; the
    // pose reaching beyond the sensors (dropped) and trimmed differently.
    let mut files = raw_files(120, true);
    for (name, content) in &mut files {
        let Some(dup) = content.lines().nth(7).map(str::to_owned) else {
            continue;
        };
        *content = content.replacen(&format!("{dup}\n"), &format!("{dup}\n\n{dup}\n# note\n"), 1);
        if *name == "pose.txt" {
            let t0 = common::T0_NS - 50_000_000;
            let early = format!("{t0} 0 0.5 1.5 0 0 0 1\n");
            *content = content.replacen('\n', &format!("\n{early}"), 1);
        }
    }
    raw_case(dir, "edited", &files, &opts).unwrap();
    for trim in [0, 1, 7] {
        let opts = ReadOptions {
            pose_trim: trim,
            ..raw_options()
        };
        raw_case(dir, &format!("trim{trim}"), &raw_files(60, true), &opts).unwrap();
    }
    // Gzip-compressed files, whatever their names.
    let gz: Vec<(&'static str, String)> = raw_files(70, true);
    let folder = dir.join("gz");
    write_files(&folder, &gz);
    for (name, content) in &gz {
        std::fs::write(folder.join(name), gzip(content.as_bytes())).unwrap();
    }
    let whole = ridi_raw::read(&folder, &opts);
    assert!(whole.is_ok(), "{whole:?}");
    assert_streams_as_read(&folder, &opts, &whole);
    // A capture folder with processed/data.csv streams that, as it reads.
    let seq = read_sequence(&folder, &opts).unwrap();
    std::fs::create_dir_all(folder.join("processed")).unwrap();
    write_ridi_csv(&seq, folder.join("processed/data.csv")).unwrap();
    let rows = streamed(&folder, &opts).unwrap();
    assert_eq!(rows.len(), seq.len());
}

#[test]
fn a_raw_folder_with_one_fault_gets_the_whole_readers_error() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let opts = raw_options();
    type Edit = Box<dyn Fn(&mut Vec<(&'static str, String)>)>;
    let on = |file: &'static str, line: usize, f: fn(&mut Vec<String>)| -> Edit {
        Box::new(move |files| edit_file(files, file, edit_line(line, f)))
    };
    // `f` on every record of `file` (given its line).
    let every = |file: &'static str, f: fn(usize, &mut Vec<String>)| -> Edit {
        Box::new(move |files| {
            edit_file(files, file, |t| {
                edit_cells(t, ' ', |i, c| {
                    if !c[0].starts_with('#') {
                        f(i, c);
                    }
                })
            })
        })
    };
    let cases: Vec<(&str, Edit)> = vec![
        ("not a number", on("gyro.txt", 9, |c| c[2] = "x".into())),
        ("too few fields", on("linacce.txt", 4, |c| c.truncate(3))),
        ("time going back", on("acce.txt", 12, |c| c[0] = "1".into())),
        (
            "no rotation",
            on("orientation.txt", 30, |c| c[4] = "3".into()),
        ),
        (
            "pose no rotation, kept",
            on("pose.txt", 20, |c| c[7] = "2".into()),
        ),
        (
            "pose no rotation, trimmed",
            on("pose.txt", 3, |c| c[7] = "2".into()),
        ),
        (
            "value beyond its bound",
            on("gravity.txt", 8, |c| c[1] = "-30".into()),
        ),
        (
            "pose beyond its bound",
            on("pose.txt", 40, |c| c[2] = "2e6".into()),
        ),
        (
            "ground truth jump",
            on("pose.txt", 30, |c| c[1] = "40".into()),
        ),
        ("first pose off", on("pose.txt", 7, |c| c[2] = "-40".into())),
        (
            "a later file's parse error before an earlier file's check",
            Box::new(|files| {
                edit_file(files, "gyro.txt", edit_line(6, |c| c[1] = "500".into()));
                edit_file(files, "step.txt", edit_line(2, |c| c[1] = "z".into()));
            }),
        ),
        (
            "a file's check before the rotations",
            Box::new(|files| {
                edit_file(
                    files,
                    "orientation.txt",
                    edit_line(3, |c| c[4] = "3".into()),
                );
                edit_file(files, "pose.txt", edit_line(50, |c| c[3] = "-2e6".into()));
            }),
        ),
        (
            "the gyro's units before its values",
            every("gyro.txt", |i, c| {
                c[3] = if i == 5 { "300" } else { "30" }.into()
            }),
        ),
        (
            "gravity in g",
            Box::new(|files| edit_file(files, "gravity.txt", |t| t.replace(" 9.8 ", " 1 "))),
        ),
        (
            "the rotation vector as w x y z",
            every("orientation.txt", |_, c| c[1..5].rotate_right(1)),
        ),
        (
            "steps beyond any number once interpolated",
            Box::new(|files| {
                edit_file(files, "step.txt", |_| {
                    format!(
                        "# t count\n{} 1e308\n{} -1e308\n",
                        common::T0_NS,
                        common::T0_NS + 400_000_000
                    )
                })
            }),
        ),
        (
            "pose in millimetres",
            every("pose.txt", |i, c| c[1] = (i * 100).to_string()),
        ),
        (
            "no overlap",
            every("magnet.txt", |_, c| {
                let ns: i64 = c[0].parse().unwrap();
                c[0] = (ns + 10_000_000_000).to_string();
            }),
        ),
        (
            "empty",
            Box::new(|files| edit_file(files, "acce.txt", |_| "# t x y z\n".into())),
        ),
        (
            "missing",
            Box::new(|files| files.retain(|(n, _)| *n != "gravity.txt")),
        ),
    ];
    for (what, edit) in cases {
        let mut files = raw_files(60, true);
        edit(&mut files);
        let whole = raw_case(dir, what, &files, &opts);
        let trimmed_rotation = what == "pose no rotation, trimmed";
        assert_eq!(whole.is_ok(), trimmed_rotation, "{what}: {whole:?}");
    }
    // Not UTF-8 after a line that does not parse, and then a gzip stream cut short: the
    // whole reader decodes and checks the text before it parses any of it.
    let mut files = raw_files(60, true);
    edit_file(
        &mut files,
        "magnet.txt",
        edit_line(5, |c| c[1] = "y".into()),
    );
    let folder = dir.join("bytes");
    write_files(&folder, &files);
    let magnet = folder.join("magnet.txt");
    let mut bytes = std::fs::read(&magnet).unwrap();
    let at = bytes.len() / 2;
    bytes.insert(at, 0xff);
    std::fs::write(&magnet, &bytes).unwrap();
    let whole = ridi_raw::read(&folder, &opts);
    assert!(
        whole
            .as_ref()
            .unwrap_err()
            .to_string()
            .contains("is not UTF-8"),
        "{whole:?}"
    );
    assert_streams_as_read(&folder, &opts, &whole);
    let gz = gzip(&bytes);
    std::fs::write(&magnet, &gz[..gz.len() - 10]).unwrap();
    let whole = ridi_raw::read(&folder, &opts);
    let e = whole.as_ref().unwrap_err().to_string();
    assert!(
        e.contains("magnet.txt: corrupt or truncated gzip data"),
        "{e}"
    );
    assert_streams_as_read(&folder, &opts, &whole);
    // A gap on the pose clock (the sequence's, after trimming; the pose file's own clock may
    // have gaps).
    let mut files = raw_files(60, true);
    edit_file(&mut files, "pose.txt", |t| {
        let lines: Vec<&str> = t.lines().collect();
        [&lines[..30], &lines[40..]].concat().join("\n") + "\n"
    });
    let mut opts = raw_options();
    opts.validation.max_gap_s = 0.02;
    let e = raw_case(dir, "pose gap", &files, &opts).unwrap_err();
    assert!(
        e.to_string()
            .contains("pose.txt:31: field `time`: gap of 0.055 s"),
        "{e}"
    );
    // The pose trimmed away, and no pose at a rate without a frame or with gaps.
    let e = raw_case(dir, "trim", &raw_files(60, true), &ReadOptions::default());
    assert!(e.is_err());
    for (rate, max_gap_s) in [
        (0.0, 1.0),
        (f64::INFINITY, 1.0),
        (f64::NAN, 1.0),
        (4.0, 0.1),
        (1e12, 1.0),
    ] {
        let mut opts = ReadOptions {
            rate_without_pose_hz: rate,
            ..raw_options()
        };
        opts.validation.max_gap_s = max_gap_s;
        let e = raw_case(dir, &format!("rate{rate}"), &raw_files(60, false), &opts);
        assert!(e.is_err(), "{rate} Hz");
    }
    // Refused with a pose too, before the work: the option is never passed over unsaid.
    let opts = ReadOptions {
        rate_without_pose_hz: 1e12,
        ..raw_options()
    };
    let e = raw_case(dir, "rate with pose", &raw_files(60, true), &opts).unwrap_err();
    assert!(
        e.to_string()
            .contains("field `rate_without_pose_hz`: output rate 1000000000000 Hz"),
        "{e}"
    );
}

/// Asserts that the rows of a raw folder of 6000 records a file (`raw_files`, after `edit`)
/// end in the error of a file changed since [`RowReader::open`] read it through, `at` that
/// file (and line), when `change` changes the folder after that: every file is over 64 KiB,
/// so that a change is not hidden by what the second pass buffered on opening.
#[track_caller]
fn refused_as_changed(
    edit: impl FnOnce(&mut Vec<(&'static str, String)>),
    change: impl FnOnce(&Path),
    at: &str,
) {
    let dir = tempfile::tempdir().unwrap();
    let mut files = raw_files(6000, true);
    edit(&mut files);
    write_files(dir.path(), &files);
    let whole = ridi_raw::read(dir.path(), &raw_options());
    assert!(whole.is_ok(), "{whole:?}");
    let mut rows = RowReader::open(dir.path(), &raw_options()).unwrap();
    change(dir.path());
    let mut n = 0;
    let e = loop {
        match rows.next() {
            Some(Ok(_)) => n += 1,
            Some(Err(e)) => break e.to_string(),
            None => panic!("{at}: {n} rows and no error"),
        }
    };
    let changed = "changed while being read: its records are not those read before";
    assert!(e.ends_with(&format!("/{at}: {changed}")), "{e}");
}

/// Cuts the file `name` in `folder` in place to its first `lines` lines.
fn cut(folder: &Path, name: &str, lines: usize) {
    let path = folder.join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let kept: String = text.lines().take(lines).map(|l| format!("{l}\n")).collect();
    std::fs::write(&path, kept).unwrap();
}

/// Appends `records` records of `values` to the file `name` in `folder`, 5 ms apart from 5 ms
/// after its last.
fn append(folder: &Path, name: &str, records: usize, values: &str) {
    let path = folder.join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let last: i64 = text
        .lines()
        .last()
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let mut file = std::fs::OpenOptions::new()
        .append(true)
        .open(&path)
        .unwrap();
    for i in 1..=records as i64 {
        writeln!(file, "{} {values}", last + 5_000_000 * i).unwrap();
    }
}

#[test]
fn a_sensor_or_pose_file_that_loses_records_after_open_is_refused_as_changed() {
    // A sensor cut in the middle of the timeline (its last value was held from there on) and
    // beyond the last frame (the rows are the first pass's, the file is not); the pose cut in
    // the records trimmed at its end (the kept ones are all there) and in the kept ones.
    let cuts = [
        ("gyro.txt", 3000),
        ("acce.txt", 6015),
        ("pose.txt", 5998),
        ("pose.txt", 3000),
    ];
    for (name, lines) in cuts {
        refused_as_changed(|_| {}, |dir| cut(dir, name, lines), name);
    }
}

#[test]
fn a_sensor_file_that_grows_after_open_is_refused_as_changed() {
    // The gyro ends first, at a pose time: the last frame is at its last record, from where
    // the interpolation read on to the end of the file.
    let gyro_first = |files: &mut Vec<(&'static str, String)>| {
        edit_file(files, "gyro.txt", |t| {
            t.lines().take(5001).map(|l| format!("{l}\n")).collect()
        });
        edit_file(files, "pose.txt", |t| {
            edit_cells(t, ' ', |_, c| {
                if let Ok(ns) = c[0].parse::<i64>() {
                    c[0] = (ns - 1_000_000).to_string();
                }
            })
        });
    };
    let grow = |dir: &Path| append(dir, "gyro.txt", 3, "9 9 9");
    refused_as_changed(gyro_first, grow, "gyro.txt:5002");
    // A file whose end no frame reached.
    let grow = |dir: &Path| append(dir, "magnet.txt", 1, "1 2 3");
    refused_as_changed(|_| {}, grow, "magnet.txt:6022");
}

#[test]
fn a_pose_file_that_grows_after_open_is_refused_as_changed() {
    let grow = |dir: &Path| append(dir, "pose.txt", 2, "0 0.5 1.5 0 0 0 1");
    refused_as_changed(|_| {}, grow, "pose.txt:6002");
}

/// `csv` (a `data.csv`'s text) without the columns whose names start with one of `dropped`.
fn without_columns(csv: &str, dropped: &[&str]) -> String {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let keep: Vec<usize> = (0..header.len())
        .filter(|&c| !dropped.iter().any(|d| header[c].starts_with(d)))
        .collect();
    let pick = |l: &str| -> String {
        let cells: Vec<&str> = l.split(',').collect();
        let kept: Vec<&str> = keep.iter().map(|&c| cells[c]).collect();
        kept.join(",") + "\n"
    };
    std::iter::once(header.join(","))
        .chain(lines.map(String::from))
        .map(|l| pick(&l))
        .collect()
}

/// Asserts that `path` streams as `whole` reads it: the same rows bit for bit, or the same
/// error.
fn assert_processed_streams_as_read(path: &Path, whole: &ridi_data::Result<Sequence>) {
    let stream = streamed(path, &ReadOptions::default());
    let read = match whole {
        Err(e) => return assert_eq!(stream.map(|_| ()), Err(e.to_string())),
        Ok(read) => read,
    };
    let rows = stream.unwrap();
    assert_eq!(rows.len(), read.len());
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r.time, read.time()[i]);
        assert_eq!(r.gyro, read.gyro()[i]);
        assert_eq!(r.acce, read.acce()[i]);
        assert_eq!(r.linacce, read.linacce()[i], "frame {i}");
        assert_eq!(r.gravity, read.gravity()[i], "frame {i}");
        assert_eq!(r.orientation, read.orientation()[i], "frame {i}");
        assert_eq!(r.magnet, read.magnet().map(|m| m[i]));
        let gt = read
            .ground_truth()
            .map(|g| (g.position[i], g.orientation[i]));
        assert_eq!(r.ground_truth, gt);
    }
    let reader = RowReader::open(path, &ReadOptions::default()).unwrap();
    assert_eq!(reader.orientation_source(), read.orientation_source());
}

/// The columns of the phone's own orientation, which a recorder of gyro and accelerometer alone
/// does not write.
const ORIENTATION_COLUMNS: [&str; 3] = ["linacce_", "grav_", "rv_"];

#[test]
fn a_data_csv_without_orientation_columns_reads_and_streams_with_the_estimate() {
    let dir = tempfile::tempdir().unwrap();
    // 6 s: the estimate settles over the first 2 s before it gives an orientation.
    let seq = walk(1200);
    let full = dir.path().join("full.csv");
    write_ridi_csv(&seq, &full).unwrap();
    let text = without_columns(
        &std::fs::read_to_string(&full).unwrap(),
        &ORIENTATION_COLUMNS,
    );
    let path = file(dir.path(), "walk.csv", &text);
    let opts = ReadOptions::default();
    let read = read_sequence(&path, &opts);
    assert_processed_streams_as_read(&path, &read);
    let read = read.unwrap();
    assert_eq!(
        read.orientation_source(),
        Some(OrientationSource::Estimated)
    );
    // What the whole recording's estimate gives, bit for bit.
    let mut parts = seq.clone().into_parts();
    parts.estimate_orientation(&Default::default()).unwrap();
    assert_eq!(read.orientation(), &parts.orientation[..]);
    assert_eq!(read.gravity(), &parts.gravity[..]);
    assert_eq!(read.linacce(), &parts.linacce[..]);
    // A flat phone: the estimate's gravity is along device z.
    let g = read.gravity()[600];
    assert!(
        g.z() > 9.7 && g.x().abs() < 0.3 && g.y().abs() < 0.3,
        "{g:?}"
    );
    assert!(read.ground_truth().is_some() && read.magnet().is_some());
    // The same, gzip-compressed, and with a sidecar that says so.
    let gz = dir.path().join("walk.csv.gz");
    std::fs::write(&gz, gzip(text.as_bytes())).unwrap();
    file(
        dir.path(),
        "walk.csv.gz.meta",
        "orientation_source = estimated\n",
    );
    let read = read_sequence(&gz, &opts);
    assert_processed_streams_as_read(&gz, &read);
    assert_eq!(read.unwrap().orientation(), &parts.orientation[..]);
}

#[test]
fn a_data_csv_with_part_of_its_orientation_or_no_gravity_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let seq = walk(1200);
    let full = dir.path().join("full.csv");
    write_ridi_csv(&seq, &full).unwrap();
    let full = std::fs::read_to_string(&full).unwrap();
    let opts = ReadOptions::default();
    let refused = |path: &Path, expected: &str| {
        let whole = read_sequence(path, &opts);
        assert_processed_streams_as_read(path, &whole);
        let Err(e) = whole else {
            panic!("{}: accepted", path.display())
        };
        let e = e.to_string();
        assert!(e.contains(expected), "{e}");
    };
    // A rotation without the gravity it goes with, or the other way round.
    let path = file(dir.path(), "a.csv", &without_columns(&full, &["grav_"]));
    refused(
        &path,
        "a.csv:1: field `grav_x`: missing column `grav_x` (linacce_*, grav_* and rv_*",
    );
    let path = file(dir.path(), "b.csv", &without_columns(&full, &["rv_w"]));
    refused(&path, "b.csv:1: field `rv_w`: missing column");
    // A sidecar naming the phone's orientation beside a file that has none.
    let text = without_columns(&full, &ORIENTATION_COLUMNS);
    let path = file(dir.path(), "c.csv", &text);
    file(
        dir.path(),
        "c.csv.meta",
        "device = Pixel 7\norientation_source = rotation-vector\n",
    );
    refused(
        &path,
        "c.csv.meta:2: field `orientation_source`: names `rotation-vector`, but the data file \
         has no orientation columns",
    );
    // An accelerometer of exact zeros: short, and for longer than the estimate may wait.
    let zeros = |rows: usize| -> String {
        let mut out = String::from("time,gyro_x,gyro_y,gyro_z,acce_x,acce_y,acce_z\n");
        for i in 0..rows {
            out += &format!("{},0.01,0.02,0.03,0,0,0\n", 1_000_000_000 + 20_000_000 * i);
        }
        out
    };
    refused(
        &file(dir.path(), "short.csv", &zeros(100)),
        "short.csv: field `acce_x..acce_z`: no nonzero accelerometer reading",
    );
    // 50 Hz: frame 3001 (line 3003) is the first more than 60 s after the first.
    refused(
        &file(dir.path(), "zeros.csv", &zeros(3100)),
        "zeros.csv:3003: field `acce_x..acce_z`: the orientation estimate has not started 60 s \
         or 100000 rows into the file",
    );
    // Time in microseconds read as nanoseconds: 2 s never pass, and the rows are bounded.
    let mut fast = String::from("time,gyro_x,gyro_y,gyro_z,acce_x,acce_y,acce_z\n");
    for i in 0..100_010 {
        fast += &format!("{},0.01,0.02,0.03,0.1,0.2,9.8\n", 1_000_000_000 + 5 * i);
    }
    refused(
        &file(dir.path(), "fast.csv", &fast),
        "fast.csv:100002: field `acce_x..acce_z`: the orientation estimate has not started",
    );
    // Readings too small to have a direction count as zero in both readers.
    let mut tiny = String::from("time,gyro_x,gyro_y,gyro_z,acce_x,acce_y,acce_z\n");
    for i in 0..4000 {
        let a = if i < 3500 {
            "1e-200,0,0"
        } else {
            "0.1,0.2,9.8"
        };
        tiny += &format!(
            "{},0.01,0.02,0.03,{a}\n",
            1_000_000_000 + 20_000_000 * i as u64
        );
    }
    refused(
        &file(dir.path(), "tiny.csv", &tiny),
        "tiny.csv:3003: field `acce_x..acce_z`: the orientation estimate has not started",
    );
}
