//! `ridi inspect` and `ridi convert --from ronin` on the RoNIN-layout fixtures of ridi-data
//! (`crates/ridi-data/tests/ronin`, written by h5py).

use std::path::{Path, PathBuf};

use ridi_test_support::{assert_names_file, stderr};

mod common;

use common::{ridi, s};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../ridi-data/tests/ronin")
}

/// A RoNIN split folder holding the valid sequence.
fn split(dir: &Path) -> PathBuf {
    let root = dir.join("train_dataset_1");
    let seq = root.join("a000_1");
    std::fs::create_dir_all(&seq).unwrap();
    for f in ["data.hdf5", "info.json"] {
        std::fs::copy(fixtures().join("a000_1").join(f), seq.join(f)).unwrap();
    }
    root
}

#[test]
fn inspect_reads_a_ronin_folder() {
    let seq = fixtures().join("a000_1");
    let out = ridi(&["inspect", s(&seq)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("RoNIN folder") && text.contains("game rotation vector"),
        "{text}"
    );
    let out = ridi(&["inspect", s(&seq.join("data.hdf5")), "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["frames"], 280);

    // Bad input: one line naming the file and the dataset.
    let bad = fixtures().join("bad/wrong_shape");
    let out = ridi(&["inspect", s(&bad)]);
    assert!(!out.status.success());
    let err = stderr(&out);
    let blame = assert_names_file(&err, &bad.join("data.hdf5"));
    assert_eq!(blame.field.as_deref(), Some("synced/acce"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}

#[test]
fn convert_from_ronin_writes_the_ridi_layout() {
    let dir = tempfile::tempdir().unwrap();
    let root = split(dir.path());
    for (from, out) in [(Some("ronin"), "conv"), (None, "detected")] {
        let out_dir = dir.path().join(out);
        let mut args = vec!["convert", s(&root), "--out", s(&out_dir)];
        if let Some(f) = from {
            args.extend(["--from", f]);
        }
        let out = ridi(&args);
        assert!(out.status.success(), "{from:?}: {}", stderr(&out));
        let seq = out_dir.join("a000_1");
        let out = ridi(&["inspect", s(&seq), "--json"]);
        assert!(out.status.success(), "{}", stderr(&out));
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(json["frames"], 280);
        assert_eq!(json["format"], "ridi-csv");
    }
    // One sequence folder converts too.
    let one = dir.path().join("one");
    let out = ridi(&[
        "convert",
        s(&root.join("a000_1")),
        "--from",
        "ronin",
        "--out",
        s(&one),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));

    // Another format given as RoNIN says what it is.
    let csv = dir.path().join("conv/a000_1/processed/data.csv");
    let out = ridi(&[
        "convert",
        s(&csv),
        "--from",
        "ronin",
        "--out",
        s(&dir.path().join("nothing")),
    ]);
    let err = stderr(&out);
    assert!(
        err.contains("not a RoNIN folder (it is a RIDI processed csv)"),
        "{err}"
    );
}
