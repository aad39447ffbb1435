//! `cargo xtask fetch`: get a dataset from the manifest into `<dir>/<name>`, verified.
//!
//! Whatever the source (download, local archive, local folder), the content is assembled in
//! a temporary folder inside `<dir>`, checked against the manifest's layout, marked, and only
//! then renamed to `<dir>/<name>`: a dataset folder either is complete and verified or does
//! not exist.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};

use crate::archive;
use crate::checksum::{self, ListEntry};
use crate::download;
use crate::manifest::Dataset;

/// Written last into a dataset folder; its presence with matching checksums makes a later
/// fetch a no-op.
pub const MARKER: &str = ".xtask-fetch.toml";

#[derive(Debug, Clone)]
pub struct Options {
    /// Folder holding one sub-folder per dataset.
    pub dir: PathBuf,
    /// Local archive or folder to use instead of downloading.
    pub from: Option<PathBuf>,
    /// Accept content no checksum vouches for (and print the sha256 to pin it).
    pub trust_unpinned: bool,
    pub progress: bool,
}

#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Marker {
    pub dataset: String,
    pub source: String,
    /// SHA-256 of the archive the folder was unpacked from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub archive_sha256: Option<String>,
    /// SHA-256 of the per-file list a local folder was verified with.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub list_sha256: Option<String>,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Outcome {
    /// Nothing done: the folder is in place and its marker matches the manifest.
    AlreadyPresent { path: PathBuf, source: String },
    Installed {
        path: PathBuf,
        /// SHA-256 of the archive used, if the source was an archive.
        archive_sha256: Option<String>,
        /// Whether a checksum from the repository verified the content.
        verified: bool,
        files: usize,
    },
}

pub fn fetch(ds: &Dataset, opts: &Options) -> Result<Outcome> {
    ds.validate()?;
    let target = opts.dir.join(&ds.name);
    if let Some(marker) = current_marker(ds, &target, false)? {
        return Ok(Outcome::AlreadyPresent {
            path: target,
            source: marker.source,
        });
    }
    fs::create_dir_all(&opts.dir)
        .with_context(|| format!("cannot create {}", opts.dir.display()))?;
    let _lock = lock_dir(&opts.dir)?;
    // Another fetch may have finished while this one waited for the lock.
    if let Some(marker) = current_marker(ds, &target, true)? {
        return Ok(Outcome::AlreadyPresent {
            path: target,
            source: marker.source,
        });
    }
    remove_leftovers(ds, &opts.dir)?;
    let from = match &opts.from {
        Some(from) => Some(
            fs::canonicalize(from)
                .with_context(|| format!("--from {}: no such file or folder", from.display()))?,
        ),
        None => None,
    };
    match &from {
        Some(from) if from.is_dir() => from_folder(ds, opts, from, &target),
        Some(from) => from_archive(ds, opts, from, &target),
        None => from_network(ds, opts, &target),
    }
}

/// Serializes fetches into one datasets folder (an OS lock, so a killed fetch releases it);
/// under it, staging folders left by a killed fetch can be removed safely.
#[cfg(unix)]
fn lock_dir(dir: &Path) -> Result<fs::File> {
    let handle = fs::File::open(dir).with_context(|| format!("cannot open {}", dir.display()))?;
    if handle.try_lock().is_err() {
        eprintln!("waiting for another fetch into {} to finish", dir.display());
        handle
            .lock()
            .with_context(|| format!("cannot lock {}", dir.display()))?;
    }
    Ok(handle)
}

#[cfg(not(unix))]
fn lock_dir(_dir: &Path) -> Result<()> {
    Ok(())
}

fn remove_leftovers(ds: &Dataset, dir: &Path) -> Result<()> {
    let prefixes = [
        format!(".{}.staging-", ds.name),
        format!(".{}.old-", ds.name),
    ];
    let rd = fs::read_dir(dir).with_context(|| format!("cannot list {}", dir.display()))?;
    for entry in rd.flatten() {
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if prefixes.iter().any(|p| name.starts_with(p.as_str())) {
            let path = entry.path();
            fs::remove_dir_all(&path)
                .with_context(|| format!("cannot remove leftover {}", path.display()))?;
        }
    }
    Ok(())
}

/// `Some` if `target` holds a finished fetch that still matches the manifest, `None` if
/// there is nothing there or a stale fetch to replace, an error for a folder fetch never made.
fn current_marker(ds: &Dataset, target: &Path, announce_stale: bool) -> Result<Option<Marker>> {
    if !target.exists() {
        return Ok(None);
    }
    let marker_path = target.join(MARKER);
    let Ok(text) = fs::read_to_string(&marker_path) else {
        bail!(
            "{} exists but was not made by `cargo xtask fetch` (no {MARKER}); move it away or \
             choose another --dir",
            target.display()
        );
    };
    let marker: Marker = toml::from_str(&text).map_err(|_| {
        anyhow::anyhow!("{} is corrupt; delete it to refetch", marker_path.display())
    })?;
    let archive_ok = marker
        .archive_sha256
        .as_deref()
        .is_some_and(|got| ds.pinned_sha256().is_none_or(|want| want == got));
    let list_ok = match (&marker.list_sha256, &ds.files) {
        (Some(got), Some(list)) => checksum::sha256_file(list).is_ok_and(|want| &want == got),
        _ => false,
    };
    // A folder copied without any checksum has neither; it stays accepted only as long as the
    // manifest still has nothing to check it against.
    let unverified_ok =
        marker.archive_sha256.is_none() && marker.list_sha256.is_none() && ds.files.is_none();
    if archive_ok || list_ok || unverified_ok {
        Ok(Some(marker))
    } else {
        if announce_stale {
            eprintln!(
                "{}: made from an older manifest entry; fetching again",
                target.display()
            );
        }
        Ok(None)
    }
}

