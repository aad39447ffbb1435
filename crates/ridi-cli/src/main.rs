//! The `ridi` command line. Thin: parsing, printing and exit codes; the work is in the `ridi`
//! crate.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};

use ridi::correct::PlacementSmoother;
use ridi::data::{Format, ListEntry, ReadOptions, Sequence};
use ridi::eval::{AlignWindow, EvalConfig};
use ridi::features::FeatureConfig;
use ridi::frames::UpAxis;
use ridi::regress::{Cascade, MODEL_MAGIC, ProgressEvent, RegressError, Stage, Storage};
use ridi::source::{ReadFiles, folder_of, resolved};
use ridi::staging::Staging;
use ridi::{
    EvalOptions, GridChoice, Method, Orientation, PipelineError, PlacementMap, Purpose,
    TrackOptions, TrainOptions, apply_orientation,
};

/// `println!` that ignores a closed stdout (`ridi train ... | head`): the command's results are
/// its files, which must still be written, and printing must never abort it with a panic.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

/// `print!` that ignores a closed stdout, as [`outln!`].
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stdout(), $($arg)*);
    }};
}

#[derive(Parser)]
#[command(
    name = "ridi",
    version,
    about = "Robust IMU Double Integration: pedestrian trajectories from a phone's IMU",
    long_about = None,
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Describe a recording (format, duration, rate, gravity, ground truth, warnings) or a
    /// model file (placements, feature window, frame, regressors, cross-validation).
    #[command(after_help = "Examples:\n  \
        ridi inspect datasets/sample/Jakob_Nexus5_NoDist_Texting\n  \
        ridi inspect model.ridi\n  \
        ridi inspect path/to/ridi/dan_body1/processed/data.csv --json\n  \
        ridi inspect ../shared/data/raw/tyrex-attitude-smartphones/datasets/android/Guillaume_Nexus5_NoDist_AR")]
    Inspect {
        /// A RIDI data.csv, data_plain.txt, RIDI raw folder, Tyrex sequence folder, Indoor
        /// Location Competition path file, or a model file of `ridi train`.
        sequence: PathBuf,
        /// Print JSON instead of text: one object, or an array of the parts of a recording
        /// split at its gaps (each with the reader's warnings).
        #[arg(long)]
        json: bool,
    },
    /// Convert recordings to the RIDI processed layout, with list files.
    #[command(after_help = "Examples:\n  \
        ridi convert ../shared/data/raw/tyrex-attitude-smartphones --out converted\n  \
        ridi convert my_capture/ --from ridi-raw --out converted\n  \
        ridi convert indoor-location-competition-20/data --from ilc --out converted\n  \
        ridi convert phone_at_100hz/ --out converted --rate 200   (train, track and eval need 200 Hz)\n\n\
        Writes <out>/<name>/processed/data.csv per sequence and list files \
        (`path,placement` per line): for a Tyrex root, list_<subject>.txt per person and list_all.txt.")]
    Convert {
        /// A sequence (file or folder), a folder of sequences, a Tyrex dataset root, or a folder
        /// searched for Indoor Location Competition path files.
        source: PathBuf,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Source format (detected when omitted).
        #[arg(long, value_enum)]
        from: Option<FromFormat>,
        /// Resample every sequence to this rate, Hz (linear interpolation, slerp for
        /// rotations); a gap longer than 5 frame intervals is refused: split it first.
        #[arg(long, value_name = "HZ", value_parser = rate_hz)]
        rate: Option<f64>,
    },

    /// Train the placement classifier and velocity regressors on labelled recordings.
    #[command(after_help = "Examples:\n  \
        ridi train --list datasets/sample/list_train.txt --out model.ridi --grid small \
        --placement-map tyrex4\n  \
        ridi train --list ridi/list_train_publish_v2.txt --out ridi.model --grid paper --jobs 2\n  \
        ridi train --list list.txt --out paper.ridi --turned-copies 0 --no-speed --up-axis plus-y   (the paper's cascade; \
        add --no-standardize for the original's raw features)\n\n\
        Every sequence needs ground truth and a placement (the list's second column).")]
    Train {
        /// List files (`path,placement` per line); several are concatenated.
        #[arg(long, required = true, num_args = 1..)]
        list: Vec<PathBuf>,
        /// Model file to write.
        #[arg(long)]
        out: PathBuf,
        /// Regressor hyper-parameter search.
        #[arg(long, value_enum, default_value = "paper")]
        grid: Grid,
        /// Group placement labels: `tyrex4` (hand, swing, pocket, running) or a file of
        /// `label,class` lines.
        #[arg(long)]
        placement_map: Option<String>,
        /// Train on raw features (the original RIDI) instead of standardized ones.
        #[arg(long)]
        no_standardize: bool,
        /// Classifier C (paper: 10).
        #[arg(long, default_value_t = 10.0, value_parser = positive)]
        classifier_c: f64,
        /// Orientation to train and track with: as recorded, or estimated from gyro +
        /// accelerometer (straighter tracks where the recorded one uses the magnetometer
        /// indoors). The model records it: `ridi track` and `ridi eval` use the same.
        #[arg(long, value_enum, default_value = "recorded")]
        orientation: OrientationArg,
        /// How the model stores its samples for prediction.
        #[arg(long, value_enum, default_value = "projected")]
        storage: StorageArg,
        /// Also train on N copies of each window turned about the vertical (features and
        /// velocity together), for phones carried at other headings than in the training
        /// recordings; 0 for the paper, at most 32.
        #[arg(long, default_value_t = 1, value_name = "N", value_parser = |s: &str| count(s, 0, MAX_TURNED_COPIES))]
        turned_copies: usize,
        /// Frames between training windows [default: 10 x (N + 1), N turned copies: the
        /// paper's 10 without copies, and the paper's number of rows with them].
        #[arg(long, value_name = "FRAMES", value_parser = |s: &str| count(s, 1, MAX_FRAMES_APART))]
        step: Option<usize>,
        /// Frames per feature window [default: the paper's 200, 1 s at 200 Hz]. The model
        /// records it; recordings must then be longer than one window to track. 100 gave a
        /// lower RTE 5 s and shorter paths on the Tyrex protocol (docs/benchmarks.md).
        #[arg(long, value_name = "FRAMES", value_parser = |s: &str| count(s, MIN_WINDOW, MAX_WINDOW))]
        window: Option<usize>,
        /// No speed regressor (the paper): by default each placement also regresses the speed
        /// and each regressed velocity is scaled to it, since turned training windows make the
        /// velocity's direction less certain than its size.
        #[arg(long)]
        no_speed: bool,
        /// The device axis the stabilized frame S is built on: `plus-y` always (the paper),
        /// or `plus-or-minus-y`, which builds it on -y while the phone is upside down (top
        /// down in a hanging hand, say), where the paper's S turns erratically.
        #[arg(long, value_enum, default_value = "plus-or-minus-y")]
        up_axis: UpAxisArg,
        /// Worker threads (default: all cores).
        #[arg(long, value_parser = |s: &str| count(s, 1, 4096))]
        jobs: Option<usize>,
    },
    /// Track a recording with a trained model: one pose per frame.
    #[command(after_help = "Examples:\n  \
        ridi track datasets/sample/Thibaud_Nexus5_NoDist_Texting --model model.ridi --out traj.csv \
        --plot traj.png\n  \
        ridi track capture/ --model model.ridi --out traj.csv --online\n\n\
        The CSV has time,pos_x,pos_y,pos_z,vel_x,vel_y,vel_z,placement,bias_x,bias_y,bias_z \
        (world frame of the device orientation, metres from the start).")]
    Track {
        /// A RIDI data.csv, data_plain.txt, raw folder, Tyrex run, or Indoor Location
        /// Competition path file.
        sequence: PathBuf,
        /// Model file from `ridi train`.
        #[arg(long)]
        model: PathBuf,
        /// Trajectory CSV to write.
        #[arg(long)]
        out: PathBuf,
        /// Streaming mode: correction every 200 frames over the latest 1000.
        #[arg(long)]
        online: bool,
        /// Also draw the trajectory (and ground truth if any) to a .png or .svg file.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Frames between regressions.
        #[arg(long, default_value_t = 50, value_parser = |s: &str| count(s, 1, MAX_FRAMES_APART))]
        regress_every: usize,
        /// Weight of the bias prior (paper: 0.1).
        #[arg(long, default_value_t = 0.1, value_parser = positive)]
        lambda: f64,
        /// Estimate the initial velocity instead of assuming the walk starts at rest.
        #[arg(long)]
        estimate_initial_velocity: bool,
        /// Placement majority window, seconds: each regression takes the most frequent placement
        /// label within it (centred in batch, the seconds before it with --online); 0 keeps each
        /// window's own label, as in the paper.
        #[arg(long, value_name = "SECONDS", default_value_t = 10.0, value_parser = non_negative)]
        placement_window: f64,
    },
    /// Evaluate RIDI and the baselines on labelled recordings: report.json, report.md, plots.
    #[command(after_help = "Examples:\n  \
        ridi eval --list datasets/sample/list_test.txt --model model.ridi --out report \
        --placement-map tyrex4\n  \
        ridi eval --list test.txt --model model.ridi --out report --methods ridi,pdr,still\n  \
        ridi eval --list test.txt --model model.ridi --out report-whole --align all\n\n\
        Methods: ridi, raw, pdr, ridi_mag, ridi_ori, velocity, still.")]
    Eval {
        /// List files of the sequences to evaluate (ground truth required).
        #[arg(long, required = true, num_args = 1..)]
        list: Vec<PathBuf>,
        /// Model file from `ridi train`.
        #[arg(long)]
        model: PathBuf,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Methods to compare (comma-separated).
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "ridi,raw,pdr,ridi_mag,ridi_ori,velocity,still"
        )]
        methods: Vec<String>,
        /// Group placement labels as at training (`tyrex4` or a `label,class` file).
        #[arg(long)]
        placement_map: Option<String>,
        /// Plot format, or `none`.
        #[arg(long, value_enum, default_value = "png")]
        plots: Plots,
        /// Worker threads (default: all cores).
        #[arg(long, value_parser = |s: &str| count(s, 1, 4096))]
        jobs: Option<usize>,
        /// Placement majority window, seconds: each regression takes the most frequent placement
        /// label within it, centred on it; 0 keeps each window's own label, as in the paper.
        #[arg(long, value_name = "SECONDS", default_value_t = 10.0, value_parser = non_negative)]
        placement_window: f64,
        /// Stretch every trajectory is aligned to the ground truth on (2D rigid, no scale):
        /// its first SECONDS, as in the paper, or `all` for the whole run (a best case that
        /// hides initial-heading errors).
        #[arg(long, value_name = "SECONDS|all", default_value = "10", value_parser = parse_align)]
        align: AlignWindow,
    },
    /// Train on the bundled sample (two people) and evaluate on the held-out person.
    #[command(after_help = "Example:\n  ridi demo --out demo-out\n\n\
        Uses datasets/sample (list_train.txt, list_test.txt) with the four Tyrex placement \
        groups; writes the model, report.json, report.md and plots into --out.")]
    Demo {
        /// Output folder.
        #[arg(long, default_value = "demo-out")]
        out: PathBuf,
        /// The bundled sample folder (default: datasets/sample of this checkout).
        #[arg(long)]
        data: Option<PathBuf>,
        /// Regressor hyper-parameter search.
        #[arg(long, value_enum, default_value = "none")]
        grid: Grid,
        /// Plot format, or `none`.
        #[arg(long, value_enum, default_value = "png")]
        plots: Plots,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Grid {
    /// C in {0.1, 1, 10, 100} x epsilon in {0.001, 0.01, 0.1, 1}, 3 folds by sequence.
    Paper,
    /// C in {1, 10} x epsilon in {0.01, 0.1}, 3 folds.
    Small,
    /// C = 10, epsilon = 0.01.
    None,
}

impl From<Grid> for GridChoice {
    fn from(g: Grid) -> GridChoice {
        match g {
            Grid::Paper => GridChoice::Paper,
            Grid::Small => GridChoice::Small,
            Grid::None => GridChoice::None,
        }
    }
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
enum OrientationArg {
    /// As recorded in the file.
    Recorded,
    /// Estimated from gyro + accelerometer.
    Estimated,
}

impl From<OrientationArg> for Orientation {
    fn from(o: OrientationArg) -> Self {
        match o {
            OrientationArg::Recorded => Orientation::Recorded,
            OrientationArg::Estimated => Orientation::Estimated,
        }
    }
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
enum StorageArg {
    /// Coordinates on the principal directions holding 99.99 % of the feature variance (several
    /// times faster queries; velocities move by about as much as half precision moves them).
    Projected,
    /// Every feature value in half precision.
    Half,
}

impl From<StorageArg> for Storage {
    fn from(s: StorageArg) -> Self {
        match s {
            StorageArg::Projected => Storage::DEFAULT,
            StorageArg::Half => Storage::Half,
        }
    }
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
enum UpAxisArg {
    /// Device +y at every attitude (the paper's S).
    PlusY,
    /// Device -y while the phone is upside down, +y otherwise.
    PlusOrMinusY,
}

impl From<UpAxisArg> for UpAxis {
    fn from(a: UpAxisArg) -> Self {
        match a {
            UpAxisArg::PlusY => UpAxis::PlusY,
            UpAxisArg::PlusOrMinusY => UpAxis::PlusOrMinusY,
        }
    }
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
enum Plots {
    Png,
    Svg,
    None,
}

#[derive(Clone, Copy, ValueEnum)]
enum FromFormat {
    /// RIDI raw recorder folder (gyro.txt, acce.txt, ..., pose.txt).
    RidiRaw,
    /// RIDI processed data.csv (or data_plain.txt).
    RidiCsv,
    /// Tyrex smartphone benchmark (a sequence folder or the dataset root).
    Tyrex,
    /// Indoor Location Competition 2.0 path files (a file, or a folder searched recursively).
    Ilc,
}

impl From<FromFormat> for Format {
    fn from(f: FromFormat) -> Format {
        match f {
            FromFormat::RidiRaw => Format::RidiRaw,
            FromFormat::RidiCsv => Format::RidiCsv,
            FromFormat::Tyrex => Format::Tyrex,
            FromFormat::Ilc => Format::Ilc,
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Inspect { sequence, json } => {
            if is_model_file(&sequence) {
                let model = load_model(&sequence)?;
                let report = ridi::inspect::inspect_model(&model);
                if json {
                    outln!("{}", serde_json::to_string_pretty(&report)?);
                } else {
                    out!("{report}");
                }
                return Ok(());
            }
            let opts = ReadOptions::default();
            let loaded = ridi::read_any(&sequence, None, &opts)?;
            let mut reports = Vec::new();
            for seq in &loaded.sequences {
                let mut report = ridi::inspect::inspect(seq, loaded.format);
                if json {
                    // The reader's warnings (gaps, splits, dropped parts) belong to every part.
                    report
                        .warnings
                        .splice(0..0, loaded.warnings.iter().cloned());
                }
                reports.push(report);
            }
            if json {
                // One object, or an array of the parts of a recording split at its gaps.
                let text = match &reports[..] {
                    [one] => serde_json::to_string_pretty(one)?,
                    parts => serde_json::to_string_pretty(parts)?,
                };
                outln!("{text}");
            } else {
                for (i, report) in reports.iter().enumerate() {
                    if i > 0 {
                        outln!();
                    }
                    out!("{report}");
                }
                // Once for the recording, not once per part.
                for w in &loaded.warnings {
                    outln!("warning:      {w}");
                }
            }
        }
        Command::Convert {
            source,
            out,
            from,
            rate,
        } => {
            let opts = ridi::convert::ConvertOptions {
                from: from.map(Format::from),
                read: ReadOptions::default(),
                rate_hz: rate,
            };
            check_output_folder(&out)?;
            let summary = ridi::convert::convert(&source, &out, &opts)?;
            for w in &summary.warnings {
                eprintln!("warning: {w}");
            }
            for c in &summary.sequences {
                outln!(
                    "{}  {}",
                    c.path.display(),
                    c.placement.as_deref().unwrap_or("-")
                );
            }
            for l in &summary.lists {
                outln!("list: {}", l.display());
            }
        }
        Command::Train {
            list,
            out,
            grid,
            placement_map,
            no_standardize,
            classifier_c,
            jobs,
            orientation,
            storage,
            turned_copies,
            step,
            window,
            no_speed,
            up_axis,
        } => {
            set_jobs(jobs)?;
            check_output(&out)?;
            let entries = ridi::lists::read_lists(&list)?;
            let mut read = list.clone();
            read.extend(entries.iter().map(|e| e.path.clone()));
            let inputs = ReadFiles::of(&read);
            check_not_input(&out, &inputs, &[])?;
            let listed = load_listed(entries, placement_map.as_deref(), Purpose::Training)?;
            let seqs = &listed.seqs;
            let defaults = TrainOptions::default();
            let mut opts = TrainOptions {
                standardize: !no_standardize,
                turned_copies,
                features: FeatureConfig {
                    step: step.unwrap_or(ridi::train::default_step(turned_copies)),
                    window: window.unwrap_or(defaults.features.window),
                    up_axis: up_axis.into(),
                    orientation: orientation.into(),
                    ..defaults.features.clone()
                },
                ..defaults
            };
            opts.cascade.classifier_c = classifier_c;
            opts.cascade.regressors = GridChoice::from(grid).regressors();
            opts.cascade.storage = storage.into();
            opts.cascade.speed = !no_speed;
            let model = train_with_progress(seqs, &opts).map_err(|e| {
                let e = listed.locate(e);
                let folds = matches!(
                    e.downcast_ref::<PipelineError>(),
                    Some(PipelineError::Regress(RegressError::TooFewSequences { .. }))
                );
                if folds {
                    e.context(
                        "the grid search cross-validates over each placement's sequences \
                         (`--grid none` trains without it)",
                    )
                } else {
                    e
                }
            })?;
            print_training(&model);
            model
                .save(&out)
                .with_context(|| format!("cannot write {}", out.display()))?;
            outln!("model: {}", out.display());
        }
        Command::Track {
            sequence,
            model,
            out,
            online,
            plot,
            regress_every,
            lambda,
            estimate_initial_velocity,
            placement_window,
        } => {
            // Every output is checked before any work, so that a bad --plot cannot leave the
            // trajectory written and the command failed.
            let inputs = ReadFiles::of([&sequence, &model]);
            check_output(&out)?;
            check_not_input(&out, &inputs, &[])?;
            if let Some(plot) = &plot {
                check_output(plot)?;
                check_not_input(plot, &inputs, &[&out])?;
                ridi::plot::PlotFormat::from_path(plot)?;
            }
            let model = load_model(&model)?;
            let mut loaded = ridi::read_any(&sequence, None, &ReadOptions::default())?;
            for w in &loaded.warnings {
                eprintln!("warning: {w}");
            }
            // The model's orientation, once, so that the plot shows what was tracked.
            apply_orientation(model.feature_config().orientation, &mut loaded.sequences)?;
            let [seq] = &loaded.sequences[..] else {
                bail!(
                    "{} holds {} sequences; convert it with `ridi convert` and track each",
                    sequence.display(),
                    loaded.sequences.len()
                );
            };
            let mut opts = TrackOptions {
                regress_every,
                online,
                placement_smoothing: placement_smoothing(placement_window),
                ..TrackOptions::default()
            };
            opts.correction.lambda = lambda;
            if estimate_initial_velocity {
                opts.correction.initial_velocity = ridi::correct::InitialVelocity::Estimate;
            }
            let track = ridi::track(seq, &model, &opts)
                .with_context(|| format!("cannot track {}", sequence.display()))?;
            // Both outputs are written in full before either replaces a file: the trajectory
            // under a temporary name beside it, then the plot (itself written through a
            // temporary file), then the trajectory renamed into place. A failed write leaves
            // both as they were; only a failed rename, after the plot's, would not.
            let staged = tempfile::Builder::new()
                .prefix(".ridi-track-")
                .suffix(".csv")
                .tempfile_in(folder_of(&out))
                .with_context(|| format!("cannot write {}", out.display()))?
                .into_temp_path();
            track
                .write_csv(&staged)
                .with_context(|| format!("cannot write {}", out.display()))?;
            if let Some(plot) = &plot {
                plot_track(seq, &track, plot)?;
            }
            staged
                .persist(&out)
                .with_context(|| format!("cannot write {}", out.display()))?;
            let n = track.regressions.len();
            outln!(
                "{}: {} frames, {n} regression{} -> {}",
                seq.name(),
                track.time.len(),
                if n == 1 { "" } else { "s" },
                out.display()
            );
            if let Some(plot) = plot {
                outln!("plot: {}", plot.display());
            }
        }
        Command::Eval {
            list,
            model,
            out,
            methods,
            placement_map,
            plots,
            jobs,
            placement_window,
            align,
        } => {
            set_jobs(jobs)?;
            check_eval_output(&out, plots)?;
            let mut chosen: Vec<Method> = Vec::new();
            for m in &methods {
                let m = m.parse::<Method>().map_err(anyhow::Error::msg)?;
                if !chosen.contains(&m) {
                    chosen.push(m);
                }
            }
            let model = load_model(&model)?;
            let listed = load_listed(
                ridi::lists::read_lists(&list)?,
                placement_map.as_deref(),
                Purpose::Evaluation,
            )?;
            let track = TrackOptions {
                placement_smoothing: placement_smoothing(placement_window),
                ..TrackOptions::default()
            };
            evaluate_and_write(
                &listed.seqs,
                &model,
                None,
                chosen,
                track,
                align,
                &out,
                plots,
            )
            .map_err(|e| listed.locate(e))?;
        }
        Command::Demo {
            out,
            data,
            grid,
            plots,
        } => demo(&out, data, grid, plots)?,
    }
    Ok(())
}

/// Refuses an output path that cannot be written: its folder missing, not a folder or not
/// writable, or the path itself a folder. Checked before long work (training, tracking)
/// rather than after it.
fn check_output(path: &Path) -> Result<()> {
    let parent = folder_of(path);
    if !parent.is_dir() {
        bail!(
            "cannot write {}: the folder {} does not exist",
            path.display(),
            parent.display()
        );
    }
    if path.is_dir() {
        bail!("cannot write {}: it is a folder", path.display());
    }
    // Outputs are written through a temporary file beside them.
    probe(parent).map_err(|e| {
        anyhow::anyhow!(
            "cannot write {}: cannot create files in {} ({e})",
            path.display(),
            parent.display()
        )
    })
}

/// Whether new entries can be made in the folder `dir`: makes and removes an empty temporary
/// folder there. The error is its kind alone, since the error's own text names the temporary
/// entry, not the output.
fn probe(dir: &Path) -> std::io::Result<()> {
    tempfile::tempdir_in(dir)
        .map(drop)
        .map_err(|e| e.kind().into())
}

/// Refuses, before any work, an evaluation's output folder (and its `plots/` if plots are
/// written) that exists as a file or cannot be written.
fn check_eval_output(out: &Path, plots: Plots) -> Result<()> {
    check_output_folder(out)?;
    if plots != Plots::None {
        check_output_folder(&out.join("plots"))?;
    }
    Ok(())
}

/// Refuses, before any work, an output folder that exists as something else (a file) or
/// could not be written (nor created).
fn check_output_folder(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!(
            "cannot write into {}: it is a file, not a folder",
            dir.display()
        );
    }
    // The folder, or the nearest existing one it would be created in, must take new entries.
    let Some(existing) = dir
        .ancestors()
        .map(|d| {
            if d.as_os_str().is_empty() {
                Path::new(".")
            } else {
                d
            }
        })
        .find(|d| d.exists())
    else {
        return Ok(());
    };
    if !existing.is_dir() {
        bail!(
            "cannot write into {}: {} is a file, not a folder",
            dir.display(),
            existing.display()
        );
    }
    probe(existing).map_err(|e| {
        anyhow::anyhow!(
            "cannot write into {}: cannot create folders in {} ({e})",
            dir.display(),
            existing.display()
        )
    })
}

/// Refuses an output that would replace what the command reads (`inputs`) or another of its
/// outputs (`others`).
fn check_not_input(out: &Path, inputs: &ReadFiles, others: &[&Path]) -> Result<()> {
    if let Some(input) = inputs.overwritten_by(out) {
        bail!(
            "cannot write {}: the command reads it ({}); choose another output",
            out.display(),
            input.display()
        );
    }
    let target = resolved(out);
    if target.is_some() && others.iter().any(|o| resolved(o) == target) {
        bail!("cannot write {}: it is given as two outputs", out.display());
    }
    Ok(())
}

/// `--placement-window` (checked by clap: finite, at least 0): 0 turns the majority vote off.
fn placement_smoothing(window_s: f64) -> Option<PlacementSmoother> {
    (window_s > 0.0).then_some(PlacementSmoother { window_s })
}

fn set_jobs(jobs: Option<usize>) -> Result<()> {
    if let Some(n) = jobs {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n.max(1))
            .build_global()
            .context("cannot set up the worker threads")?;
    }
    Ok(())
}

/// The listed sequences, each with the list entry it was read from.
struct Listed {
    seqs: Vec<Sequence>,
    entries: Vec<ListEntry>,
}

impl Listed {
    /// Adds the list file and line to an error about one listed sequence (found after loading,
    /// as too short a recording), which names the sequence only.
    fn locate(&self, e: anyhow::Error) -> anyhow::Error {
        let Some(PipelineError::Sequence { sequence, .. }) = e.downcast_ref::<PipelineError>()
        else {
            return e;
        };
        // Only where the name is the one sequence's (training allows recordings of one name).
        let mut named = self
            .seqs
            .iter()
            .enumerate()
            .filter(|(_, s)| s.name() == sequence);
        match (named.next(), named.next()) {
            (Some((i, _)), None) => e.context(self.entries[i].location().to_string()),
            _ => e,
        }
    }
}

fn load_listed(entries: Vec<ListEntry>, map: Option<&str>, purpose: Purpose) -> Result<Listed> {
    let map = map.map(PlacementMap::from_arg).transpose()?;
    let seqs = ridi::lists::load_listed(&entries, map.as_ref(), purpose, &ReadOptions::default())?;
    Ok(Listed { seqs, entries })
}

fn load_model(path: &Path) -> Result<Cascade> {
    Cascade::load(path).with_context(|| format!("cannot load model {}", path.display()))
}

fn bar(len: u64) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template("{prefix:>24} [{bar:30}] {pos}/{len} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar
}

fn train_with_progress(seqs: &[Sequence], opts: &TrainOptions) -> Result<Cascade> {
    let bar = bar(0);
    let mut progress = |e: &ProgressEvent<'_>| {
        let stage = match e.stage {
            Stage::Classifier => "placement classifier".to_string(),
            Stage::Grid { placement } => format!("grid {placement}"),
            Stage::Regressors { placement } => format!("regressors {placement}"),
        };
        bar.set_prefix(stage);
        bar.set_length(e.total as u64);
        bar.set_position(e.done as u64);
        true
    };
    let model = ridi::train(seqs, opts, &mut progress)?;
    bar.finish_and_clear();
    Ok(model)
}

fn print_training(model: &Cascade) {
    out!("{}", ridi::inspect::inspect_model(model));
}

/// `true` for a `.ridi` file, or a file that starts like a model file or is a model file's
/// first bytes cut short (recordings never are): loading it then says what is wrong with it.
fn is_model_file(path: &Path) -> bool {
    use std::io::Read;
    // A `.ridi` file is meant as a model: if it is none, say so, not which data it is not.
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ridi"))
        && path.is_file()
    {
        return true;
    }
    let Ok(file) = std::fs::File::open(path) else {
        return false;
    };
    let mut head = Vec::new();
    let magic = &MODEL_MAGIC;
    file.take(magic.len() as u64).read_to_end(&mut head).is_ok()
        && !head.is_empty()
        && magic.starts_with(&head)
}

fn plot_track(seq: &Sequence, track: &ridi::Track, path: &Path) -> Result<()> {
    use ridi::plot::{Trajectory, TrajectoryOptions, TrajectoryPlot, plot_trajectories};
    let est = track.horizontal();
    let gt = seq.ground_truth().map(|gt| gt.horizontal());
    // With ground truth, show the estimate aligned on the first 10 s, as evaluations do.
    let shown = match &gt {
        Some(gt) => ridi::eval::align_trajectory(seq.time(), &est, gt, Default::default())?.1,
        None => est,
    };
    let estimates = [Trajectory {
        name: "ridi",
        points: &shown,
    }];
    plot_trajectories(
        path,
        &TrajectoryPlot {
            title: seq.name(),
            ground_truth: gt.as_deref().map(|points| Trajectory {
                name: "ground truth",
                points,
            }),
            estimates: &estimates,
        },
        &TrajectoryOptions::default(),
    )?;
    Ok(())
}

/// Evaluates `seqs`, then writes the reports, the plots and, if `model_name` is given, the
/// model under that name into `out` all or nothing ([`Staging`]): a failure on the way leaves
/// `out` as it was. (The staging folder exists only while the files are written, so a killed
/// evaluation leaves nothing behind.)
#[allow(clippy::too_many_arguments)]
fn evaluate_and_write(
    seqs: &[Sequence],
    model: &Cascade,
    model_name: Option<&str>,
    methods: Vec<Method>,
    track: TrackOptions,
    align: AlignWindow,
    out: &Path,
    plots: Plots,
) -> Result<ridi::Report> {
    let opts = EvalOptions {
        methods,
        track,
        metrics: EvalConfig {
            align,
            ..EvalConfig::default()
        },
    };
    let ext = match plots {
        Plots::Png => Some("png"),
        Plots::Svg => Some("svg"),
        Plots::None => None,
    };
    let plot_dir = out.join("plots");
    // Read before report.json is replaced: whose plots an earlier evaluation wrote.
    let mut plotted = earlier_sequences(out);
    plotted.extend(seqs.iter().map(|s| s.name().to_string()));
    let spinner = ProgressBar::new_spinner();
    spinner.set_message(format!("evaluating {} sequences", seqs.len()));
    spinner.enable_steady_tick(std::time::Duration::from_millis(200));
    let (report, traces) = ridi::evaluate(seqs, model, &opts)?;
    spinner.finish_and_clear();
    let staging =
        Staging::new(out).with_context(|| format!("cannot write into {}", out.display()))?;
    if let Some(name) = model_name {
        let path = staging.file(Path::new(name))?;
        model
            .save(&path)
            .with_context(|| format!("cannot write {}", out.join(name).display()))?;
    }
    let mut written = Vec::new();
    if let Some(ext) = ext {
        let staged = staging.dir(Path::new("plots"))?;
        for t in &traces {
            for file in t.plot(&staged, ext)? {
                written.extend(file.file_name().map(|name| plot_dir.join(name)));
            }
        }
    }
    let reports = report.write(&staging.dir(Path::new(""))?)?.len();
    staging.commit()?;
    // The new report is in place: an old plot that cannot go is worth a warning, not a failure.
    let stale = remove_stale_plots(&plot_dir, &plotted, &written).unwrap_or_else(|e| {
        eprintln!("warning: {}", one_line(&e));
        0
    });
    print_summary(&report);
    outln!(
        "wrote {} files into {} (report.md, report.json{}){}",
        written.len() + reports,
        out.display(),
        if ext.is_some() { ", plots/" } else { "" },
        if stale > 0 {
            format!("; removed {stale} plots of an earlier evaluation from plots/")
        } else {
            String::new()
        }
    );
    Ok(report)
}

/// The sequences of the `report.json` an earlier evaluation left in `out` (none when there is
/// none, or it cannot be read: it only decides which old plots may go).
fn earlier_sequences(out: &Path) -> Vec<String> {
    let Ok(text) = std::fs::read_to_string(out.join("report.json")) else {
        return Vec::new();
    };
    let Ok(json) = serde_json::from_str::<serde_json::Value>(&text) else {
        return Vec::new();
    };
    json["sequences"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|s| s["name"].as_str().map(str::to_string))
        .collect()
}

/// Removes the plots an earlier evaluation left in `dir` that this one did not write (other
/// sequences, the other format, or `--plots none`), so that the folder matches the report.
/// Only the plot files of `sequences` (those of the earlier report and of this evaluation)
/// are touched, so other files in `dir` stay; `dir` goes if that empties it.
fn remove_stale_plots(dir: &Path, sequences: &[String], written: &[PathBuf]) -> Result<usize> {
    let mut removed = 0;
    // A name that is not a plain file name (an edited report.json) must not reach outside.
    let plain = |name: &&String| Path::new(name.as_str()).file_name() == Some(name.as_ref());
    for name in sequences.iter().filter(plain) {
        for kind in ["trajectory", "velocity"] {
            for ext in ["png", "svg"] {
                let path = dir.join(format!("{name}.{kind}.{ext}"));
                if path.is_file() && !written.contains(&path) {
                    std::fs::remove_file(&path)
                        .with_context(|| format!("cannot remove {}", path.display()))?;
                    removed += 1;
                }
            }
        }
    }
    // Only succeeds when nothing else is in the folder.
    let _ = std::fs::remove_dir(dir);
    Ok(removed)
}

/// Largest `--turned-copies`: copy `j` of a window is turned by `j / N` of a full turn, so a few
/// dozen copies already cover the circle every few degrees, while each copy costs a full set of
/// training rows (memory and time grow without limit).
const MAX_TURNED_COPIES: usize = 32;

/// Largest `--step` and `--regress-every`: one minute at 200 Hz. Windows further apart leave
/// too few training rows, or too few regressions for the correction, to mean anything.
const MAX_FRAMES_APART: usize = 12_000;

/// Smallest `--window`: 0.1 s at 200 Hz, about the feature smoothing's kernel (17 taps at sigma 2).
const MIN_WINDOW: usize = 20;

/// Largest `--window`: 3 s at 200 Hz. Features grow with the window (3,600 values here, 1,200
/// for the paper's 1 s), and so do their memory and the projected storage's covariance and
/// eigendecomposition (quadratic and cubic in it); 400 frames were measured, and were worse.
const MAX_WINDOW: usize = 600;

/// A whole number in `min..=max`, for clap.
fn count(text: &str, min: usize, max: usize) -> std::result::Result<usize, String> {
    match text.parse::<usize>() {
        Ok(n) if (min..=max).contains(&n) => Ok(n),
        _ => Err(format!(
            "`{text}` is not a whole number from {min} to {max}"
        )),
    }
}

/// A finite number above 0, for clap.
fn positive(text: &str) -> std::result::Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("`{text}` is not a finite number above 0")),
    }
}

