//! `cargo xtask fuzz`: the fuzz targets of `fuzz/` without cargo-fuzz. Builds a target with a
//! nightly toolchain and the flags `cargo fuzz build` sets ([`RUSTFLAGS`]), writes its seed
//! corpus from the repository's test fixtures into `fuzz/corpus/<target>` (cargo-fuzz's layout,
//! ignored by git; libFuzzer adds what it finds there) and runs it for a given time, crashes
//! going to `fuzz/artifacts/<target>/`. `--input` replays (or with libFuzzer's
//! `-minimize_crash=1`, minimizes) saved inputs instead.
//!
//! Seeds are built in the input layout of each target (`fuzz/fuzz_targets/*.rs`): the raw and
//! Tyrex targets take their files joined with NUL bytes, the RoNIN target a 2-byte length and
//! `info.json` before the HDF5 bytes. The MAT files, which no fixture on disk holds, and the
//! Tyrex runs are written in code, by the writer and of the synthetic run of ridi-data's own
//! tests (`ridi_test_support`'s `MatWriter`, `tyrex_mocap`), small so that libFuzzer's mutations
//! stay fast.

use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail, ensure};
use ridi_test_support::{
    MatWriter, TYREX_OMEGA, TYREX_TIME_DIFF, qtm_take, tyrex_mocap, tyrex_phone_rows,
};

/// The fuzz targets' harness of the Tyrex runs, the very file, for the check that the seeds are
/// valid runs.
#[cfg(test)]
#[path = "../../fuzz/fuzz_targets/common/tyrex_run.rs"]
#[allow(dead_code, reason = "`read_run` is the fuzz targets' entry point")]
mod tyrex_run;

/// The targets of `fuzz/Cargo.toml` (its `[[bin]]` names; a test checks they agree).
pub const TARGETS: [&str; 9] = [
    "csv",
    "plain",
    "raw",
    "list",
    "mat",
    "tyrex",
    "tyrex_ios",
    "ilc",
    "ronin",
];

/// The rustc flags of `cargo fuzz build` (cargo-fuzz's `src/project.rs`, AddressSanitizer, on
/// Linux) with its `--debug-assertions`, and the overflow checks that come with them; the
/// sanitizer flag is added unless `--no-asan`. `RUSTFLAGS` from the environment are appended,
/// as cargo-fuzz does.
pub const RUSTFLAGS: &[&str] = &[
    "-Cpasses=sancov-module",
    "-Cllvm-args=-sanitizer-coverage-level=4",
    "-Cllvm-args=-sanitizer-coverage-inline-8bit-counters",
    "-Cllvm-args=-sanitizer-coverage-pc-table",
    "-Cllvm-args=-sanitizer-coverage-trace-compares",
    "-Cllvm-args=-simplifycfg-branch-fold-threshold=0",
    "-Cllvm-args=-sanitizer-coverage-stack-depth",
    "--cfg",
    "fuzzing",
    "-Clink-dead-code",
    "-Cdebug-assertions",
    "-Coverflow-checks",
    "-Ccodegen-units=1",
];

/// The libFuzzer limits of every run (before the caller's own arguments, which override them).
pub const LIMITS: &[&str] = &["-rss_limit_mb=2048", "-timeout=10"];

/// The host's target triple, as `rustc -vV` of `toolchain` reports it: sanitizer builds name
/// it explicitly, as cargo-fuzz does, so that the flags do not reach build scripts.
fn host_triple(toolchain: &str) -> Result<String> {
    let out = Command::new("rustup")
        .args(["run", toolchain, "rustc", "-vV"])
        .output()
        .with_context(|| format!("running rustup run {toolchain} rustc -vV"))?;
    ensure!(
        out.status.success(),
        "rustup run {toolchain} rustc -vV failed"
    );
    host_of(&String::from_utf8_lossy(&out.stdout))
        .map(str::to_owned)
        .context("rustc -vV names no host")
}

/// The `host: ` line of `rustc -vV`'s output.
fn host_of(version: &str) -> Option<&str> {
    version
        .lines()
        .find_map(|l| l.strip_prefix("host: "))
        .map(str::trim)
}

