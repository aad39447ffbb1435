//! `convert` on the full Tyrex data in `../shared` (beside the checkout); returns early with a
//! note when the data are not there.

use std::path::Path;

use ridi::data::{ReadOptions, read_list};

#[test]
fn the_whole_tyrex_root_converts_with_one_list_per_person() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/raw/tyrex-attitude-smartphones");
    if !root.join("datasets/android").is_dir() {
        eprintln!("note: {} not found: skipped", root.display());
        return;
    }
    let out = tempfile::tempdir().unwrap();
    let summary = ridi::convert::convert(&root, out.path(), None, &ReadOptions::default()).unwrap();
    // 24 runs, some split at long mocap or sensor gaps into parts, each named and listed.
    assert!(summary.sequences.len() >= 24, "{}", summary.sequences.len());
    assert!(!summary.warnings.is_empty(), "splits are reported");
    let all = read_list(out.path().join("list_all.txt")).unwrap();
    assert_eq!(all.len(), summary.sequences.len());
    let mut per_person = 0;
    for person in ["Guillaume", "Jakob", "Thibaud"] {
        let list = read_list(out.path().join(format!("list_{person}.txt"))).unwrap();
        assert!(
            list.iter()
                .all(|e| e.path.to_string_lossy().contains(person))
        );
        assert!(list.iter().all(|e| e.placement.is_some()));
        per_person += list.len();
    }
    assert_eq!(per_person, all.len(), "every part is in its person's list");
    for c in &summary.sequences {
        assert!(c.path.is_file(), "{}", c.path.display());
    }
}