fn refuse_unpinned(ds: &Dataset, what: &str) -> anyhow::Error {
    anyhow::anyhow!(
        "dataset {} has no pinned sha256 for {what}; rerun with --trust-unpinned to accept it \
         unverified (the computed sha256 is printed so it can be pinned in the manifest)",
        ds.name
    )
}

fn from_network(ds: &Dataset, opts: &Options, target: &Path) -> Result<Outcome> {
    if ds.urls.is_empty() {
        bail!(
            "dataset {} lists no URL; use --from with a local copy",
            ds.name
        );
    }
    let pinned = ds.pinned_sha256();
    if pinned.is_none() && !opts.trust_unpinned {
        return Err(refuse_unpinned(ds, "its archive"));
    }
    let part = opts.dir.join(format!(".{}.part", ds.name));
    let agent = download::agent();
    let mut failures = Vec::new();
    for (i, url) in ds.urls.iter().enumerate() {
        let more = i + 1 < ds.urls.len();
        eprintln!("downloading {} from {url}", ds.name);
        let req = download::Request {
            url,
            part: &part,
            key: match pinned {
                Some(sha) => format!("sha256:{sha}"),
                None => format!("url:{url}"),
            },
            expected_size: ds.size,
            progress: opts.progress,
        };
        if let Err(e) = download::download(&agent, &req) {
            if more {
                eprintln!("  failed ({e:#}); trying the next mirror");
            }
            failures.push(format!("{e:#}"));
            continue;
        }
        let got = checksum::sha256_file(&part)?;
        if let Some(want) = pinned
            && got != want
        {
            download::discard(&part);
            let msg =
                format!("{url}: sha256 mismatch (expected {want}, got {got}); download deleted");
            if more {
                eprintln!("  failed ({msg}); trying the next mirror");
            }
            failures.push(msg);
            continue;
        }
        // Whatever happens next, the archive is not kept: a verified archive that fails to
        // unpack would fail the same way again, and the unpacked folder is what is used.
        let result = install_archive(ds, &part, &got, url, target);
        download::discard(&part);
        return result;
    }
    bail!(
        "could not download dataset {}: {}",
        ds.name,
        failures.join("; ")
    )
}

fn from_archive(ds: &Dataset, opts: &Options, archive: &Path, target: &Path) -> Result<Outcome> {
    let got = checksum::sha256_file(archive)?;
    match ds.pinned_sha256() {
        Some(want) if want != got => bail!(
            "{}: sha256 mismatch (expected {want}, got {got}); not the archive the manifest pins",
            archive.display()
        ),
        Some(_) => {}
        None if opts.trust_unpinned => {}
        None => return Err(refuse_unpinned(ds, "its archive")),
    }
    let source = archive.display().to_string();
    install_archive(ds, archive, &got, &source, target)
}

fn install_archive(
    ds: &Dataset,
    archive: &Path,
    sha256: &str,
    source: &str,
    target: &Path,
) -> Result<Outcome> {
    let verified = ds.pinned_sha256().is_some();
    let mut files = 0;
    install(ds, target, |staging| {
        let stats = archive::unpack(archive, staging, ds.strip_prefix.as_deref())
            .with_context(|| format!("cannot unpack {source}"))?;
        if stats.skipped > 0 {
            let prefix = ds.strip_prefix.as_deref().unwrap_or_default();
            eprintln!(
                "  skipped {} archive entries outside {prefix}/",
                stats.skipped
            );
        }
        files = stats.files;
        Ok(Marker {
            dataset: ds.name.clone(),
            source: source.to_owned(),
            archive_sha256: Some(sha256.to_owned()),
            list_sha256: None,
        })
    })?;
    Ok(Outcome::Installed {
        path: target.to_path_buf(),
        archive_sha256: Some(sha256.to_owned()),
        verified,
        files,
    })
}

