//! `cargo xtask tidy`: fast checks that keep the codebase's conventions true.
//!
//! - Every workspace crate's dependencies on other workspace crates are exactly the row of the
//!   layer table in `docs/ARCHITECTURE.md` (normal and build dependencies; dev-dependencies
//!   may only name crates of that row, `ridi-test-support`, or the crate itself).
//! - No error enum uses a retired spelling: `NotFinite`, `DimensionMismatch`, a `Shape(..)`
//!   variant, `LengthMismatch` / `NonFinite` as unit or tuple variants, or with other fields
//!   than `what`, `expected`, `found`, `index` (and a plot's `series`).
//! - No crate declares a public module outside [`PUBLIC_MODULES`], and the list names no module
//!   that is not public: new items are re-exported at the crate root from private modules, as
//!   ripgrep's crates do.
//!
//! - The dev profile compiles every workspace crate as the root Cargo.toml names it (a
//!   `[profile.dev.package.<crate>]` section each, no `package."*"`, which would take
//!   precedence over build-override and optimize build scripts and proc macros), and
//!   crates/ridi-py, a workspace of its own, repeats the root's dev and release profiles for
//!   itself and the crates it builds, so that both share artifacts in one `target/`.
//!
//! - Each crate README's dependency count ("**Dependencies:** N crates", and ridi's "N with
//!   `default-features = false`") is what `cargo tree` counts now, for Linux (x86_64): the
//!   count differs by a crate or two on other platforms (rustix's backend, windows-sys).
//!
//! It reads files and runs `cargo tree` (no build), so it takes about a second.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

/// The public modules each crate has, exactly; every other item lives in a private module and
/// is re-exported at the crate root. These few are namespaces on purpose: ridi-data has one
/// per format (each with its own `read` and `parse`, so `ridi_data::tyrex::read`), and ridi's
/// optional figures (`plot`, with their own error type). A new public module is a design
/// decision: say why in the crate docs and here.
pub const PUBLIC_MODULES: &[(&str, &[&str])] = &[
    (
        "ridi-data",
        &[
            "ilc",
            "ridi_csv",
            "ridi_plain",
            "ridi_raw",
            "ronin",
            "tyrex",
        ],
    ),
    ("ridi", &["plot"]),
];

/// Retired variant names, wherever they appear in code, and what replaced them.
const RETIRED_NAMES: &[(&str, &str)] = &[
    ("NotFinite", "the variant is `NonFinite`"),
    (
        "DimensionMismatch",
        "the variant is `LengthMismatch { what, expected, found }`",
    ),
];

/// The names a field of a `LengthMismatch` or `NonFinite` variant may have.
const ERROR_FIELDS: &[&str] = &["what", "expected", "found", "index", "series"];

/// Runs every check under the workspace `root`; the error lists every problem found.
pub fn run(root: &Path) -> Result<()> {
    let mut problems = Vec::new();
    let crates = workspace_crates(root)?;
    let table = layer_table(&root.join("docs/ARCHITECTURE.md"))?;
    check_layers(&crates, &table, &mut problems);
    check_profiles(root, &crates, &mut problems)?;
    check_dependency_counts(root, &crates, &mut problems)?;
    for krate in crates.values() {
        // This file names the retired spellings.
        for file in rust_files(&krate.dir.join("src"))?
            .into_iter()
            .filter(|f| !f.ends_with("xtask/src/tidy.rs"))
        {
            let text = std::fs::read_to_string(&file)
                .with_context(|| format!("reading {}", file.display()))?;
            let shown = file
                .strip_prefix(root)
                .unwrap_or(&file)
                .display()
                .to_string();
            check_error_spellings(&shown, &text, &mut problems);
        }
        // xtask is no library anyone depends on: its modules serve its own tests.
        if !krate.dir.ends_with("xtask") {
            check_public_modules(root, krate, &mut problems)?;
        }
    }
    if problems.is_empty() {
        println!(
            "tidy: {} crates: layers, error spellings, public modules, profiles and dependency \
             counts as documented",
            crates.len()
        );
        return Ok(());
    }
    let mut text = String::new();
    for p in &problems {
        let _ = writeln!(text, "  {p}");
    }
    bail!(
        "tidy found {}:\n{text}",
        ridi_data::counted(problems.len(), "problem")
    )
}

