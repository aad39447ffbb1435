//! Hostile inputs through every reader and command: the committed corpus in `tests/corpus/`
//! (small files written once by its `make.py`), the inputs made here that are too large or
//! too odd to commit (a gzip bomb, long recordings, Tyrex runs, names with control
//! characters, a FIFO, a sparse 65 MiB list, damaged copies of a model trained here), and the
//! manifest `tests/corpus/expected.txt` of what `ridi` must do with each.
//!
//! Manifest lines are `command | exit [flags] | substrings` (`#` starts a comment line):
//! - the command is split at spaces; `{corpus}`, `{gen}` (the inputs made here) and `{tmp}` (an
//!   empty folder of the case's own) are replaced, and `\n`, `\t`, `\\`, `\xHH` and `\u{H..}`
//!   escapes give the characters a name cannot be typed with;
//! - exit is the exit code, or `hang`: the command is still waiting after 0.5 s (on a FIFO, which
//!   is then given a writer so that the command ends); flags: `raw-stdout` (stdout may hold a
//!   control character), `names-twice` (the error may name an input twice);
//! - substrings, separated by ` && `, must be in stderr, or in stdout for those starting with
//!   `stdout:`, and must not be there when they start with `!`; `{corpus}`, `{gen}` and `{tmp}`
//!   are replaced in them too, nothing else: they match the escaped text (`line\nbreak`).
//!
//! Every case is also held to the rules of docs/cli.md ("Behaviour common to all commands"):
//! never a panic or a hang; a failure is exactly one `error: ` line (warnings aside) with exit
//! code 1 (2 for clap's usage errors); no Rust debug text (`Custom {`, `kind: `,
//! `UnexpectedEnd { .. }`); no control character on stdout or stderr other than line breaks;
//! no input named twice in one error; after a failure every `--out` and `--plot` is as it was
//! before (absent when it was), and no temporary (`.ridi-tmp-*`, `.ridi-staging-*`, `*.tmp*`)
//! is left in `{tmp}`, `{gen}` or the output's folder. A case marked with a flag or an
//! unexpected outcome under a `# BUG:` comment holds the current, wrong, behaviour: fixing the
//! bug fails the case, and its line is then corrected.
//!
//! Unix only (FIFOs, `/dev/zero`, names with control characters). The cases run on two
//! threads in about 8 s of a debug build; the summary line names the slowest.
//! `RIDI_CORPUS_KEEP=1` keeps the inputs made here and each case's folder to look into.

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, mpsc};
use std::time::{Duration, Instant};

mod common;

use common::{ridi, s};

/// How long a case may run before it counts as a hang.
const HANG: Duration = Duration::from_secs(20);
/// How long a case expected to hang is given before its FIFO is released.
const HANG_EXPECTED: Duration = Duration::from_millis(500);

/// The committed corpus.
fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus")
}

