//! All-or-nothing output folders, the one staging mechanism of ridi-rs (`ridi convert`,
//! evaluations and the demo): files are written into a hidden staging folder inside the output
//! folder, each through [`ridi_data::write_atomically`], then moved into place together once
//! every one of them was written.
//!
//! The staging folder, `.ridi-staging-<pid>-XXXXXX` ([`ridi_data::register_temporary`]: named with
//! its owner's process id, its `lock` file held while in use), holds:
//!
//! - `new/`: the files to put in place, at their paths relative to the output folder;
//! - `gone/`: an empty file for each output file the commit removes ([`Staging::remove`]);
//! - `old/`: the files they replace or remove, kept until the commit is done, to undo it;
//! - `commit`: the commit point. It is renamed into place, one rename, once every file is in
//!   `new/` and every check passed; the files are moved only after it. A commit cut short (a
//!   kill) is therefore finished, or rolled back, by the next [`Staging::new`] on that folder:
//!   with `commit` there it moves what is left in `new/` into place and removes what `gone/`
//!   names (roll forward); without it nothing in the output folder was touched and the staging
//!   folder goes (roll back). Either way the folder then holds the new files or the old ones,
//!   never a mix, and no staging folder of a killed run is left.
//!
//! Only the files the command writes (and those it asks to remove) are touched: other files in
//! the output folder stay.

use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};

use ridi_data::{
    DataError, Location, STAGING_LOCK, STAGING_PREFIX, Temporary, hold_temporaries,
    register_temporary, remove_temporary, stale_temporaries, temporary_prefix, write_atomically,
};

/// An output folder being written. [`Staging::write`] writes an output file (or
/// [`Staging::file`] gives where a writer of ridi-rs, which goes through
/// [`ridi_data::write_atomically`], is to write it); [`Staging::commit`] moves them all into
/// the output folder. Dropped without a commit (an
/// error on the way), it removes what it wrote and the folders it created, so the output
/// folder is left as it was. A program ending on a signal removes it with
/// [`ridi_data::remove_temporaries_for_exit`]; what a kill leaves, the next `Staging` on the
/// same folder finishes or rolls back (see the module's documentation).
#[derive(Debug)]
pub struct Staging {
    out: PathBuf,
    /// The staging folder.
    root: PathBuf,
    /// Held while the staging folder is in use (taken only by the tests' simulated kill).
    lock: Option<File>,
    _registered: Temporary,
    created: CreatedDirs,
    /// Output files to remove at the commit (relative to the output folder).
    removals: Vec<PathBuf>,
}

/// Folders created for the output, removed when dropped if they are empty; those made before
/// the commit are registered so that an interrupted run's cleanup does the same
/// ([`ridi_data::register_created_folder`]; the cleanup waits for a commit under way).
#[derive(Debug, Default)]
struct CreatedDirs(Vec<(PathBuf, Option<Temporary>)>);

impl CreatedDirs {
    /// Creates `dir` and its missing ancestors, remembering those it created, registered when
    /// `register` (not during a commit, which holds the registry:
    /// [`ridi_data::hold_temporaries`]).
    fn create(&mut self, dir: &Path, register: bool) -> Result<(), DataError> {
        let missing: Vec<PathBuf> = dir
            .ancestors()
            .take_while(|d| !d.as_os_str().is_empty() && !d.exists())
            .map(Path::to_path_buf)
            .collect();
        std::fs::create_dir_all(dir).map_err(|e| DataError::io(dir, e))?;
        self.0.extend(missing.into_iter().map(|d| {
            let registered = register.then(|| ridi_data::register_created_folder(d.clone()));
            (d, registered)
        }));
        Ok(())
    }
}

impl Drop for CreatedDirs {
    fn drop(&mut self) {
        self.0
            .sort_by_key(|(d, _)| std::cmp::Reverse(d.components().count()));
        for (dir, _) in &self.0 {
            // Only when empty: never what someone else put there meanwhile.
            let _ = std::fs::remove_dir(dir);
        }
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        // Gone already after a commit.
        remove_temporary(&self.root);
    }
}

