//! Random and mutated input to every reader: each must return `Ok` or `Err`, never panic.
//! Mutations start from valid files so that most cases get deep into the parsers.

mod common;

use std::path::Path;
use std::sync::LazyLock;

use common::*;
use proptest::prelude::*;
use ridi_data::ilc::{self, IlcOptions};
use ridi_data::{ReadOptions, parse_list, ridi_csv, ridi_plain, ridi_raw};

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

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn csv_reader_survives_mutations(edits in edits()) {
        let _ = ridi_csv::parse(&mutate(&CSV, &edits), Path::new("data.csv"), &opts());
    }

    #[test]
    fn plain_reader_survives_mutations(edits in edits()) {
        let _ = ridi_plain::parse(&mutate(&PLAIN, &edits), Path::new("data_plain.txt"), &opts());
    }

    #[test]
    fn text_readers_survive_random_bytes(bytes in prop::collection::vec(interesting_byte(), 0..400)) {
        let _ = ridi_csv::parse(&bytes, Path::new("data.csv"), &opts());
        let _ = ridi_plain::parse(&bytes, Path::new("data_plain.txt"), &opts());
        let _ = parse_list(&bytes, Path::new("list.txt"));
        let _ = ilc::parse(&bytes, Path::new("path.txt"), &IlcOptions::default());
        let _ = ilc::looks_like_path_file(&bytes);
    }

    #[test]
    fn ilc_reader_survives_mutations(edits in edits()) {
        let _ = ilc::parse(&mutate(ILC, &edits), Path::new("path.txt"), &IlcOptions::default());
    }

    #[test]
    fn list_parser_survives_mutations(edits in edits()) {
        let base = b"# train\nseq_a,body\n/abs/seq_b , bag\n\nseq_c\n";
        if let Ok(entries) = parse_list(&mutate(base, &edits), Path::new("/d/list.txt")) {
            prop_assert!(entries.iter().all(|e| !e.path.as_os_str().is_empty()));
        }
    }
}

proptest! {
    // Each case writes a folder of eight files: fewer cases keep the suite fast.
    #![proptest_config(config(48))]

    #[test]
    fn raw_reader_survives_mutations(file in 0usize..8, edits in edits(), trim in 0usize..8) {
        let dir = tempfile::tempdir().unwrap();
        let mut files = raw_files(30, true);
        let content = mutate(files[file].1.as_bytes(), &edits);
        files.remove(file);
        write_files(dir.path(), &files);
        std::fs::write(dir.path().join(raw_files(30, true)[file].0), content).unwrap();
        let opts = ReadOptions { pose_trim: trim, ..ReadOptions::default() };
        let _ = ridi_raw::read(dir.path(), &opts);
    }
}
