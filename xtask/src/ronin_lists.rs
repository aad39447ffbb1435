//! RoNIN's split lists as ridi list files, written into a fetched RoNIN folder.
//!
//! RoNIN's lists (`datasets/protocols/ronin/list_<split>.txt`, copied from its repository)
//! name one sequence folder per line (`a000_1`) relative to a root folder its scripts take
//! separately. The public release spreads the folders over four split folders
//! (`train_dataset_1`, `train_dataset_2`, `seen_subjects_test_set`, `unseen_subjects_test_set`),
//! not always those of the lists' splits, so the lists are rewritten with each name's path from
//! the dataset root (`train_dataset_1/a000_1`): ridi list files (`path,placement` per line,
//! relative to the list), readable by `--list`. The placement is [`PLACEMENT`] for every
//! sequence: RoNIN labels none, and its phones change between hand, pocket and bag within a
//! sequence. A listed name that is in no split folder is left out, with a `# missing:` comment
//! line and a warning.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

/// The placement label of every listed sequence.
pub const PLACEMENT: &str = "mixed";

/// The splits, RoNIN's names.
pub const SPLITS: [&str; 4] = ["train", "val", "test_seen", "test_unseen"];

/// The release's split folders, searched in this order for each name.
pub const FOLDERS: [&str; 4] = [
    "train_dataset_1",
    "train_dataset_2",
    "seen_subjects_test_set",
    "unseen_subjects_test_set",
];

/// The names of a RoNIN list (RoNIN's own reading: `#` lines skipped, the first word of each
/// other non-blank line).
pub fn parse_names(text: &str) -> Vec<String> {
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_owned)
        .collect()
}

/// Where `name` is under `root`: `<split folder>/<name>` holding a `data.hdf5`, or `<name>`
/// directly (a root holding the sequences itself).
fn locate(root: &Path, name: &str) -> Option<String> {
    FOLDERS
        .iter()
        .map(|f| format!("{f}/{name}"))
        .chain(std::iter::once(name.to_owned()))
        .find(|rel| root.join(rel).join("data.hdf5").is_file())
}

/// Writes `list_<split>.txt` into `root` for every split of `protocols`; returns the paths
/// written and a warning per split with names that are not in `root`.
///
/// # Errors
/// A list cannot be read or written, or no listed name is found at all (not a RoNIN folder).
pub fn write_lists(root: &Path, protocols: &Path) -> Result<(Vec<PathBuf>, Vec<String>)> {
    let mut written = Vec::new();
    let mut warnings = Vec::new();
    let mut found_any = false;
    for split in SPLITS {
        let source = protocols.join(format!("list_{split}.txt"));
        let text = std::fs::read_to_string(&source)
            .with_context(|| format!("cannot read {}", source.display()))?;
        let mut out = format!(
            "# RoNIN's split `{split}` ({}), as ridi list lines relative to this folder \
             (written by `cargo xtask fetch ronin`).\n",
            source
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default()
        );
        let mut missing = Vec::new();
        for name in parse_names(&text) {
            match locate(root, &name) {
                Some(rel) => {
                    found_any = true;
                    let _ = writeln!(out, "{rel},{PLACEMENT}");
                }
                None => missing.push(name),
            }
        }
        if !missing.is_empty() {
            let _ = writeln!(out, "# missing: {}", missing.join(" "));
            warnings.push(format!(
                "ronin: {} of `{split}` not in {}: {}",
                ridi_data::counted(missing.len(), "sequence"),
                root.display(),
                missing.join(" ")
            ));
        }
        let path = root.join(format!("list_{split}.txt"));
        std::fs::write(&path, out).with_context(|| format!("cannot write {}", path.display()))?;
        written.push(path);
    }
    if !found_any {
        bail!(
            "{}: none of RoNIN's listed sequences is there (expected {} holding folders such as \
             a000_1 with data.hdf5)",
            root.display(),
            FOLDERS.join(", ")
        );
    }
    Ok((written, warnings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_committed_lists_are_ronins_splits() {
        let protocols = crate::workspace_root().join("datasets/protocols/ronin");
        let counts: Vec<usize> = SPLITS
            .iter()
            .map(|s| {
                let text = std::fs::read_to_string(protocols.join(format!("list_{s}.txt")));
                parse_names(&text.unwrap()).len()
            })
            .collect();
        assert_eq!(counts, [73, 16, 32, 32]);
    }

    #[test]
    fn lists_name_each_sequence_by_its_split_folder() {
        let dir = tempfile::tempdir().unwrap();
        let protocols = dir.path().join("protocols");
        std::fs::create_dir_all(&protocols).unwrap();
        for s in SPLITS {
            let names = match s {
                "train" => "a000_1\na007_3\n",
                "val" => "# comment\na000_6  extra\n",
                _ => "a059_2\n",
            };
            std::fs::write(protocols.join(format!("list_{s}.txt")), names).unwrap();
        }
        let root = dir.path().join("ronin");
        for rel in [
            "train_dataset_1/a000_1",
            "seen_subjects_test_set/a000_6",
            "a059_2",
        ] {
            std::fs::create_dir_all(root.join(rel)).unwrap();
            std::fs::write(root.join(rel).join("data.hdf5"), b"").unwrap();
        }
        let (written, warnings) = write_lists(&root, &protocols).unwrap();
        assert_eq!(written.len(), 4);
        let train = std::fs::read_to_string(root.join("list_train.txt")).unwrap();
        let lines: Vec<&str> = train.lines().filter(|l| !l.starts_with('#')).collect();
        assert_eq!(lines, ["train_dataset_1/a000_1,mixed"]);
        assert!(train.contains("# missing: a007_3"));
        let val = std::fs::read_to_string(root.join("list_val.txt")).unwrap();
        assert!(
            val.lines()
                .any(|l| l == "seen_subjects_test_set/a000_6,mixed")
        );
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(warnings[0].contains("a007_3"));
        // Not a RoNIN folder at all: an error.
        let empty = dir.path().join("empty");
        std::fs::create_dir_all(&empty).unwrap();
        assert!(write_lists(&empty, &protocols).is_err());
    }
}