/// The parts of a staging folder.
const NEW: &str = "new";
const OLD: &str = "old";
const GONE: &str = "gone";
const COMMIT: &str = "commit";

/// An output file moved by a commit: where to, and whether it was a staged file put in place
/// (or an output file removed) and whether an output file went to `old/`.
struct Moved {
    rel: PathBuf,
    installed: bool,
    backed_up: bool,
}

impl Staging {
    /// Creates `out` if needed and a hidden staging folder in it. First finishes or rolls back
    /// what killed runs left in `out` (their staging folders, whose owner is gone): an error
    /// if an interrupted commit cannot be finished.
    pub fn new(out: &Path) -> Result<Self, DataError> {
        let mut created = CreatedDirs::default();
        created.create(out, true)?;
        recover(out)?;
        let prefix = temporary_prefix(STAGING_PREFIX);
        let ((root, lock), registered) = register_temporary(|| {
            let root = tempfile::Builder::new()
                .prefix(&prefix)
                .tempdir_in(out)?
                .keep();
            let locked = File::create(root.join(STAGING_LOCK)).and_then(|f| f.lock().map(|()| f));
            match locked {
                Ok(lock) => Ok(((root.clone(), lock), root)),
                Err(e) => {
                    remove_temporary(&root);
                    Err(e)
                }
            }
        })
        .map_err(|e| DataError::io(out, e))?;
        Ok(Self {
            out: out.to_path_buf(),
            root,
            lock: Some(lock),
            _registered: registered,
            created,
            removals: Vec::new(),
        })
    }

    /// Removes the output file `rel` (relative to the output folder) at the commit, if it is
    /// there and no staged file replaces it; a failed commit puts it back. For a file that must
    /// not outlive the ones written beside it (the sidecar of a `data.csv` rewritten without
    /// one, the plots of an earlier evaluation).
    pub fn remove(&mut self, rel: &Path) {
        self.removals.push(rel.to_path_buf());
    }

