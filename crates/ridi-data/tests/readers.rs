//! Readers, writers, lists and detection on small fixture files built in temp folders.

mod common;

use std::path::Path;

use common::*;
use ridi_data::{
    DataError, Format, ListEntry, Listed, ReadOptions, Sequence, detect, parse_list, read_sequence,
    ridi_csv, ridi_plain, ridi_raw, write_ridi_csv, write_ridi_plain,
};
use ridi_test_support::{assert_err, edit_file, edit_rows, with_cell, write_files};

fn opts() -> ReadOptions {
    ReadOptions::default()
}

fn csv_string() -> String {
    String::from_utf8(valid_csv(20)).unwrap()
}

/// The sequences of the list file `list`.
fn load_list(list: &Path) -> ridi_data::Result<Vec<Sequence>> {
    Listed::read(&[list], &opts()).map(Listed::into_sequences)
}

fn parse_csv(text: &str) -> ridi_data::Result<Sequence> {
    ridi_csv::parse(text.as_bytes(), Path::new("walk/data.csv"), &opts())
}

// ---- round trips -------------------------------------------------------------------------

#[test]
fn csv_round_trip_is_exact_with_and_without_optional_channels() {
    let dir = tempfile::tempdir().unwrap();
    for (gt, magnet) in [(true, true), (false, false), (true, false), (false, true)] {
        let seq = sample_sequence("walk", 300, gt, magnet);
        let path = dir.path().join("walk/processed/data.csv");
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        write_ridi_csv(&seq, &path).unwrap();
        let back = ridi_csv::read(&path, &opts()).unwrap();
        assert_eq!(back, seq, "gt {gt} magnet {magnet}");
        assert_eq!(back.ground_truth().is_some(), gt);
        assert_eq!(back.magnet().is_some(), magnet);
    }
}

#[test]
fn plain_round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    for gt in [true, false] {
        let seq = sample_sequence("walk", 200, gt, true);
        let path = dir.path().join("walk/data_plain.txt");
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        write_ridi_plain(&seq, &path).unwrap();
        assert_eq!(ridi_plain::read(&path, &opts()).unwrap(), seq);
    }
}

#[test]
fn csv_layout_matches_pandas_output() {
    let text = csv_string();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with(",time,gyro_x,gyro_y,gyro_z,acce_x,"));
    assert!(header.ends_with(",ori_w,ori_x,ori_y,ori_z,rv_w,rv_x,rv_y,rv_z"));
    let first: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(first.len(), 28);
    assert_eq!(first[0], "0");
    assert_eq!(first[1], T0_NS.to_string(), "time is written in integer ns");
}

#[test]
fn csv_columns_are_selected_by_name() {
    let text = csv_string();
    let expected = parse_csv(&text).unwrap();
    // No index column, columns reversed, an unknown extra column, CRLF line endings.
    let reordered: String = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let mut cells: Vec<&str> = l.split(',').skip(1).collect();
            cells.reverse();
            let extra = if i == 0 { "stab_gyro_x" } else { "123.5" };
            format!("{},{extra}\r\n", cells.join(","))
        })
        .collect();
    assert_eq!(parse_csv(&reordered).unwrap(), expected);
}

#[test]
fn csv_without_optional_columns_reads_without_magnet_and_ground_truth() {
    let text = csv_string();
    let full = parse_csv(&text).unwrap();
    // Keep the index, time, gyro..grav (cells 0..14) and rv (cells 24..28).
    let text = edit_rows(&text, |_, cells| {
        cells.drain(14..24);
    });
    let seq = parse_csv(&text).unwrap();
    assert!(seq.magnet().is_none() && seq.ground_truth().is_none());
    assert_eq!(seq.gyro(), full.gyro());
    assert_eq!(seq.orientation(), full.orientation());
}

// ---- bad csv input -----------------------------------------------------------------------

#[test]
fn csv_missing_column_names_header_line_and_column() {
    let text = edit_rows(&csv_string(), |_, cells| {
        cells.remove(3);
    });
    assert_err(
        parse_csv(&text),
        &["walk/data.csv:1", "field `gyro_y`", "missing column"],
    );
}

#[test]
fn csv_non_numeric_cell_names_line_and_field() {
    let text = with_cell(&csv_string(), 4, 2, "abc");
    assert_err(
        parse_csv(&text),
        &["data.csv:4: field `gyro_x`: `abc` is not a number"],
    );
}

