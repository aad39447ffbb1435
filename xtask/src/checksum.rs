//! SHA-256 of files and per-file checksum lists in `sha256sum` format.

use std::collections::BTreeMap;
use std::fs::{self, File};
use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use sha2::{Digest, Sha256};

use crate::archive::safe_relative_path;

pub fn to_hex(bytes: &[u8]) -> String {
    const DIGITS: &[u8; 16] = b"0123456789abcdef";
    let mut out = String::with_capacity(bytes.len() * 2);
    for b in bytes {
        out.push(DIGITS[usize::from(b >> 4)] as char);
        out.push(DIGITS[usize::from(b & 0x0f)] as char);
    }
    out
}

/// Lower-case only: the manifest and the lists are compared as strings.
pub fn is_sha256_hex(s: &str) -> bool {
    s.len() == 64
        && s.bytes()
            .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
}

pub fn sha256_reader(mut reader: impl Read) -> io::Result<String> {
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = reader.read(&mut buf)?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
    }
    Ok(to_hex(&hasher.finalize()))
}

pub fn sha256_file(path: &Path) -> Result<String> {
    let file = File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    sha256_reader(file).with_context(|| format!("cannot read {}", path.display()))
}

/// Copies `src` to a new file `dst` and returns the SHA-256 of the bytes copied, so a local
/// copy is verified in the same pass that makes it (reading twice would double the I/O).
pub fn copy_hashing(src: &Path, dst: &Path) -> Result<String> {
    let mut input = File::open(src).with_context(|| format!("cannot open {}", src.display()))?;
    let mut output = fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(dst)
        .with_context(|| format!("cannot create {}", dst.display()))?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = input
            .read(&mut buf)
            .with_context(|| format!("cannot read {}", src.display()))?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
        output
            .write_all(&buf[..n])
            .with_context(|| format!("cannot write {}", dst.display()))?;
    }
    Ok(to_hex(&hasher.finalize()))
}

/// One line of a `sha256sum` list: the digest and a relative path (always `/`-separated).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ListEntry {
    pub sha256: String,
    pub path: String,
}

/// Parses `sha256sum` output (`<hex>  <path>` or `<hex> *<path>`). Paths must be safe relative
/// paths because they are joined to a destination folder when a copy is made.
pub fn parse_list(text: &str, origin: &Path) -> Result<Vec<ListEntry>> {
    let mut entries = Vec::new();
    let mut seen = BTreeMap::new();
    for (idx, line) in text.lines().enumerate() {
        let lineno = idx + 1;
        if line.trim().is_empty() || line.starts_with('#') {
            continue;
        }
        let Some((hash, rest)) = line.split_once(' ') else {
            bail!("{}:{lineno}: expected `<sha256>  <path>`", origin.display());
        };
        // sha256sum writes ` ` (text mode) or `*` (binary mode) before the name; both hash
        // the same bytes on Unix.
        let path = rest
            .strip_prefix(' ')
            .or_else(|| rest.strip_prefix('*'))
            .with_context(|| {
                format!("{}:{lineno}: expected `<sha256>  <path>`", origin.display())
            })?;
        if !is_sha256_hex(hash) {
            bail!(
                "{}:{lineno}: `{hash}` is not a lower-case sha256",
                origin.display()
            );
        }
        safe_relative_path(path).with_context(|| format!("{}:{lineno}", origin.display()))?;
        if seen.insert(path.to_owned(), lineno).is_some() {
            bail!("{}:{lineno}: `{path}` is listed twice", origin.display());
        }
        entries.push(ListEntry {
            sha256: hash.to_owned(),
            path: path.to_owned(),
        });
    }
    if entries.is_empty() {
        bail!("{}: the list has no entries", origin.display());
    }
    Ok(entries)
}

pub fn format_list(entries: &[ListEntry]) -> String {
    entries
        .iter()
        .map(|e| format!("{}  {}\n", e.sha256, e.path))
        .collect()
}

/// Every regular file under `root` (except a fetch marker), as sorted `/`-separated relative paths. Symlinks are an
/// error: a checksum list must describe content, and a link's target is not part of the tree.
pub fn walk_files(root: &Path) -> Result<Vec<String>> {
    fn visit(root: &Path, dir: &Path, out: &mut Vec<String>) -> Result<()> {
        let rd = fs::read_dir(dir).with_context(|| format!("cannot list {}", dir.display()))?;
        for entry in rd {
            let entry = entry.with_context(|| format!("cannot list {}", dir.display()))?;
            let path = entry.path();
            let ty = entry
                .file_type()
                .with_context(|| format!("cannot stat {}", path.display()))?;
            if ty.is_dir() {
                visit(root, &path, out)?;
            } else if ty.is_file() {
                // The fetch marker is this tool's bookkeeping, not dataset content.
                if entry.file_name() != crate::fetch::MARKER {
                    out.push(relative_slash_path(root, &path)?);
                }
            } else {
                bail!(
                    "{} is not a regular file or folder (symlinks are not supported)",
                    path.display()
                );
            }
        }
        Ok(())
    }
    let mut out = Vec::new();
    visit(root, root, &mut out)?;
    out.sort();
    Ok(out)
}

fn relative_slash_path(root: &Path, path: &Path) -> Result<String> {
    let rel = path
        .strip_prefix(root)
        .expect("walked paths are under the root");
    let parts: Option<Vec<&str>> = rel.iter().map(|c| c.to_str()).collect();
    match parts {
        Some(parts) => Ok(parts.join("/")),
        None => bail!("{} is not valid UTF-8", path.display()),
    }
}

/// The checksum list of every file under `root`, sorted by path (the committed lists are
/// generated by this, so regenerating one gives a reviewable diff).
pub fn list_tree(root: &Path) -> Result<Vec<ListEntry>> {
    walk_files(root)?
        .into_iter()
        .map(|path| {
            let sha256 = sha256_file(&root.join(&path))?;
            Ok(ListEntry { sha256, path })
        })
        .collect()
}

/// Joins a validated `/`-separated relative path onto `base`.
pub fn join_relative(base: &Path, rel: &str) -> PathBuf {
    rel.split('/').fold(base.to_path_buf(), |p, c| p.join(c))
}
