use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::{Args, Parser, Subcommand};

mod bench;
mod bootstrap;
mod eval_devices;
mod eval_orientation;
mod eval_tyrex;
mod fuzz;
mod model;
mod sample;

use xtask::checksum;
use xtask::fetch::{self, Outcome};
use xtask::manifest::Manifest;

#[derive(Parser)]
#[command(
    name = "cargo xtask",
    bin_name = "cargo xtask",
    about = "Developer tasks for ridi-rs"
)]
struct Cli {
    #[command(subcommand)]
    task: Task,
}

#[derive(Subcommand)]
enum Task {
    /// Download a dataset of datasets/manifest.toml (or install it from a local copy), verify
    /// it and unpack it into <dir>/<dataset>.
    Fetch {
        /// Dataset name in the manifest (e.g. ridi, tyrex).
        dataset: String,
        /// Local archive (checked against the pinned sha256) or folder (checked against the
        /// dataset's per-file list) to use instead of downloading.
        #[arg(long, value_name = "PATH")]
        from: Option<PathBuf>,
        /// Folder holding the datasets [default: <workspace>/datasets].
        #[arg(long, value_name = "DIR")]
        dir: Option<PathBuf>,
        /// Manifest to read [default: <workspace>/datasets/manifest.toml].
        #[arg(long, value_name = "FILE")]
        manifest: Option<PathBuf>,
        /// Accept content that no checksum in the repository vouches for, and print its
        /// sha256 so that it can be pinned.
        #[arg(long)]
        trust_unpinned: bool,
    },
    /// Fast convention checks (no build): each crate's dependencies match the layer table of
    /// docs/ARCHITECTURE.md, no error enum uses a retired spelling, no new public module, the
    /// dev profile names every crate and crates/ridi-py repeats the workspace's profiles.
    Tidy,
    /// Check that the workspace's rust-version is at least that of every package in Cargo.lock
    /// (`cargo metadata`) and that the README names it.
    RustVersion,
    /// Check that CI's three builds (the workspace's tests, ridi without default features, the
    /// Python package) turn on the same features of every dependency they share, so that they
    /// share its artifacts in target/ (`cargo tree`, no build).
    Features,
    /// Print the sha256sum list of every file under a folder (sorted), e.g. to regenerate
    /// datasets/<name>.sha256.
    Checksums { folder: PathBuf },
    /// Accuracy protocols on the Tyrex data: `eval tyrex` (RIDI and its baselines) and
    /// `eval orientation` (the orientation estimator).
    #[command(subcommand)]
    Eval(Eval),
    /// Same as `eval tyrex` (the name of earlier versions).
    #[command(hide = true)]
    EvalTyrex(TyrexArgs),
    /// Same as `eval orientation` (the name of earlier versions).
    #[command(hide = true)]
    EvalOrientation(OrientationArgs),
    /// Rebuild the bundled sample (datasets/sample) from the Tyrex data: 24 s of every Nexus 5
    /// run without disturbance and of two of Thibaud's iPhone 4S runs, RIDI processed layout,
    /// gzip + f32, with sidecars and list files.
    Sample {
        /// Tyrex root [default: <workspace>/../shared/data/raw/tyrex-attitude-smartphones, else
        /// <workspace>/datasets/tyrex from `cargo xtask fetch tyrex`].
        #[arg(long, value_name = "DIR")]
        data: Option<PathBuf>,
        /// Output folder [default: <workspace>/datasets/sample].
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// Rebuild the model bundled in the ridi crate (crates/ridi/model/ridi-tyrex.ridi) from
    /// every run of datasets/protocols/tyrex-runs.txt: both phones, three people, the Nyström
    /// solver; docs/model-card.md has its figures.
    Model {
        /// Tyrex root [default: <workspace>/../shared/data/raw/tyrex-attitude-smartphones, else
        /// <workspace>/datasets/tyrex from `cargo xtask fetch tyrex`].
        #[arg(long, value_name = "DIR")]
        data: Option<PathBuf>,
        /// Model file to write [default: <workspace>/crates/ridi/model/ridi-tyrex.ridi].
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
    },
    /// Run the benchmark set (criterion benches, correction latency, `ridi demo`), write a JSON
    /// report and docs/bench-latest.md, and compare with the baseline of this CPU model
    /// (benchmarks/baseline-<model>.json, else benchmarks/baseline.json).
    Bench {
        /// Short measurement times and a subset of the benches.
        #[arg(long)]
        quick: bool,
        /// Report to write [default: <target dir>/bench-report.json].
        #[arg(long, value_name = "FILE")]
        json: Option<PathBuf>,
        /// Record this run as the baseline of this CPU model instead of comparing with it
        /// (benchmarks/baseline.json when that is this model's or absent, else its own file).
        #[arg(long)]
        update_baseline: bool,
    },
    /// Build a fuzz target of fuzz/ with a nightly toolchain and the flags of `cargo fuzz build`
    /// (no cargo-fuzz needed), seed fuzz/corpus/<target> from the test fixtures and run
    /// libFuzzer on it; failing inputs go to fuzz/artifacts/<target>.
    Fuzz {
        /// csv, plain, raw, list, mat, tyrex, tyrex_ios, ilc, ronin, or `all` for each in turn.
        target: String,
        /// Fuzzing time per target.
        #[arg(long, value_name = "N", default_value_t = 60)]
        seconds: u64,
        /// Toolchain of the build (`rustup run <toolchain> cargo`); it must accept `-Z` flags.
        #[arg(long, value_name = "NAME", default_value = "nightly")]
        toolchain: String,
        /// Build without AddressSanitizer (where its runtime does not work).
        #[arg(long)]
        no_asan: bool,
        /// Run the target on these inputs (e.g. a crash from fuzz/artifacts) instead of fuzzing;
        /// with `-- -minimize_crash=1 -runs=N` libFuzzer minimizes a crash.
        #[arg(long, value_name = "FILE")]
        input: Vec<PathBuf>,
        /// More libFuzzer arguments, after `--` (e.g. `-- -max_len=4096`).
        #[arg(last = true, value_name = "LIBFUZZER ARGS")]
        libfuzzer: Vec<String>,
    },
}

#[derive(Subcommand)]
enum Eval {
    /// The accuracy protocols on every Tyrex run of datasets/protocols/tyrex-runs.txt: leave
    /// one person out over both phones, across phones (Nexus 5 -> iPhone 4S and the reverse,
    /// beside the same-phone models) and on the 24 undisturbed Nexus 5 runs; writes
    /// docs/bench-devices.md. With --variants: one variant per open choice of the paper on the
    /// 24 Nexus 5 runs; writes docs/bench-accuracy.md.
    Tyrex(TyrexArgs),
    /// Compare the gyro + accelerometer orientation estimator (default gains and a kp/ki
    /// sweep) and the OS orientation (Android rotation vector, or the iPhone's Core Motion
    /// attitude) with the Tyrex motion capture, and write a markdown report.
    Orientation(OrientationArgs),
    /// Compare two reports of `eval tyrex` (e.g. `--orientation recorded` and `estimated`):
    /// RIDI's figures on the runs both tested (both phones' protocol), paired run by run, with
    /// 95 % intervals; per device and condition.
    Compare {
        /// The reference report (docs/bench-devices.md of one setting).
        before: PathBuf,
        /// The report of the other setting.
        after: PathBuf,
    },
}

#[derive(Args)]
struct TyrexArgs {
    /// Tyrex root [default: <workspace>/../shared/data/raw/tyrex-attitude-smartphones, else
    /// <workspace>/datasets/tyrex from `cargo xtask fetch tyrex`].
    #[arg(long, value_name = "DIR")]
    data: Option<PathBuf>,
    /// Report to write [default: <workspace>/docs/bench-devices.md, with --variants
    /// docs/bench-accuracy.md].
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// The variant sweep on the 24 Nexus 5 runs instead of the device protocols.
    #[arg(long)]
    variants: bool,
    /// With --variants: only the reference variants.
    #[arg(long, requires = "variants")]
    quick: bool,
    /// Only the protocols (with --variants: the variants) whose name contains this text (e.g.
    /// "iPhone", "turned").
    #[arg(long, value_name = "TEXT")]
    only: Option<String>,
    /// Training sample step in frames [default: ridi train's, 20]; a coarser step trains
    /// faster on fewer windows (the report says so).
    #[arg(long, value_name = "FRAMES", conflicts_with = "variants", value_parser = clap::value_parser!(u64).range(1..))]
    step: Option<u64>,
    /// Device orientation the models see: as recorded, or estimated from gyro and
    /// accelerometer.
    #[arg(long, value_name = "SOURCE", default_value = "estimated", value_parser = ["recorded", "estimated"], conflicts_with = "variants")]
    orientation: String,
    /// With the estimated orientation: its heading drift `corrected` by the recorded
    /// orientation's slow heading (`ridi track`'s default), or the `gyro`'s alone.
    #[arg(long, value_name = "HEADING", default_value = "corrected", value_parser = ["corrected", "gyro"], conflicts_with = "variants")]
    heading: String,
    /// Train with the Nyström solver on this many landmarks instead of the exact SMO.
    #[arg(long, value_name = "N", conflicts_with = "variants")]
    landmarks: Option<usize>,
    /// Regressor parameters: `none` fixes C = 10, epsilon = 0.01; `paper` searches the paper's
    /// grid by cross-validation on the training people (cheap with --landmarks, 48 times the
    /// training without).
    #[arg(long, value_name = "GRID", default_value = "none", value_parser = ["none", "paper"], conflicts_with = "variants")]
    grid: String,
    /// Seed of training's random draws (`ridi train --seed`): the Nyström landmarks and
    /// sweeps, the grid's folds. Reports of other seeds show how much a figure owes to them.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 0,
        conflicts_with = "variants"
    )]
    seed: u64,
}

