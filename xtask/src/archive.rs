//! Unpacking zip and tar.gz archives into a folder without letting an entry write outside it.

use std::fs::{self, File};
use std::io::{self, BufReader, Read, Seek};
use std::path::{Component, Path, PathBuf};

use anyhow::{Context, Result, bail};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Zip,
    TarGz,
}

/// Detects the format from the magic bytes: a mirror's URL or a user's file name may not say
/// what the archive is, the bytes always do.
pub fn sniff(path: &Path) -> Result<Format> {
    let mut head = [0u8; 4];
    let mut file = File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let n = file
        .read(&mut head)
        .with_context(|| format!("cannot read {}", path.display()))?;
    match &head[..n] {
        [b'P', b'K', 3, 4] | [b'P', b'K', 5, 6] => Ok(Format::Zip),
        [0x1f, 0x8b, ..] => Ok(Format::TarGz),
        _ => bail!(
            "{} is neither a zip nor a gzip-compressed tar archive",
            path.display()
        ),
    }
}

/// Validates an archive entry name, list entry or manifest path: relative, no `..`, not
/// empty. `.` components are dropped.
pub fn safe_relative_path(name: &str) -> Result<PathBuf> {
    if name.contains('\0') {
        bail!("unsafe path `{}`: contains a NUL byte", name.escape_debug());
    }
    let mut out = PathBuf::new();
    for comp in Path::new(name).components() {
        match comp {
            Component::Normal(c) => out.push(c),
            Component::CurDir => {}
            Component::ParentDir => bail!("unsafe path `{name}`: contains `..`"),
            Component::RootDir | Component::Prefix(_) => bail!("unsafe path `{name}`: absolute"),
        }
    }
    if out.as_os_str().is_empty() {
        bail!("empty path `{name}`");
    }
    Ok(out)
}

#[derive(Debug, Default, Clone, PartialEq, Eq)]
pub struct UnpackStats {
    pub files: usize,
    pub dirs: usize,
    pub symlinks: usize,
    /// Entries outside `strip_prefix` (e.g. `__MACOSX/` added by macOS zip tools).
    pub skipped: usize,
}

enum Kind {
    Dir,
    File,
    Symlink(PathBuf),
}

struct Unpacker<'a> {
    dest: &'a Path,
    prefix: Option<PathBuf>,
    stats: UnpackStats,
    links: Vec<(PathBuf, PathBuf)>,
}

impl Unpacker<'_> {
    /// Maps an entry name to its path relative to `dest`; `None` for entries to skip.
    fn target(&mut self, name: &str) -> Result<Option<PathBuf>> {
        let rel = safe_relative_path(name).with_context(|| format!("archive entry `{name}`"))?;
        let Some(prefix) = &self.prefix else {
            return Ok(Some(rel));
        };
        match rel.strip_prefix(prefix) {
            Ok(inner) if inner.as_os_str().is_empty() => Ok(None),
            Ok(inner) => Ok(Some(inner.to_path_buf())),
            Err(_) => {
                self.stats.skipped += 1;
                Ok(None)
            }
        }
    }

    fn entry(&mut self, name: &str, kind: Kind, content: &mut dyn Read) -> Result<()> {
        let Some(rel) = self.target(name)? else {
            return Ok(());
        };
        let path = self.dest.join(&rel);
        match kind {
            Kind::Dir => {
                fs::create_dir_all(&path)
                    .with_context(|| format!("cannot create {}", path.display()))?;
                self.stats.dirs += 1;
            }
            Kind::File => {
                if let Some(parent) = path.parent() {
                    fs::create_dir_all(parent)
                        .with_context(|| format!("cannot create {}", parent.display()))?;
                }
                // create_new: a duplicate entry must not silently replace verified content.
                let mut out = fs::OpenOptions::new()
                    .write(true)
                    .create_new(true)
                    .open(&path)
                    .with_context(|| {
                        format!("cannot create {} (duplicate entry?)", path.display())
                    })?;
                io::copy(content, &mut out)
                    .with_context(|| format!("cannot unpack archive entry `{name}`"))?;
                self.stats.files += 1;
            }
            Kind::Symlink(target) => {
                check_link_target(&rel, &target)
                    .with_context(|| format!("archive entry `{name}`"))?;
                self.links.push((rel, target));
            }
        }
        Ok(())
    }

    /// Links are made last so that no file entry can be written through a link, then each
    /// one is resolved for real: lexical checks alone miss chains such as `b -> a/..` with
    /// `a -> .`.
    fn finish(mut self) -> Result<UnpackStats> {
        for (rel, target) in &self.links {
            let path = self.dest.join(rel);
            if let Some(parent) = path.parent() {
                fs::create_dir_all(parent)
                    .with_context(|| format!("cannot create {}", parent.display()))?;
            }
            make_symlink(target, &path)?;
            self.stats.symlinks += 1;
        }
        let root = fs::canonicalize(self.dest)
            .with_context(|| format!("cannot resolve {}", self.dest.display()))?;
        for (rel, target) in &self.links {
            let path = self.dest.join(rel);
            let resolved = fs::canonicalize(&path).map_err(|_| {
                anyhow::anyhow!(
                    "unsafe archive: symlink `{}` -> `{}` does not resolve inside the archive",
                    rel.display(),
                    target.display()
                )
            })?;
            if !resolved.starts_with(&root) {
                bail!(
                    "unsafe archive: symlink `{}` -> `{}` points outside the archive",
                    rel.display(),
                    target.display()
                );
            }
        }
        Ok(self.stats)
    }
}