#[test]
fn csv_nan_and_inf_are_rejected_outside_ground_truth() {
    let text = with_cell(&csv_string(), 5, 7, "NaN");
    assert_err(
        parse_csv(&text),
        &["data.csv:5: field `acce_z`", "not a finite number"],
    );
    let text = with_cell(&csv_string(), 7, 1, "inf");
    assert_err(
        parse_csv(&text),
        &["data.csv:7: field `time`", "not a finite number"],
    );
    let text = with_cell(&csv_string(), 7, 17, "-inf");
    assert_err(
        parse_csv(&text),
        &["data.csv:7: field `pos_x`", "not a finite number"],
    );
}

#[test]
fn csv_partial_nan_ground_truth_is_an_error() {
    // One NaN cell: the row names what it lacks and what it has.
    let text = with_cell(&csv_string(), 9, 21, "nan");
    assert_err(
        parse_csv(&text),
        &[
            "data.csv:9: field `ori_x`",
            "ground truth is incomplete: ori_x NaN but pos_x, pos_y, pos_z, ori_w, ori_y, ori_z given",
        ],
    );
    // A whole row NaN among rows with ground truth.
    let mut text = csv_string();
    for col in 17..24 {
        text = with_cell(&text, 9, col, "nan");
    }
    assert_err(
        parse_csv(&text),
        &[
            "data.csv:9: field `pos_x`",
            "NaN here but present on other rows",
        ],
    );
}

#[test]
fn csv_empty_and_header_only_files_are_errors() {
    assert_err(parse_csv(""), &["walk/data.csv", "file is empty"]);
    assert_err(parse_csv("\n\n"), &["file is empty"]);
    let header = csv_string().lines().next().unwrap().to_owned();
    assert_err(parse_csv(&header), &["data.csv:1", "only a header line"]);
}

#[test]
fn csv_truncated_last_line_names_it() {
    let text = csv_string();
    let cut = &text[..text.len() - 60];
    let last = cut.lines().count();
    assert_err(
        parse_csv(cut),
        &[&format!("data.csv:{last}:"), "truncated line?"],
    );
}

#[test]
fn csv_duplicate_and_decreasing_timestamps_name_the_line() {
    let text = csv_string();
    let time_of = |line: usize| {
        text.lines()
            .nth(line - 1)
            .unwrap()
            .split(',')
            .nth(1)
            .unwrap()
            .to_owned()
    };
    let dup = with_cell(&text, 6, 1, &time_of(5));
    assert_err(
        parse_csv(&dup),
        &["data.csv:6: field `time`: duplicate timestamp (same as line 5)"],
    );
    let back = with_cell(&text, 6, 1, &time_of(3));
    assert_err(
        parse_csv(&back),
        &["data.csv:6: field `time`: timestamp goes back"],
    );
}

#[test]
fn csv_gap_longer_than_a_second_names_the_line() {
    let text = edit_rows(&csv_string(), |line, cells| {
        if line >= 10 {
            let t: i64 = cells[1].parse().unwrap();
            cells[1] = (t + 2_000_000_000).to_string();
        }
    });
    assert_err(
        parse_csv(&text),
        &[
            "data.csv:10: field `time`: gap of 2.00",
            "exceeds the limit of 1 s",
        ],
    );
}

#[test]
fn csv_gravity_in_wrong_units_names_the_file() {
    let text = edit_rows(&csv_string(), |line, cells| {
        if line > 1 {
            for c in &mut cells[11..14] {
                *c = (c.parse::<f64>().unwrap() / 9.80665).to_string();
            }
        }
    });
    let e = assert_err(
        parse_csv(&text),
        &["walk/data.csv", "gravity magnitude 1.000", "wrong units"],
    );
    assert!(matches!(e, DataError::Sequence { .. }));
}

#[test]
fn csv_bad_rotation_names_line_and_column() {
    let text = with_cell(&csv_string(), 3, 24, "2.0");
    assert_err(
        parse_csv(&text),
        &["data.csv:3: field `rv_w`", "not a rotation"],
    );
}

#[test]
fn csv_invalid_utf8_names_the_line() {
    let mut bytes = valid_csv(5);
    let at = bytes.len() - 3;
    bytes[at] = 0xff;
    assert_err(
        ridi_csv::parse(&bytes, Path::new("x.csv"), &opts()),
        &["x.csv:6", "not UTF-8"],
    );
}

// ---- bad plain input ---------------------------------------------------------------------