/// A local folder is copied, not symlinked: the dataset folder then belongs to this tool
/// (marker, atomic replacement), and later edits or removal of the source cannot change
/// data that was verified.
fn from_folder(ds: &Dataset, opts: &Options, from: &Path, target: &Path) -> Result<Outcome> {
    // An unpacked archive may be given by the folder holding its top folder.
    let inner = ds
        .strip_prefix
        .as_deref()
        .map(|p| checksum::join_relative(from, p));
    let from = match &inner {
        Some(inner) if inner.is_dir() => inner.as_path(),
        _ => from,
    };
    let source = from.display().to_string();
    let (entries, list_sha256) = match &ds.files {
        Some(list_path) => {
            let text = fs::read_to_string(list_path)
                .with_context(|| format!("cannot read file list {}", list_path.display()))?;
            let entries = checksum::parse_list(&text, list_path)?;
            let sha = checksum::sha256_reader(text.as_bytes()).context("hashing the list")?;
            (entries, Some(sha))
        }
        None if opts.trust_unpinned => {
            let entries = checksum::walk_files(from)?
                .into_iter()
                .map(|path| ListEntry {
                    sha256: String::new(),
                    path,
                })
                .collect();
            (entries, None)
        }
        None => return Err(refuse_unpinned(ds, "local folders (no per-file list)")),
    };
    let listed: BTreeSet<&str> = entries.iter().map(|e| e.path.as_str()).collect();
    // Only informative, so a source the walk cannot describe (e.g. with symlinks) is fine.
    if list_sha256.is_some()
        && let Ok(all) = checksum::walk_files(from)
    {
        let unlisted = all.iter().filter(|p| !listed.contains(p.as_str())).count();
        if unlisted > 0 {
            eprintln!(
                "  ignoring {unlisted} files of {} not in the checksum list",
                from.display()
            );
        }
    }
    eprintln!(
        "copying {} files of {} from {}",
        entries.len(),
        ds.name,
        from.display()
    );
    install(ds, target, |staging| {
        let mut failures = Vec::new();
        for e in &entries {
            let src = checksum::join_relative(from, &e.path);
            let dst = checksum::join_relative(staging, &e.path);
            if let Some(parent) = dst.parent() {
                fs::create_dir_all(parent)
                    .with_context(|| format!("cannot create {}", parent.display()))?;
            }
            if !src.is_file() {
                failures.push(format!("{}: missing", e.path));
                continue;
            }
            let got = checksum::copy_hashing(&src, &dst)?;
            if !e.sha256.is_empty() && got != e.sha256 {
                failures.push(format!("{}: sha256 mismatch", e.path));
            }
        }
        if let Some(first) = failures.first() {
            bail!(
                "{} of {} files in {} fail verification (first: {first})",
                failures.len(),
                entries.len(),
                from.display()
            );
        }
        Ok(Marker {
            dataset: ds.name.clone(),
            source: source.clone(),
            archive_sha256: None,
            list_sha256: list_sha256.clone(),
        })
    })?;
    Ok(Outcome::Installed {
        path: target.to_path_buf(),
        archive_sha256: None,
        verified: list_sha256.is_some(),
        files: entries.len(),
    })
}

/// Fills a staging folder next to `target`, checks the layout, writes the marker and renames
/// the folder into place; on any error the staging folder is removed.
fn install(ds: &Dataset, target: &Path, fill: impl FnOnce(&Path) -> Result<Marker>) -> Result<()> {
    let parent = target.parent().context("dataset folder has no parent")?;
    let staging = tempfile::Builder::new()
        .prefix(&format!(".{}.staging-", ds.name))
        .tempdir_in(parent)
        .with_context(|| format!("cannot create a staging folder in {}", parent.display()))?;
    let marker = fill(staging.path())?;
    let missing: Vec<&str> = ds
        .layout
        .iter()
        .filter(|p| !checksum::join_relative(staging.path(), p).exists())
        .map(String::as_str)
        .collect();
    if !missing.is_empty() {
        bail!(
            "{} lacks the expected {} (wrong archive or strip_prefix?)",
            ds.name,
            missing.join(", ")
        );
    }
    let text = toml::to_string(&marker).context("cannot encode the marker")?;
    fs::write(staging.path().join(MARKER), text).context("cannot write the marker")?;
    replace_dir(staging, target)
}

fn replace_dir(staging: tempfile::TempDir, target: &Path) -> Result<()> {
    let staged = staging.keep();
    let result = swap_into_place(&staged, target);
    if result.is_err() {
        let _ = fs::remove_dir_all(&staged);
    }
    result
}

fn swap_into_place(staged: &Path, target: &Path) -> Result<()> {
    if !target.exists() {
        return fs::rename(staged, target)
            .with_context(|| format!("cannot move the dataset into {}", target.display()));
    }
    // A stale fetch is swapped out by rename so that a crash never leaves a half-deleted
    // dataset under the real name.
    let name = target
        .file_name()
        .context("dataset folder has no name")?
        .to_string_lossy();
    let old = target.with_file_name(format!(".{name}.old-{}", std::process::id()));
    fs::rename(target, &old).with_context(|| format!("cannot move {} aside", target.display()))?;
    if let Err(e) = fs::rename(staged, target) {
        let _ = fs::rename(&old, target);
        return Err(e)
            .with_context(|| format!("cannot move the dataset into {}", target.display()));
    }
    fs::remove_dir_all(&old).with_context(|| format!("cannot remove {}", old.display()))
}
