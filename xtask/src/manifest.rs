//! `datasets/manifest.toml`: what can be fetched, from where, and how it is checked.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde::Deserialize;

use crate::archive::safe_relative_path;
use crate::checksum::is_sha256_hex;

#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Dataset {
    /// Table key in the manifest; also the folder name under the datasets directory.
    #[serde(skip)]
    pub name: String,
    pub description: String,
    pub licence: String,
    #[serde(default)]
    pub homepage: Option<String>,
    /// Mirrors of one and the same archive, tried in order.
    pub urls: Vec<String>,
    /// SHA-256 of the archive; empty when nobody could compute it yet (unpinned).
    pub sha256: String,
    /// Archive size in bytes, when known; lets a wrong file be refused before downloading it.
    #[serde(default)]
    pub size: Option<u64>,
    /// Top folder inside the archive whose content becomes the dataset folder.
    #[serde(default)]
    pub strip_prefix: Option<String>,
    /// Relative paths that must exist once the dataset is in place.
    pub layout: Vec<String>,
    /// Per-file `sha256sum` list verifying a local folder given with `--from` (resolved
    /// relative to the manifest's folder when loaded from a file).
    #[serde(default)]
    pub files: Option<PathBuf>,
}

impl Dataset {
    pub fn pinned_sha256(&self) -> Option<&str> {
        (!self.sha256.is_empty()).then_some(self.sha256.as_str())
    }

    pub fn validate(&self) -> Result<()> {
        let name = &self.name;
        if name.is_empty()
            || !name
                .bytes()
                .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-')
        {
            bail!("dataset name `{name}` must be lower-case letters, digits and `-`");
        }
        if !self.sha256.is_empty() && !is_sha256_hex(&self.sha256) {
            bail!("dataset {name}: sha256 must be empty (unpinned) or 64 lower-case hex digits");
        }
        if self.layout.is_empty() {
            bail!("dataset {name}: layout must list at least one path");
        }
        for p in &self.layout {
            safe_relative_path(p).with_context(|| format!("dataset {name}: layout"))?;
        }
        if let Some(prefix) = &self.strip_prefix {
            safe_relative_path(prefix).with_context(|| format!("dataset {name}: strip_prefix"))?;
        }
        for url in &self.urls {
            if !(url.starts_with("https://") || url.starts_with("http://")) {
                bail!("dataset {name}: url `{url}` is not http(s)");
            }
        }
        Ok(())
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ManifestFile {
    datasets: BTreeMap<String, Dataset>,
}

#[derive(Debug)]
pub struct Manifest {
    pub path: PathBuf,
    pub datasets: BTreeMap<String, Dataset>,
}

impl Manifest {
    pub fn load(path: &Path) -> Result<Self> {
        let text = fs::read_to_string(path)
            .with_context(|| format!("cannot read manifest {}", path.display()))?;
        let base = path.parent().unwrap_or(Path::new("."));
        Self::parse(&text, base)
            .map(|datasets| Manifest {
                path: path.to_path_buf(),
                datasets,
            })
            .with_context(|| format!("invalid manifest {}", path.display()))
    }

    pub fn parse(text: &str, base_dir: &Path) -> Result<BTreeMap<String, Dataset>> {
        let file: ManifestFile = toml::from_str(text).map_err(|e| {
            // toml's message spans several lines (source excerpt); keep errors one line.
            anyhow::anyhow!(
                "{}",
                e.to_string()
                    .split_whitespace()
                    .collect::<Vec<_>>()
                    .join(" ")
            )
        })?;
        let mut datasets = file.datasets;
        for (name, ds) in &mut datasets {
            ds.name = name.clone();
            if let Some(files) = &ds.files {
                ds.files = Some(base_dir.join(files));
            }
            ds.validate()?;
        }
        Ok(datasets)
    }

    pub fn get(&self, name: &str) -> Result<&Dataset> {
        self.datasets.get(name).with_context(|| {
            let known: Vec<&str> = self.datasets.keys().map(String::as_str).collect();
            format!(
                "unknown dataset `{name}` (known in {}: {})",
                self.path.display(),
                known.join(", ")
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
[datasets.demo]
description = "d"
licence = "MIT"
urls = ["https://example.invalid/a.zip"]
sha256 = ""
layout = ["a/b.txt"]
files = "demo.sha256"
"#;

    #[test]
    fn parses_and_resolves_the_file_list_next_to_the_manifest() {
        let ds = Manifest::parse(GOOD, Path::new("/m")).unwrap();
        let demo = &ds["demo"];
        assert_eq!(demo.name, "demo");
        assert_eq!(demo.pinned_sha256(), None);
        assert_eq!(demo.files.as_deref(), Some(Path::new("/m/demo.sha256")));
    }

    #[test]
    fn rejects_unsafe_layout_bad_hash_and_unknown_keys() {
        let bad_layout = GOOD.replace("a/b.txt", "../b.txt");
        assert!(Manifest::parse(&bad_layout, Path::new(".")).is_err());
        let bad_hash = GOOD.replace("sha256 = \"\"", "sha256 = \"ABC\"");
        let err = Manifest::parse(&bad_hash, Path::new(".")).unwrap_err();
        assert!(format!("{err:#}").contains("64 lower-case hex"), "{err:#}");
        let unknown = GOOD.replace("licence", "license");
        assert!(Manifest::parse(&unknown, Path::new(".")).is_err());
    }

    #[test]
    fn the_committed_manifest_is_valid_and_names_the_expected_datasets() {
        let path = crate::workspace_root().join("datasets/manifest.toml");
        let m = Manifest::load(&path).unwrap();
        for name in ["ridi", "tyrex", "indoor-location-competition-20", "ronin"] {
            let ds = m.get(name).unwrap();
            assert!(!ds.urls.is_empty(), "{name} has no url");
        }
        let tyrex_list = m.get("tyrex").unwrap().files.clone().unwrap();
        assert!(tyrex_list.is_file(), "{} missing", tyrex_list.display());
        assert!(m.get("nope").is_err());
    }
}