fn parse_plain(text: &str) -> ridi_data::Result<Sequence> {
    ridi_plain::parse(text.as_bytes(), Path::new("data_plain.txt"), &opts())
}

#[test]
fn plain_header_and_row_counts_are_checked() {
    let text = String::from_utf8(valid_plain(10)).unwrap();
    assert!(parse_plain(&text).is_ok());
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert_err(parse_plain(""), &["data_plain.txt", "file is empty"]);
    assert_err(
        parse_plain(&format!("10\n{}", rows.join("\n"))),
        &["data_plain.txt:1", "expected `N 27`"],
    );
    assert_err(
        parse_plain(&format!("10 28\n{}", rows.join("\n"))),
        &["data_plain.txt:1: field `columns`"],
    );
    // A data.csv saved as .txt: named as what it is.
    let csv = String::from_utf8(valid_csv(10)).unwrap();
    assert_err(
        parse_plain(&csv),
        &[
            "data_plain.txt:1",
            "the header of a RIDI `data.csv`; name the file `.csv`",
        ],
    );
    assert_err(
        parse_plain(&format!("x 27\n{}", rows.join("\n"))),
        &["data_plain.txt:1: field `rows`"],
    );
    assert_err(parse_plain("0 27\n"), &["announces no rows"]);
    assert_err(
        parse_plain(&format!("12 27\n{}", rows.join("\n"))),
        &["data_plain.txt:11", "ends after 10 of the 12 rows"],
    );
    assert_err(
        parse_plain(&format!("9 27\n{}", rows.join("\n"))),
        &["data_plain.txt:11", "more rows than the 9"],
    );
    let cut = &text[..text.len() - 30];
    assert_err(parse_plain(cut), &["data_plain.txt:11", "truncated line?"]);
    let bad = text.replacen('\t', "\tzz", 1);
    assert_err(
        parse_plain(&bad),
        &["data_plain.txt:2: field `gyro_x`: `zz", "not a number"],
    );
}

// ---- raw folders -------------------------------------------------------------------------

#[test]
fn raw_folder_is_synchronized_on_the_trimmed_pose_timeline() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("hang_leg1");
    write_files(&folder, &raw_files(100, true));
    let seq = ridi_raw::read(&folder, &raw_options()).unwrap();
    assert_eq!(seq.name(), "hang_leg1");
    assert_eq!(seq.len(), 90, "5 pose records dropped at each end");
    let first_ns = T0_NS + 1_000_000 + 5 * 5_000_000;
    assert_eq!(seq.time()[0], first_ns as f64 / 1e9);
    for k in [0, 17, 89] {
        let since_start = (1_000_000 + 5_000_000 * (5 + k) as i64) as f64 / 1e9;
        let g = seq.gyro()[k];
        assert!(
            (g.x() - 0.005 * since_start).abs() < 1e-6,
            "gyro x at {k}: {g:?}"
        );
        assert!((g.z() + 0.005 * since_start).abs() < 1e-6);
        let gt = seq.ground_truth().unwrap();
        assert!((gt.position[k].x() - 0.01 * (5 + k) as f64).abs() < 1e-12);
        let [w, ..] = gt.orientation[k].to_wxyz();
        assert_eq!(w, 1.0);
        // The rotation vector, upright, turns about z by 2 * 0.001 rad per 5 ms record.
        let r = std::f64::consts::FRAC_1_SQRT_2;
        let upright = ridi_data::ridi_frames::WorldFromDevice::from_wxyz([r, r, 0.0, 0.0]).unwrap();
        let rv_angle = seq.orientation()[k].angle_to(&upright);
        assert!(
            (rv_angle - 0.002 * since_start / 0.005).abs() < 1e-6,
            "{rv_angle}"
        );
    }
    assert!(seq.magnet().is_some());
    let steps = seq.steps().unwrap();
    assert!(steps.windows(2).all(|w| w[1] >= w[0]));
    assert_eq!(
        seq.orientation_source(),
        Some(ridi_data::OrientationSource::GameRotationVector)
    );
    // The default trim of 800 needs more than 1600 pose records.
    assert_err(
        ridi_raw::read(&folder, &opts()),
        &["pose.txt", "dropping 800 at each end leaves none"],
    );
}

