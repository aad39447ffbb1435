//! Random and mutated input to every reader: each must return `Ok` or an error that names the
//! file (and the line and field where there is one), never panic. Mutations start from valid
//! files so that most cases get deep into the parsers.

mod common;

use std::path::Path;
use std::sync::LazyLock;

use common::*;
use proptest::prelude::*;
use ridi_data::ilc::{self, IlcOptions};
use ridi_data::{ReadOptions, parse_list, ridi_csv, ridi_plain, ridi_raw};
use ridi_test_support::{
    assert_err, assert_names_file, edit_cells, edit_file, edit_rows, with_cell, write_files,
};

static CSV: LazyLock<Vec<u8>> = LazyLock::new(|| valid_csv(12));
static PLAIN: LazyLock<Vec<u8>> = LazyLock::new(|| valid_plain(12));

/// A valid Indoor Location Competition path file: three 50 Hz IMU records, two waypoints.
const ILC: &[u8] = b"#\tstartTime:1574559495000\n\
    1574559495000\tTYPE_WAYPOINT\t81.3\t93.3\n\
    1574559495000\tTYPE_ACCELEROMETER\t-0.8\t1.8\t9.8\t2\n\
    1574559495000\tTYPE_GYROSCOPE\t-0.3\t-0.07\t0.09\t3\n\
    1574559495000\tTYPE_MAGNETIC_FIELD\t29.7\t6.4\t-30.0\t3\n\
    1574559495000\tTYPE_ROTATION_VECTOR\t0.06\t0.07\t0.57\t3\n\
    1574559495020\tTYPE_ACCELEROMETER\t-0.6\t1.8\t9.9\t2\n\
    1574559495020\tTYPE_GYROSCOPE\t-0.5\t-0.2\t0.08\t3\n\
    1574559495020\tTYPE_MAGNETIC_FIELD\t29.7\t5.0\t-27.3\t3\n\
    1574559495020\tTYPE_ROTATION_VECTOR\t0.05\t0.07\t0.57\t3\n\
    1574559494900\tTYPE_WIFI\tssid\t00:11:22:33:44:55\t-60\t5180\t1574559494900\n\
    1574559495040\tTYPE_ACCELEROMETER\t-0.6\t1.9\t10.3\t2\n\
    1574559495040\tTYPE_GYROSCOPE\t-0.6\t-0.1\t0.1\t3\n\
    1574559495040\tTYPE_MAGNETIC_FIELD\t29.7\t3.6\t-28.7\t3\n\
    1574559495040\tTYPE_ROTATION_VECTOR\t0.05\t0.07\t0.57\t3\n\
    1574559495040\tTYPE_WAYPOINT\t81.4\t93.2\n\
    #\tendTime:1574559495040\n";

/// One edit of a byte string.
#[derive(Debug, Clone)]
enum Edit {
    Flip(usize, u8),
    Delete(usize),
    Insert(usize, u8),
    Truncate(usize),
}

/// Bytes that matter to the parsers, besides arbitrary ones.
fn interesting_byte() -> impl Strategy<Value = u8> {
    prop_oneof![
        any::<u8>(),
        prop::sample::select(b",\t \n\r#-+.eE0123456789naNinf".to_vec()),
    ]
}

fn edits() -> impl Strategy<Value = Vec<Edit>> {
    prop::collection::vec(
        prop_oneof![
            (any::<usize>(), interesting_byte()).prop_map(|(i, b)| Edit::Flip(i, b)),
            any::<usize>().prop_map(Edit::Delete),
            (any::<usize>(), interesting_byte()).prop_map(|(i, b)| Edit::Insert(i, b)),
            any::<usize>().prop_map(Edit::Truncate),
        ],
        1..6,
    )
}

