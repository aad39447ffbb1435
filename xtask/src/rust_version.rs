//! `cargo xtask rust-version`: the workspace's declared `rust-version` is at least that of every
//! package in Cargo.lock (as `cargo metadata` reports them: normal, build and dev-dependencies,
//! every target), and the README's "Rust toolchain (X or newer)" says the same version.
//!
//! Runs `cargo metadata --locked` (no build; it reads the registry's copies of the manifests,
//! downloading those not yet there).

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result, bail};

/// A Rust version as `rust-version` spells it (`1.89`, `1.89.0`), compared by number.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct RustVersion(pub [u64; 3]);

impl RustVersion {
    /// Parses `major.minor[.patch]`.
    pub fn parse(text: &str) -> Option<Self> {
        let mut parts = text.trim().split('.').map(|p| p.parse::<u64>().ok());
        let major = parts.next()??;
        let minor = parts.next()??;
        let patch = parts.next().unwrap_or(Some(0))?;
        parts
            .next()
            .is_none()
            .then_some(Self([major, minor, patch]))
    }
}

impl std::fmt::Display for RustVersion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [major, minor, patch] = self.0;
        if patch == 0 {
            write!(f, "{major}.{minor}")
        } else {
            write!(f, "{major}.{minor}.{patch}")
        }
    }
}

/// One package of `cargo metadata`: name, version, declared rust-version, workspace member.
#[derive(Debug, Clone)]
pub struct Package {
    /// Package name.
    pub name: String,
    /// Package version.
    pub version: String,
    /// Its `rust-version`, if it declares one.
    pub rust_version: Option<RustVersion>,
    /// Whether it is a member of this workspace.
    pub member: bool,
}

/// The packages of a `cargo metadata --format-version 1` document.
pub fn packages(metadata: &serde_json::Value) -> Result<Vec<Package>> {
    let members: Vec<&str> = metadata["workspace_members"]
        .as_array()
        .context("cargo metadata: no workspace_members")?
        .iter()
        .filter_map(|m| m.as_str())
        .collect();
    metadata["packages"]
        .as_array()
        .context("cargo metadata: no packages")?
        .iter()
        .map(|p| {
            let name = p["name"].as_str().context("a package without a name")?;
            let rust_version = match p["rust_version"].as_str() {
                Some(v) => Some(
                    RustVersion::parse(v)
                        .with_context(|| format!("{name}: rust-version `{v}` is no version"))?,
                ),
                None => None,
            };
            Ok(Package {
                name: name.to_owned(),
                version: p["version"].as_str().unwrap_or_default().to_owned(),
                rust_version,
                member: p["id"].as_str().is_some_and(|id| members.contains(&id)),
            })
        })
        .collect()
}

/// Problems: members that declare no rust-version, and members whose rust-version is below a
/// dependency's (grouped by the version they declare, naming the dependencies that need more,
/// newest first).
pub fn check(packages: &[Package]) -> Vec<String> {
    let mut deps: Vec<&Package> = packages
        .iter()
        .filter(|p| !p.member && p.rust_version.is_some())
        .collect();
    deps.sort_by_key(|d| std::cmp::Reverse(d.rust_version));
    let mut problems = Vec::new();
    let mut by_version: BTreeMap<RustVersion, Vec<&str>> = BTreeMap::new();
    for member in packages.iter().filter(|p| p.member) {
        match member.rust_version {
            Some(v) => by_version.entry(v).or_default().push(&member.name),
            None => problems.push(format!("{}: no rust-version", member.name)),
        }
    }
    for (declared, members) in by_version {
        let newer: Vec<String> = deps
            .iter()
            .filter(|d| d.rust_version > Some(declared))
            .map(|d| {
                let v = d.rust_version.map(|v| v.to_string()).unwrap_or_default();
                format!("{} {} ({v})", d.name, d.version)
            })
            .collect();
        if !newer.is_empty() {
            problems.push(format!(
                "{}: rust-version {declared}, but Cargo.lock has packages that need more: {}; \
                 raise rust-version in the root Cargo.toml (and the README's) or hold them back",
                members.join(", "),
                newer.join(", ")
            ));
        }
    }
    problems
}

