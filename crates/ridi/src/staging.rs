//! All-or-nothing output folders, the one staging mechanism of ridi-rs (`ridi convert`,
//! evaluations and the demo): files are written into a hidden staging folder inside the output
//! folder, each through [`ridi_data::write_atomically`], then moved into place together once
//! every one of them was written.

use std::path::{Path, PathBuf};

use ridi_data::{DataError, write_atomically};

/// An output folder being written. [`Staging::write`] writes an output file (or
/// [`Staging::file`] gives where a writer of ridi-rs, which goes through
/// [`ridi_data::write_atomically`], is to write it); [`Staging::commit`] moves them all into
/// the output folder. Dropped without a commit (an
/// error on the way), it removes what it wrote and the folders it created, so the output
/// folder is left as it was.
#[derive(Debug)]
pub struct Staging {
    out: PathBuf,
    /// `new/` holds the staged files, `old/` the files they replace until the commit is done.
    /// Dropped before `created`, which may hold it.
    temp: tempfile::TempDir,
    created: CreatedDirs,
    /// Output files to remove at the commit (relative to the output folder).
    removals: Vec<PathBuf>,
}

/// Folders created for the output, removed when dropped if they are empty.
#[derive(Debug, Default)]
struct CreatedDirs(Vec<PathBuf>);

impl CreatedDirs {
    /// Creates `dir` and its missing ancestors, remembering those it created.
    fn create(&mut self, dir: &Path) -> Result<(), DataError> {
        let missing: Vec<PathBuf> = dir
            .ancestors()
            .take_while(|d| !d.as_os_str().is_empty() && !d.exists())
            .map(Path::to_path_buf)
            .collect();
        std::fs::create_dir_all(dir).map_err(|e| DataError::io(dir, e))?;
        self.0.extend(missing);
        Ok(())
    }
}

impl Drop for CreatedDirs {
    fn drop(&mut self) {
        self.0
            .sort_by_key(|d| std::cmp::Reverse(d.components().count()));
        for dir in &self.0 {
            // Only when empty: never what someone else put there meanwhile.
            let _ = std::fs::remove_dir(dir);
        }
    }
}

impl Staging {
    /// Creates `out` if needed and a hidden staging folder in it.
    pub fn new(out: &Path) -> Result<Self, DataError> {
        let mut created = CreatedDirs::default();
        created.create(out)?;
        let temp = tempfile::Builder::new()
            .prefix(".ridi-staging-")
            .tempdir_in(out)
            .map_err(|e| DataError::io(out, e))?;
        Ok(Self {
            out: out.to_path_buf(),
            temp,
            created,
            removals: Vec::new(),
        })
    }

    /// Removes the output file `rel` (relative to the output folder) at the commit, if it is
    /// there and no staged file replaces it; a failed commit puts it back. For a file that must
    /// not outlive the ones written beside it (the sidecar of a `data.csv` rewritten without
    /// one).
    pub fn remove(&mut self, rel: &Path) {
        self.removals.push(rel.to_path_buf());
    }

    /// Where to write the output file `rel` (relative to the output folder) until the commit;
    /// its folder exists.
    pub fn file(&self, rel: &Path) -> Result<PathBuf, DataError> {
        let path = self.temp.path().join("new").join(rel);
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|e| DataError::io(dir, e))?;
        }
        Ok(path)
    }

    /// Writes the output file `rel` (relative to the output folder) through
    /// [`write_atomically`] until the commit, and returns where it is staged.
    pub fn write(
        &self,
        rel: &Path,
        content: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
    ) -> Result<PathBuf, DataError> {
        let path = self.file(rel)?;
        write_atomically(&path, content)?;
        Ok(path)
    }

    /// The staged folder `rel` (relative to the output folder, `""` for the output folder
    /// itself), created: where to write output files whose names another function chooses.
    pub fn dir(&self, rel: &Path) -> Result<PathBuf, DataError> {
        let dir = self.temp.path().join("new").join(rel);
        std::fs::create_dir_all(&dir).map_err(|e| DataError::io(&dir, e))?;
        Ok(dir)
    }

    /// Moves every staged file into the output folder, replacing files of the same name, and
    /// removes the files [`Staging::remove`] named. If a move fails, those done are undone
    /// (replaced and removed files come back) and the error returned.
    pub fn commit(mut self) -> Result<(), DataError> {
        let new = self.temp.path().join("new");
        let old = self.temp.path().join("old");
        let mut files = Vec::new();
        staged_files(&new, Path::new(""), &mut files)?;
        // (destination, where the file it replaced went)
        let mut moved: Vec<(PathBuf, Option<PathBuf>)> = Vec::new();
        let removals: Vec<&PathBuf> = self
            .removals
            .iter()
            .filter(|rel| !files.contains(rel) && self.out.join(rel).is_file())
            .collect();
        let removed = removals.iter().try_for_each(|rel| {
            let dest = self.out.join(rel);
            let b = old.join(rel);
            if let Some(dir) = b.parent() {
                std::fs::create_dir_all(dir).map_err(|e| DataError::io(dir, e))?;
            }
            std::fs::rename(&dest, &b).map_err(|e| DataError::io(&dest, e))?;
            moved.push((dest, Some(b)));
            Ok(())
        });
        let result = removed.and_then(|()| {
            files.iter().try_for_each(|rel| {
                let dest = self.out.join(rel);
                if let Some(dir) = dest.parent() {
                    self.created.create(dir)?;
                }
                let backup = if dest.is_file() {
                    let b = old.join(rel);
                    if let Some(dir) = b.parent() {
                        std::fs::create_dir_all(dir).map_err(|e| DataError::io(dir, e))?;
                    }
                    std::fs::rename(&dest, &b).map_err(|e| DataError::io(&dest, e))?;
                    Some(b)
                } else {
                    None
                };
                let renamed =
                    std::fs::rename(new.join(rel), &dest).map_err(|e| DataError::io(&dest, e));
                moved.push((dest, backup));
                renamed
            })
        });
        if result.is_err() {
            for (dest, backup) in moved.iter().rev() {
                let _ = std::fs::remove_file(dest);
                if let Some(b) = backup {
                    let _ = std::fs::rename(b, dest);
                }
            }
        } else {
            self.created.0.clear();
        }
        result
    }
}

