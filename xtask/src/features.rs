//! `cargo xtask features`: CI's three builds turn on the same features of every dependency
//! they share, so that they share its compiled artifacts in `target/`.
//!
//! `.ci/run` builds the workspace's tests, then ridi's tests without default features, then the
//! Python package (crates/ridi-py, a workspace of its own), all into one `target/`. Cargo
//! compiles a dependency again when its features (or those of anything below it) differ from
//! the build before: a feature that only linfa, clap or zip turn on, in `num-traits` or in the
//! proc-macro side's `syn`, made the two later builds compile the numeric stack (faer, nalgebra,
//! serde and what depends on them) twice more, a third of CI's time. `ridi-test-support` (a
//! dev-dependency of ridi) and `ridi-py` therefore depend on those crates with the workspace's
//! features, as cargo-hakari's "workspace-hack" crates do. This check runs `cargo tree --locked`
//! for the three builds (no build) and names each shared dependency whose features, or whose
//! version in ridi-py's own Cargo.lock, differ, and the manifest to align.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use anyhow::{Context, Result, bail};

/// The features a build turns on, per dependency (`name`, `version`): one entry per way the
/// build compiles it (the proc-macro side and the target side may differ), each the sorted,
/// comma-separated list `cargo tree`'s `{f}` prints. The workspace's own packages are left out.
pub type Resolved = BTreeMap<(String, String), BTreeSet<String>>;

/// One of the builds checked against the workspace's tests.
struct Build {
    /// How the message names it.
    name: &'static str,
    /// `cargo tree` arguments selecting it (besides `--locked` and the format).
    args: &'static [&'static str],
    /// The manifest whose alignment list it takes.
    aligned_in: &'static str,
}

const WORKSPACE: &[&str] = &["--workspace"];

const OTHERS: &[Build] = &[
    Build {
        name: "`cargo test -p ridi --no-default-features`",
        args: &["-p", "ridi", "--no-default-features"],
        aligned_in: "crates/ridi-test-support/Cargo.toml",
    },
    Build {
        name: "the Python package",
        // `maturin develop` builds the library only: no dev-dependencies.
        args: &[
            "--manifest-path",
            "crates/ridi-py/Cargo.toml",
            "-e",
            "normal,build",
        ],
        aligned_in: "crates/ridi-py/Cargo.toml",
    },
];

/// Parses `cargo tree --prefix none --format '{p}|{f}'`: lines `name vX.Y.Z [(...)]|features`,
/// ` (*)` after a repeat. Local packages (their `{p}` names a path) are left out.
pub fn parse(tree: &str) -> Result<Resolved> {
    let mut resolved = Resolved::new();
    for line in tree.lines().filter(|l| !l.trim().is_empty()) {
        let (package, features) = line
            .split_once('|')
            .with_context(|| format!("cargo tree: no `|` in {line:?}"))?;
        if package.contains(" (/") || package.contains(":\\") {
            continue;
        }
        let features = features.trim().trim_end_matches("(*)").trim_end();
        let mut words = package.split_whitespace();
        let (Some(name), Some(version)) = (words.next(), words.next()) else {
            bail!("cargo tree: no package and version in {line:?}");
        };
        let version = version.strip_prefix('v').unwrap_or(version);
        resolved
            .entry((name.to_owned(), version.to_owned()))
            .or_default()
            .insert(features.to_owned());
    }
    Ok(resolved)
}

/// Cargo's compatibility class of a version: the major number, or `0.minor` below 1.
fn compatible(version: &str) -> String {
    let mut parts = version.split('.');
    match (parts.next(), parts.next()) {
        (Some("0"), Some(minor)) => format!("0.{minor}"),
        (Some(major), _) => major.to_owned(),
        _ => version.to_owned(),
    }
}

fn shown(sets: &BTreeSet<String>) -> String {
    sets.iter()
        .map(|s| if s.is_empty() { "(none)" } else { s.as_str() })
        .map(|s| format!("[{s}]"))
        .collect::<Vec<_>>()
        .join(" and ")
}

/// Problems of `other` (named `name`, aligned in `aligned_in`) against the workspace's build:
/// a dependency both compile with other features, and one `other` resolves to another version
/// of the same compatibility class (ridi-py's Cargo.lock).
pub fn compare(
    workspace: &Resolved,
    other: &Resolved,
    name: &str,
    aligned_in: &str,
) -> Vec<String> {
    let mut problems = Vec::new();
    for ((package, version), features) in other {
        match workspace.get(&(package.clone(), version.clone())) {
            // A build that needs only one of the ways the workspace compiles a crate (for the
            // proc-macro side and for the target, say) reuses that one. `cargo tree` does not
            // say which side a feature set is for: one the workspace builds for the host only
            // (opt-level 0) and another build needs on the target passes here, and is compiled
            // again.
            Some(ours) if !features.is_subset(ours) => problems.push(format!(
                "{package} {version}: {name} turns on {}, where the workspace's tests build {}: \
                 give it the workspace's features in {aligned_in} (as a build-dependency when \
                 a proc-macro or build script needs it)",
                shown(features),
                shown(ours)
            )),
            Some(_) => {}
            None => {
                let class = compatible(version);
                let ours: Vec<&str> = workspace
                    .keys()
                    .filter(|(p, v)| p == package && compatible(v) == class)
                    .map(|(_, v)| v.as_str())
                    .collect();
                if !ours.is_empty() {
                    problems.push(format!(
                        "{package}: {name} resolves {version}, the workspace {}: `cargo update \
                         --manifest-path {aligned_in} -p {package}@{version} --precise {}`",
                        ours.join(", "),
                        ours[0]
                    ));
                }
            }
        }
    }
    problems
}

