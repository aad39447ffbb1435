//! `cargo xtask eval tyrex` and `cargo xtask eval orientation` as a user runs them: what
//! happens without the data, and under the names of earlier versions.

use std::process::Command;

#[test]
fn missing_data_folder_fails_with_a_clear_message_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let data = tmp.path().join("no-tyrex-here");
    let out = tmp.path().join("report.md");
    for task in [
        &["eval", "tyrex"][..],
        &["eval", "orientation"],
        &["eval-tyrex"],
        &["eval-orientation"],
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_xtask"))
            .args(task)
            .arg("--data")
            .arg(&data)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert!(!o.status.success(), "{task:?}");
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            stderr.starts_with("error: Tyrex data folder")
                && stderr.contains("no-tyrex-here")
                && stderr.contains("--data"),
            "{task:?}: {stderr}"
        );
        assert_eq!(stderr.lines().count(), 1, "{task:?}: {stderr}");
        assert!(!out.exists(), "{task:?}");
    }
}

#[test]
fn a_filter_that_matches_nothing_fails_before_reading_data() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("report.md");
    for (variants, expect, listed) in [
        (true, "no variant's name contains", "(ridi's defaults)"),
        (false, "no protocol's name contains", "Nexus 5 -> iPhone 4S"),
    ] {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_xtask"));
        cmd.args(["eval", "tyrex", "--only", "no such thing", "--data"])
            .arg(tmp.path().join("absent"))
            .arg("--out")
            .arg(&out);
        if variants {
            cmd.arg("--variants");
        }
        let o = cmd.output().unwrap();
        assert!(!o.status.success());
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            stderr.starts_with(&format!("error: {expect} \"no such thing\"; the "))
                && stderr.contains(listed),
            "{stderr}"
        );
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(!out.exists());
    }
}