fn mutate(base: &[u8], edits: &[Edit]) -> Vec<u8> {
    let mut v = base.to_vec();
    for e in edits {
        let n = v.len().max(1);
        match *e {
            Edit::Flip(i, b) if !v.is_empty() => v[i % n] = b,
            Edit::Delete(i) if !v.is_empty() => {
                v.remove(i % n);
            }
            Edit::Insert(i, b) => v.insert(i % (v.len() + 1), b),
            Edit::Truncate(i) => v.truncate(i % (v.len() + 1)),
            _ => {}
        }
    }
    v
}

/// `cases` by default; `RIDI_ROBUSTNESS_CASES=N` runs more for a deeper local search.
fn config(cases: u32) -> ProptestConfig {
    let cases = std::env::var("RIDI_ROBUSTNESS_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(cases);
    ProptestConfig {
        cases,
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

fn opts() -> ReadOptions {
    ReadOptions::default()
}

#[test]
fn unmutated_fixtures_are_valid() {
    ridi_csv::parse(&CSV, Path::new("data.csv"), &opts()).unwrap();
    ridi_plain::parse(&PLAIN, Path::new("data_plain.txt"), &opts()).unwrap();
    ilc::parse(ILC, Path::new("path.txt"), &IlcOptions::default()).unwrap();
}

/// The project's rule for an error of a reader on `bytes` read as `file`: it names the file, and
/// a line it names is one of the file's lines.
fn assert_error_names<T>(r: ridi_data::Result<T>, file: &str, bytes: &[u8]) {
    if let Err(e) = r {
        assert_names_file(&e, Path::new(file)).assert_line_in(bytes);
    }
}

/// The rule for an error of the list parser on `bytes` read as `file`: it names the file, and
/// the line (of the file) unless nothing is listed at all, and a field only as `path` or
/// `placement`, the two of a line.
fn assert_list_error(e: &ridi_data::DataError, file: &Path, bytes: &[u8]) {
    let blame = assert_names_file(e, file);
    blame.assert_line_in(bytes);
    assert!(
        blame.line.is_some() || e.to_string().contains("no sequences listed"),
        "no line in `{e}`"
    );
    assert!(
        matches!(blame.field.as_deref(), None | Some("path" | "placement")),
        "field of `{e}`"
    );
}

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn csv_reader_survives_mutations(edits in edits()) {
        let bytes = mutate(&CSV, &edits);
        let r = ridi_csv::parse(&bytes, Path::new("data.csv"), &opts());
        assert_error_names(r, "data.csv", &bytes);
    }

    #[test]
    fn plain_reader_survives_mutations(edits in edits()) {
        let bytes = mutate(&PLAIN, &edits);
        let r = ridi_plain::parse(&bytes, Path::new("data_plain.txt"), &opts());
        assert_error_names(r, "data_plain.txt", &bytes);
    }

    #[test]
    fn text_readers_survive_random_bytes(bytes in prop::collection::vec(interesting_byte(), 0..400)) {
        let csv = ridi_csv::parse(&bytes, Path::new("data.csv"), &opts());
        assert_error_names(csv, "data.csv", &bytes);
        let plain = ridi_plain::parse(&bytes, Path::new("data_plain.txt"), &opts());
        assert_error_names(plain, "data_plain.txt", &bytes);
        if let Err(e) = parse_list(&bytes, Path::new("list.txt")) {
            assert_list_error(&e, Path::new("list.txt"), &bytes);
        }
        let path = ilc::parse(&bytes, Path::new("path.txt"), &IlcOptions::default());
        assert_error_names(path, "path.txt", &bytes);
        let _ = ilc::looks_like_path_file(&bytes);
    }

    #[test]
    fn ilc_reader_survives_mutations(edits in edits()) {
        let bytes = mutate(ILC, &edits);
        let r = ilc::parse(&bytes, Path::new("path.txt"), &IlcOptions::default());
        assert_error_names(r, "path.txt", &bytes);
    }

    #[test]
    fn list_parser_survives_mutations(edits in edits()) {
        let base = b"# train\nseq_a,body\n/abs/seq_b , bag\n\nseq_c\n";
        let bytes = mutate(base, &edits);
        match parse_list(&bytes, Path::new("/d/list.txt")) {
            Ok(entries) => prop_assert!(entries.iter().all(|e| !e.path.as_os_str().is_empty())),
            Err(e) => assert_list_error(&e, Path::new("/d/list.txt"), &bytes),
        }
    }
}

proptest! {
    // Each case writes a folder of eight files: fewer cases keep the suite fast.
    #![proptest_config(config(48))]

    #[test]
    fn raw_reader_survives_mutations(
        mutations in prop::collection::vec((0usize..8, edits()), 1..3),
        trim in 0usize..8,
    ) {
        let dir = tempfile::tempdir().unwrap();
        let files = raw_files(30, true);
        write_files(dir.path(), &files);
        // One or two files mutated (the same one twice, or two whose faults race).
        for (file, edits) in &mutations {
            let path = dir.path().join(files[*file].0);
            let content = mutate(&std::fs::read(&path).unwrap(), edits);
            std::fs::write(path, content).unwrap();
        }
        let opts = ReadOptions { pose_trim: trim, ..ReadOptions::default() };
        let whole = ridi_raw::read(dir.path(), &opts);
        if let Err(e) = &whole {
            // The folder, or one of its files (whose lines the error may name).
            let blame = assert_names_file(e, dir.path());
            if blame.file != dir.path() {
                blame.assert_line_in(&std::fs::read(&blame.file).unwrap());
            }
        }
        // Read as a stream: the same rows, or the same error.
        assert_streams_as_read(dir.path(), &opts, &whole);
    }
}

// ---- implausible values: refused with the file, line and field --------------------------

/// Degrees per second in radians per second.
const DEG: f64 = 57.295_779_513_082_32;

fn csv_text() -> String {
    String::from_utf8(CSV.clone()).unwrap()
}

fn parse_csv(text: &str) -> ridi_data::Result<ridi_data::Sequence> {
    ridi_csv::parse(text.as_bytes(), Path::new("walk/data.csv"), &opts())
}

/// `f` applied to the numbers in `cells` (data rows only: the header is line 1).
fn scale(cells: &mut [String], f: impl Fn(f64) -> f64) {
    for c in cells {
        *c = f(c.trim().parse::<f64>().unwrap()).to_string();
    }
}

/// The csv fixture with `f` applied to columns `cols` (0 = the pandas index) of every data row.
fn csv_scaled(cols: std::ops::Range<usize>, f: impl Fn(f64) -> f64) -> String {
    edit_rows(&csv_text(), |line, cells| {
        if line > 1 {
            scale(&mut cells[cols.clone()], &f);
        }
    })
}

#[test]
fn csv_gyro_in_degrees_per_second_is_refused() {
    assert_err(
        parse_csv(&csv_scaled(2..5, |v| v * DEG)),
        &[
            "walk/data.csv: field `gyro_x..gyro_z`: median |gyro| ",
            "rad/s is above 10 rad/s: gyroscope in deg/s instead of rad/s?",
        ],
    );
}

#[test]
fn csv_gyro_that_does_not_turn_with_the_orientation_is_refused() {
    // The fixture's orientation turns at about 0.7 rad/s; a gyro column of zeros (a sensor
    // that was not recorded, filled in) passes every bound on its own.
    let text = edit_rows(&csv_text(), |line, cells| {
        if line > 1 {
            for c in &mut cells[2..5] {
                *c = "0".into();
            }
        }
    });
    assert_err(
        parse_csv(&text),
        &[
            "walk/data.csv: field `gyro_x..gyro_z`: the gyro turns 0 times as fast as the \
             orientation (least squares over frames), outside 0.25..4: a gyro in another unit, \
             or of another recording or device?",
        ],
    );
}

#[test]
fn csv_accelerometer_in_g_is_refused() {
    // `acce` and `linacce` in g, gravity in m/s^2.
    assert_err(
        parse_csv(&csv_scaled(5..11, |v| v / 9.80665)),
        &[
            "walk/data.csv: field `acce_x..acce_z`: mean |acce| 1 m/s^2 is 0.102 times mean \
             |gravity| 9.807 m/s^2, outside 0.5..3: accelerometer in g instead of m/s^2?",
        ],
    );
}

#[test]
fn csv_linear_acceleration_alone_in_g_is_refused() {
    assert_err(
        parse_csv(&csv_scaled(8..11, |v| v / 9.80665)),
        &[
            "walk/data.csv: field `linacce_x..linacce_z`: accelerometer minus gravity is 9.807 \
             times the linear acceleration (least squares), outside 0.5..2: linear acceleration \
             in g instead of m/s^2?",
        ],
    );
    // Off by a factor of 1.5 (a lagging filter, say) is still a linear acceleration.
    assert!(parse_csv(&csv_scaled(8..11, |v| v * 1.5)).is_ok());
}

#[test]
fn csv_positions_in_millimetres_are_refused() {
    let header = csv_text().lines().next().unwrap().to_owned();
    let pos_x = header.split(',').position(|c| c == "pos_x").unwrap();
    assert_err(
        parse_csv(&csv_scaled(pos_x..pos_x + 3, |v| v * 1000.0)),
        &[
            "walk/data.csv: field `pos_x..pos_z`: the ground truth moves at a median ",
            "m/s, above 20 m/s: positions in mm or cm instead of metres?",
        ],
    );
    // In metres the same walk passes.
    parse_csv(&csv_text()).unwrap();
}

#[test]
fn csv_time_in_seconds_or_milliseconds_is_refused() {
    for (divisor, step, unit) in [
        (
            1e9,
            "e-12 s (median)",
            "seconds instead of nanoseconds (multiply by 1e9)",
        ),
        (
            1e6,
            "by 5e-9 s (median)",
            "milliseconds instead of nanoseconds (multiply by 1e6)",
        ),
    ] {
        let text = csv_scaled(1..2, |ns| {
            let t = ns / divisor;
            // Milliseconds as integers, like a recorder would write them.
            if divisor == 1e6 { t.round() } else { t }
        });
        assert_err(
            parse_csv(&text),
            &[
                "walk/data.csv: field `time`: timestamps step by ",
                step,
                "outside 1e-4..1 s: time in ",
                unit,
                "? (this format expects nanoseconds)",
            ],
        );
    }
}

#[test]
fn csv_one_absurd_value_names_its_line_and_column() {
    let cases = [
        (
            4,
            2,
            "1e300",
            "data.csv:4: field `gyro_x`: 1e300 rad/s is beyond any phone gyroscope (|value| <= 100 rad/s)",
        ),
        (
            5,
            6,
            "1e308",
            "data.csv:5: field `acce_y`: 1e308 m/s^2 is beyond any phone accelerometer (|value| <= 2000 m/s^2)",
        ),
        (
            6,
            10,
            "-5000",
            "data.csv:6: field `linacce_z`: -5000 m/s^2 is beyond any phone accelerometer",
        ),
        (
            7,
            11,
            "25",
            "data.csv:7: field `grav_x`: 25 m/s^2 is beyond any gravity reading (|value| <= 20 m/s^2)",
        ),
        (
            8,
            15,
            "1e5",
            "data.csv:8: field `magnet_y`: 100000 uT is beyond any phone magnetometer (|value| <= 10000 uT)",
        ),
        (
            9,
            17,
            "1e300",
            "data.csv:9: field `pos_x`: 1e300 m is beyond any plausible ground-truth position (|value| <= 1e6 m)",
        ),
    ];
    for (line, col, value, expected) in cases {
        assert_err(
            parse_csv(&with_cell(&csv_text(), line, col, value)),
            &[expected],
        );
    }
}

#[test]
fn plain_one_absurd_value_names_its_line_and_column() {
    let text = String::from_utf8(PLAIN.clone()).unwrap();
    // Line 1 is `N 27`; no index column, so acce_x is the fifth cell.
    let text = edit_cells(&text, '\t', |line, cells| {
        if line == 6 {
            cells[4] = "-1e308".into();
        }
    });
    assert_err(
        ridi_plain::parse(text.as_bytes(), Path::new("data_plain.txt"), &opts()),
        &["data_plain.txt:6: field `acce_x`: -1e308 m/s^2 is beyond any phone accelerometer"],
    );
}

/// `f` applied to the values (not the time) of every data row of a raw file.
fn raw_scaled(f: impl Fn(f64) -> f64 + Copy) -> impl FnOnce(&str) -> String {
    move |text| {
        edit_cells(text, ' ', |_, cells| {
            if !cells[0].starts_with('#') {
                scale(&mut cells[1..], f);
            }
        })
    }
}

#[test]
fn raw_gyro_in_degrees_per_second_is_refused() {
    // A steady turn of 35 deg/s, written in deg/s.
    let (_d, r) = raw_with(|f| {
        edit_file(f, "gyro.txt", raw_scaled(|_| 35.0));
    });
    assert_err(
        r,
        &[
            "gyro.txt: field `x..z`: median |gyro| 60.622 rad/s is above 10 rad/s: gyroscope in deg/s",
        ],
    );
}

#[test]
fn raw_accelerometer_in_g_is_refused() {
    let (_d, r) = raw_with(|f| {
        edit_file(f, "acce.txt", raw_scaled(|v| v / 9.80665));
        edit_file(f, "linacce.txt", raw_scaled(|v| v / 9.80665));
    });
    assert_err(
        r,
        &[
            "acce.txt: field `x..z`: mean |acce| 1.0",
            "accelerometer in g instead of m/s^2?",
        ],
    );
}

#[test]
fn raw_linear_acceleration_alone_in_g_is_refused() {
    // The fixture's phone hardly moves: add 2 m/s^2 on every axis so there is something to
    // judge, then write the linear acceleration in g.
    let (_d, r) = raw_with(|f| {
        edit_file(f, "acce.txt", raw_scaled(|v| v + 2.0));
        edit_file(f, "linacce.txt", raw_scaled(|v| (v + 2.0) / 9.80665));
    });
    assert_err(
        r,
        &[
            "linacce.txt: field `x..z`: accelerometer minus gravity is",
            "linear acceleration in g instead of m/s^2?",
        ],
    );
}

#[test]
fn raw_time_in_seconds_is_refused() {
    let (_d, r) = raw_with(|f| {
        edit_file(f, "gyro.txt", |text| {
            edit_cells(text, ' ', |_, cells| {
                if !cells[0].starts_with('#') {
                    scale(&mut cells[..1], |ns| ns / 1e9);
                }
            })
        });
    });
    assert_err(
        r,
        &[
            "gyro.txt: field `t`: timestamps step by 5e-12 s (median)",
            "(this format expects nanoseconds)",
        ],
    );
}

#[test]
fn raw_one_absurd_value_names_its_file_line_and_field() {
    let cases = [
        (
            "gyro.txt",
            3,
            1,
            "1e300",
            "gyro.txt:3: field `x`: 1e300 rad/s is beyond any phone gyroscope",
        ),
        (
            "acce.txt",
            4,
            2,
            "1e308",
            "acce.txt:4: field `y`: 1e308 m/s^2 is beyond any phone accelerometer",
        ),
        (
            "linacce.txt",
            5,
            3,
            "-3000",
            "linacce.txt:5: field `z`: -3000 m/s^2 is beyond any phone accelerometer",
        ),
        (
            "gravity.txt",
            6,
            1,
            "-25",
            "gravity.txt:6: field `x`: -25 m/s^2 is beyond any gravity reading",
        ),
        (
            "magnet.txt",
            7,
            2,
            "2e4",
            "magnet.txt:7: field `y`: 20000 uT is beyond any phone magnetometer",
        ),
        (
            "pose.txt",
            8,
            1,
            "1e300",
            "pose.txt:8: field `tx`: 1e300 m is beyond any plausible ground-truth position",
        ),
    ];
    for (file, line, col, value, expected) in cases {
        let (_d, r) = raw_with(|f| {
            edit_file(f, file, |text| {
                edit_cells(text, ' ', |n, cells| {
                    if n == line {
                        cells[col] = value.into();
                    }
                })
            });
        });
        assert_err(r, &[expected]);
    }
}

fn ilc_text() -> String {
    String::from_utf8(ILC.to_vec()).unwrap()
}

fn parse_ilc(text: &str) -> ridi_data::Result<ilc::IlcPath> {
    ilc::parse(
        text.as_bytes(),
        Path::new("site/path.txt"),
        &IlcOptions::default(),
    )
}

/// The ILC fixture with `f` applied to the three values of every `kind` record.
fn ilc_scaled(kind: &str, f: impl Fn(f64) -> f64) -> String {
    edit_cells(&ilc_text(), '\t', |_, cells| {
        if cells.get(1).map(String::as_str) == Some(kind) {
            scale(&mut cells[2..5], &f);
        }
    })
}

#[test]
fn ilc_gyro_in_degrees_per_second_is_refused() {
    assert_err(
        parse_ilc(&ilc_scaled("TYPE_GYROSCOPE", |v| v * DEG)),
        &[
            "site/path.txt: field `TYPE_GYROSCOPE`: median |gyro| ",
            "gyroscope in deg/s instead of rad/s?",
        ],
    );
}

#[test]
fn ilc_accelerometer_in_g_is_refused() {
    assert_err(
        parse_ilc(&ilc_scaled("TYPE_ACCELEROMETER", |v| v / 9.80665)),
        &[
            "site/path.txt: field `TYPE_ACCELEROMETER`: mean |acce| 1.0",
            "accelerometer in g instead of m/s^2?",
        ],
    );
}

#[test]
fn ilc_time_in_seconds_is_refused() {
    let text = edit_cells(&ilc_text(), '\t', |_, cells| {
        if !cells[0].starts_with('#') {
            scale(&mut cells[..1], |ms| ms / 1000.0);
        }
    });
    assert_err(
        parse_ilc(&text),
        &[
            "site/path.txt: field `unix_ms`: timestamps step by 2e-5 s (median)",
            "(this format expects milliseconds)",
        ],
    );
}

#[test]
fn ilc_one_absurd_value_names_its_line_and_field() {
    let cases = [
        (
            7,
            2,
            "1e308",
            "path.txt:7: field `TYPE_ACCELEROMETER x`: 1e308 m/s^2 is beyond any phone accelerometer",
        ),
        (
            8,
            4,
            "-1e300",
            "path.txt:8: field `TYPE_GYROSCOPE z`: -1e300 rad/s is beyond any phone gyroscope",
        ),
        (
            9,
            3,
            "1e5",
            "path.txt:9: field `TYPE_MAGNETIC_FIELD y`: 100000 uT is beyond any phone magnetometer",
        ),
        (
            2,
            2,
            "1e300",
            "path.txt:2: field `TYPE_WAYPOINT x`: 1e300 m is beyond any plausible ground-truth position",
        ),
    ];
    for (line, col, value, expected) in cases {
        let text = edit_cells(&ilc_text(), '\t', |n, cells| {
            if n == line {
                cells[col] = value.into();
            }
        });
        assert_err(parse_ilc(&text), &[expected]);
    }
}