fn tree(root: &Path, args: &[&str]) -> Result<Resolved> {
    let mut all = vec!["tree", "--locked"];
    all.extend(args);
    all.extend(["--prefix", "none", "--format", "{p}|{f}"]);
    parse(&crate::cargo_stdout(root, &all, &[])?)
}

/// Runs the check in the workspace at `root`; prints what it compared on success.
pub fn run(root: &Path) -> Result<()> {
    let workspace = tree(root, WORKSPACE)?;
    let mut problems = Vec::new();
    let mut shared = Vec::new();
    for build in OTHERS {
        let other = tree(root, build.args)?;
        let n = other.keys().filter(|k| workspace.contains_key(*k)).count();
        shared.push(format!("{n} with {}", build.name));
        problems.extend(compare(&workspace, &other, build.name, build.aligned_in));
    }
    if !problems.is_empty() {
        bail!(
            "features: the builds would compile these dependencies again:\n  {}",
            problems.join("\n  ")
        );
    }
    println!(
        "features: the workspace's tests build {} dependencies; they share {}, each with the \
         same features",
        workspace.len(),
        shared.join(" and ")
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const WS: &str = "\
ridi v0.1.0 (/work/crates/ridi)|default,plot
num-traits v0.2.19|default,i128,libm,std
syn v3.0.9 (proc-macro)|full,parsing
syn v3.0.9|full,parsing (*)
serde v1.0.229|std
faer v0.24.4|
";

    #[test]
    fn parse_leaves_out_local_packages_and_keeps_each_feature_set() {
        let r = parse(WS).unwrap();
        assert_eq!(r.len(), 4, "{r:?}");
        let key = |p: &str, v: &str| (p.to_owned(), v.to_owned());
        assert_eq!(r[&key("syn", "3.0.9")].len(), 1);
        assert!(r[&key("faer", "0.24.4")].contains(""));
        assert!(parse("no bar here").is_err());
    }

    #[test]
    fn compare_names_features_and_versions_that_differ() {
        let ws = parse(WS).unwrap();
        let other = parse(
            "num-traits v0.2.19|default,i128,std\nsyn v3.0.9|full,parsing\nserde v1.0.228|std\n\
             pyo3 v0.30.1|abi3\nfaer v0.24.4|\n",
        )
        .unwrap();
        let problems = compare(
            &ws,
            &other,
            "the Python package",
            "crates/ridi-py/Cargo.toml",
        );
        assert_eq!(problems.len(), 2, "{problems:#?}");
        assert!(
            problems[0].contains("num-traits 0.2.19")
                && problems[0].contains("[default,i128,std]")
                && problems[0].contains("[default,i128,libm,std]")
                && problems[0].contains("crates/ridi-py/Cargo.toml"),
            "{}",
            problems[0]
        );
        assert!(
            problems[1]
                .contains("serde: the Python package resolves 1.0.228, the workspace 1.0.229")
                && problems[1].contains(
                    "--manifest-path crates/ridi-py/Cargo.toml -p serde@1.0.228 --precise 1.0.229"
                ),
            "{}",
            problems[1]
        );
        assert!(compare(&ws, &ws, "x", "y").is_empty());
        // One of the two ways the workspace builds a crate is no problem; a third is.
        let ws = parse("libc v0.2.1|std\nlibc v0.2.1|default,std\n").unwrap();
        let one = parse("libc v0.2.1|default,std\n").unwrap();
        assert!(compare(&ws, &one, "x", "y").is_empty());
        let other = parse("libc v0.2.1|extra_traits,std\n").unwrap();
        assert_eq!(compare(&ws, &other, "x", "y").len(), 1);
    }

    #[test]
    fn versions_of_another_compatibility_class_are_no_problem() {
        let ws = parse("syn v2.0.119|full\n").unwrap();
        let other = parse("syn v1.0.109|full\n").unwrap();
        assert!(compare(&ws, &other, "x", "y").is_empty());
        assert_eq!(compatible("0.24.4"), "0.24");
        assert_eq!(compatible("3.0.9"), "3");
    }
}