pub struct Options {
    /// A target of [`TARGETS`], or `all` for each in turn.
    pub target: String,
    pub seconds: u64,
    pub toolchain: String,
    pub asan: bool,
    /// Inputs to run instead of fuzzing the corpus.
    pub inputs: Vec<PathBuf>,
    /// More libFuzzer arguments.
    pub libfuzzer: Vec<String>,
}

pub fn run(opts: &Options) -> Result<()> {
    let root = xtask::workspace_root();
    let targets: Vec<&str> = if opts.target == "all" {
        TARGETS.to_vec()
    } else if let Some(t) = TARGETS.iter().find(|t| **t == opts.target) {
        vec![*t]
    } else {
        bail!(
            "no fuzz target `{}`: one of {} or `all`",
            opts.target,
            TARGETS.join(", ")
        );
    };
    ensure!(
        opts.inputs.is_empty() || targets.len() == 1,
        "--input needs a single target"
    );
    let fuzz = root.join("fuzz");
    let binaries = build(&fuzz, &targets, &opts.toolchain, opts.asan)?;
    let mut failed = Vec::new();
    for (target, binary) in targets.iter().zip(&binaries) {
        let artifacts = fuzz.join("artifacts").join(target);
        std::fs::create_dir_all(&artifacts)
            .with_context(|| format!("creating {}", artifacts.display()))?;
        let mut cmd = Command::new(binary);
        // The prefix is a folder only with its trailing slash.
        cmd.arg(format!("-artifact_prefix={}/", artifacts.display()))
            .args(LIMITS)
            .env("ASAN_OPTIONS", asan_options());
        if opts.inputs.is_empty() {
            let corpus = fuzz.join("corpus").join(target);
            let n = write_seeds(&root, target, &corpus)?;
            println!("{target}: {n} seeds in {}", corpus.display());
            cmd.arg(format!("-max_total_time={}", opts.seconds))
                .arg("-print_final_stats=1")
                .args(&opts.libfuzzer)
                .arg(&corpus);
        } else {
            cmd.args(&opts.libfuzzer).args(&opts.inputs);
        }
        let status = cmd
            .status()
            .with_context(|| format!("running {}", binary.display()))?;
        if !status.success() {
            eprintln!(
                "{target}: libFuzzer stopped with {status}; inputs that fail are in {}",
                artifacts.display()
            );
            failed.push(*target);
        }
    }
    ensure!(failed.is_empty(), "failed: {}", failed.join(", "));
    Ok(())
}

/// cargo-fuzz's AddressSanitizer options, after the caller's.
fn asan_options() -> String {
    match std::env::var("ASAN_OPTIONS") {
        Ok(o) if !o.is_empty() => format!("{o}:detect_odr_violation=0"),
        _ => "detect_odr_violation=0".into(),
    }
}

/// Builds `targets` in `fuzz` (target folder `fuzz/target`, whatever `CARGO_TARGET_DIR` says,
/// so that instrumented builds never mix with the workspace's); returns their binaries.
fn build(fuzz: &Path, targets: &[&str], toolchain: &str, asan: bool) -> Result<Vec<PathBuf>> {
    let target_dir = fuzz.join("target");
    let mut flags = RUSTFLAGS.join(" ");
    if asan {
        flags.push_str(" -Zsanitizer=address");
    }
    if let Ok(more) = std::env::var("RUSTFLAGS") {
        flags.push(' ');
        flags.push_str(&more);
    }
    let triple = host_triple(toolchain)?;
    // Through rustup, not the `CARGO` of this (stable) run.
    let mut cmd = Command::new("rustup");
    cmd.args(["run", toolchain, "cargo"])
        .args([
            "build",
            "--release",
            "--config",
            "profile.release.debug=true",
        ])
        .args(["--target", triple.as_str()])
        .current_dir(fuzz)
        .env("CARGO_TARGET_DIR", &target_dir)
        .env("RUSTFLAGS", &flags)
        .env_remove("CARGO_ENCODED_RUSTFLAGS")
        .env_remove("RUSTUP_TOOLCHAIN");
    for t in targets {
        cmd.args(["--bin", t]);
    }
    let status = cmd
        .status()
        .with_context(|| format!("running rustup run {toolchain} cargo (is rustup installed?)"))?;
    ensure!(
        status.success(),
        "the {toolchain} build of the fuzz targets failed ({status}); the build needs a \
         nightly toolchain (`rustup toolchain install nightly`), and --no-asan where \
         AddressSanitizer does not work"
    );
    let bin_dir = target_dir.join(&triple).join("release");
    Ok(targets.iter().map(|t| bin_dir.join(t)).collect())
}