#[test]
#[cfg_attr(
    not(unix),
    ignore = "FIFOs, /dev/zero and names with control characters are Unix's"
)]
fn every_hostile_input_gets_its_expected_outcome() {
    let started = Instant::now();
    let root = tempfile::tempdir().unwrap();
    // RIDI_CORPUS_KEEP=1 keeps the inputs made here and each case's folder, and says where.
    let root = if std::env::var_os("RIDI_CORPUS_KEEP").is_some() {
        let kept = root.keep();
        eprintln!("keeping {}", kept.display());
        Root::Kept(kept)
    } else {
        Root::Temporary(root)
    };
    let root = &root;
    let gen_dir = root.path().join("gen");
    generate(&gen_dir);
    let generated = started.elapsed();
    let manifest = std::fs::read_to_string(corpus().join("expected.txt")).unwrap();
    let cases: Vec<Case> = manifest
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .map(|(i, l)| Case::parse(i + 1, l))
        .collect();
    let places = Places {
        corpus: s(&corpus()).to_owned(),
        generated: s(&gen_dir).to_owned(),
    };
    // Two workers take the cases in turn; those on a FIFO run alone afterwards, since giving
    // one FIFO a writer ends every wait on it.
    let (fifo, other): (Vec<_>, Vec<_>) = cases
        .iter()
        .enumerate()
        .partition(|(_, c)| c.exit == Exit::Hang || c.args.iter().any(|a| a.contains("fifo")));
    let results = Mutex::new(Vec::new());
    let run_one = |k: usize, case: &Case| {
        let tmp = root.path().join(format!("case-{k}"));
        std::fs::create_dir(&tmp).unwrap();
        let t0 = Instant::now();
        let result = case.check(&places, &tmp);
        results
            .lock()
            .unwrap()
            .push((case.line, t0.elapsed(), result));
    };
    let next = AtomicUsize::new(0);
    std::thread::scope(|scope| {
        for _ in 0..2 {
            scope.spawn(|| {
                while let Some(&(k, case)) = other.get(next.fetch_add(1, Ordering::Relaxed)) {
                    run_one(k, case);
                }
            });
        }
    });
    for (k, case) in fifo {
        run_one(k, case);
    }
    let mut results = results.into_inner().unwrap();
    results.sort_by_key(|(line, ..)| *line);
    let ran = results.len();
    let mut failures: Vec<String> = results
        .iter()
        .filter_map(|(_, _, r)| r.as_ref().err().cloned())
        .collect();
    results.sort_by_key(|r| std::cmp::Reverse(r.1));
    let slowest: Vec<String> = results
        .iter()
        .take(5)
        .map(|(line, t, _)| format!("expected.txt:{line} {:.2} s", t.as_secs_f64()))
        .collect();
    let uncovered = uncovered_corpus_files(&cases, &places);
    if !uncovered.is_empty() {
        failures.push(format!(
            "corpus files no case of expected.txt reads (add cases, or remove them from \
             make.py): {uncovered:?}"
        ));
    }
    eprintln!(
        "{ran} cases in {:.1} s (inputs made in {:.1} s); slowest: {}",
        started.elapsed().as_secs_f64(),
        generated.as_secs_f64(),
        slowest.join(", ")
    );
    assert!(
        failures.is_empty(),
        "{} of {ran} cases failed:\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}

/// The folder of a run: removed at the end, or kept to look into.
enum Root {
    Temporary(tempfile::TempDir),
    Kept(PathBuf),
}

impl Root {
    fn path(&self) -> &Path {
        match self {
            Root::Temporary(t) => t.path(),
            Root::Kept(p) => p,
        }
    }
}

// ---- the manifest --------------------------------------------------------------------------

/// The folders a manifest line names with placeholders.
struct Places {
    corpus: String,
    generated: String,
}

impl Places {
    fn expand(&self, text: &str, tmp: &Path) -> String {
        text.replace("{corpus}", &self.corpus)
            .replace("{gen}", &self.generated)
            .replace("{tmp}", s(tmp))
    }
}

/// What a case must end with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Exit {
    Code(i32),
    /// Still running after [`HANG_EXPECTED`] (a bug kept in the manifest until it is fixed).
    Hang,
}

/// One line of the manifest.
struct Case {
    line: usize,
    text: String,
    args: Vec<String>,
    exit: Exit,
    raw_stdout: bool,
    names_twice: bool,
    says: Vec<String>,
}

impl Case {
    fn parse(line: usize, text: &str) -> Case {
        let mut fields = text.splitn(3, '|').map(str::trim);
        let (Some(command), Some(outcome)) = (fields.next(), fields.next()) else {
            panic!("expected.txt:{line}: expected `command | exit | substrings`: {text}");
        };
        let says = fields.next().unwrap_or("");
        let mut outcome = outcome.split_whitespace();
        let exit = match outcome.next() {
            Some("hang") => Exit::Hang,
            Some(code) => Exit::Code(
                code.parse()
                    .unwrap_or_else(|_| panic!("expected.txt:{line}: exit code `{code}`")),
            ),
            None => panic!("expected.txt:{line}: no exit code"),
        };
        let flags: Vec<&str> = outcome.collect();
        for flag in &flags {
            assert!(
                ["raw-stdout", "names-twice"].contains(flag),
                "expected.txt:{line}: unknown flag `{flag}`"
            );
        }
        Case {
            line,
            text: text.to_owned(),
            args: command.split_whitespace().map(unescape).collect(),
            exit,
            raw_stdout: flags.contains(&"raw-stdout"),
            names_twice: flags.contains(&"names-twice"),
            says: says
                .split(" && ")
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .map(str::to_owned)
                .collect(),
        }
    }

    /// Runs the case in its own empty folder `tmp`; the error says what went wrong, with the
    /// command and its output.
    fn check(&self, places: &Places, tmp: &Path) -> Result<(), String> {
        let args: Vec<String> = self.args.iter().map(|a| places.expand(a, tmp)).collect();
        let outputs: Vec<PathBuf> = args
            .windows(2)
            .filter(|w| w[0] == "--out" || w[0] == "--plot")
            .map(|w| PathBuf::from(&w[1]))
            .collect();
        let before: Vec<Option<Snapshot>> = outputs.iter().map(|p| snapshot(p)).collect();
        let (outcome, took) = run(&args, self.exit == Exit::Hang, places);
        let mut problems = Vec::new();
        let (out, hung) = match outcome {
            Ran::Finished(out) => (Some(out), false),
            Ran::Released(out) => (Some(out), true),
            Ran::Hung => (None, true),
        };
        match (self.exit, hung) {
            (Exit::Hang, false) => problems.push(format!(
                "expected to hang (a known bug), but it finished in {:.1} s: correct the case",
                took.as_secs_f64()
            )),
            (Exit::Code(_), true) => problems.push(format!(
                "still running after {} s: it hangs",
                took.as_secs()
            )),
            _ => {}
        }
        let Some(out) = out else {
            return Err(self.report(&args, None, &problems));
        };
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        let code = out.status.code();
        if let Exit::Code(want) = self.exit
            && code != Some(want)
        {
            problems.push(format!("exit code {code:?}, expected {want}"));
        }
        if code == Some(101) || stderr.contains("panicked") || stderr.contains("RUST_BACKTRACE") {
            problems.push("it panicked".into());
        }
        if code.is_none() {
            problems.push("killed by a signal (an abort?)".into());
        }
        let errors: Vec<&str> = stderr
            .lines()
            .filter(|l| l.starts_with("error: "))
            .collect();
        match code {
            Some(0) if !errors.is_empty() => problems.push("an error line on success".into()),
            Some(1) | None if errors.len() != 1 => problems.push(format!(
                "{} `error: ` lines, expected exactly one",
                errors.len()
            )),
            Some(1) => {
                for l in stderr.lines() {
                    if !["error: ", "warning: ", "no --model: "]
                        .iter()
                        .any(|p| l.starts_with(p))
                    {
                        problems.push(format!("a stderr line that is no error or warning: {l}"));
                    }
                }
            }
            _ => {}
        }
        if let Some(debug) = debug_text(&stderr) {
            problems.push(format!("Rust debug text in stderr: `{debug}`"));
        }
        if let Some(c) = control_char(&stderr) {
            problems.push(format!("a raw control character {c:?} in stderr"));
        }
        match control_char(&stdout) {
            Some(c) if !self.raw_stdout => {
                problems.push(format!("a raw control character {c:?} in stdout"))
            }
            None if self.raw_stdout => problems.push(
                "no raw control character in stdout any more (flag raw-stdout): correct the case"
                    .into(),
            ),
            _ => {}
        }
        if code == Some(1) {
            let twice: Vec<&String> = args
                .iter()
                .filter(|a| a.contains('/'))
                .filter(|a| {
                    let shown = ridi::data::shown(Path::new(a.as_str())).to_string();
                    errors.iter().any(|e| names(e, &shown) > 1)
                })
                .collect();
            match (twice.is_empty(), self.names_twice) {
                (false, false) => problems.push(format!("the error names {twice:?} twice")),
                (true, true) => problems.push(
                    "the error no longer names an input twice (flag names-twice): correct the \
                     case"
                        .into(),
                ),
                _ => {}
            }
        }
        for want in &self.says {
            let want = places.expand(want, tmp);
            let (absent, want) = match want.strip_prefix('!') {
                Some(w) => (true, w.to_owned()),
                None => (false, want),
            };
            let (text, want) = match want.strip_prefix("stdout:") {
                Some(w) => (&stdout, w.trim_start().to_owned()),
                None => (&stderr, want),
            };
            match (text.contains(&want), absent) {
                (false, false) => problems.push(format!("does not say `{want}`")),
                (true, true) => problems.push(format!("says `{want}`, which it should not")),
                _ => {}
            }
        }
        for (path, before) in outputs.iter().zip(&before) {
            let after = snapshot(path);
            if code == Some(0) {
                if after.is_none() {
                    problems.push(format!("succeeded without writing {}", path.display()));
                }
            } else if after != *before {
                problems.push(format!(
                    "failed, yet {} changed ({})",
                    path.display(),
                    if before.is_none() {
                        "it was absent"
                    } else {
                        "it existed"
                    }
                ));
            }
        }
        let mut folders = vec![tmp.to_path_buf(), PathBuf::from(&places.generated)];
        folders.extend(
            outputs
                .iter()
                .filter_map(|p| p.parent().map(Path::to_path_buf)),
        );
        for litter in temporaries(&folders) {
            problems.push(format!("left {}", litter.display()));
        }
        if problems.is_empty() {
            Ok(())
        } else {
            Err(self.report(&args, Some(&out), &problems))
        }
    }

    fn report(&self, args: &[String], out: Option<&Output>, problems: &[String]) -> String {
        let mut text = format!(
            "expected.txt:{}: {}\n  $ ridi {}\n",
            self.line,
            self.text,
            args.iter()
                .map(|a| format!("{a:?}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
        for p in problems {
            let _ = writeln!(text, "  - {p}");
        }
        if let Some(out) = out {
            let _ = writeln!(text, "  exit code: {:?}", out.status.code());
            for (name, bytes) in [("stderr", &out.stderr), ("stdout", &out.stdout)] {
                let _ = writeln!(text, "  {name}:");
                for l in String::from_utf8_lossy(bytes).lines().take(12) {
                    let _ = writeln!(text, "    {}", l.escape_debug());
                }
            }
        }
        text
    }
}

/// `\n`, `\t`, `\\`, `\xHH` (the character U+00HH) and `\u{H..}` in a manifest argument.
fn unescape(arg: &str) -> String {
    let mut out = String::new();
    let mut chars = arg.chars();
    while let Some(c) = chars.next() {
        if c != '\\' {
            out.push(c);
            continue;
        }
        match chars.next() {
            Some('n') => out.push('\n'),
            Some('t') => out.push('\t'),
            Some('\\') => out.push('\\'),
            Some('x') => {
                let hex: String = chars.by_ref().take(2).collect();
                out.push(char::from(u8::from_str_radix(&hex, 16).unwrap()));
            }
            Some('u') => {
                assert_eq!(chars.next(), Some('{'), "{arg}");
                let hex: String = chars.by_ref().take_while(|&c| c != '}').collect();
                out.push(char::from_u32(u32::from_str_radix(&hex, 16).unwrap()).unwrap());
            }
            other => panic!("unknown escape \\{other:?} in {arg}"),
        }
    }
    out
}

// ---- running and judging -------------------------------------------------------------------

/// How a run ended.
enum Ran {
    Finished(Output),
    /// Waiting on a FIFO until [`release_fifos`] gave it a writer or reader.
    Released(Output),
    Hung,
}

/// Runs `ridi args` on a thread, so that a hang is a failure rather than a stuck test. A run
/// expected to hang gets [`HANG_EXPECTED`], a run that is not [`HANG`]; then the FIFOs in `{gen}`
/// get a writer and a reader, which ends a wait in `open`.
fn run(args: &[String], expect_hang: bool, places: &Places) -> (Ran, Duration) {
    let started = Instant::now();
    let (send, receive) = mpsc::channel();
    let owned = args.to_vec();
    std::thread::spawn(move || {
        let args: Vec<&str> = owned.iter().map(String::as_str).collect();
        let _ = send.send(ridi(&args));
    });
    let wait = if expect_hang { HANG_EXPECTED } else { HANG };
    if let Ok(out) = receive.recv_timeout(wait) {
        return (Ran::Finished(out), started.elapsed());
    }
    let took = started.elapsed();
    let deadline = Instant::now() + Duration::from_secs(10);
    while Instant::now() < deadline {
        release_fifos(Path::new(&places.generated));
        if let Ok(out) = receive.recv_timeout(Duration::from_millis(100)) {
            return (Ran::Released(out), took);
        }
    }
    (Ran::Hung, took)
}

/// Opens every FIFO in `dir` without blocking, for writing (which ends a reader's wait in
/// `open`) and for reading (a writer's), and closes it at once: the waiting side then reads an
/// end of file.
#[cfg(unix)]
fn release_fifos(dir: &Path) {
    use std::os::unix::fs::{FileTypeExt as _, OpenOptionsExt as _};
    for entry in std::fs::read_dir(dir).unwrap() {
        let entry = entry.unwrap();
        if entry.file_type().unwrap().is_fifo() {
            let mut open = std::fs::OpenOptions::new();
            open.custom_flags(libc::O_NONBLOCK);
            let _ = open.clone().write(true).open(entry.path());
            let _ = open.read(true).open(entry.path());
        }
    }
}

#[cfg(not(unix))]
fn release_fifos(_: &Path) {}

/// What a path holds, to tell whether a failed command changed it.
#[derive(Debug, PartialEq, Eq)]
enum Snapshot {
    File(Vec<u8>),
    Folder(BTreeSet<String>),
    Other,
}

fn snapshot(path: &Path) -> Option<Snapshot> {
    let meta = std::fs::symlink_metadata(path).ok()?;
    Some(if meta.is_file() {
        Snapshot::File(std::fs::read(path).unwrap_or_default())
    } else if meta.is_dir() {
        let mut names = BTreeSet::new();
        list_tree(path, path, &mut names);
        Snapshot::Folder(names)
    } else {
        Snapshot::Other
    })
}

/// Every path under `dir`, relative to `base`.
fn list_tree(base: &Path, dir: &Path, names: &mut BTreeSet<String>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        names.insert(
            path.strip_prefix(base)
                .unwrap()
                .to_string_lossy()
                .into_owned(),
        );
        if entry.file_type().is_ok_and(|t| t.is_dir()) {
            list_tree(base, &path, names);
        }
    }
}

/// Temporaries left in `folders` (the case's own folder searched whole, the others their top
/// level): the names the atomic writers and staging folders use.
fn temporaries(folders: &[PathBuf]) -> Vec<PathBuf> {
    let mut found = Vec::new();
    for (i, folder) in folders.iter().enumerate() {
        let mut names = BTreeSet::new();
        if i == 0 {
            list_tree(folder, folder, &mut names);
        } else if let Ok(entries) = std::fs::read_dir(folder) {
            names.extend(
                entries
                    .flatten()
                    .map(|e| e.file_name().to_string_lossy().into_owned()),
            );
        }
        for name in names {
            let file = name.rsplit('/').next().unwrap_or(&name);
            if file.starts_with(".ridi-tmp-")
                || file.starts_with(".ridi-staging-")
                || (file.starts_with('.') && file.contains(".tmp"))
            {
                found.push(folder.join(&name));
            }
        }
    }
    found
}

/// Rust's debug formatting in `text`, if any: a struct (`Custom { kind: .. }`), an `Os`
/// error, an `Option` or `Result` variant.
fn debug_text(text: &str) -> Option<String> {
    for marker in [
        "Custom {", "kind: ", "Os {", "Some(", "Ok(", "Err(", "None,",
    ] {
        if text.contains(marker) {
            return Some(marker.to_owned());
        }
    }
    // `Name { field: ... }`: a word right before ` { `.
    text.match_indices(" { ").find_map(|(i, _)| {
        let word: String = text[..i]
            .chars()
            .rev()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        (!word.is_empty()).then(|| text[i - word.len()..(i + 8).min(text.len())].to_owned())
    })
}

/// How many times `line` names the path `path`: not as the start of a longer path or name.
fn names(line: &str, path: &str) -> usize {
    line.match_indices(path)
        .filter(|(i, _)| {
            line[i + path.len()..]
                .chars()
                .next()
                .is_none_or(|c| !(c.is_alphanumeric() || "/._-".contains(c)))
        })
        .count()
}

/// The first control character in `text` other than a line break.
fn control_char(text: &str) -> Option<char> {
    text.chars().find(|c| c.is_control() && *c != '\n')
}

/// Committed corpus files that no case reads: neither the file nor a folder holding it (below
/// the corpus root) is an argument.
fn uncovered_corpus_files(cases: &[Case], places: &Places) -> Vec<String> {
    let root = corpus();
    let mut named = BTreeSet::new();
    for case in cases {
        for arg in &case.args {
            if arg.contains("{corpus}/") {
                let path = arg.replace("{corpus}", &places.corpus);
                named.insert(PathBuf::from(path.trim_end_matches('/')));
            }
        }
    }
    let mut files = BTreeSet::new();
    list_tree(&root, &root, &mut files);
    files
        .into_iter()
        .filter(|f| {
            root.join(f).is_file()
                && !["make.py", "expected.txt", ".gitattributes"].contains(&f.as_str())
        })
        .filter(|f| {
            !root
                .join(f)
                .ancestors()
                .take_while(|a| *a != root)
                .any(|a| named.contains(a))
        })
        .collect()
}

// ---- the inputs made at test time ----------------------------------------------------------

/// Writes into `dir` what the manifest names `{gen}/...`.
fn generate(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    let corpus = corpus();
    let reference = std::fs::read(corpus.join("ok/processed/data.csv")).unwrap();

    // A gzip bomb: 80 MiB of line breaks in 81 KB, over the 64 MiB every gzip input may
    // reach; as a recording of each text format and as a list.
    let bomb = gzip_bomb(80 << 20);
    for name in ["bomb/data.csv.gz", "bomb/data_plain.txt.gz", "bomb-list.gz"] {
        write(&dir.join(name), &bomb);
    }
    write(
        &dir.join("bomb-listed.txt"),
        format!("{},Texting\n", s(&dir.join("bomb/data.csv.gz"))).as_bytes(),
    );

    // A long recording (100 s), and the same with a NaN on its last row.
    let long = walk_csv(20_000, None);
    write(&dir.join("long/data.csv"), long.as_bytes());
    write(
        &dir.join("long-nan-end/data.csv"),
        walk_csv(20_000, Some(19_999)).as_bytes(),
    );

    // Names a list line cannot hold, with control characters, as recordings; and lists of
    // them.
    for name in [
        "line\nbreak",
        "esc\x1b[31mred",
        "csi\u{9b}31m",
        "del\x7f",
        "bell\x07",
        "tab\tx",
        " lead",
    ] {
        write(
            &dir.join("names").join(name).join("processed/data.csv"),
            &reference,
        );
    }
    write(&dir.join("names/esc-list.txt"), b"esc\x1b[31mred,Texting\n");
    write(
        &dir.join("label-esc.txt"),
        format!("{},Tex\x1bting\n", s(&corpus.join("ok"))).as_bytes(),
    );

    // Inputs that are no regular file: a FIFO as recording, model and list, and a list that
    // lists one; a list file larger than 64 MiB (sparse: no disk space).
    for name in ["fifo.csv", "fifo.ridi", "fifo-list.txt", "fifo"] {
        make_fifo(&dir.join(name));
    }
    write(
        &dir.join("fifo-listed.txt"),
        format!("{},Texting\n", s(&dir.join("fifo.csv"))).as_bytes(),
    );
    std::fs::File::create(dir.join("huge-list.txt"))
        .unwrap()
        .set_len(65 << 20)
        .unwrap();

    // Outputs that would overwrite their input.
    write(&dir.join("self/data.csv"), &reference);
    write(&dir.join("self/list.txt"), b"data.csv,Texting\n");

    // Tyrex runs of 10.5 s (a part shorter than 10 s is dropped): without any Qualisys
    // file, and with one that is a folder, a FIFO, empty, or no MAT file past its header.
    let mat_header =
        ridi_test_support::MatWriter::LE.header("MATLAB 5.0 MAT-file, Platform: GLNXA64");
    let mut noise = ridi_test_support::SplitMix64(7);
    let garbage: Vec<u8> = (0..400).map(|_| noise.next_u64() as u8).collect();
    // A compressed element (type 15) that declares 2 GB.
    let huge = [15u32.to_le_bytes(), 0x7fff_fff0u32.to_le_bytes()].concat();
    for (root, mat) in [
        ("no-qualisys", Mat::None),
        ("mat-folder", Mat::Folder),
        ("mat-fifo", Mat::Fifo),
        ("mat-empty", Mat::Bytes(Vec::new())),
        (
            "mat-garbage",
            Mat::Bytes([&mat_header[..], &garbage].concat()),
        ),
        (
            "mat-huge",
            Mat::Bytes([&mat_header[..], &huge, b"x\x9c"].concat()),
        ),
    ] {
        let root = dir.join("tyrex").join(root);
        let run = root.join("datasets/android/Ann_Nexus5_NoDist_Texting");
        tyrex_run(&run, 2100);
        let mat_path = root.join("datasets/qualisys/Ann_Nexus5_NoDist_Texting.mat");
        match &mat {
            Mat::None => {}
            Mat::Folder => std::fs::create_dir_all(&mat_path).unwrap(),
            Mat::Fifo => {
                std::fs::create_dir_all(mat_path.parent().unwrap()).unwrap();
                make_fifo(&mat_path);
            }
            Mat::Bytes(bytes) => write(&mat_path, bytes),
        }
        if !matches!(mat, Mat::None) {
            // With ground truth, the run needs its clock offset to the motion capture.
            write(&run.join("timeAlignment.txt"), b"0.0\n");
        }
    }

    // RoNIN: ridi-data's fixture, as it is and with its data.hdf5 cut in half.
    let fixture = ridi_test_support::workspace_root().join("crates/ridi-data/tests/ronin/a000_1");
    for (name, cut) in [("ronin/ok", false), ("ronin/hdf5-cut", true)] {
        for file in ["data.hdf5", "info.json"] {
            let mut bytes = std::fs::read(fixture.join(file)).unwrap();
            if cut && file == "data.hdf5" {
                bytes.truncate(bytes.len() / 2);
            }
            write(&dir.join(name).join(file), &bytes);
        }
    }

    // Models trained here on the reference walk (Nyström, version 8, and exact, version 7),
    // and damaged copies: each way the codec checks, on a real payload.
    let ok_list = corpus.join("lists/ok.txt");
    for (name, extra) in [
        (
            "tiny.ridi",
            &["--solver", "nystrom", "--landmarks", "8"][..],
        ),
        ("tiny-exact.ridi", &[][..]),
    ] {
        let out = dir.join(name);
        let mut args = vec!["train", "--list", s(&ok_list), "--out", s(&out)];
        args.extend(["--grid", "none", "--step", "2"]);
        args.extend(extra);
        let run = ridi(&args);
        assert!(run.status.success(), "{}", ridi_test_support::stderr(&run));
    }
    let label_model = dir.join("label-esc.ridi");
    let run = ridi(&[
        "train",
        "--list",
        s(&dir.join("label-esc.txt")),
        "--out",
        s(&label_model),
        "--grid",
        "none",
        "--step",
        "2",
    ]);
    assert!(run.status.success(), "{}", ridi_test_support::stderr(&run));
    let tiny = std::fs::read(dir.join("tiny.ridi")).unwrap();
    let exact = std::fs::read(dir.join("tiny-exact.ridi")).unwrap();
    let mut flipped = tiny.clone();
    flipped[tiny.len() / 2] ^= 0x01;
    let as_version = |bytes: &[u8], version: u32| {
        let mut b = bytes.to_vec();
        b[8..12].copy_from_slice(&version.to_le_bytes());
        b
    };
    // The payload one byte short, with a header (length, checksum) that says so.
    let payload = &tiny[24..tiny.len() - 1];
    let mut cut_payload = tiny[..24].to_vec();
    cut_payload[12..20].copy_from_slice(&(payload.len() as u64).to_le_bytes());
    cut_payload[20..24].copy_from_slice(&crc32(payload).to_le_bytes());
    cut_payload.extend_from_slice(payload);
    for (name, bytes) in [
        ("tiny-half.ridi", tiny[..tiny.len() / 2].to_vec()),
        ("tiny-header.ridi", tiny[..24].to_vec()),
        ("tiny-flipped.ridi", flipped),
        ("tiny-trailing.ridi", [&tiny[..], b"\n"].concat()),
        ("tiny-payload-cut.ridi", cut_payload),
        ("tiny-as-v7.ridi", as_version(&tiny, 7)),
        ("exact-as-v8.ridi", as_version(&exact, 8)),
        ("tiny-future.ridi", as_version(&tiny, 9)),
        ("tiny-no-suffix", tiny.clone()),
    ] {
        write(&dir.join(name), &bytes);
    }
}

#[cfg(unix)]
fn make_fifo(path: &Path) {
    let c_path = std::ffi::CString::new(s(path)).unwrap();
    // SAFETY: a valid C string; mkfifo has no other precondition.
    let made = unsafe { libc::mkfifo(c_path.as_ptr(), 0o644) };
    assert_eq!(made, 0, "mkfifo {}", path.display());
}

/// Elsewhere no FIFO: the cases that need one are marked `unix`.
#[cfg(not(unix))]
fn make_fifo(_: &Path) {}

/// A Tyrex run's Qualisys file.
enum Mat {
    None,
    Folder,
    Fifo,
    Bytes(Vec<u8>),
}

fn write(path: &Path, bytes: &[u8]) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, bytes).unwrap();
}

/// The reference walk of `make.py` (`frame`), `n` frames of it as a RIDI `data.csv`, with
/// `NaN` as `gyro_x` of frame `nan_at`.
fn walk_csv(n: usize, nan_at: Option<usize>) -> String {
    const G: f64 = 9.806_65;
    const YAW_RATE: f64 = 0.5;
    let mut text = String::from(
        ",time,gyro_x,gyro_y,gyro_z,acce_x,acce_y,acce_z,linacce_x,linacce_y,linacce_z,\
         grav_x,grav_y,grav_z,magnet_x,magnet_y,magnet_z,pos_x,pos_y,pos_z,\
         ori_w,ori_x,ori_y,ori_z,rv_w,rv_x,rv_y,rv_z\n",
    );
    for i in 0..n {
        let t = i as f64 * 0.005;
        let yaw = YAW_RATE * t;
        let (qw, qz) = ((yaw / 2.0).cos(), (yaw / 2.0).sin());
        let bounce = 2.0 * std::f64::consts::PI * 2.0 * t;
        let lin = [0.4 * bounce.sin(), 0.3 * bounce.cos(), 1.2 * bounce.sin()];
        let radius = 1.0 / YAW_RATE;
        let gyro_x = if nan_at == Some(i) { "NaN" } else { "0" };
        let _ = writeln!(
            text,
            "{i},{},{gyro_x},0,{YAW_RATE},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},0,0,{G},0,0,0,\
             {:.6},{:.6},1.2,{qw:.7},0,0,{qz:.7},{qw:.7},0,0,{qz:.7}",
            10_000_000_000_i64 + 5_000_000 * i as i64,
            lin[0],
            lin[1],
            lin[2] + G,
            lin[0],
            lin[1],
            lin[2],
            radius * yaw.sin(),
            radius * (1.0 - yaw.cos()),
        );
    }
    text
}

/// A Tyrex Android run folder `run` of a phone lying still for `frames` frames at 200 Hz.
fn tyrex_run(run: &Path, frames: usize) {
    for (file, values) in [
        ("accelerometer.txt", "0.0 0.0 9.80665"),
        ("gyroscope-calibrated.txt", "0.0 0.0 0.0"),
        ("rotation-vector.txt", "0.0 0.0 0.0 1.0 0.17"),
    ] {
        let text = ridi_test_support::tyrex_phone_rows(200.0, frames as f64 / 200.0, |t| {
            format!("{t:.9} {values}")
        });
        write(&run.join(file), text.as_bytes());
    }
}

/// A gzip file of `size` line breaks or a little more (a line break, then matches of 258 bytes
/// at distance 1), 2 bits per 258 bytes: a dynamic Huffman block whose length code 285 and
/// distance code 0 have 1-bit codes, a ratio of about 1000 (the most deflate allows), which no
/// encoder at hand in this test makes.
fn gzip_bomb(size: usize) -> Vec<u8> {
    let matches = size.div_ceil(258);
    let mut w = BitWriter::default();
    w.bits(1, 1); // the last block
    w.bits(2, 2); // dynamic Huffman codes
    w.bits(286 - 257, 5); // literal/length codes 0..=285
    w.bits(2 - 1, 5); // distance codes 0..=1
    w.bits(18 - 4, 4); // code length codes, in their order, up to that of symbol 1
    // The code length code lengths in the order 16 17 18 0 8 7 9 6 10 5 11 4 12 3 13 2 14 1:
    // symbols 1, 2, 17 and 18 (the only ones used) have 2 bits.
    for len in [0, 2, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 2] {
        w.bits(len, 3);
    }
    // Code length codes (canonical, by symbol): 1 -> 00, 2 -> 01, 17 -> 10, 18 -> 11.
    let (one, two, zeros_3_10, zeros_11_138) = (0b00, 0b01, 0b10, 0b11);
    w.code(zeros_3_10, 2); // literals 0..=9 unused
    w.bits(10 - 3, 3);
    w.code(two, 2); // literal 10, the line break: 2 bits
    w.code(zeros_11_138, 2); // literals 11..=255 unused (245 = 138 + 107)
    w.bits(138 - 11, 7);
    w.code(zeros_11_138, 2);
    w.bits(107 - 11, 7);
    w.code(two, 2); // 256, the end of the block: 2 bits
    w.code(zeros_11_138, 2); // lengths 257..=284 unused
    w.bits(28 - 11, 7);
    w.code(one, 2); // 285, a match of 258 bytes: 1 bit
    w.code(one, 2); // distance code 0 (distance 1): 1 bit
    w.code(one, 2); // distance code 1, unused, completing the distance code
    // Literal/length codes (canonical): 285 -> 0, 10 -> 10, 256 -> 11; distance 0 -> 0.
    w.code(0b10, 2);
    for _ in 0..matches {
        w.code(0, 1);
        w.code(0, 1);
    }
    w.code(0b11, 2);
    let deflate = w.finish();
    let total = 1 + 258 * matches;
    let mut crc = Crc32::default();
    let chunk = vec![b'\n'; 1 << 16];
    let mut left = total;
    while left > 0 {
        let n = left.min(chunk.len());
        crc.update(&chunk[..n]);
        left -= n;
    }
    let mut out = vec![0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 2, 255];
    out.extend(deflate);
    out.extend(crc.value().to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out
}

/// Deflate's bit order: values least significant bit first, Huffman codes most significant
/// bit first.
#[derive(Default)]
struct BitWriter {
    out: Vec<u8>,
    acc: u64,
    n: u32,
}

impl BitWriter {
    fn bits(&mut self, value: u64, count: u32) {
        self.acc |= value << self.n;
        self.n += count;
        while self.n >= 8 {
            self.out.push(self.acc as u8);
            self.acc >>= 8;
            self.n -= 8;
        }
    }

    fn code(&mut self, code: u64, len: u32) {
        let reversed = (0..len).fold(0, |r, i| (r << 1) | ((code >> i) & 1));
        self.bits(reversed, len);
    }

    fn finish(mut self) -> Vec<u8> {
        if self.n > 0 {
            self.out.push(self.acc as u8);
        }
        self.out
    }
}

/// CRC-32 (IEEE, reflected), as gzip and the model file use.
struct Crc32 {
    table: [u32; 256],
    crc: u32,
}

impl Default for Crc32 {
    fn default() -> Self {
        let mut table = [0u32; 256];
        for (i, t) in table.iter_mut().enumerate() {
            *t = (0..8).fold(i as u32, |c, _| {
                if c & 1 == 1 {
                    0xedb8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                }
            });
        }
        Crc32 {
            table,
            crc: 0xffff_ffff,
        }
    }
}

impl Crc32 {
    fn update(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.crc = self.table[((self.crc ^ u32::from(b)) & 0xff) as usize] ^ (self.crc >> 8);
        }
    }

    fn value(&self) -> u32 {
        !self.crc
    }
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = Crc32::default();
    crc.update(bytes);
    crc.value()
}

#[test]
fn the_bomb_is_a_gzip_file_of_line_breaks() {
    // Small enough to check by hand here; the test's own is 80 MiB.
    let bomb = gzip_bomb(258 * 4);
    assert_eq!(&bomb[..3], &[0x1f, 0x8b, 8]);
    let n = bomb.len();
    assert_eq!(
        u32::from_le_bytes(bomb[n - 4..].try_into().unwrap()),
        1 + 258 * 4
    );
    assert_eq!(crc32(b"123456789"), 0xcbf4_3926);
}
