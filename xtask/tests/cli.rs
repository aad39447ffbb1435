//! The `cargo xtask` binary: exit codes, one-line errors, and the offline path CI uses.

use std::fs;
use std::path::Path;
use std::process::{Command, Output};

use ridi_test_support::{shared_dataset, stderr};

fn xtask(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn errors_are_one_line_with_a_failing_exit_code() {
    let tmp = tempfile::tempdir().unwrap();
    let manifest = tmp.path().join("manifest.toml");
    fs::write(
        &manifest,
        r#"
[datasets.demo]
description = "d"
licence = "l"
urls = ["http://127.0.0.1:9/demo.zip"]
sha256 = ""
layout = ["x"]
"#,
    )
    .unwrap();
    let m = manifest.to_str().unwrap();
    let dir = tmp.path().join("data");
    let d = dir.to_str().unwrap();

    let out = xtask(&["fetch", "demo", "--manifest", m, "--dir", d]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("error: ") && err.contains("--trust-unpinned"),
        "{err}"
    );

    let out = xtask(&["fetch", "nope", "--manifest", m, "--dir", d]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("unknown dataset `nope`"),
        "{}",
        stderr(&out)
    );
}

/// What CI runs: the Tyrex subset from the shared folder, verified by datasets/tyrex.sha256.
#[test]
#[ignore = "needs ../shared beside the checkout: `cargo test --workspace --tests -- --ignored` (.ci/run)"]
fn tyrex_from_the_shared_folder_installs_then_is_a_no_op() {
    let shared = shared_dataset("tyrex-attitude-smartphones", "datasets/android");
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path().to_str().unwrap();
    let from = shared.to_str().unwrap();
    let out = xtask(&["fetch", "tyrex", "--from", from, "--dir", d]);
    assert!(out.status.success(), "{}", stderr(&out));
    let root = tmp.path().join("tyrex");
    let probe = Path::new("datasets/android/Guillaume_Nexus5_NoDist_Texting/accelerometer.txt");
    assert_eq!(
        fs::read(root.join(probe)).unwrap(),
        fs::read(shared.join(probe)).unwrap()
    );

    let again = xtask(&["fetch", "tyrex", "--from", from, "--dir", d]);
    assert!(again.status.success(), "{}", stderr(&again));
    assert!(String::from_utf8_lossy(&again.stdout).contains("already in"));
}
