//! The temporary files and folders ridi-rs writes its outputs through: what a killed or
//! interrupted run leaves, and who removes it.
//!
//! Each is named with its kind and its owner's process id (`.ridi-tmp-<pid>-XXXXXX` beside an
//! output file, `.ridi-staging-<pid>-XXXXXX` inside an output folder) and locked (the file
//! itself, or the `lock` file inside the folder) while its owner uses it. So:
//!
//! - the next run that writes into the same folder finds those of its own kind whose owner is
//!   gone ([`stale_temporaries`]: the process id is not running and the lock is free) and
//!   removes them ([`crate::write_pending`] for files; `ridi::Staging` for folders, which
//!   first finishes or rolls back a commit it finds interrupted);
//! - a program that ends itself on a signal calls [`remove_temporaries_for_exit`] first: it
//!   removes every temporary of this process that is registered ([`register_temporary`]: all
//!   of ridi-rs's are) and keeps new ones from being made. The library installs no signal
//!   handler: that belongs to the program (the `ridi` binary installs one); a library user
//!   that does not call it gets what a kill leaves, which the next run removes.

use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// Name prefix of a temporary file beside an output file ([`crate::write_pending`]).
pub const TEMPORARY_FILE_PREFIX: &str = ".ridi-tmp-";
/// Name prefix of a staging folder inside an output folder (`ridi::Staging`).
pub const STAGING_PREFIX: &str = ".ridi-staging-";
/// The file inside a staging folder that its owner holds locked.
pub const STAGING_LOCK: &str = "lock";

/// The temporaries of this process, and whether it is on its way out.
struct Registry {
    next: u64,
    /// Each path, and whether it is a folder made for an output, removed only when empty
    /// ([`register_created_folder`]), rather than a temporary, removed with all it holds.
    entries: Vec<(u64, PathBuf, bool)>,
    exiting: bool,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    next: 0,
    entries: Vec::new(),
    exiting: false,
});

fn registry() -> MutexGuard<'static, Registry> {
    // A panic elsewhere while holding it leaves a list that is still a list.
    REGISTRY.lock().unwrap_or_else(PoisonError::into_inner)
}

/// A temporary file or folder of this process, removed by [`remove_temporaries_for_exit`] until
/// dropped (dropping it forgets it; it does not remove it).
#[derive(Debug)]
pub struct Temporary(u64);

impl Drop for Temporary {
    fn drop(&mut self) {
        registry().entries.retain(|(id, _, _)| *id != self.0);
    }
}

/// Makes a temporary with `create`, which returns it and its path, and registers the path, as
/// one step that [`remove_temporaries_for_exit`] cannot come between: once that has run,
/// `create` is not called and this fails (`Interrupted`).
///
/// The temporary files and folders ridi-rs writes its outputs through are named with their
/// kind and their owner's process id ([`TEMPORARY_FILE_PREFIX`]`<pid>-XXXXXX` beside an output
/// file, [`STAGING_PREFIX`]`<pid>-XXXXXX` inside an output folder: [`temporary_prefix`]) and
/// locked (the file itself, or the [`STAGING_LOCK`] file in the folder) while in use. The next
/// run that writes into the same folder removes those whose owner is gone
/// ([`stale_temporaries`]); a program ending on a signal calls
/// [`remove_temporaries_for_exit`] first. The library installs no signal handler: that is the
/// program's (the `ridi` binary installs one).
pub fn register_temporary<T>(
    create: impl FnOnce() -> io::Result<(T, PathBuf)>,
) -> io::Result<(T, Temporary)> {
    let mut reg = registry();
    if reg.exiting {
        return Err(io::Error::new(
            io::ErrorKind::Interrupted,
            "the program is ending on a signal",
        ));
    }
    let (made, path) = create()?;
    let id = reg.next;
    reg.next += 1;
    reg.entries.push((id, path, false));
    Ok((made, Temporary(id)))
}

/// Registers `folder`, made for an output (an `--out` folder that did not exist), so that
/// [`remove_temporaries_for_exit`] removes it if it is still empty once the temporaries inside
/// are gone: an interrupted run leaves no empty folder behind. Its owner removes it, if empty,
/// when the output fails otherwise.
pub fn register_created_folder(folder: PathBuf) -> Temporary {
    let mut reg = registry();
    let id = reg.next;
    reg.next += 1;
    reg.entries.push((id, folder, true));
    Temporary(id)
}

/// Holds off [`remove_temporaries_for_exit`] while alive: for a commit that must not be cut in half
/// by an interrupted program's cleanup (the cleanup waits for it instead).
pub struct TemporariesHold {
    _held: MutexGuard<'static, Registry>,
}

impl std::fmt::Debug for TemporariesHold {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("TemporariesHold")
    }
}

/// See [`TemporariesHold`]. Neither [`register_temporary`] nor a [`Temporary`] drop may happen on
/// the same thread while it is held.
pub fn hold_temporaries() -> TemporariesHold {
    TemporariesHold { _held: registry() }
}

/// For a program about to end on a signal (Ctrl-C): removes every registered temporary file and
/// staging folder of this process, after any commit under way ([`hold_temporaries`]) is done, and
/// keeps new ones from being made until the process ends: the threads that would make or commit one
/// wait for ever. Call it from the program's signal handler thread, then exit.
pub fn remove_temporaries_for_exit() {
    let mut reg = registry();
    reg.exiting = true;
    let (mut folders, temporaries): (Vec<_>, Vec<_>) = std::mem::take(&mut reg.entries)
        .into_iter()
        .partition(|(_, _, created)| *created);
    for (_, path, _) in temporaries {
        remove_temporary(&path);
    }
    // The deepest first; only when empty: never what someone else put there meanwhile.
    folders.sort_by_key(|(_, path, _)| std::cmp::Reverse(path.components().count()));
    for (_, path, _) in folders {
        let _ = std::fs::remove_dir(&path);
    }
    // Held until the process ends.
    std::mem::forget(reg);
}