#[test]
fn raw_duplicate_timestamps_are_removed() {
    let dir = tempfile::tempdir().unwrap();
    let mut files = raw_files(60, true);
    write_files(&dir.path().join("a"), &files);
    for (name, content) in &mut files {
        if *name == "gyro.txt" || *name == "pose.txt" {
            let dup = content.lines().nth(7).unwrap().to_owned();
            *content = content.replacen(&format!("{dup}\n"), &format!("{dup}\n{dup}\n"), 1);
        }
    }
    write_files(&dir.path().join("b"), &files);
    let a = ridi_raw::read(dir.path().join("a"), &raw_options()).unwrap();
    let mut b = ridi_raw::read(dir.path().join("b"), &raw_options()).unwrap();
    b.set_name("a");
    assert_eq!(a, b);
}

#[test]
fn raw_folder_without_pose_is_uniform_200_hz_without_ground_truth() {
    let dir = tempfile::tempdir().unwrap();
    write_files(dir.path(), &raw_files(50, false));
    let seq = ridi_raw::read(dir.path(), &raw_options()).unwrap();
    assert!(seq.ground_truth().is_none());
    assert_eq!(seq.len(), 70);
    assert!((seq.rate_hz() - 200.0).abs() < 1e-6);
    assert_eq!(seq.time()[0], T0_NS as f64 / 1e9);
}

#[test]
fn raw_bad_files_name_file_line_and_field() {
    let (_d, r) = raw_with(|f| f.retain(|(n, _)| *n != "acce.txt"));
    assert_err(
        r,
        &["RIDI raw folder without acce.txt: it needs gyro.txt, acce.txt"],
    );
    let (_d, r) = raw_with(|f| edit_file(f, "linacce.txt", |_| "# t x y z\n".into()));
    assert_err(r, &["linacce.txt", "has no data rows"]);
    let (_d, r) = raw_with(|f| edit_file(f, "gyro.txt", |s| s.replacen(" 0.4 ", " 0.4 \n", 1)));
    assert_err(r, &["gyro.txt:2: field `z`", "truncated line?"]);
    let (_d, r) = raw_with(|f| {
        edit_file(f, "gyro.txt", |s| {
            s.trim_end().rsplit_once(' ').unwrap().0.to_owned()
        })
    });
    assert_err(r, &["gyro.txt:81: field `z`", "truncated line?"]);
    let (_d, r) = raw_with(|f| edit_file(f, "magnet.txt", |s| s.replacen(" 5\n", " x5\n", 1)));
    assert_err(r, &["magnet.txt:2: field `z`: `x5` is not a number"]);
    let (_d, r) = raw_with(|f| {
        edit_file(f, "gravity.txt", |s| {
            let mut l: Vec<&str> = s.lines().collect();
            l.swap(10, 11);
            l.join("\n") + "\n"
        })
    });
    assert_err(r, &["gravity.txt:12: field `t`: timestamp goes back"]);
    let (_d, r) = raw_with(|f| {
        edit_file(f, "acce.txt", |s| {
            s.lines()
                .enumerate()
                .map(|(i, l)| match l.split_once(' ') {
                    Some((t, rest)) if i >= 30 => {
                        format!("{} {rest}\n", t.parse::<i64>().unwrap() + 3_000_000_000)
                    }
                    _ => format!("{l}\n"),
                })
                .collect()
        })
    });
    assert_err(r, &["acce.txt:31: field `t`: gap of 3.00"]);
    let (_d, r) = raw_with(|f| {
        edit_file(f, "orientation.txt", |s| {
            s.replacen(" 0.7071067811865476\n", " 3\n", 1)
        })
    });
    assert_err(r, &["orientation.txt:2: field `x..w`", "not a rotation"]);
    let (_d, r) =
        raw_with(|f| edit_file(f, "pose.txt", |s| s.replace(" 0 0 0 1\n", " 0 0 0 NaN\n")));
    assert_err(r, &["pose.txt:2: field `qw`", "not a finite number"]);
}