fn check_link_target(link: &Path, target: &Path) -> Result<()> {
    if target.is_absolute() {
        bail!("unsafe symlink -> `{}`: absolute target", target.display());
    }
    // Depth below the root of the folder holding the link; `..` may climb at most that far.
    let mut depth = link.components().count().saturating_sub(1) as isize;
    for comp in target.components() {
        match comp {
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
            Component::ParentDir => {
                depth -= 1;
                if depth < 0 {
                    bail!(
                        "unsafe symlink -> `{}`: points outside the archive",
                        target.display()
                    );
                }
            }
            Component::RootDir | Component::Prefix(_) => {
                bail!("unsafe symlink -> `{}`: absolute target", target.display())
            }
        }
    }
    Ok(())
}

#[cfg(unix)]
fn make_symlink(target: &Path, path: &Path) -> Result<()> {
    std::os::unix::fs::symlink(target, path)
        .with_context(|| format!("cannot create symlink {}", path.display()))
}

#[cfg(not(unix))]
fn make_symlink(_target: &Path, path: &Path) -> Result<()> {
    bail!(
        "archive contains symlink {}; symlinks are only supported on Unix",
        path.display()
    )
}

/// Unpacks `archive` into the existing, empty folder `dest`. With `strip_prefix`, only entries
/// under that folder are unpacked, relative to it.
pub fn unpack(archive: &Path, dest: &Path, strip_prefix: Option<&str>) -> Result<UnpackStats> {
    let prefix = strip_prefix.map(safe_relative_path).transpose()?;
    let unpacker = Unpacker {
        dest,
        prefix,
        stats: UnpackStats::default(),
        links: Vec::new(),
    };
    let file = File::open(archive).with_context(|| format!("cannot open {}", archive.display()))?;
    let reader = BufReader::new(file);
    let stats = match sniff(archive)? {
        Format::Zip => unpack_zip(reader, unpacker)?,
        Format::TarGz => unpack_tar_gz(reader, unpacker)?,
    };
    Ok(stats)
}

fn unpack_zip(reader: impl Read + Seek, mut u: Unpacker<'_>) -> Result<UnpackStats> {
    let mut zip = zip::ZipArchive::new(reader).context("corrupt zip archive")?;
    for i in 0..zip.len() {
        let mut entry = zip.by_index(i).context("corrupt zip archive")?;
        let name = entry.name().context("corrupt zip entry name")?.into_owned();
        if entry.is_dir() {
            u.entry(&name, Kind::Dir, &mut io::empty())?;
        } else if entry.is_symlink() {
            let mut target = String::new();
            entry
                .read_to_string(&mut target)
                .with_context(|| format!("cannot read symlink entry `{name}`"))?;
            u.entry(
                &name,
                Kind::Symlink(PathBuf::from(target)),
                &mut io::empty(),
            )?;
        } else {
            u.entry(&name, Kind::File, &mut entry)?;
        }
    }
    u.finish()
}