/// The files under `dir`, relative to the staging root (`rel` is `dir`'s path there), sorted.
fn staged_files(dir: &Path, rel: &Path, out: &mut Vec<PathBuf>) -> Result<(), DataError> {
    if !dir.exists() {
        return Ok(());
    }
    let mut entries = std::fs::read_dir(dir)
        .and_then(|it| it.collect::<std::io::Result<Vec<_>>>())
        .map_err(|e| DataError::io(dir, e))?;
    entries.sort_by_key(|e| e.file_name());
    for entry in entries {
        let path = entry.path();
        let rel = rel.join(entry.file_name());
        if path.is_dir() {
            staged_files(&path, &rel, out)?;
        } else {
            out.push(rel);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tree(dir: &Path) -> Vec<String> {
        let mut files = Vec::new();
        staged_files(dir, Path::new(""), &mut files).unwrap();
        files.iter().map(|p| p.display().to_string()).collect()
    }

    #[test]
    fn commit_moves_everything_into_place() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("a/b/out");
        std::fs::create_dir_all(out.join("x")).unwrap();
        std::fs::write(out.join("x/keep.txt"), "old").unwrap();
        std::fs::write(out.join("x/data.txt"), "old").unwrap();
        let staging = Staging::new(&out).unwrap();
        std::fs::write(staging.file(Path::new("x/data.txt")).unwrap(), "new").unwrap();
        std::fs::write(staging.file(Path::new("y/z/list.txt")).unwrap(), "list").unwrap();
        assert_eq!(tree(&out).len(), 4, "{:?}", tree(&out));
        staging.commit().unwrap();
        assert_eq!(tree(&out), ["x/data.txt", "x/keep.txt", "y/z/list.txt"]);
        assert_eq!(
            std::fs::read_to_string(out.join("x/data.txt")).unwrap(),
            "new"
        );
    }

    #[test]
    fn dropped_staging_leaves_nothing_new() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("a/b/out");
        let staging = Staging::new(&out).unwrap();
        std::fs::write(staging.file(Path::new("x/data.txt")).unwrap(), "new").unwrap();
        drop(staging);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);

        std::fs::create_dir_all(&out).unwrap();
        let staging = Staging::new(&out).unwrap();
        std::fs::write(staging.file(Path::new("x/data.txt")).unwrap(), "new").unwrap();
        drop(staging);
        assert!(out.is_dir() && tree(&out).is_empty());
    }

    #[test]
    fn removals_happen_at_the_commit_and_are_undone_with_it() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        std::fs::create_dir_all(out.join("a")).unwrap();
        std::fs::write(out.join("a/data.csv"), "old").unwrap();
        std::fs::write(out.join("a/data.csv.meta"), "old").unwrap();
        let mut staging = Staging::new(&out).unwrap();
        std::fs::write(staging.file(Path::new("a/data.csv")).unwrap(), "new").unwrap();
        staging.remove(Path::new("a/data.csv.meta"));
        staging.remove(Path::new("a/never.txt"));
        assert!(
            out.join("a/data.csv.meta").is_file(),
            "not before the commit"
        );
        staging.commit().unwrap();
        assert_eq!(tree(&out), ["a/data.csv"]);

        // A failed commit brings the removed file back.
        std::fs::write(out.join("a/data.csv.meta"), "old").unwrap();
        std::fs::create_dir_all(out.join("b/data.csv")).unwrap();
        let mut staging = Staging::new(&out).unwrap();
        staging.remove(Path::new("a/data.csv.meta"));
        std::fs::write(staging.file(Path::new("b/data.csv")).unwrap(), "new").unwrap();
        assert!(staging.commit().is_err());
        assert_eq!(
            std::fs::read_to_string(out.join("a/data.csv.meta")).unwrap(),
            "old"
        );
    }

    #[test]
    fn a_failed_commit_is_undone() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        std::fs::create_dir_all(out.join("b/data.txt")).unwrap();
        std::fs::create_dir_all(out.join("a")).unwrap();
        std::fs::write(out.join("a/data.txt"), "old").unwrap();
        let staging = Staging::new(&out).unwrap();
        for name in ["a/data.txt", "b/data.txt", "c/data.txt"] {
            std::fs::write(staging.file(Path::new(name)).unwrap(), "new").unwrap();
        }
        // b/data.txt is a folder: the move fails after a/ was replaced, which is undone.
        let err = staging.commit().unwrap_err().to_string();
        assert!(err.contains("data.txt"), "{err}");
        assert_eq!(
            std::fs::read_to_string(out.join("a/data.txt")).unwrap(),
            "old"
        );
        assert!(!out.join("c").exists());
        let names: Vec<_> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}");
    }
}