#[test]
fn partial_folders_are_detected_and_name_what_they_lack() {
    // Detected as a raw folder from the files it has; reading names those it lacks.
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("raw");
    let mut files = raw_files(60, true);
    files.retain(|(n, _)| !["gyro.txt", "orientation.txt"].contains(n));
    write_files(&raw, &files);
    assert_eq!(detect(&raw).unwrap(), Format::RidiRaw);
    let e = assert_err(read_sequence(&raw, &raw_options()), &[]);
    assert_eq!(
        e.to_string(),
        format!(
            "{}: RIDI raw folder without gyro.txt, orientation.txt: it needs gyro.txt, acce.txt, \
             linacce.txt, gravity.txt, orientation.txt",
            raw.display()
        )
    );
    // Only the pose: not recognisably raw.
    let pose_only = dir.path().join("pose_only");
    write_files(&pose_only, &[("pose.txt", "# t\n".into())]);
    assert_err(detect(&pose_only), &["not a known dataset folder"]);

    let tyrex = dir.path().join("Jakob_Nexus5_NoDist_Texting");
    write_files(&tyrex, &[("accelerometer.txt", "0 0 0 9.8\n".into())]);
    assert_eq!(detect(&tyrex).unwrap(), Format::Tyrex);
    assert_err(
        read_sequence(&tyrex, &opts()),
        &["gyroscope-calibrated.txt"],
    );
    // A file is no Tyrex root: say what one looks like.
    assert_err(
        ridi_data::tyrex::list_sequences(tyrex.join("accelerometer.txt")),
        &[
            "accelerometer.txt: not a Tyrex run or root (not a folder): a Tyrex run is a folder",
            "datasets/android/",
        ],
    );
}

#[test]
fn raw_validation_failures_name_the_stream_file() {
    // Gravity in g: the mean magnitude check blames gravity.txt, not the pose clock.
    let (d, r) = raw_with(|f| edit_file(f, "gravity.txt", |s| s.replace(" 9.8 ", " 1 ")));
    let e = assert_err(r, &["gravity magnitude 1.000 m/s^2 is outside"]);
    let msg = e.to_string();
    assert!(
        msg.starts_with(&format!("{}: ", d.path().join("gravity.txt").display())),
        "{msg}"
    );
    assert!(!msg.contains("pose.txt"), "{msg}");
    // Without a pose file too.
    let (d, r) = raw_with(|f| {
        f.retain(|(n, _)| *n != "pose.txt");
        edit_file(f, "gravity.txt", |s| s.replace(" 9.8 ", " 1 "));
    });
    let msg = assert_err(r, &["gravity magnitude"]).to_string();
    assert!(
        msg.starts_with(&d.path().join("gravity.txt").display().to_string()),
        "{msg}"
    );
}

// ---- detection and lists -----------------------------------------------------------------

/// A dataset folder with one sequence of each RIDI format and a Tyrex folder.
fn dataset() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    std::fs::create_dir_all(root.join("csv_seq/processed")).unwrap();
    write_ridi_csv(
        &sample_sequence("csv_seq", 50, true, true),
        root.join("csv_seq/processed/data.csv"),
    )
    .unwrap();
    std::fs::create_dir_all(root.join("plain_seq")).unwrap();
    write_ridi_plain(
        // Another length: the same samples would be the same recording (`Listed::load`).
        &sample_sequence("plain_seq", 60, true, false),
        root.join("plain_seq/data_plain.txt"),
    )
    .unwrap();
    write_files(&root.join("raw_seq"), &raw_files(1700, true));
    write_files(
        &root.join("tyrex"),
        &[
            ("accelerometer.txt", "0 0 0 9.8\n".into()),
            ("gyroscope-calibrated.txt", "0 0 0 0\n".into()),
        ],
    );
    std::fs::create_dir_all(root.join("nothing")).unwrap();
    dir
}

#[test]
fn formats_are_detected() {
    let d = dataset();
    let root = d.path();
    assert_eq!(detect(root.join("csv_seq")).unwrap(), Format::RidiCsv);
    assert_eq!(
        detect(root.join("csv_seq/processed/data.csv")).unwrap(),
        Format::RidiCsv
    );
    assert_eq!(detect(root.join("plain_seq")).unwrap(), Format::RidiPlain);
    assert_eq!(detect(root.join("raw_seq")).unwrap(), Format::RidiRaw);
    assert_eq!(detect(root.join("tyrex")).unwrap(), Format::Tyrex);
    assert_err(
        detect(root.join("nothing")),
        &["nothing", "not a known dataset folder"],
    );
    assert_err(
        detect(root.join("absent")),
        &["absent", "no such file or folder"],
    );
    // Detected as Tyrex and handed to its reader, which names the file it lacks.
    assert_err(
        read_sequence(root.join("tyrex"), &opts()),
        &["tyrex", "rotation-vector.txt"],
    );
    let seq = read_sequence(root.join("csv_seq"), &opts()).unwrap();
    assert_eq!(seq, sample_sequence("csv_seq", 50, true, true));
}