/// Writes the seeds of `target` into `corpus` (created if needed) as `seed-<name>`; returns
/// how many.
pub fn write_seeds(root: &Path, target: &str, corpus: &Path) -> Result<usize> {
    std::fs::create_dir_all(corpus).with_context(|| format!("creating {}", corpus.display()))?;
    let seeds = seeds(root, target)?;
    for (name, bytes) in &seeds {
        let file = corpus.join(format!("seed-{name}"));
        std::fs::write(&file, bytes).with_context(|| format!("writing {}", file.display()))?;
    }
    Ok(seeds.len())
}

/// The seeds of `target`: (name, input bytes).
pub fn seeds(root: &Path, target: &str) -> Result<Vec<(String, Vec<u8>)>> {
    let corpus = root.join("crates/ridi-cli/tests/corpus");
    let data_tests = root.join("crates/ridi-data/tests");
    let mut out = Vec::new();
    match target {
        "csv" => {
            for f in files_in(&corpus.join("csv"))? {
                out.push((file_name(&f), gunzipped(&read(&f)?)));
            }
            for f in ["names/#hash/processed/data.csv", "ok/processed/data.csv"] {
                out.push((f.replace(['/', '#'], "_"), read(&corpus.join(f))?));
            }
        }
        "plain" => {
            for dir in dirs_in(&corpus.join("plain"))? {
                out.push((file_name(&dir), read(&dir.join("data_plain.txt"))?));
            }
        }
        "raw" => {
            for dir in dirs_in(&corpus.join("raw"))? {
                let parts = ridi_data::ridi_raw::FILES
                    .iter()
                    .map(|(name, _)| read(&dir.join(name)).unwrap_or_default())
                    .collect::<Vec<_>>();
                out.push((file_name(&dir), parts.join(&0u8)));
            }
        }
        "list" => {
            for f in files_in(&corpus.join("lists"))?
                .into_iter()
                .chain(files_in(&corpus.join("lists/csv"))?)
                .chain(files_in(&corpus.join("demo"))?)
                .chain([corpus.join("ok/list.txt")])
            {
                let name = f.strip_prefix(&corpus).unwrap_or(&f).to_string_lossy();
                out.push((name.replace('/', "_"), read(&f)?));
            }
        }
        "mat" => {
            let vars = qtm(6);
            out.push(("qtm.mat".into(), MatWriter::LE.file(&vars, false)));
            out.push(("qtm-compressed.mat".into(), MatWriter::LE.file(&vars, true)));
            out.push((
                "qtm-big-endian.mat".into(),
                MatWriter::BE.file(&vars, false),
            ));
        }
        "tyrex" => {
            let vars = qtm(MOCAP_FRAMES);
            let run = android_run();
            let mat = MatWriter::LE.file(&vars, false);
            out.push(("android".into(), nul_joined(&run, &mat)));
            let zipped = MatWriter::LE.file(&vars, true);
            out.push(("android-compressed".into(), nul_joined(&run, &zipped)));
        }
        "tyrex_ios" => {
            let mat = MatWriter::LE.file(&qtm(MOCAP_FRAMES), false);
            out.push(("ios".into(), nul_joined(&ios_run(), &mat)));
        }
        "ilc" => {
            for f in files_in(&corpus.join("ilc"))? {
                out.push((file_name(&f), read(&f)?));
            }
            // The valid file the corpus derives `nan-gyro.txt` from (its make.py).
            let nan = String::from_utf8(read(&corpus.join("ilc/nan-gyro.txt"))?)?;
            out.push((
                "ok.txt".into(),
                nan.replacen("nan", "-0.07", 1).into_bytes(),
            ));
        }
        "ronin" => {
            let ronin = data_tests.join("ronin");
            let mut runs = vec![("a000_1".to_owned(), ronin.join("a000_1"))];
            for dir in dirs_in(&ronin.join("bad"))?
                .into_iter()
                .chain(dirs_in(&corpus.join("ronin"))?)
            {
                runs.push((file_name(&dir), dir));
            }
            for (name, dir) in runs {
                let seed = ronin_input(
                    &read(&dir.join("info.json"))?,
                    &read(&dir.join("data.hdf5"))?,
                )?;
                out.push((name, seed));
            }
            let latest = read(&ronin.join("variants/latest.hdf5"))?;
            for info in ["info_gyro.json", "info_ekf.json"] {
                let seed = ronin_input(&read(&ronin.join("variants").join(info))?, &latest)?;
                out.push((format!("latest-{info}"), seed));
            }
        }
        _ => bail!("no fuzz target `{target}`"),
    }
    ensure!(
        !out.is_empty(),
        "no seeds for `{target}`: are the test fixtures there?"
    );
    Ok(out)
}