/// The version of the README's "Rust toolchain (X or newer)".
pub fn readme_version(readme: &str) -> Option<RustVersion> {
    let at = readme.find(" or newer)")?;
    let start = readme[..at].rfind('(')? + 1;
    RustVersion::parse(&readme[start..at])
}

/// Runs the check in the workspace at `root`; prints the versions on success.
pub fn run(root: &Path) -> Result<()> {
    let out = crate::cargo_stdout(
        root,
        &["metadata", "--format-version", "1", "--locked"],
        &[],
    )?;
    let metadata: serde_json::Value =
        serde_json::from_str(&out).context("parsing the output of cargo metadata")?;
    let packages = packages(&metadata)?;
    let mut problems = check(&packages);
    let declared = packages
        .iter()
        .filter(|p| p.member)
        .filter_map(|p| p.rust_version)
        .min();
    let readme_path = root.join("README.md");
    let readme = std::fs::read_to_string(&readme_path)
        .with_context(|| format!("reading {}", readme_path.display()))?;
    match (readme_version(&readme), declared) {
        (Some(r), Some(d)) if r == d => {}
        (r, d) => problems.push(format!(
            "README.md: \"Rust toolchain ({} or newer)\" should name the declared rust-version {}",
            r.map(|v| v.to_string()).unwrap_or_else(|| "?".into()),
            d.map(|v| v.to_string()).unwrap_or_else(|| "?".into()),
        )),
    }
    if !problems.is_empty() {
        bail!("rust-version: {}", problems.join("\n  "));
    }
    let newest = packages
        .iter()
        .filter(|p| !p.member)
        .filter_map(|p| p.rust_version.map(|v| (v, p)))
        .max_by_key(|(v, _)| *v);
    let declared = declared.map(|v| v.to_string()).unwrap_or_default();
    match newest {
        Some((v, p)) => println!(
            "rust-version {declared}: the newest a dependency declares is {v} ({} {}), of {} \
             packages in Cargo.lock",
            p.name,
            p.version,
            packages.len()
        ),
        None => println!("rust-version {declared}: no dependency declares one"),
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn package(name: &str, v: Option<&str>, member: bool) -> Package {
        Package {
            name: name.into(),
            version: "1.0.0".into(),
            rust_version: v.and_then(RustVersion::parse),
            member,
        }
    }

    #[test]
    fn versions_compare_by_number() {
        let v = |s| RustVersion::parse(s).unwrap();
        assert!(v("1.89") < v("1.100"));
        assert_eq!(v("1.89"), v("1.89.0"));
        assert!(v("1.89.1") > v("1.89"));
        assert_eq!(v("1.89").to_string(), "1.89");
        assert_eq!(RustVersion::parse("1"), None);
        assert_eq!(RustVersion::parse("1.89.0.1"), None);
        assert_eq!(RustVersion::parse("1.x"), None);
    }

    #[test]
    fn a_dependency_newer_than_the_declared_version_is_named() {
        let packages = [
            package("ours", Some("1.89"), true),
            package("also-ours", Some("1.89"), true),
            package("old", Some("1.70"), false),
            package("same", Some("1.89.0"), false),
            package("new", Some("1.91"), false),
            package("none", None, false),
        ];
        let problems = check(&packages);
        assert_eq!(problems.len(), 1, "{problems:?}");
        assert!(
            problems[0].starts_with("ours, also-ours: rust-version 1.89"),
            "{problems:?}"
        );
        assert!(problems[0].contains("need more: new 1.0.0 (1.91);"));
        let without_new: Vec<Package> = packages
            .iter()
            .filter(|p| p.name != "new")
            .cloned()
            .collect();
        assert!(check(&without_new).is_empty());
        assert_eq!(
            check(&[package("ours", None, true)]),
            ["ours: no rust-version"]
        );
    }

    #[test]
    fn the_readme_names_its_version() {
        let text = "You need a Rust toolchain (1.89 or newer). From a fresh checkout:";
        assert_eq!(readme_version(text), RustVersion::parse("1.89"));
        assert_eq!(readme_version("no version here"), None);
    }
}