/// `--rate`: 1 Hz to 10 kHz, the frame intervals (1 s to 0.1 ms) the readers accept
/// (`ridi_data::Validation::time_step_range`); phone sensors deliver 5-500 Hz.
fn rate_hz(text: &str) -> std::result::Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if (1.0..=10_000.0).contains(&x) => Ok(x),
        _ => Err(format!(
            "`{text}` is not a rate of 1 to 10000 Hz (frames 1 s to 0.1 ms apart)"
        )),
    }
}

/// A finite number of at least 0, for clap.
fn non_negative(text: &str) -> std::result::Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && x >= 0.0 => Ok(x),
        _ => Err(format!("`{text}` is not a finite number of at least 0")),
    }
}

/// `--align`: seconds, or `all` for the whole run.
fn parse_align(text: &str) -> std::result::Result<AlignWindow, String> {
    if text.eq_ignore_ascii_case("all") {
        return Ok(AlignWindow::All);
    }
    match text.parse::<f64>() {
        Ok(s) if s.is_finite() && s > 0.0 => Ok(AlignWindow::Seconds(s)),
        _ => Err(format!(
            "`{text}` is neither a positive number of seconds nor `all`"
        )),
    }
}

fn print_summary(report: &ridi::Report) {
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    let weak = report
        .sequences
        .iter()
        .filter(|s| s.alignment_extent_m < ridi::eval::WEAK_ALIGNMENT_EXTENT_M)
        .count();
    if weak > 0 {
        eprintln!(
            "warning: in {weak} of {} sequences the ground truth moves less than {} m within the \
             alignment window, so their fitted heading is weakly determined (listed in report.md)",
            report.sequences.len(),
            ridi::eval::WEAK_ALIGNMENT_EXTENT_M
        );
    }
    outln!(
        "\n{} sequences; velocity MSE S-x {:.3} S-z {:.3} (m/s)^2; placement accuracy {}",
        report.sequences.len(),
        report.velocity_mse[0],
        report.velocity_mse[1],
        report
            .placement_accuracy
            .map_or("-".into(), |a| format!("{a:.3}"))
    );
    outln!(
        "{:<10} {:>9} {:>9} {:>9} {:>9} {:>11}",
        "method",
        "RTE 5s m",
        "ATE m",
        "RTE m",
        "MPE m",
        "path ratio"
    );
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
    for key in &report.methods {
        if let Some(m) = report.summary.get(key) {
            outln!(
                "{key:<10} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>11}",
                m.rte_5s_m,
                m.ate_m,
                m.rte_m,
                m.mpe_m,
                opt(m.path_length_ratio)
            );
        }
    }
}