/// Removes the file or folder `path` (a folder with all it holds), if it is there. Another
/// thread may still be writing into a folder: tried a few times.
pub fn remove_temporary(path: &Path) {
    for _ in 0..10 {
        let gone = match std::fs::symlink_metadata(path) {
            Err(_) => return,
            Ok(m) if m.is_dir() => std::fs::remove_dir_all(path),
            Ok(_) => std::fs::remove_file(path),
        };
        if gone.is_ok() {
            return;
        }
    }
}

/// `name` with `prefix` for a temporary of this process: `<prefix><pid>-`, to which the
/// creator adds random characters.
pub fn temporary_prefix(prefix: &str) -> String {
    format!("{prefix}{}-", std::process::id())
}

/// A temporary of another process, found by [`stale_temporaries`]: its owner is gone. Holds its
/// lock (when it has one) so that no other run takes it at the same time.
#[derive(Debug)]
pub struct StaleTemporary {
    /// The file or folder.
    pub path: PathBuf,
    _lock: Option<File>,
}

/// The entries of `dir` named with `prefix` ([`TEMPORARY_FILE_PREFIX`] or [`STAGING_PREFIX`]) whose
/// owner is gone: its process id is not running here (when that can be told) and its lock is
/// free. Those of running processes, of this one, and what cannot be told stay. An unreadable
/// `dir` has none.
pub fn stale_temporaries(dir: &Path, prefix: &str) -> Vec<StaleTemporary> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut found = Vec::new();
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name
            .to_str()
            .and_then(|n| n.strip_prefix(prefix))
            .and_then(|rest| rest.split('-').next())
            .and_then(|pid| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if pid == std::process::id() || running(pid) == Some(true) {
            continue;
        }
        let path = entry.path();
        let lock_path = if prefix == STAGING_PREFIX {
            path.join(STAGING_LOCK)
        } else {
            path.clone()
        };
        let lock = match File::open(&lock_path) {
            Ok(file) => match file.try_lock() {
                Ok(()) => Some(file),
                // Held: its owner is alive (on another machine, or in another pid namespace).
                Err(std::fs::TryLockError::WouldBlock) => continue,
                // Locks not supported here: the process id alone decides.
                Err(std::fs::TryLockError::Error(_)) if running(pid) == Some(false) => None,
                Err(std::fs::TryLockError::Error(_)) => continue,
            },
            // A folder without its lock file: made by a run killed before it locked it. Only
            // when the process id says so, as the lock cannot.
            Err(_) if running(pid) == Some(false) => None,
            Err(_) => continue,
        };
        found.push(StaleTemporary { path, _lock: lock });
    }
    found
}

/// Whether the process `pid` runs on this machine, when that can be told (`/proc`).
fn running(pid: u32) -> Option<bool> {
    Path::new("/proc/self")
        .exists()
        .then(|| Path::new("/proc").join(pid.to_string()).exists())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A process id that is not running: a child that has exited and been reaped.
    fn dead_pid() -> u32 {
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        pid
    }

    #[test]
    fn only_temporaries_of_gone_owners_are_stale() {
        let dir = tempfile::tempdir().unwrap();
        let dead = dead_pid();
        let file = |name: String| {
            let path = dir.path().join(name);
            std::fs::write(&path, "x").unwrap();
            path
        };
        let gone = file(format!("{TEMPORARY_FILE_PREFIX}{dead}-abc"));
        file(format!("{}abc", temporary_prefix(TEMPORARY_FILE_PREFIX)));
        file(format!("{TEMPORARY_FILE_PREFIX}1-abc")); // init: running
        file(format!("{TEMPORARY_FILE_PREFIX}x-abc"));
        file(format!("{STAGING_PREFIX}{dead}-abc"));
        file("data.csv".into());
        // A dead pid whose file is locked (its owner elsewhere) stays.
        let held = file(format!("{TEMPORARY_FILE_PREFIX}{dead}-held"));
        let holder = File::open(&held).unwrap();
        holder.lock().unwrap();
        let found: Vec<PathBuf> = stale_temporaries(dir.path(), TEMPORARY_FILE_PREFIX)
            .into_iter()
            .map(|s| s.path)
            .collect();
        assert_eq!(found, [gone]);
    }

    #[test]
    fn removal_for_exit_removes_what_is_registered() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a");
        let (_, kept) = register_temporary(|| {
            std::fs::create_dir_all(a.join("b"))?;
            std::fs::write(a.join("b/c"), "x")?;
            Ok(((), a.clone()))
        })
        .unwrap();
        let b = dir.path().join("b");
        let (_, forgotten) =
            register_temporary(|| std::fs::write(&b, "x").map(|()| ((), b.clone()))).unwrap();
        drop(forgotten);
        // Not called for real: it would stop every other test's writes. What it does to
        // each entry:
        let entries: Vec<PathBuf> = registry()
            .entries
            .iter()
            .map(|(_, p, _)| p.clone())
            .collect();
        assert!(entries.contains(&a) && !entries.contains(&b));
        remove_temporary(&a);
        assert!(!a.exists() && b.exists());
        drop(kept);
    }
}