fn read(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).with_context(|| format!("reading seed {}", path.display()))
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The entries of `dir` that `keep`, sorted.
fn entries(dir: &Path, keep: impl Fn(&Path) -> bool) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).with_context(|| format!("listing {}", dir.display()))? {
        let path = e?.path();
        if keep(&path) {
            out.push(path);
        }
    }
    out.sort();
    Ok(out)
}

fn files_in(dir: &Path) -> Result<Vec<PathBuf>> {
    entries(dir, Path::is_file)
}

fn dirs_in(dir: &Path) -> Result<Vec<PathBuf>> {
    entries(dir, Path::is_dir)
}

/// `bytes` decompressed when they are a whole gzip stream, else as they are (the targets parse
/// text; a cut `.gz` is kept for its bytes).
fn gunzipped(bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    match flate2::read::MultiGzDecoder::new(bytes).read_to_end(&mut out) {
        Ok(_) => out,
        Err(_) => bytes.to_vec(),
    }
}

/// The RoNIN target's input: `info`'s length (2 bytes, little-endian), `info`, then the HDF5.
fn ronin_input(info: &[u8], hdf5: &[u8]) -> Result<Vec<u8>> {
    let len = u16::try_from(info.len()).context("info.json longer than 65535 bytes")?;
    let mut out = len.to_le_bytes().to_vec();
    out.extend(info);
    out.extend(hdf5);
    Ok(out)
}

/// The Tyrex targets' input: the run's files joined with NUL bytes, then the `.mat` after one
/// more.
fn nul_joined(files: &[String], mat: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    for f in files {
        out.extend(f.as_bytes());
        out.push(0);
    }
    out.extend(mat);
    out
}

/// Phone samples of the synthetic runs: 100 Hz over 3 s of phone time.
const PHONE_HZ: f64 = 100.0;
const PHONE_S: f64 = 3.0;
/// Mocap frames (60 Hz, from mocap time 0, so phone time 2 s to 3 s).
const MOCAP_FRAMES: usize = 60;
/// `[Time] BootTime` of the iOS run.
const BOOT: f64 = 145_406.917_9;

/// Rows of a phone file of the synthetic runs: `row(t)` at each phone time `t`.
fn phone_rows(row: impl Fn(f64) -> String) -> String {
    tyrex_phone_rows(PHONE_HZ, PHONE_S, row)
}

/// The files of an Android run (in the target's order): the phone lies flat and turns about z
/// at [`TYREX_OMEGA`].
fn android_run() -> Vec<String> {
    vec![
        phone_rows(|t| format!("{t:.9} {:.6} 0.0 9.80665", 0.1 * t.sin())),
        phone_rows(|t| format!("{t:.9} 0.0 0.0 {TYREX_OMEGA}")),
        phone_rows(|t| {
            let h = TYREX_OMEGA * t / 2.0;
            format!("{t:.9} 0.0 0.0 {:.9} {:.9} 0.17453292", h.sin(), h.cos())
        }),
        format!("  {TYREX_TIME_DIFF:e}\n"),
    ]
}

