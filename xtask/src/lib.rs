//! Developer tasks for ridi-rs, as a library so that integration tests drive the same code as
//! `cargo xtask` (with manifest entries and URLs of their own, e.g. a server on 127.0.0.1).

pub mod archive;
pub mod checksum;
pub mod download;
pub mod features;
pub mod fetch;
pub mod manifest;
pub mod ronin_lists;
pub mod rust_version;
pub mod tidy;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

/// Where the Tyrex data are by default, relative to the workspace root: the shared data folder
/// beside the checkout.
pub const DEFAULT_TYREX: &str = "../shared/data/raw/tyrex-attitude-smartphones";

/// The workspace root, fixed at build time: xtask always runs from this checkout, and the
/// defaults (manifest, datasets folder) must not depend on the caller's working directory.
pub fn workspace_root() -> PathBuf {
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    here.parent().map(PathBuf::from).unwrap_or(here)
}

/// The Tyrex root a task reads: `data`; without it [`DEFAULT_TYREX`] beside the workspace, or
/// else `datasets/tyrex`, where `cargo xtask fetch tyrex` installs it.
///
/// # Errors
/// The folder does not exist: the message says how to pass or install one.
pub fn tyrex_root(data: Option<PathBuf>) -> anyhow::Result<PathBuf> {
    let root = workspace_root();
    let data = data.unwrap_or_else(|| {
        let shared = root.join(DEFAULT_TYREX);
        let fetched = root.join("datasets/tyrex");
        if !shared.is_dir() && fetched.is_dir() {
            fetched
        } else {
            shared
        }
    });
    anyhow::ensure!(
        data.is_dir(),
        "Tyrex data folder {} not found: pass --data <tyrex root> (`cargo xtask fetch tyrex` \
         installs one in datasets/tyrex)",
        data.display()
    );
    Ok(data)
}

/// Runs cargo (the one `cargo xtask` runs under, `$CARGO`) with `args` and the environment
/// `env` in `root`, its stderr on the terminal; returns its stdout, or an error naming the
/// command when it fails.
pub fn cargo_stdout(root: &Path, args: &[&str], env: &[(&str, &Path)]) -> Result<String> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let out = std::process::Command::new(cargo)
        .args(args)
        .envs(env.iter().copied())
        .current_dir(root)
        .stderr(std::process::Stdio::inherit())
        .output()
        .with_context(|| format!("running cargo {}", args.join(" ")))?;
    if !out.status.success() {
        bail!("cargo {} failed: {}", args.join(" "), out.status);
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}