/// A workspace crate: its folder and the workspace crates it depends on.
#[derive(Debug)]
pub struct Crate {
    /// The folder holding its Cargo.toml.
    pub dir: PathBuf,
    /// Workspace crates among its normal and build dependencies.
    pub deps: BTreeSet<String>,
    /// Workspace crates among its dev-dependencies.
    pub dev_deps: BTreeSet<String>,
}

/// The crates under `crates/` and `xtask/`, by package name.
pub fn workspace_crates(root: &Path) -> Result<BTreeMap<String, Crate>> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root.join("crates"))
        .context("reading crates/")?
        .map(|e| e.map(|e| e.path()))
        .collect::<std::io::Result<_>>()?;
    dirs.push(root.join("xtask"));
    let mut manifests = BTreeMap::new();
    for dir in dirs {
        let path = dir.join("Cargo.toml");
        if !path.is_file() {
            continue;
        }
        let text = std::fs::read_to_string(&path)?;
        let doc: toml::Table =
            toml::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
        let name = doc
            .get("package")
            .and_then(|p| p.get("name"))
            .and_then(|n| n.as_str())
            .with_context(|| format!("{}: no package.name", path.display()))?
            .to_owned();
        manifests.insert(name, (dir, doc));
    }
    let names: BTreeSet<String> = manifests.keys().cloned().collect();
    // A dependency's crate is its `package` when renamed; target-specific sections count too.
    let deps_of = |doc: &toml::Table, sections: &[&str]| -> BTreeSet<String> {
        let targets = doc
            .get("target")
            .and_then(|t| t.as_table())
            .into_iter()
            .flat_map(|t| t.values().filter_map(|v| v.as_table()));
        std::iter::once(doc)
            .chain(targets)
            .flat_map(|table| {
                sections
                    .iter()
                    .filter_map(|s| table.get(*s).and_then(|t| t.as_table()))
            })
            .flat_map(|t| t.iter())
            .map(|(key, value)| {
                value
                    .get("package")
                    .and_then(|p| p.as_str())
                    .unwrap_or(key)
                    .to_owned()
            })
            .filter(|name| names.contains(name))
            .collect()
    };
    Ok(manifests
        .into_iter()
        .map(|(name, (dir, doc))| {
            let deps = deps_of(&doc, &["dependencies", "build-dependencies"]);
            let dev_deps = deps_of(&doc, &["dev-dependencies"]);
            (
                name,
                Crate {
                    dir,
                    deps,
                    dev_deps,
                },
            )
        })
        .collect())
}

/// The rows of the table under `## Layer table` in ARCHITECTURE.md: crate -> the workspace
/// crates it depends on (`-` for none).
pub fn layer_table(path: &Path) -> Result<BTreeMap<String, BTreeSet<String>>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let section = text
        .split("\n## ")
        .find(|s| s.starts_with("Layer table"))
        .with_context(|| format!("{}: no `## Layer table` section", path.display()))?;
    let mut out = BTreeMap::new();
    for line in section.lines().filter(|l| l.starts_with("| `")) {
        let cells: Vec<&str> = line.trim_matches('|').split('|').map(str::trim).collect();
        let [krate, deps, ..] = cells.as_slice() else {
            bail!(
                "{}: layer table row `{line}` has no second cell",
                path.display()
            );
        };
        let name = |s: &str| s.trim().trim_matches('`').to_owned();
        let deps: BTreeSet<String> = deps
            .split(',')
            .map(name)
            .filter(|d| !d.is_empty() && d != "-")
            .collect();
        out.insert(name(krate), deps);
    }
    if out.is_empty() {
        bail!("{}: the layer table has no rows", path.display());
    }
    Ok(out)
}

/// Compares the dependency counts each crate's README states (its "**Dependencies:** N
/// crates", and ridi's "N with `default-features = false`" after it) with `cargo tree`'s,
/// counted as the READMEs say: `cargo tree -p <crate> -e normal --prefix none --no-dedupe
/// [--no-default-features] | sort -u | wc -l`, resolved for [`COUNTED_TARGET`].
/// The platform whose dependency counts the READMEs state.
const COUNTED_TARGET: &str = "x86_64-unknown-linux-gnu";

