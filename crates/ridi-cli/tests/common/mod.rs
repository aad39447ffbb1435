//! What every test of the `ridi` binary needs: running it, and paths as arguments.

use std::path::Path;
use std::process::{Command, Output};

/// Runs the `ridi` binary with `args` and waits for it.
pub(crate) fn ridi(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ridi"))
        .args(args)
        .output()
        .expect("run ridi")
}

/// `p` as a command-line argument (the tests' paths are UTF-8).
pub(crate) fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}
