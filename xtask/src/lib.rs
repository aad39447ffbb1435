//! Developer tasks for ridi-rs, as a library so that integration tests drive the same code as
//! `cargo xtask` (with manifest entries and URLs of their own, e.g. a server on 127.0.0.1).

pub mod archive;
pub mod checksum;
pub mod download;
pub mod fetch;
pub mod manifest;

use std::path::PathBuf;

/// The workspace root, fixed at build time: xtask always runs from this checkout, and the
/// defaults (manifest, datasets folder) must not depend on the caller's working directory.
pub fn workspace_root() -> PathBuf {
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    here.parent().map(PathBuf::from).unwrap_or(here)
}
