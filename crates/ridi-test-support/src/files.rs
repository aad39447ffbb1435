//! Files written and found by the tests, and the output of a binary they run.

use std::path::Path;
use std::process::Output;

/// Writes `files` (name, content) into `dir`, creating it if needed.
#[track_caller]
pub fn write_files(dir: &Path, files: &[(&str, String)]) {
    std::fs::create_dir_all(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    for (name, content) in files {
        let path = dir.join(name);
        std::fs::write(&path, content).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    }
}

/// Applies `f` to the content of file `name` among `files`; the file must be there.
#[track_caller]
pub fn edit_file(files: &mut [(&'static str, String)], name: &str, f: impl FnOnce(&str) -> String) {
    let entry = files
        .iter_mut()
        .find(|(n, _)| *n == name)
        .unwrap_or_else(|| panic!("no file {name} among the fixtures"));
    entry.1 = f(&entry.1);
}

/// The names of the entries of `dir`, sorted (none when `dir` does not exist): what a test
/// compares to see that no temporary or partial file was left behind.
#[track_caller]
pub fn file_names(dir: &Path) -> Vec<String> {
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Vec::new(),
        Err(e) => panic!("{}: {e}", dir.display()),
    };
    let mut names: Vec<String> = entries
        .map(|e| {
            e.unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    names.sort();
    names
}

/// The standard error of a finished run, as text.
pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Makes a named pipe at `path` (`mkfifo`): what a test gives where a regular file is expected
/// (an output the atomic rename would replace; a device such as `/dev/null` would be replaced
/// for good, were the check to fail in a test run as root).
#[cfg(unix)]
#[track_caller]
pub fn make_fifo(path: &Path) {
    let made = std::process::Command::new("mkfifo").arg(path).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo {}", path.display());
}

/// Whether `path` is (still) a named pipe, not followed if a link: what a refused write must
/// have left of [`make_fifo`]'s.
#[cfg(unix)]
pub fn is_fifo(path: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt as _;
    std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_fifo())
}