    /// Where to write the output file `rel` (relative to the output folder) until the commit;
    /// its folder exists.
    pub fn file(&self, rel: &Path) -> Result<PathBuf, DataError> {
        let path = self.root.join(NEW).join(rel);
        if let Some(dir) = path.parent() {
            create_below(&self.root, dir)?;
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
        let dir = self.root.join(NEW).join(rel);
        create_below(&self.root, &dir)?;
        Ok(dir)
    }

    /// The output file the staged file `staged` (a path [`Staging::file`] or
    /// [`Staging::dir`] gave) becomes at the commit, for messages; any other path as it is.
    pub fn destination(&self, staged: &Path) -> PathBuf {
        match staged.strip_prefix(self.root.join(NEW)) {
            Ok(rel) => self.out.join(rel),
            Err(_) => staged.to_path_buf(),
        }
    }

    /// Moves every staged file into the output folder, replacing files of the same name, and
    /// removes the files [`Staging::remove`] named, other files staying. Whatever can be
    /// checked is checked first (no folder where a file goes, no file where a folder does);
    /// then the commit point (one rename), then the moves. If a move fails, those done are
    /// undone (replaced and removed files come back) and the error returned; a kill on the way
    /// is finished by the next `Staging` on the folder.
    pub fn commit(mut self) -> Result<(), DataError> {
        let files = files_under(&self.root.join(NEW))?;
        for rel in &files {
            check_destination(&self.out, rel)?;
        }
        let removals: Vec<PathBuf> = self
            .removals
            .iter()
            .filter(|rel| !files.contains(rel) && self.out.join(rel).is_file())
            .cloned()
            .collect();
        for rel in &removals {
            let mark = self.root.join(GONE).join(rel);
            if let Some(dir) = mark.parent() {
                create_below(&self.root, dir)?;
            }
            File::create(&mark).map_err(|e| DataError::io(&mark, e))?;
        }
        // An interrupted program's cleanup waits for the commit rather than cut it in half.
        let hold = hold_temporaries();
        let point = self.root.join(COMMIT);
        let marked = File::create(self.root.join("commit.tmp"))
            .and_then(|f| f.sync_all())
            .and_then(|()| kill_point::pass())
            .and_then(|()| std::fs::rename(self.root.join("commit.tmp"), &point));
        let mut moved = Vec::new();
        let result = marked
            .map_err(|e| DataError::io(&point, e))
            .and_then(|()| {
                files
                    .iter()
                    .filter_map(|rel| self.out.join(rel).parent().map(Path::to_path_buf))
                    .try_for_each(|dir| self.created.create(&dir, false))
            })
            .and_then(|()| move_into_place(&self.root, &self.out, &mut moved));
        if kill_point::killed() {
            // As a kill leaves it: no undo, no cleanup, the lock released.
            self.lock = None;
            std::mem::forget(self);
            return result;
        }
        // Forgotten (their registrations dropped) once the hold is released.
        let mut kept = Vec::new();
        if result.is_ok() {
            remove_temporary(&self.root);
            kept = std::mem::take(&mut self.created.0);
        } else {
            for m in moved.iter().rev() {
                let dest = self.out.join(&m.rel);
                if m.installed {
                    let _ = std::fs::rename(&dest, self.root.join(NEW).join(&m.rel));
                }
                if m.backed_up {
                    let _ = std::fs::rename(self.root.join(OLD).join(&m.rel), &dest);
                }
            }
            // Rolled back: the commit did not happen.
            let _ = std::fs::remove_file(&point);
        }
        drop(hold);
        drop(kept);
        result
    }
}

/// Moves the files in `root`'s `new/` to `out`, the output files they replace to `old/`, and
/// the output files `gone/` names to `old/`, recording each move in `moved`. What is already
/// moved (a commit cut short) is not in `new/` any more, so running it again finishes it.
fn move_into_place(root: &Path, out: &Path, moved: &mut Vec<Moved>) -> Result<(), DataError> {
    let back_up = |rel: &Path| -> Result<bool, DataError> {
        let dest = out.join(rel);
        if !dest.is_file() {
            return Ok(false);
        }
        let backup = root.join(OLD).join(rel);
        if let Some(dir) = backup.parent() {
            create_below(root, dir)?;
        }
        kill_point::pass()
            .and_then(|()| std::fs::rename(&dest, &backup))
            .map_err(|e| DataError::io(&dest, e))?;
        Ok(true)
    };
    for rel in files_under(&root.join(NEW))? {
        let dest = out.join(&rel);
        if let Some(dir) = dest.parent() {
            std::fs::create_dir_all(dir).map_err(|e| DataError::io(dir, e))?;
        }
        let backed_up = back_up(&rel)?;
        let renamed = kill_point::pass()
            .and_then(|()| std::fs::rename(root.join(NEW).join(&rel), &dest))
            .map_err(|e| DataError::io(&dest, e));
        moved.push(Moved {
            rel,
            installed: renamed.is_ok(),
            backed_up,
        });
        renamed?;
    }
    for rel in files_under(&root.join(GONE))? {
        let backed_up = back_up(&rel)?;
        moved.push(Moved {
            rel,
            installed: false,
            backed_up,
        });
    }
    Ok(())
}

/// The tests' simulated kill: [`pass`](kill_point::pass) before each rename of a commit
/// counts down the renames a test allows, then fails as if the process had died there (and
/// the commit leaves its state as a kill would). Nothing outside the tests.
mod kill_point {
    #[cfg(test)]
    thread_local! {
        pub(super) static RENAMES_LEFT: std::cell::Cell<Option<usize>> =
            const { std::cell::Cell::new(None) };
        static KILLED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    }

    /// Whether the next rename may happen.
    pub(super) fn pass() -> std::io::Result<()> {
        #[cfg(test)]
        if let Some(left) = RENAMES_LEFT.get() {
            if left == 0 || KILLED.get() {
                KILLED.set(true);
                return Err(std::io::Error::other("killed (simulated)"));
            }
            RENAMES_LEFT.set(Some(left - 1));
        }
        Ok(())
    }