#[test]
fn list_files_parse_comments_paths_and_placements() {
    let list = Path::new("/data/lists/train.txt");
    let text = "# RIDI train split\n\nseq_a,body\n  /abs/seq_b , bag \n../seq_c\nseq_d,\n";
    let entries = parse_list(text.as_bytes(), list).unwrap();
    let got: Vec<(String, Option<&str>, usize)> = entries
        .iter()
        .map(|e| (e.path.display().to_string(), e.placement.as_deref(), e.line))
        .collect();
    assert_eq!(
        got,
        vec![
            ("/data/lists/seq_a".into(), Some("body"), 3),
            ("/abs/seq_b".into(), Some("bag"), 4),
            ("/data/lists/../seq_c".into(), None, 5),
            ("/data/lists/seq_d".into(), None, 6),
        ]
    );
    assert_err(
        parse_list(b"a,b,c\n", list),
        &["train.txt:1", "more than two"],
    );
    assert_err(
        parse_list(b"ok\n ,body\n", list),
        &["train.txt:2: field `path`", "empty sequence path"],
    );
    assert_err(
        parse_list(b"a,hand held\n", list),
        &["train.txt:1: field `placement`"],
    );
    assert_err(
        ListEntry::read(&["/definitely/not/here.txt"]),
        &["here.txt"],
    );
}

#[test]
fn list_entries_know_their_list_and_line() {
    let list = Path::new("/data/lists/train.txt");
    let entries = parse_list(b"# split\nseq_a,body\n\nseq_b\n", list).unwrap();
    assert!(entries.iter().all(|e| e.list == list));
    assert_eq!(entries[1].location().to_string(), "/data/lists/train.txt:4");
}

#[test]
fn lists_without_sequences_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let list = dir.path().join("empty.txt");
    for text in ["", "\n\n", "# only a comment\n\n# another\n"] {
        std::fs::write(&list, text).unwrap();
        let e = assert_err(ListEntry::read(&[&list]), &[]);
        assert_eq!(
            e.to_string(),
            format!(
                "{}: no sequences listed (expected `path,placement` lines)",
                list.display()
            )
        );
        assert_err(load_list(&list), &["empty.txt", "no sequences listed"]);
    }
}

/// A list that is a device, a folder or larger than any list is refused before it is read:
/// `--list /dev/zero` used to grow until the kernel killed it.
#[test]
fn lists_that_are_not_regular_files_or_too_large_are_refused_unread() {
    let dev = Path::new("/dev/zero");
    if dev.exists() {
        assert_err(
            ListEntry::read(&[dev]),
            &["/dev/zero", "not a regular file"],
        );
    }
    let dir = tempfile::tempdir().unwrap();
    assert_err(ListEntry::read(&[dir.path()]), &["is a folder"]);
    // A sparse file of 3 GB: refused by its size, unread (its zeros would parse as a line).
    let huge = dir.path().join("huge.txt");
    std::fs::File::create(&huge)
        .unwrap()
        .set_len(3 << 30)
        .unwrap();
    assert_err(
        ListEntry::read(&[&huge]),
        &["huge.txt", "larger than such a file can be"],
    );
}

#[test]
fn lists_load_every_format_and_set_placements() {
    let d = dataset();
    let root = d.path();
    let list = root.join("list.txt");
    std::fs::write(
        &list,
        format!(
            "csv_seq,handheld\n# raw\nraw_seq,leg\n{}\n",
            root.join("plain_seq/data_plain.txt").display()
        ),
    )
    .unwrap();
    let seqs = load_list(&list).unwrap();
    let got: Vec<(&str, Option<&str>)> = seqs.iter().map(|s| (s.name(), s.placement())).collect();
    assert_eq!(
        got,
        vec![
            ("csv_seq", Some("handheld")),
            ("raw_seq", Some("leg")),
            ("plain_seq", None)
        ]
    );
    assert_eq!(seqs[1].len(), 1700 - 1600);

    std::fs::write(&list, "csv_seq,body\n\nmissing_seq,bag\n").unwrap();
    assert_err(
        load_list(&list),
        &[
            "list.txt:3: field `path`",
            "missing_seq",
            "does not exist (a relative path in a list is read from the list's folder, ",
        ],
    );
    // A tab or a semicolon for the comma: the whole line is read as the path.
    for separator in ["\t", ";"] {
        std::fs::write(&list, format!("csv_seq{separator}body\n")).unwrap();
        assert_err(
            load_list(&list),
            &[
                "list.txt:1: field `path`",
                "does not exist (a list line is `path,placement`, separated by a comma)",
            ],
        );
    }
    std::fs::write(&list, "nothing\n").unwrap();
    assert_err(load_list(&list), &["nothing", "not a known dataset folder"]);
}