/// The files of an iOS run (in the target's order), the same motion in the authors' iOS
/// conventions: accelerometer in g with the opposite sign, times on the boot clock, the
/// attitude (w x y z) a quarter turn from east-north-up.
fn ios_run() -> Vec<String> {
    let at = |t: f64| t + BOOT;
    vec![
        phone_rows(|t| format!("{:.9} 0.0 0.0 -1.0", at(t))),
        phone_rows(|t| format!("{:.9} 0.0 0.0 {TYREX_OMEGA}", at(t))),
        phone_rows(|t| {
            let h = (TYREX_OMEGA * t - std::f64::consts::FRAC_PI_2) / 2.0;
            format!("{:.9} {:.12} 0.0 0.0 {:.12}", at(t), h.cos(), h.sin())
        }),
        format!("[Time]\nBootTime = {BOOT}"),
        format!("  {TYREX_TIME_DIFF:e}\n"),
    ]
}

/// The QTM export of `n` mocap frames of the synthetic runs' motion.
fn qtm(n: usize) -> Vec<(String, ridi_test_support::MatArray)> {
    let (positions, rotations) = tyrex_mocap(n, &[]);
    qtm_take("Take_1", 60.0, &positions, &rotations)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_host_triple_is_read_from_rustc() {
        let v = "rustc 1.97.0-nightly (abc 2026-05-19)\nbinary: rustc\nhost: aarch64-unknown-linux-gnu\nrelease: 1.97.0\n";
        assert_eq!(host_of(v), Some("aarch64-unknown-linux-gnu"));
        assert_eq!(host_of("rustc 1.0\n"), None);
    }

    /// The `[[bin]]` names of `fuzz/Cargo.toml`.
    fn fuzz_bins(root: &Path) -> Vec<String> {
        let text = std::fs::read_to_string(root.join("fuzz/Cargo.toml")).unwrap();
        let manifest: toml::Table = toml::from_str(&text).unwrap();
        manifest["bin"]
            .as_array()
            .expect("[[bin]] tables")
            .iter()
            .map(|b| b["name"].as_str().expect("a bin's name").to_owned())
            .collect()
    }

    #[test]
    fn targets_are_the_bins_of_the_fuzz_crate() {
        let mut bins = fuzz_bins(&xtask::workspace_root());
        bins.sort();
        let mut targets = TARGETS.map(str::to_owned).to_vec();
        targets.sort();
        assert_eq!(
            targets, bins,
            "TARGETS against fuzz/Cargo.toml's [[bin]] names"
        );
    }

    #[test]
    fn every_target_has_seeds() {
        let root = xtask::workspace_root();
        for t in TARGETS {
            let seeds = seeds(&root, t).unwrap();
            assert!(!seeds.is_empty(), "{t}");
            for (name, bytes) in &seeds {
                assert!(
                    bytes.len() < 128 * 1024,
                    "{t}/{name}: {} bytes",
                    bytes.len()
                );
            }
        }
    }

    #[test]
    fn tyrex_seeds_are_valid_runs_with_ground_truth() {
        let root = xtask::workspace_root();
        for (target, run) in [
            ("tyrex", &tyrex_run::ANDROID),
            ("tyrex_ios", &tyrex_run::IOS),
        ] {
            for (name, seed) in seeds(&root, target).unwrap() {
                let read = tyrex_run::try_read_run(&seed, run)
                    .unwrap_or_else(|e| panic!("{target}/{name}: {e}"));
                assert!(
                    read.sequences.iter().any(|s| s.ground_truth().is_some()),
                    "{target}/{name}: {:?}",
                    read.warnings
                );
            }
        }
    }

    #[test]
    fn ronin_seed_carries_its_info_length() {
        let input = ronin_input(b"{}", b"\x89HDF").unwrap();
        assert_eq!(input, b"\x02\x00{}\x89HDF");
    }
}