#[derive(Args)]
struct OrientationArgs {
    /// Tyrex root [default: <workspace>/../shared/data/raw/tyrex-attitude-smartphones, else
    /// <workspace>/datasets/tyrex from `cargo xtask fetch tyrex`].
    #[arg(long, value_name = "DIR")]
    data: Option<PathBuf>,
    /// Report to write [default: <workspace>/docs/bench-orientation.md, for the iPhone 4S
    /// docs/bench-orientation-iphone4s.md].
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// The phone whose 24 undisturbed runs are evaluated.
    #[arg(long, value_enum, default_value = "nexus5")]
    phone: eval_devices::Phone,
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.task {
        Task::Fetch {
            dataset,
            from,
            dir,
            manifest,
            trust_unpinned,
        } => {
            let root = xtask::workspace_root();
            let manifest_path = manifest.unwrap_or_else(|| root.join("datasets/manifest.toml"));
            let manifest = Manifest::load(&manifest_path)?;
            let ds = manifest.get(&dataset)?;
            let opts = fetch::Options {
                dir: dir.unwrap_or_else(|| root.join("datasets")),
                from,
                trust_unpinned,
                progress: true,
            };
            let outcome = fetch::fetch(ds, &opts)?;
            match &outcome {
                Outcome::AlreadyPresent { path, source } => {
                    println!("{dataset}: already in {} (from {source})", path.display());
                }
                Outcome::Installed {
                    path,
                    archive_sha256,
                    verified,
                    files,
                } => {
                    println!("{dataset}: {files} files in {}", path.display());
                    if !*verified {
                        match archive_sha256 {
                            Some(sha) => println!(
                                "{dataset}: UNPINNED archive, sha256 {sha}; to pin it set \
                                 sha256 = \"{sha}\" in {}",
                                manifest.path.display()
                            ),
                            None => println!(
                                "{dataset}: UNVERIFIED copy; to pin it commit the output of \
                                 `cargo xtask checksums {}` as a per-file list",
                                path.display()
                            ),
                        }
                    }
                }
            }
            if dataset == "ronin" {
                // RoNIN's split lists, with each sequence's folder in the release.
                let (Outcome::AlreadyPresent { path, .. } | Outcome::Installed { path, .. }) =
                    &outcome;
                let protocols = root.join("datasets/protocols/ronin");
                let (written, warnings) = xtask::ronin_lists::write_lists(path, &protocols)?;
                for w in warnings {
                    eprintln!("warning: {w}");
                }
                println!(
                    "{dataset}: {} split lists in {}",
                    written.len(),
                    path.display()
                );
            }
        }
        Task::Tidy => xtask::tidy::run(&xtask::workspace_root())?,
        Task::RustVersion => xtask::rust_version::run(&xtask::workspace_root())?,
        Task::Features => xtask::features::run(&xtask::workspace_root())?,
        Task::Checksums { folder } => {
            let list = checksum::list_tree(&folder)?;
            print!("{}", checksum::format_list(&list));
        }
        Task::Eval(Eval::Tyrex(args)) | Task::EvalTyrex(args) => {
            let out = if args.variants {
                eval_tyrex::run(args.data, args.out, args.quick, args.only)?
            } else {
                eval_devices::run(eval_devices::Options {
                    data: args.data,
                    out: args.out,
                    only: args.only,
                    step: args.step.map(|s| s as usize),
                    orientation: match args.orientation.as_str() {
                        "estimated" => ridi::features::Orientation::Estimated,
                        _ => ridi::features::Orientation::Recorded,
                    },
                    recorded_heading: (args.heading == "corrected")
                        .then(ridi::frames::HeadingConfig::default),
                    landmarks: args.landmarks,
                    grid: args.grid == "paper",
                    seed: args.seed,
                })?
            };
            println!("wrote {}", out.display());
        }
        Task::Eval(Eval::Compare { before, after }) => {
            print!("{}", eval_devices::compare(&before, &after)?);
        }
        Task::Eval(Eval::Orientation(args)) | Task::EvalOrientation(args) => {
            let out = eval_orientation::run(args.data, args.out, args.phone)?;
            println!("wrote {}", out.display());
        }
        Task::Model { data, out } => {
            let out = model::run(data, out)?;
            println!("wrote {}", out.display());
        }
        Task::Sample { data, out } => {
            let data = xtask::tyrex_root(data)?;
            let out = out.unwrap_or_else(|| xtask::workspace_root().join("datasets/sample"));
            sample::build(&data, &out)?;
            println!("wrote {}", out.display());
        }
        Task::Bench {
            quick,
            json,
            update_baseline,
        } => bench::run(bench::Options {
            quick,
            json,
            update_baseline,
        })?,
        Task::Fuzz {
            target,
            seconds,
            toolchain,
            no_asan,
            input,
            libfuzzer,
        } => fuzz::run(&fuzz::Options {
            target,
            seconds,
            toolchain,
            asan: !no_asan,
            inputs: input,
            libfuzzer,
        })?,
    }
    Ok(())
}
