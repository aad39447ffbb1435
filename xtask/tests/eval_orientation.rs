//! `cargo xtask eval-orientation` as a user runs it: what happens without the data.

use std::process::Command;

#[test]
fn missing_data_folder_fails_with_a_clear_message_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let data = tmp.path().join("no-tyrex-here");
    let out = tmp.path().join("report.md");
    let o = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .arg("eval-orientation")
        .arg("--data")
        .arg(&data)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(!o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.starts_with("error: Tyrex data folder") && stderr.contains("no-tyrex-here"),
        "{stderr}"
    );
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(!out.exists());
}
