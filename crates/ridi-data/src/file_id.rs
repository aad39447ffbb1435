//! Which file a path names, whatever its spelling.

use std::path::Path;

/// The identity of an existing file: two paths name the same file exactly when their ids are
/// equal, through links, `..`, hard links and bind mounts, which comparing resolved paths
/// misses. The device and inode numbers on Unix; elsewhere the canonical path (which sees
/// links and `..` only).
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FileId(Inner);

#[cfg(unix)]
type Inner = (u64, u64);
#[cfg(not(unix))]
type Inner = std::path::PathBuf;

impl FileId {
    /// The id of the file `path` names (following links).
    ///
    /// # Errors
    /// When the file does not exist or cannot be inspected.
    pub fn of(path: &Path) -> std::io::Result<FileId> {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt as _;
            let m = std::fs::metadata(path)?;
            Ok(FileId((m.dev(), m.ino())))
        }
        #[cfg(not(unix))]
        {
            Ok(FileId(path.canonicalize()?))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_spelling_of_a_file_has_its_id_and_other_files_do_not() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.csv");
        let b = dir.path().join("b.csv");
        std::fs::write(&a, "x").unwrap();
        std::fs::write(&b, "x").unwrap();
        let id = FileId::of(&a).unwrap();
        assert_ne!(id, FileId::of(&b).unwrap());
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        assert_eq!(FileId::of(&sub.join("../a.csv")).unwrap(), id);
        // A hard link is the same file under another name: canonical paths differ.
        let hard = dir.path().join("hard.csv");
        std::fs::hard_link(&a, &hard).unwrap();
        #[cfg(unix)]
        assert_eq!(FileId::of(&hard).unwrap(), id);
        #[cfg(unix)]
        {
            let link = dir.path().join("link.csv");
            std::os::unix::fs::symlink(&a, &link).unwrap();
            assert_eq!(FileId::of(&link).unwrap(), id);
        }
        assert!(FileId::of(&dir.path().join("missing")).is_err());
    }
}