fn demo(out: &Path, data: Option<PathBuf>, grid: Grid, plots: Plots) -> Result<()> {
    let data = match data {
        Some(d) => d,
        None => {
            let here = PathBuf::from("datasets/sample");
            if here.join("list_train.txt").is_file() {
                here
            } else {
                Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets/sample")
            }
        }
    };
    let train_list = data.join("list_train.txt");
    if !train_list.is_file() {
        bail!(
            "no bundled sample at {} (give its folder with --data)",
            data.display()
        );
    }
    // Before training: an output folder that cannot be written fails in a second, not after it.
    check_eval_output(out, plots)?;
    let map = Some("tyrex4");
    let train_entries = ridi::lists::read_lists(&[train_list])?;
    let test_entries = ridi::lists::read_lists(&[data.join("list_test.txt")])?;
    // Held out means held out: no recording on both lists.
    ridi::data::check_entries(&[train_entries.as_slice(), &test_entries].concat())?;
    let train = load_listed(train_entries, map, Purpose::Training)?;
    let test = load_listed(test_entries, map, Purpose::Evaluation)?;
    // Also not as a copy in another folder or format (the paths above differ).
    ridi::data::check_distinct((&train.seqs, &train.entries), (&test.seqs, &test.entries))?;
    outln!(
        "demo: training on {} sequences ({:.0} s), testing on {} held-out sequences",
        train.seqs.len(),
        train.seqs.iter().map(|s| s.duration()).sum::<f64>(),
        test.seqs.len()
    );
    let mut opts = TrainOptions::default();
    opts.cascade.regressors = GridChoice::from(grid).regressors();
    // A held-out run that cannot be evaluated fails before the training, not after it.
    for seq in &test.seqs {
        ridi::evaluate::check_evaluable(seq, &opts.features, &EvalOptions::default())
            .map_err(|e| test.locate(e.into()))?;
    }
    let started = std::time::Instant::now();
    let model = train_with_progress(&train.seqs, &opts).map_err(|e| train.locate(e))?;
    outln!("trained in {:.1} s", started.elapsed().as_secs_f64());
    print_training(&model);
    evaluate_and_write(
        &test.seqs,
        &model,
        Some("model.ridi"),
        Method::ALL.to_vec(),
        TrackOptions::default(),
        AlignWindow::default(),
        out,
        plots,
    )
    .map_err(|e| test.locate(e))?;
    Ok(())
}

