//! Inputs the fuzz targets of `fuzz/` found, minimized (`cargo xtask fuzz <target> --input
//! <file> -- -minimize_crash=1`; see fuzz/README.md), in `tests/fuzz_found/<target>/`, each
//! replayed through the entry point of its target: `Ok`, or an error naming the file, without
//! a panic. The reader's own tests check what each one broke (a timeout is checked there by
//! what the fix changed, not by a clock); this keeps the inputs themselves.

use std::path::Path;

use ridi_data::MatFile;
use ridi_test_support::{assert_names_file, file_names};

/// The inputs found by `target`, (file name, bytes).
fn found(target: &str) -> Vec<(String, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz_found")
        .join(target);
    let names = file_names(&dir);
    assert!(!names.is_empty(), "nothing in {}", dir.display());
    names
        .into_iter()
        .map(|name| {
            let bytes = std::fs::read(dir.join(&name)).unwrap();
            (name, bytes)
        })
        .collect()
}

/// Runs `read` on each input of `target`: it must not panic, and its error, if any, must name
/// the file `file`.
fn replay<T>(target: &str, file: &str, read: impl Fn(&[u8]) -> ridi_data::Result<T>) {
    for (name, bytes) in found(target) {
        if let Err(e) = read(&bytes) {
            eprintln!("{target}/{name}: {e}");
            assert_names_file(&e, Path::new(file));
        }
    }
}

#[test]
fn mat() {
    // As fuzz/fuzz_targets/mat.rs: parse, then walk what was decoded.
    replay("mat", "fuzz.mat", |bytes| {
        let file = MatFile::from_bytes(bytes, "fuzz.mat")?;
        for (_, value) in file.variables() {
            let _ = value.lookup("RigidBodies.Positions");
        }
        Ok(())
    });
}