fn check_dependency_counts(
    root: &Path,
    crates: &BTreeMap<String, Crate>,
    problems: &mut Vec<String>,
) -> Result<()> {
    const STATED: &str = "**Dependencies:** ";
    const LEAN: &str = " with `default-features = false`";
    for (name, krate) in crates {
        let Ok(readme) = std::fs::read_to_string(krate.dir.join("README.md")) else {
            continue;
        };
        let Some(at) = readme.find(STATED) else {
            continue;
        };
        // The statement's paragraph, up to the next blank line.
        let statement = &readme[at + STATED.len()..];
        let statement = statement.split("\n\n").next().unwrap_or(statement);
        let mut stated = vec![(leading_count(statement), " crates", None)];
        // "...itself included; 90 with `default-features = false`".
        if let Some(end) = statement.find(LEAN) {
            let before = &statement[..end];
            let start = before
                .rfind(|c: char| !c.is_ascii_digit())
                .map_or(0, |i| i + 1);
            stated.push((
                leading_count(&before[start..]),
                LEAN,
                Some("--no-default-features"),
            ));
        }
        for (count, what, flag) in stated {
            let (found, command) = dependency_count(root, name, flag)?;
            if count != Some(found) {
                problems.push(format!(
                    "{}/README.md: states {}{what}; `cargo {}` counts {found}",
                    krate.dir.strip_prefix(root).unwrap_or(&krate.dir).display(),
                    count.map_or("no number".to_owned(), |n| n.to_string()),
                    command,
                ));
            }
        }
    }
    Ok(())
}

/// The distinct crates of `name`'s normal dependency tree on [`COUNTED_TARGET`], itself
/// included, with `flag` (`--no-default-features`) when given; and the `cargo` arguments
/// that counted them.
fn dependency_count(root: &Path, name: &str, flag: Option<&str>) -> Result<(usize, String)> {
    let mut args = vec![
        "tree",
        "--locked",
        "--target",
        COUNTED_TARGET,
        "-p",
        name,
        "-e",
        "normal",
        "--prefix",
        "none",
        "--no-dedupe",
    ];
    args.extend(flag);
    let tree = crate::cargo_stdout(root, &args, &[])?;
    let found = tree
        .lines()
        .filter(|l| !l.is_empty())
        .collect::<BTreeSet<_>>();
    Ok((found.len(), args.join(" ")))
}

/// The number `text` starts with.
fn leading_count(text: &str) -> Option<usize> {
    let digits: String = text.chars().take_while(char::is_ascii_digit).collect();
    digits.parse().ok()
}

/// Compares each crate's workspace dependencies with its row of the table.
pub fn check_layers(
    crates: &BTreeMap<String, Crate>,
    table: &BTreeMap<String, BTreeSet<String>>,
    problems: &mut Vec<String>,
) {
    for (name, krate) in crates {
        let Some(allowed) = table.get(name) else {
            problems.push(format!(
                "{name}: not in the layer table of docs/ARCHITECTURE.md: add its row"
            ));
            continue;
        };
        for extra in krate.deps.difference(allowed) {
            problems.push(format!(
                "{name} depends on {extra}, which its row of the layer table \
                 (docs/ARCHITECTURE.md) does not allow"
            ));
        }
        for missing in allowed.difference(&krate.deps) {
            problems.push(format!(
                "{name}: the layer table says it depends on {missing}, its Cargo.toml does not: \
                 correct the table"
            ));
        }
        for dev in &krate.dev_deps {
            // A crate may dev-depend on itself, to turn on a feature for its own benches.
            if !allowed.contains(dev) && dev != "ridi-test-support" && dev != name {
                problems.push(format!(
                    "{name} has a dev-dependency on {dev}, outside its row of the layer table"
                ));
            }
        }
    }
    for name in table.keys().filter(|n| !crates.contains_key(*n)) {
        problems.push(format!(
            "the layer table of docs/ARCHITECTURE.md lists {name}, which is no workspace crate"
        ));
    }
}

/// The profile sections of a manifest: `profile.<name>` tables.
fn profiles(path: &Path) -> Result<toml::Table> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let doc: toml::Table =
        toml::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    Ok(doc
        .get("profile")
        .and_then(|p| p.as_table())
        .cloned()
        .unwrap_or_default())
}

