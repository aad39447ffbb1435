//! Data beside the code: the checkout's bundled sample and the third-party data in `../shared`.

use std::path::{Path, PathBuf};

/// The root of the checkout (the folder of the workspace `Cargo.toml`), without `..` in it.
pub fn workspace_root() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    root.canonicalize()
        .unwrap_or_else(|e| panic!("{}: {e}", root.display()))
}

/// `datasets/sample`: the small Tyrex subset the repository ships, in RIDI's processed layout.
pub fn sample_dataset() -> PathBuf {
    workspace_root().join("datasets/sample")
}

/// `../shared/data/raw/<dataset>` beside the checkout, which must hold `probe`. The tests that
/// call this are `#[ignore]`d (they run when asked for, as `.ci/run` does), so a missing folder
/// is a failure, not a silent pass.
#[track_caller]
pub fn shared_dataset(dataset: &str, probe: &str) -> PathBuf {
    let root = workspace_root().join("../shared/data/raw").join(dataset);
    assert!(
        root.join(probe).exists(),
        "{} not found: these checks need the shared data beside the checkout",
        root.join(probe).display()
    );
    root
}