    /// Whether the simulated kill happened (and clears it).
    pub(super) fn killed() -> bool {
        #[cfg(test)]
        if KILLED.replace(false) {
            RENAMES_LEFT.set(None);
            return true;
        }
        false
    }
}

/// Finishes (with `commit` there) or rolls back (without) the staging folders killed runs left
/// in `out`, and removes them.
fn recover(out: &Path) -> Result<(), DataError> {
    for stale in stale_temporaries(out, STAGING_PREFIX) {
        let root = &stale.path;
        if root.join(COMMIT).is_file() {
            move_into_place(root, out, &mut Vec::new()).map_err(|e| {
                DataError::format(
                    Location::file(root),
                    format!(
                        "a killed run left its output half moved into place, and it cannot be \
                         finished: {e}"
                    ),
                )
            })?;
        }
        remove_temporary(root);
    }
    Ok(())
}

/// Refuses a staged file `rel` that could not be moved into `out`: its path there is a folder,
/// or runs through a file; or that must not be: a symbolic link, a device, a pipe or a socket
/// there, which the move would replace with a regular file (an output folder holds regular
/// files, and its commit moves the file it replaces aside, not the one a link leads to).
fn check_destination(out: &Path, rel: &Path) -> Result<(), DataError> {
    let dest = out.join(rel);
    if dest.is_dir() {
        return Err(DataError::io(&dest, io::ErrorKind::IsADirectory.into()));
    }
    if let Ok(meta) = std::fs::symlink_metadata(&dest)
        && !meta.is_file()
    {
        let what = match meta.file_type().is_symlink() {
            true => "is a symbolic link",
            false => "is a device, a pipe or a socket",
        };
        return Err(DataError::io(
            &dest,
            io::Error::other(format!(
                "{what}, which the output folder's commit would replace with a regular file: \
                 remove it, or write to another folder"
            )),
        ));
    }
    let mut dir = out.to_path_buf();
    for part in rel.parent().into_iter().flat_map(Path::components) {
        dir.push(part);
        if dir.exists() && !dir.is_dir() {
            return Err(DataError::io(&dir, io::ErrorKind::NotADirectory.into()));
        }
    }
    Ok(())
}

/// Creates `dir`, a folder inside the staging folder `root`, and its missing ancestors below
/// `root`, but never `root` itself: once an interrupted program removed it, nothing is written
/// there again.
fn create_below(root: &Path, dir: &Path) -> Result<(), DataError> {
    let Ok(rel) = dir.strip_prefix(root) else {
        return Err(DataError::io(dir, io::ErrorKind::InvalidInput.into()));
    };
    let mut path = root.to_path_buf();
    for part in rel.components() {
        path.push(part);
        match std::fs::create_dir(&path) {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists && path.is_dir() => {}
            Err(e) => return Err(DataError::io(&path, e)),
        }
    }
    Ok(())
}

/// The files under `dir`, relative to it, sorted; none when it does not exist.
fn files_under(dir: &Path) -> Result<Vec<PathBuf>, DataError> {
    let mut files = Vec::new();
    staged_files(dir, Path::new(""), &mut files)?;
    Ok(files)
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

    /// A commit killed before each of its renames in turn, then the folder recovered by the
    /// next `Staging` on it: every file is the old one (killed before the commit point) or
    /// every one the new (after it), removals included, other files stay, and no staging
    /// folder is left.
    #[test]
    fn a_commit_killed_at_any_rename_is_finished_or_rolled_back_by_the_next_run() {
        let dead = {
            let mut child = std::process::Command::new("true").spawn().unwrap();
            let pid = child.id();
            child.wait().unwrap();
            pid
        };
        let mut outcomes = Vec::new();
        for renames in 0.. {
            let dir = tempfile::tempdir().unwrap();
            let out = dir.path().join("out");
            std::fs::create_dir_all(out.join("plots")).unwrap();
            for (name, text) in [
                ("report.json", "old"),
                ("plots/a.png", "old"),
                ("plots/b.png", "old"),
                ("mine.txt", "the user's"),
            ] {
                std::fs::write(out.join(name), text).unwrap();
            }
            let mut staging = Staging::new(&out).unwrap();
            for name in ["report.json", "report.md", "plots/a.png", "plots/c.png"] {
                staging
                    .write(Path::new(name), |w| w.write_all(b"new"))
                    .unwrap();
            }
            staging.remove(Path::new("plots/b.png"));
            kill_point::RENAMES_LEFT.set(Some(renames));
            let done = staging.commit().is_ok();
            kill_point::RENAMES_LEFT.set(None);
            let old = ["mine.txt", "plots/a.png", "plots/b.png", "report.json"];
            let new = [
                "mine.txt",
                "plots/a.png",
                "plots/c.png",
                "report.json",
                "report.md",
            ];
            if done {
                assert_eq!(tree(&out), new);
                outcomes.push(true);
                break;
            }
            // The killed process's staging folder, as another (dead) process's.
            let names: Vec<_> = std::fs::read_dir(&out)
                .unwrap()
                .map(|e| e.unwrap().file_name().into_string().unwrap())
                .filter(|n| n.starts_with(STAGING_PREFIX))
                .collect();
            let [name] = &names[..] else {
                panic!("{names:?}")
            };
            let renamed = name.replacen(&std::process::id().to_string(), &dead.to_string(), 1);
            std::fs::rename(out.join(name), out.join(renamed)).unwrap();
            drop(Staging::new(&out).unwrap());
            let files = tree(&out);
            let text = |n: &str| std::fs::read_to_string(out.join(n)).unwrap();
            if files == old {
                assert!(
                    ["report.json", "plots/a.png"]
                        .iter()
                        .all(|n| text(n) == "old")
                );
                outcomes.push(false);
            } else {
                assert_eq!(files, new, "killed after {renames} renames");
                assert!(
                    ["report.json", "plots/a.png"]
                        .iter()
                        .all(|n| text(n) == "new")
                );
                outcomes.push(true);
            }
            assert_eq!(text("mine.txt"), "the user's");
        }
        // Killed before the commit point (the first rename), then after it at each move.
        assert!(!outcomes[0], "{outcomes:?}");
        assert!(outcomes[1..].iter().all(|&new| new), "{outcomes:?}");
        assert!(outcomes.len() > 5, "{outcomes:?}");
    }

    #[test]
    fn messages_name_the_output_file_not_the_staged_one() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        let staging = Staging::new(&out).unwrap();
        let staged = staging.file(Path::new("plots/a.png")).unwrap();
        assert!(staged.starts_with(&staging.root));
        assert_eq!(staging.destination(&staged), out.join("plots/a.png"));
        assert_eq!(staging.destination(Path::new("x")), Path::new("x"));
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
        // The two files, the two staged ones and the staging folder's lock.
        assert_eq!(tree(&out).len(), 5, "{:?}", tree(&out));
        staging.commit().unwrap();
        assert_eq!(tree(&out), ["x/data.txt", "x/keep.txt", "y/z/list.txt"]);
        assert_eq!(
            std::fs::read_to_string(out.join("x/data.txt")).unwrap(),
            "new"
        );
    }

    /// A symbolic link or a pipe where a staged file goes is refused at the commit, and
    /// nothing moves: the move would replace it with a regular file.
    #[cfg(unix)]
    #[test]
    fn links_and_pipes_in_the_output_folder_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out");
        std::fs::create_dir_all(&out).unwrap();
        std::fs::write(dir.path().join("keep.txt"), "kept").unwrap();
        std::os::unix::fs::symlink("../keep.txt", out.join("list.txt")).unwrap();
        let fifo = out.join("report.json");
        ridi_test_support::make_fifo(&fifo);
        for (name, what) in [
            ("list.txt", "is a symbolic link"),
            ("report.json", "is a device, a pipe or a socket"),
        ] {
            let staging = Staging::new(&out).unwrap();
            std::fs::write(staging.file(Path::new(name)).unwrap(), "new").unwrap();
            let e = staging.commit().unwrap_err().to_string();
            assert!(
                e.contains(what) && e.contains("remove it, or write to another folder"),
                "{e}"
            );
        }
        assert!(
            std::fs::symlink_metadata(out.join("list.txt"))
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(
            std::fs::read_to_string(dir.path().join("keep.txt")).unwrap(),
            "kept"
        );
        assert!(ridi_test_support::is_fifo(&fifo));
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