#[test]
fn lists_refuse_a_recording_listed_twice_also_through_another_path() {
    let d = dataset();
    let root = d.path();
    let list = root.join("list.txt");
    std::fs::write(&list, "csv_seq,handheld\nraw_seq\ncsv_seq,body\n").unwrap();
    assert_err(
        load_list(&list),
        &[
            "list.txt:3: field `path`",
            "csv_seq",
            "already listed at",
            "list.txt:1",
        ],
    );
    // The folder and the file it is read from are one recording.
    let other = root.join("other.txt");
    std::fs::write(&other, "csv_seq/processed/data.csv\n").unwrap();
    let entries: Vec<_> = ListEntry::read(&[&list, &other])
        .unwrap()
        .into_iter()
        .filter(|e| e.line != 3)
        .collect();
    let e = Listed::load(entries, &opts()).unwrap_err();
    assert!(
        e.to_string().contains("other.txt:1: field `path`") && e.to_string().contains("list.txt:1"),
        "{e}"
    );
    // A copy in another folder, and the same recording written in the plain format, are the
    // same data; another recording is not.
    let seq = ridi_data::read_sequence(root.join("csv_seq"), &opts()).unwrap();
    std::fs::create_dir_all(root.join("copy/processed")).unwrap();
    std::fs::copy(
        root.join("csv_seq/processed/data.csv"),
        root.join("copy/processed/data.csv"),
    )
    .unwrap();
    std::fs::create_dir_all(root.join("as_plain")).unwrap();
    write_ridi_plain(&seq, root.join("as_plain/data_plain.txt")).unwrap();
    for copy in ["copy", "as_plain"] {
        std::fs::write(
            &list,
            format!(
                "csv_seq,handheld
plain_seq,bag
{copy},body
"
            ),
        )
        .unwrap();
        assert_err(
            load_list(&list),
            &[
                &format!(
                    "list.txt:3: field `path`: sequence `{}",
                    root.join(copy).display()
                ),
                "holds the same recording as",
                "list.txt:1",
            ],
        );
    }
    std::fs::write(
        &list,
        "csv_seq,handheld
plain_seq,bag
",
    )
    .unwrap();
    assert_eq!(load_list(&list).unwrap().len(), 2);

    // Across two lists loaded apart (training and test): a recording on the second, by path or
    // as a copy, is named at its line with the first list's line; distinct recordings pass.
    let test = root.join("test.txt");
    std::fs::write(&test, "plain_seq,bag\nas_plain,body\n").unwrap();
    let train_entries = ListEntry::read(&[&list]).unwrap();
    let test_entries = ListEntry::read(&[&test]).unwrap();
    let load = |entries: &[ListEntry]| Listed::load(entries.to_vec(), &opts()).unwrap();
    let (train, held_out) = (load(&train_entries), load(&test_entries));
    let e = train.check_distinct(&held_out).unwrap_err().to_string();
    assert!(
        e.contains("test.txt:1: field `path`")
            && e.contains("plain_seq")
            && e.contains("already listed at")
            && e.contains("list.txt:2"),
        "{e}"
    );
    let e = train
        .check_distinct(&load(&test_entries[1..]))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("test.txt:2: field `path`")
            && e.contains("holds the same recording as")
            && e.contains("list.txt:1"),
        "{e}"
    );
    load(&train_entries[1..])
        .check_distinct(&load(&test_entries[1..]))
        .unwrap();
}

// ---- writer ------------------------------------------------------------------------------