fn unpack_tar_gz(reader: impl Read, mut u: Unpacker<'_>) -> Result<UnpackStats> {
    let mut tar = tar::Archive::new(flate2::read::GzDecoder::new(reader));
    for entry in tar.entries().context("corrupt tar.gz archive")? {
        let mut entry = entry.context("corrupt tar.gz archive")?;
        let ty = entry.header().entry_type();
        let name = String::from_utf8_lossy(&entry.path_bytes()).into_owned();
        use tar::EntryType as T;
        match ty {
            T::Regular | T::Continuous => u.entry(&name, Kind::File, &mut entry)?,
            T::Directory => u.entry(&name, Kind::Dir, &mut io::empty())?,
            T::Symlink => {
                let target = entry
                    .link_name()
                    .with_context(|| format!("bad symlink entry `{name}`"))?
                    .with_context(|| format!("symlink entry `{name}` has no target"))?
                    .into_owned();
                u.entry(&name, Kind::Symlink(target), &mut io::empty())?;
            }
            // GitHub's tarballs start with a pax global header carrying the commit id.
            T::XGlobalHeader | T::XHeader => {}
            other => bail!("unsupported tar entry `{name}` of type {other:?}"),
        }
    }
    u.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    #[test]
    fn safe_relative_path_rejects_escapes() {
        assert_eq!(safe_relative_path("./a/b").unwrap(), PathBuf::from("a/b"));
        for bad in ["../a", "a/../../b", "/etc/passwd", "", ".", "a/\0b"] {
            assert!(safe_relative_path(bad).is_err(), "{bad:?} accepted");
        }
        // `a/../b` stays inside but is still refused: archives never need it.
        assert!(safe_relative_path("a/../b").is_err());
    }

    #[test]
    fn link_targets_may_not_climb_above_the_root() {
        assert!(check_link_target(Path::new("a/b/l"), Path::new("../x")).is_ok());
        assert!(check_link_target(Path::new("a/b/l"), Path::new("../../x")).is_ok());
        assert!(check_link_target(Path::new("a/b/l"), Path::new("../../../x")).is_err());
        assert!(check_link_target(Path::new("l"), Path::new("/etc")).is_err());
    }

    fn zip_with(entries: &[(&str, Option<&str>)]) -> tempfile::NamedTempFile {
        let file = tempfile::NamedTempFile::new().unwrap();
        let mut w = zip::ZipWriter::new(file.reopen().unwrap());
        let opts = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated);
        for (name, link) in entries {
            match link {
                None => {
                    w.start_file(*name, opts).unwrap();
                    w.write_all(name.as_bytes()).unwrap();
                }
                Some(target) => w.add_symlink(*name, *target, opts).unwrap(),
            }
        }
        w.finish().unwrap();
        file
    }

    #[test]
    fn zip_with_prefix_and_inside_symlink_unpacks() {
        let z = zip_with(&[
            ("top/a/x.txt", None),
            ("__MACOSX/top/._x", None),
            ("top/link", Some("a/x.txt")),
        ]);
        let dest = tempfile::tempdir().unwrap();
        let stats = unpack(z.path(), dest.path(), Some("top")).unwrap();
        assert_eq!((stats.files, stats.symlinks, stats.skipped), (1, 1, 1));
        assert_eq!(
            fs::read_to_string(dest.path().join("link")).unwrap(),
            "top/a/x.txt"
        );
    }

    #[test]
    fn zip_escapes_are_rejected() {
        for entries in [
            vec![("../evil.txt", None)],
            vec![("/abs.txt", None)],
            vec![("l", Some("../outside"))],
            vec![("l", Some("/etc/passwd"))],
            // Each link alone stays inside; together `b` resolves to the parent of the root.
            vec![("d/a", Some("..")), ("b", Some("d/a/.."))],
        ] {
            let z = zip_with(&entries);
            let dest = tempfile::tempdir().unwrap();
            let err = unpack(z.path(), dest.path(), None).unwrap_err();
            assert!(
                format!("{err:#}").contains("unsafe"),
                "{entries:?}: {err:#}"
            );
        }
    }
}