/// The dev profile's per-crate sections against the workspace crates, and ridi-py's profiles
/// against the root's (see the module documentation).
pub fn check_profiles(
    root: &Path,
    crates: &BTreeMap<String, Crate>,
    problems: &mut Vec<String>,
) -> Result<()> {
    const PY: &str = "ridi-py";
    let ours = profiles(&root.join("Cargo.toml"))?;
    let package = |p: &toml::Table, profile: &str| -> toml::Table {
        p.get(profile)
            .and_then(|d| d.get("package"))
            .and_then(|d| d.as_table())
            .cloned()
            .unwrap_or_default()
    };
    let named = package(&ours, "dev");
    if named.contains_key("*") {
        problems.push(
            "Cargo.toml: `[profile.dev.package.\"*\"]` takes precedence over build-override: \
             set the dependencies' options in `[profile.dev]` and name the workspace's crates"
                .into(),
        );
    }
    let kinds: BTreeSet<String> = crates
        .keys()
        .filter_map(|n| named.get(n))
        .map(|t| t.to_string())
        .collect();
    if kinds.len() > 1 {
        problems.push(format!(
            "Cargo.toml: the workspace's crates have {} different dev profiles: one for all",
            kinds.len()
        ));
    }
    for name in crates.keys().filter(|n| n.as_str() != PY) {
        if !named.contains_key(name) {
            problems.push(format!(
                "Cargo.toml: no `[profile.dev.package.{name}]`: a workspace crate is compiled \
                 as the others are (opt-level 1, line tables), not as a dependency"
            ));
        }
    }
    let Some(py) = crates.get(PY) else {
        return Ok(());
    };
    let theirs = profiles(&py.dir.join("Cargo.toml"))?;
    let shown = format!("crates/{PY}/Cargo.toml");
    let without_packages = |p: &toml::Table, profile: &str| -> Option<toml::Table> {
        let mut t = p.get(profile)?.as_table()?.clone();
        t.remove("package");
        Some(t)
    };
    for profile in ["dev", "release"] {
        if without_packages(&ours, profile) != without_packages(&theirs, profile) {
            problems.push(format!(
                "{shown}: `[profile.{profile}]` is not the root Cargo.toml's: its builds would \
                 not share the workspace's artifacts"
            ));
        }
    }
    // ridi-py itself and every workspace crate it builds, as the workspace names them.
    let mut built: BTreeSet<&str> = BTreeSet::new();
    let mut todo: Vec<&str> = py.deps.iter().map(String::as_str).collect();
    while let Some(name) = todo.pop() {
        if built.insert(name) {
            todo.extend(
                crates
                    .get(name)
                    .into_iter()
                    .flat_map(|c| c.deps.iter().map(String::as_str)),
            );
        }
    }
    // ridi-py itself is compiled as the workspace's crates are (as `ridi`, say).
    let mut expected: toml::Table = named
        .iter()
        .filter(|(name, _)| !crates.contains_key(*name) || built.contains(name.as_str()))
        .map(|(name, table)| (name.clone(), table.clone()))
        .collect();
    if let Some(table) = named.get("ridi") {
        expected.insert(PY.into(), table.clone());
    }
    let py_named = package(&theirs, "dev");
    let keys: BTreeSet<&String> = expected.keys().chain(py_named.keys()).collect();
    for name in keys {
        if py_named.get(name) != expected.get(name) {
            problems.push(format!(
                "{shown}: `[profile.dev.package.{name}]` should be {} (the root Cargo.toml's, \
                 for the crates it builds)",
                match expected.get(name) {
                    Some(t) => t.to_string(),
                    None => "absent".into(),
                }
            ));
        }
    }
    Ok(())
}