/// One line: the outermost context and every cause, as users asked for. Errors that already
/// print their source in their own message are not repeated.
fn one_line(e: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if line.contains(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    line
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", one_line(&e));
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An error that prints its source in its own message, as many thiserror variants do.
    #[derive(Debug)]
    struct Wrapping(std::io::Error);

    impl std::fmt::Display for Wrapping {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "i/o error on m.ridi.tmp: {}", self.0)
        }
    }

    impl std::error::Error for Wrapping {
        fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
            Some(&self.0)
        }
    }

    /// Only the plots of the named sequences go, and only inside the folder, whatever an
    /// edited or corrupt report.json names.
    #[test]
    fn stale_plots_are_those_of_named_sequences_inside_the_folder() {
        let dir = tempfile::tempdir().unwrap();
        let plots = dir.path().join("plots");
        std::fs::create_dir_all(&plots).unwrap();
        let file = |p: &Path| {
            std::fs::write(p, "x").unwrap();
            p.to_path_buf()
        };
        let outside = file(&dir.path().join("x.trajectory.png"));
        let old = file(&plots.join("a.velocity.svg"));
        let kept = file(&plots.join("a.trajectory.png"));
        let mine = file(&plots.join("b.trajectory.png"));
        std::fs::write(
            dir.path().join("report.json"),
            r#"{"sequences":[{"name":"a"},{"name":"../x"},{"name":""},{"x":1}]}"#,
        )
        .unwrap();
        let names = earlier_sequences(dir.path());
        assert_eq!(names, ["a", "../x", ""]);
        assert_eq!(
            remove_stale_plots(&plots, &names, std::slice::from_ref(&kept)).unwrap(),
            1
        );
        assert!(!old.exists() && kept.exists() && mine.exists() && outside.exists());
        // A report.json that is not JSON, or none, names nothing.
        std::fs::write(dir.path().join("report.json"), "{ cut").unwrap();
        assert!(earlier_sequences(dir.path()).is_empty());
        assert!(earlier_sequences(&plots).is_empty());
    }

    #[test]
    fn one_line_does_not_repeat_a_cause_already_in_the_message() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "No such file or directory");
        let e = anyhow::Error::new(Wrapping(io)).context("cannot write m.ridi");
        assert_eq!(
            one_line(&e),
            "cannot write m.ridi: i/o error on m.ridi.tmp: No such file or directory"
        );
        let plain = anyhow::anyhow!("inner").context("outer");
        assert_eq!(one_line(&plain), "outer: inner");
    }
}