#[test]
fn writes_replace_atomically_and_leave_no_temporary_files() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("data.csv");
    std::fs::write(&path, "old content").unwrap();
    let seq = sample_sequence("x", 30, false, false);
    write_ridi_csv(&seq, &path).unwrap();
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("data.csv")]);
    assert!(
        std::fs::read_to_string(&path)
            .unwrap()
            .starts_with(",time,")
    );
    assert_err(
        write_ridi_csv(&seq, dir.path().join("no/such/dir/data.csv")),
        &["data.csv"],
    );
    // What the nanosecond column cannot hold is refused before anything is written, and the
    // old file and sidecar stay: two frames less than a nanosecond apart, a time past 2262.
    let mut with_device = seq.clone();
    with_device.set_device(Some(ridi_data::DeviceInfo::new("Nexus 5").unwrap()));
    write_ridi_csv(&with_device, &path).unwrap();
    let kept = std::fs::read(&path).unwrap();
    let kept_side = std::fs::read(ridi_data::sidecar_path(&path)).unwrap();
    let close = {
        let mut p = seq.parts().clone();
        p.time[1] = p.time[0] + 1e-10;
        Sequence::new(p).unwrap()
    };
    let late = {
        let mut p = seq.parts().clone();
        p.time.iter_mut().for_each(|t| *t += 1e10);
        Sequence::new(p).unwrap()
    };
    for (bad, words) in [
        (&close, "frames 0 and 1 are less than a nanosecond apart"),
        (&late, "frame 0 at"),
    ] {
        for e in [write_ridi_csv(bad, &path), write_ridi_plain(bad, &path)] {
            assert_err(e, &["data.csv: field `time`", words]);
        }
    }
    assert!(std::fs::read(&path).unwrap() == kept);
    assert!(std::fs::read(ridi_data::sidecar_path(&path)).unwrap() == kept_side);
    // A folder, with a file name or without one (its sidecar would be another folder's).
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    for folder in [dir.path().join("sub"), dir.path().join("sub").join("..")] {
        assert_err(write_ridi_csv(&seq, &folder), &["a folder, not a file"]);
    }
    assert!(!dir.path().join("sub.meta").exists());
}

#[test]
fn gzipped_f32_files_are_written_and_read_back_transparently() {
    let dir = tempfile::tempdir().unwrap();
    let seq = sample_sequence("walk_gz", 50, true, true);
    let folder = dir.path().join("walk_gz/processed");
    std::fs::create_dir_all(&folder).unwrap();
    let path = folder.join("data.csv.gz");
    ridi_data::write_ridi_csv_with(&seq, &path, ridi_data::Precision::F32).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[..2], &[0x1f, 0x8b], "not gzip");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&path).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o644, "outputs must be readable by others");
    }
    assert_eq!(detect(dir.path().join("walk_gz")).unwrap(), Format::RidiCsv);
    let back = read_sequence(dir.path().join("walk_gz"), &opts()).unwrap();
    assert_eq!(back.name(), "walk_gz");
    assert_eq!(back.len(), seq.len());
    for (a, b) in back.gyro().iter().zip(seq.gyro()) {
        assert!(
            (*a - *b).norm() <= 1e-6 * b.norm().max(1.0),
            "{a:?} vs {b:?}"
        );
    }
    for (a, b) in back.time().iter().zip(seq.time()) {
        assert_eq!(a, b, "time stays exact in integer nanoseconds");
    }
    // A cut gzip stream is an error naming the file, not a panic.
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    let err = read_sequence(dir.path().join("walk_gz"), &opts())
        .unwrap_err()
        .to_string();
    assert!(err.contains("data.csv.gz") && err.contains("gzip"), "{err}");
}

#[test]
fn source_files_are_what_the_readers_take() {
    let dir = tempfile::tempdir().unwrap();
    // A raw capture folder that also holds processed/data.csv: the processed file is read.
    let folder = dir.path().join("hang_leg1");
    write_files(&folder, &raw_files(100, true));
    std::fs::write(folder.join("notes.txt"), "not read").unwrap();
    let raw: Vec<_> = [
        "acce.txt",
        "gravity.txt",
        "gyro.txt",
        "linacce.txt",
        "magnet.txt",
        "orientation.txt",
        "pose.txt",
        "step.txt",
    ]
    .iter()
    .map(|n| folder.join(n))
    .collect();
    assert_eq!(ridi_data::source_files(&folder).unwrap(), raw);
    std::fs::create_dir_all(folder.join("processed")).unwrap();
    std::fs::write(folder.join("processed/data.csv"), csv_string()).unwrap();
    std::fs::write(folder.join("trajectory.csv"), "").unwrap();
    assert_eq!(
        ridi_data::source_files(&folder).unwrap(),
        [folder.join("processed/data.csv")]
    );
    let file = folder.join("processed/data.csv");
    assert_eq!(
        ridi_data::source_files(&file).unwrap(),
        std::slice::from_ref(&file)
    );
    assert!(ridi_data::source_files(dir.path().join("nope")).is_err());
}
