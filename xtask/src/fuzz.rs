//! `cargo xtask fuzz`: the fuzz targets of `fuzz/` without cargo-fuzz. Builds a target with a
//! nightly toolchain and the flags `cargo fuzz build` sets ([`RUSTFLAGS`]), writes its seed
//! corpus from the repository's test fixtures into `fuzz/corpus/<target>` (cargo-fuzz's layout,
//! ignored by git; libFuzzer adds what it finds there) and runs it for a given time, crashes
//! going to `fuzz/artifacts/<target>/`. `--input` replays (or with libFuzzer's
//! `-minimize_crash=1`, minimizes) saved inputs instead.
//!
//! Seeds are built in the input layout of each target (`fuzz/fuzz_targets/*.rs`): the raw and
//! Tyrex targets take their files joined with NUL bytes, the RoNIN target a 2-byte length and
//! `info.json` before the HDF5 bytes. The MAT files, which no fixture on disk holds, are written
//! here ([`mat`]), small so that libFuzzer's mutations stay fast.

use std::fmt::Write as _;
use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail, ensure};

/// The targets of `fuzz/Cargo.toml`.
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

const TRIPLE: &str = "x86_64-unknown-linux-gnu";

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
    // Through rustup, not the `CARGO` of this (stable) run.
    let mut cmd = Command::new("rustup");
    cmd.args(["run", toolchain, "cargo"])
        .args([
            "build",
            "--release",
            "--config",
            "profile.release.debug=true",
        ])
        .args(["--target", TRIPLE])
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
    let bin_dir = target_dir.join(TRIPLE).join("release");
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
            let vars = mat::qtm_take(&mocap_frames(6));
            out.push(("qtm.mat".into(), mat::file(&vars, false, false)));
            out.push(("qtm-compressed.mat".into(), mat::file(&vars, true, false)));
            out.push(("qtm-big-endian.mat".into(), mat::file(&vars, false, true)));
        }
        "tyrex" => {
            let mat = mat::file(&mat::qtm_take(&mocap_frames(MOCAP_FRAMES)), false, false);
            let run = android_run();
            out.push(("android".into(), nul_joined(&run, &mat)));
            let zipped = mat::file(&mat::qtm_take(&mocap_frames(MOCAP_FRAMES)), true, false);
            out.push(("android-compressed".into(), nul_joined(&run, &zipped)));
        }
        "tyrex_ios" => {
            let mat = mat::file(&mat::qtm_take(&mocap_frames(MOCAP_FRAMES)), false, false);
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

/// Turn rate of the synthetic runs about the room's z, rad/s.
const OMEGA: f64 = 0.3;
/// `timeAlignment.txt`: mocap time = phone time + this.
const TIME_DIFF: f64 = -2.0;
/// Phone samples of the synthetic runs: 100 Hz over 3 s of phone time.
const PHONE_HZ: f64 = 100.0;
const PHONE_S: f64 = 3.0;
/// Mocap frames (60 Hz, from mocap time 0, so phone time 2 s to 3 s).
const MOCAP_FRAMES: usize = 60;
/// `[Time] BootTime` of the iOS run.
const BOOT: f64 = 145_406.917_9;

/// Rows of a phone file: `row(t)` at each phone time `t`.
fn phone_rows(row: impl Fn(f64) -> String) -> String {
    let mut s = String::new();
    for k in 0..(PHONE_S * PHONE_HZ) as usize {
        let t = 0.003 + k as f64 / PHONE_HZ;
        writeln!(s, "{}", row(t)).expect("writing to a string");
    }
    s
}

/// The files of an Android run (in the target's order): the phone lies flat and turns about z
/// at [`OMEGA`].
fn android_run() -> Vec<String> {
    vec![
        phone_rows(|t| format!("{t:.9} {:.6} 0.0 9.80665", 0.1 * t.sin())),
        phone_rows(|t| format!("{t:.9} 0.0 0.0 {OMEGA}")),
        phone_rows(|t| {
            let h = OMEGA * t / 2.0;
            format!("{t:.9} 0.0 0.0 {:.9} {:.9} 0.17453292", h.sin(), h.cos())
        }),
        format!("  {TIME_DIFF:e}\n"),
    ]
}

/// The files of an iOS run (in the target's order), the same motion in the authors' iOS
/// conventions: accelerometer in g with the opposite sign, times on the boot clock, the
/// attitude (w x y z) a quarter turn from east-north-up.
fn ios_run() -> Vec<String> {
    let at = |t: f64| t + BOOT;
    vec![
        phone_rows(|t| format!("{:.9} 0.0 0.0 -1.0", at(t))),
        phone_rows(|t| format!("{:.9} 0.0 0.0 {OMEGA}", at(t))),
        phone_rows(|t| {
            let h = (OMEGA * t - std::f64::consts::FRAC_PI_2) / 2.0;
            format!("{:.9} {:.12} 0.0 0.0 {:.12}", at(t), h.cos(), h.sin())
        }),
        format!("[Time]\nBootTime = {BOOT}"),
        format!("  {TIME_DIFF:e}\n"),
    ]
}

/// `n` mocap frames at 60 Hz of the synthetic runs' motion: positions (mm) moving along x at
/// 1 m/s, rotations (column-major 3x3) the phone's turn at phone time = mocap time - TIME_DIFF.
fn mocap_frames(n: usize) -> Vec<([f64; 3], [f64; 9])> {
    (0..n)
        .map(|i| {
            let m = i as f64 / 60.0;
            let (s, c) = (OMEGA * (m - TIME_DIFF)).sin_cos();
            (
                [m * 1000.0, 500.0, 1200.0],
                [c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0],
            )
        })
        .collect()
}

/// A writer of the few Level 5 MAT-file elements a QTM export uses (doubles, chars, 1x1
/// structs, cells), plain or compressed, either byte order.
pub mod mat {
    use std::io::Write as _;

    use flate2::Compression;
    use flate2::write::ZlibEncoder;

    const MI_INT8: u32 = 1;
    const MI_INT32: u32 = 5;
    const MI_UINT32: u32 = 6;
    const MI_DOUBLE: u32 = 9;
    const MI_MATRIX: u32 = 14;
    const MI_COMPRESSED: u32 = 15;
    const MI_UTF16: u32 = 17;
    const CLASS_CELL: u32 = 1;
    const CLASS_STRUCT: u32 = 2;
    const CLASS_CHAR: u32 = 4;
    const CLASS_DOUBLE: u32 = 6;

    /// A value: a double array (dimensions, column-major data), a 1xN char array, a 1x1 struct,
    /// a 1xN cell.
    #[derive(Clone)]
    pub enum V {
        Num(Vec<usize>, Vec<f64>),
        Char(String),
        Struct(Vec<(&'static str, V)>),
        Cell(Vec<V>),
    }

    /// A QTM export of one rigid body, as the Tyrex `.mat` files: `Take_1` with `FrameRate`
    /// and `RigidBodies.Positions` (1x3xN) and `.Rotations` (1x9xN).
    pub fn qtm_take(frames: &[([f64; 3], [f64; 9])]) -> Vec<(&'static str, V)> {
        let n = frames.len();
        let pos = frames.iter().flat_map(|f| f.0).collect();
        let rot = frames.iter().flat_map(|f| f.1).collect();
        let bodies = V::Struct(vec![
            ("Bodies", V::Num(vec![1, 1], vec![1.0])),
            ("Name", V::Cell(vec![V::Char("Phone".into())])),
            ("Positions", V::Num(vec![1, 3, n], pos)),
            ("Rotations", V::Num(vec![1, 9, n], rot)),
        ]);
        vec![(
            "Take_1",
            V::Struct(vec![
                ("File", V::Char("C:\\take.qtm".into())),
                ("Frames", V::Num(vec![1, 1], vec![n as f64])),
                ("FrameRate", V::Num(vec![1, 1], vec![60.0])),
                ("RigidBodies", bodies),
            ]),
        )]
    }

    struct W {
        big_endian: bool,
    }

    impl W {
        /// A value's bytes in the file's byte order, given both orders.
        fn ordered<const N: usize>(&self, be: [u8; N], le: [u8; N]) -> [u8; N] {
            if self.big_endian { be } else { le }
        }

        fn u32(&self, v: u32) -> [u8; 4] {
            self.ordered(v.to_be_bytes(), v.to_le_bytes())
        }

        /// A data element (the small form up to 4 bytes, as MATLAB writes them).
        fn elem(&self, ty: u32, data: &[u8]) -> Vec<u8> {
            let mut out = Vec::new();
            if !data.is_empty() && data.len() <= 4 {
                out.extend(self.u32(((data.len() as u32) << 16) | ty));
                out.extend(data);
                out.resize(8, 0);
            } else {
                out.extend(self.u32(ty));
                out.extend(self.u32(data.len() as u32));
                out.extend(data);
                out.resize(out.len().next_multiple_of(8), 0);
            }
            out
        }

        fn array_header(&self, class: u32, dims: &[usize], name: &str) -> Vec<u8> {
            let flags = [self.u32(class), self.u32(0)].concat();
            let dims: Vec<u8> = dims.iter().flat_map(|&d| self.u32(d as u32)).collect();
            let mut out = self.elem(MI_UINT32, &flags);
            out.extend(self.elem(MI_INT32, &dims));
            out.extend(self.elem(MI_INT8, name.as_bytes()));
            out
        }

        fn matrix(&self, name: &str, v: &V) -> Vec<u8> {
            let body = match v {
                V::Num(dims, data) => {
                    let mut out = self.array_header(CLASS_DOUBLE, dims, name);
                    let bytes: Vec<u8> = data
                        .iter()
                        .flat_map(|x| self.ordered(x.to_be_bytes(), x.to_le_bytes()))
                        .collect();
                    out.extend(self.elem(MI_DOUBLE, &bytes));
                    out
                }
                V::Char(s) => {
                    let units: Vec<u16> = s.encode_utf16().collect();
                    let mut out = self.array_header(CLASS_CHAR, &[1, units.len()], name);
                    let bytes: Vec<u8> = units
                        .iter()
                        .flat_map(|u| self.ordered(u.to_be_bytes(), u.to_le_bytes()))
                        .collect();
                    out.extend(self.elem(MI_UTF16, &bytes));
                    out
                }
                V::Struct(fields) => {
                    const NAME_LEN: usize = 32;
                    let mut out = self.array_header(CLASS_STRUCT, &[1, 1], name);
                    out.extend(self.elem(MI_INT32, &self.u32(NAME_LEN as u32)));
                    let mut names = Vec::new();
                    for (n, _) in fields {
                        let mut b = n.as_bytes().to_vec();
                        b.resize(NAME_LEN, 0);
                        names.extend(b);
                    }
                    out.extend(self.elem(MI_INT8, &names));
                    for (_, f) in fields {
                        out.extend(self.matrix("", f));
                    }
                    out
                }
                V::Cell(items) => {
                    let mut out = self.array_header(CLASS_CELL, &[1, items.len()], name);
                    for it in items {
                        out.extend(self.matrix("", it));
                    }
                    out
                }
            };
            let mut out = self.u32(MI_MATRIX).to_vec();
            out.extend(self.u32(body.len() as u32));
            out.extend(body);
            out
        }
    }

    /// A MAT file of `vars`, each in a compressed element when `compress`.
    pub fn file(vars: &[(&str, V)], compress: bool, big_endian: bool) -> Vec<u8> {
        let w = W { big_endian };
        let mut out = b"MATLAB 5.0 MAT-file, written by cargo xtask fuzz".to_vec();
        out.resize(116, b' ');
        out.extend([0u8; 8]);
        out.extend(if big_endian {
            *b"\x01\x00MI"
        } else {
            *b"\x00\x01IM"
        });
        for (name, v) in vars {
            let m = w.matrix(name, v);
            if compress {
                let mut z = ZlibEncoder::new(Vec::new(), Compression::default());
                z.write_all(&m).expect("writing to memory");
                let z = z.finish().expect("writing to memory");
                out.extend(w.u32(MI_COMPRESSED));
                out.extend(w.u32(z.len() as u32));
                out.extend(z);
            } else {
                out.extend(m);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ridi_data::tyrex::{self, TyrexOptions};

    /// Lays `input` out as the Tyrex targets do (`fuzz/fuzz_targets/common/tyrex_run.rs`) and
    /// reads the run with the targets' options.
    fn read_tyrex(
        input: &[u8],
        layout: &str,
        run_name: &str,
        files: &[&str],
    ) -> ridi_data::Result<tyrex::TyrexRead> {
        let root = tempfile::tempdir().unwrap();
        let run = root.path().join("datasets").join(layout).join(run_name);
        let qualisys = root.path().join("datasets/qualisys");
        std::fs::create_dir_all(&run).unwrap();
        std::fs::create_dir_all(&qualisys).unwrap();
        let mut parts = input.splitn(files.len() + 1, |&b| b == 0);
        for name in files {
            std::fs::write(run.join(name), parts.next().unwrap_or_default()).unwrap();
        }
        if let Some(mat) = parts.next() {
            std::fs::write(qualisys.join(format!("{run_name}.mat")), mat).unwrap();
        }
        let opts = TyrexOptions {
            min_part_s: 0.5,
            ..TyrexOptions::default()
        };
        tyrex::read(&run, &opts)
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
        let android = [
            "accelerometer.txt",
            "gyroscope-calibrated.txt",
            "rotation-vector.txt",
            "timeAlignment.txt",
        ];
        let ios = [
            "accelerometer.txt",
            "gyroscope.txt",
            "attitude.txt",
            "description.txt",
            "timeAlignment.txt",
        ];
        let targets: [(&str, &str, &str, &[&str]); 2] = [
            ("tyrex", "android", "A_Nexus5_NoDist_Texting", &android),
            ("tyrex_ios", "ios", "A_iPhone4S_NoDist_Texting", &ios),
        ];
        for (target, layout, run, files) in targets {
            for (name, seed) in seeds(&root, target).unwrap() {
                let read = read_tyrex(&seed, layout, run, files)
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