/// Retired spellings in the error enums of one source file.
pub fn check_error_spellings(file: &str, text: &str, problems: &mut Vec<String>) {
    let lines: Vec<&str> = text.lines().collect();
    for (i, line) in lines.iter().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        for (name, instead) in RETIRED_NAMES {
            if contains_word(code, name) {
                problems.push(format!("{file}:{}: `{name}` is retired: {instead}", i + 1));
            }
        }
        let t = line.trim();
        // A unit or tuple variant definition (`NonFinite,`, `Shape(String),`): the workspace's
        // are struct variants that name the input.
        let shapeless = ["LengthMismatch", "NonFinite", "Shape"]
            .into_iter()
            .find(|v| {
                t.strip_prefix(v)
                    .is_some_and(|r| r == "," || r.starts_with('('))
            });
        if let Some(v) = shapeless {
            problems.push(format!(
                "{file}:{}: a unit or tuple `{v}` variant is retired: the variants are \
                 `LengthMismatch {{ what, expected, found }}` and `NonFinite {{ what, index }}`",
                i + 1
            ));
        }
        // A variant definition, not a use (`Error::LengthMismatch {` or a pattern).
        let variant = ["LengthMismatch {", "NonFinite {"]
            .into_iter()
            .find(|v| t == *v);
        let Some(variant) = variant else { continue };
        for (j, field_line) in lines.iter().enumerate().skip(i + 1) {
            let f = field_line.trim();
            if f.starts_with('}') {
                break;
            }
            if f.starts_with("//") || f.starts_with('#') {
                continue;
            }
            let Some((field, _)) = f.split_once(':') else {
                continue;
            };
            let field = field.trim().trim_start_matches("pub ").trim();
            if !ERROR_FIELDS.contains(&field) {
                problems.push(format!(
                    "{file}:{}: field `{field}` of `{}`: the fields are spelled {}",
                    j + 1,
                    variant.trim_end_matches(" {"),
                    ERROR_FIELDS.join(", ")
                ));
            }
        }
    }
}

fn contains_word(text: &str, word: &str) -> bool {
    text.match_indices(word).any(|(at, _)| {
        let before = text[..at].chars().next_back();
        let after = text[at + word.len()..].chars().next();
        let ident = |c: Option<char>| c.is_some_and(|c| c.is_alphanumeric() || c == '_');
        !ident(before) && !ident(after)
    })
}

/// `pub mod` declarations of the crate root outside [`PUBLIC_MODULES`].
fn check_public_modules(root: &Path, krate: &Crate, problems: &mut Vec<String>) -> Result<()> {
    let lib = krate.dir.join("src/lib.rs");
    if !lib.is_file() {
        return Ok(());
    }
    let name = krate
        .dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let allowed: &[&str] = PUBLIC_MODULES
        .iter()
        .find(|(c, _)| *c == name)
        .map(|(_, m)| *m)
        .unwrap_or(&[]);
    let text = std::fs::read_to_string(&lib)?;
    let shown = lib.strip_prefix(root).unwrap_or(&lib).display().to_string();
    public_modules_outside(&shown, &text, allowed, problems);
    Ok(())
}

/// Problems for the `pub mod` declarations of the crate root `text` outside `allowed`, and for
/// the modules of `allowed` it does not declare public.
fn public_modules_outside(shown: &str, text: &str, allowed: &[&str], problems: &mut Vec<String>) {
    let mut public = Vec::new();
    for (i, line) in text.lines().enumerate() {
        // `#[cfg(..)] pub mod x;` on one line too.
        let mut code = line.trim();
        while code.starts_with("#[") {
            code = code
                .find(']')
                .map_or("", |end| code[end + 1..].trim_start());
        }
        let Some(module) = code.strip_prefix("pub mod ") else {
            continue;
        };
        let module = module.trim_end_matches(';').trim_end_matches('{').trim();
        public.push(module);
        if !allowed.contains(&module) {
            problems.push(format!(
                "{shown}:{}: `pub mod {module}`: make the module private and re-export its \
                 items at the crate root (xtask/src/tidy.rs, PUBLIC_MODULES)",
                i + 1
            ));
        }
    }
    for stale in allowed.iter().filter(|m| !public.contains(m)) {
        problems.push(format!(
            "{shown}: `{stale}` is no public module: remove it from PUBLIC_MODULES \
             (xtask/src/tidy.rs), so that making it public again is caught"
        ));
    }
}

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    if !dir.is_dir() {
        return Ok(out);
    }
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).with_context(|| format!("reading {}", d.display()))? {
            let path = entry?.path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    out.sort();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_readme_dependency_count_is_cargo_trees() {
        let root = crate::workspace_root();
        let dir = tempfile::tempdir().unwrap();
        let krate = |readme: &str| {
            std::fs::write(dir.path().join("README.md"), readme).unwrap();
            let krate = Crate {
                dir: dir.path().to_owned(),
                deps: BTreeSet::new(),
                dev_deps: BTreeSet::new(),
            };
            let mut problems = Vec::new();
            check_dependency_counts(
                &root,
                &BTreeMap::from([("ridi".into(), krate)]),
                &mut problems,
            )
            .unwrap();
            problems
        };
        let count = |flag| dependency_count(&root, "ridi", flag).unwrap().0;
        let (all, lean) = (count(None), count(Some("--no-default-features")));
        let right = format!(
            "**Dependencies:** {all} crates, itself included; {lean} with \
             `default-features = false`, which"
        );
        assert_eq!(krate(&right), Vec::<String>::new());
        let problems = krate(&right.replace(&format!(" {lean} with"), " 3 with"));
        assert_eq!(problems.len(), 1, "{problems:?}");
        assert!(problems[0].ends_with(&format!("--no-default-features` counts {lean}")));
        let problems = krate(&format!("**Dependencies:** {} crates", all + 1));
        assert!(
            problems[0].contains(&format!("states {} crates;", all + 1)),
            "{problems:?}"
        );
        assert_eq!(krate("no count stated"), Vec::<String>::new());
    }

    #[test]
    fn profiles_name_every_crate_and_ridi_py_repeats_them() {
        let dir = tempfile::tempdir().unwrap();
        let member = "opt-level = 1\ndebug = \"line-tables-only\"\n";
        let root = format!(
            "[profile.release]\ndebug = 1\n[profile.dev]\nopt-level = 2\n\
             [profile.dev.package.a]\n{member}"
        );
        let own = format!("[profile.dev.package.ridi-py]\n{member}");
        let py = dir.path().join("py");
        std::fs::create_dir(&py).unwrap();
        let write = |root: &str, ridi_py: &str| {
            std::fs::write(dir.path().join("Cargo.toml"), root).unwrap();
            std::fs::write(py.join("Cargo.toml"), ridi_py).unwrap();
        };
        let krate = |dir: &Path, deps: &[&str]| Crate {
            dir: dir.to_path_buf(),
            deps: deps.iter().map(|d| d.to_string()).collect(),
            dev_deps: BTreeSet::new(),
        };
        let mut crates = BTreeMap::new();
        crates.insert("a".to_string(), krate(dir.path(), &[]));
        crates.insert("ridi".to_string(), krate(dir.path(), &["a"]));
        crates.insert("ridi-py".to_string(), krate(&py, &["ridi"]));
        let check = || {
            let mut problems = Vec::new();
            check_profiles(dir.path(), &crates, &mut problems).unwrap();
            problems
        };
        write(&root, &format!("{root}{own}"));
        assert_eq!(
            check(),
            [
                "Cargo.toml: no `[profile.dev.package.ridi]`: a workspace crate is compiled as \
                 the others are (opt-level 1, line tables), not as a dependency",
                "crates/ridi-py/Cargo.toml: `[profile.dev.package.ridi-py]` should be absent \
                 (the root Cargo.toml's, for the crates it builds)",
            ]
        );
        let fixed = format!("{root}[profile.dev.package.ridi]\n{member}");
        write(&fixed, &format!("{fixed}{own}"));
        assert!(check().is_empty(), "{:?}", check());
        // ridi-py without its own section, or with another dev profile; `package."*"` or a
        // crate of its own kind in the root.
        write(&fixed, &fixed);
        assert_eq!(check().len(), 1, "{:?}", check());
        assert!(
            check()[0].contains("`[profile.dev.package.ridi-py]` should be { "),
            "{:?}",
            check()
        );
        write(
            &fixed,
            &format!("{fixed}{own}").replace("opt-level = 2", "opt-level = 3"),
        );
        assert_eq!(check().len(), 1, "{:?}", check());
        assert!(check()[0].contains("`[profile.dev]` is not the root Cargo.toml's"));
        let star = format!("{fixed}[profile.dev.package.\"*\"]\nopt-level = 2\n");
        write(&star, &format!("{fixed}{own}"));
        let problems = check();
        assert_eq!(problems.len(), 2, "{problems:?}");
        assert!(problems[0].contains("takes precedence over build-override"));
        assert!(
            problems[1].contains("`[profile.dev.package.*]` should be { "),
            "{problems:?}"
        );
        write(
            &fixed.replacen("opt-level = 1", "opt-level = 3", 1),
            &format!("{fixed}{own}"),
        );
        assert!(
            check()
                .iter()
                .any(|p| p.contains("2 different dev profiles"))
        );
    }

    #[test]
    fn retired_error_spellings_are_named_with_file_and_line() {
        let text = "pub enum E {\n    LengthMismatch {\n        /// Which.\n        what: &'static str,\n        left: usize,\n    },\n    NotFinite,\n    Shape(String),\n    NonFinite,\n    DimensionMismatch { expected: usize },\n}\nfn f() { E::LengthMismatch {\n left: 1 }; }\n";
        let mut problems = Vec::new();
        check_error_spellings("x.rs", text, &mut problems);
        assert_eq!(
            problems,
            [
                "x.rs:5: field `left` of `LengthMismatch`: the fields are spelled what, \
                 expected, found, index, series",
                "x.rs:7: `NotFinite` is retired: the variant is `NonFinite`",
                "x.rs:8: a unit or tuple `Shape` variant is retired: the variants are \
                 `LengthMismatch { what, expected, found }` and `NonFinite { what, index }`",
                "x.rs:9: a unit or tuple `NonFinite` variant is retired: the variants are \
                 `LengthMismatch { what, expected, found }` and `NonFinite { what, index }`",
                "x.rs:10: `DimensionMismatch` is retired: the variant is `LengthMismatch { what, \
                 expected, found }`",
            ]
        );
        let mut none = Vec::new();
        check_error_spellings(
            "y.rs",
            "enum E { NonFiniteTarget }\n// NotFinite\nErr(E::NonFinite(_)),\n    ShapeOf(usize),\n",
            &mut none,
        );
        assert!(none.is_empty(), "{none:?}");
    }

    #[test]
    fn a_dependency_outside_the_table_and_a_stale_row_are_problems() {
        let krate = |deps: &[&str], dev: &[&str]| Crate {
            dir: PathBuf::new(),
            deps: deps.iter().map(|s| s.to_string()).collect(),
            dev_deps: dev.iter().map(|s| s.to_string()).collect(),
        };
        let crates = BTreeMap::from([
            ("low".to_owned(), krate(&["high"], &["ridi-test-support"])),
            ("high".to_owned(), krate(&["low"], &["other"])),
        ]);
        let set = |s: &[&str]| s.iter().map(|s| s.to_string()).collect::<BTreeSet<_>>();
        let table = BTreeMap::from([
            ("low".to_owned(), set(&[])),
            ("high".to_owned(), set(&["low", "mid"])),
            ("gone".to_owned(), set(&[])),
        ]);
        let mut problems = Vec::new();
        check_layers(&crates, &table, &mut problems);
        assert_eq!(problems.len(), 4, "{problems:#?}");
        assert!(problems[0].starts_with("high: the layer table says it depends on mid"));
        assert!(problems[1].starts_with("high has a dev-dependency on other"));
        assert!(problems[2].starts_with("low depends on high"));
        assert!(problems[3].contains("lists gone, which is no workspace crate"));
    }

    #[test]
    fn a_public_module_outside_the_list_is_named_also_behind_a_cfg() {
        let text = "mod private;\npub mod kept;\n#[cfg(feature = \"x\")] pub mod gated;\npub mod new {\n}\n";
        let mut problems = Vec::new();
        public_modules_outside("lib.rs", text, &["kept"], &mut problems);
        assert_eq!(problems.len(), 2, "{problems:#?}");
        assert!(problems[0].starts_with("lib.rs:3: `pub mod gated`"));
        assert!(problems[1].starts_with("lib.rs:4: `pub mod new`"));
    }

    #[test]
    fn a_listed_module_that_is_private_is_named_and_public_again_is_caught() {
        let mut problems = Vec::new();
        public_modules_outside(
            "lib.rs",
            "mod mat;\npub mod kept;\n",
            &["kept", "mat"],
            &mut problems,
        );
        assert_eq!(problems.len(), 1, "{problems:#?}");
        assert!(problems[0].starts_with("lib.rs: `mat` is no public module"));
        // ridi-data's MAT reader, resampling and processed layout are internal.
        let (_, data) = PUBLIC_MODULES
            .iter()
            .find(|(c, _)| *c == "ridi-data")
            .unwrap();
        let mut problems = Vec::new();
        let text = "pub mod mat;\npub mod resample;\npub mod processed;\n";
        public_modules_outside("lib.rs", text, data, &mut problems);
        for (i, module) in ["mat", "resample", "processed"].iter().enumerate() {
            let named = format!("lib.rs:{}: `pub mod {module}`", i + 1);
            assert!(
                problems.iter().any(|p| p.starts_with(&named)),
                "{problems:#?}"
            );
        }
    }

    #[test]
    fn the_workspace_is_tidy() {
        run(&crate::workspace_root()).unwrap();
    }
}
