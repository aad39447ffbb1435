//! `ridi train`: the placement classifier and velocity regressors, from labelled recordings.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};

use ridi::ReadFiles;
use ridi::data::{ListEntry, shown};
use ridi::features::{FeatureConfig, Orientation};
use ridi::frames::UpAxis;
use ridi::regress::{Cascade, Nystrom, ProgressEvent, RegressError, Solver, Stage, Storage};
use ridi::{GridChoice, PipelineError, Purpose, TrainOptions, check_not_input, check_output_file};

use crate::{Grid, MAX_FRAMES_APART, count, positive};

#[derive(clap::Args)]
pub(crate) struct Args {
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
    /// Orientation to train and track with: estimated from gyro + accelerometer, or as
    /// recorded (the original RIDI). The estimate gives longer, straighter tracks where the
    /// recorded one uses the magnetometer indoors and lower velocity errors on the iPhone
    /// (docs/bench-devices.md). The model records it: `ridi track` and `ridi eval` use the
    /// same.
    #[arg(long, value_enum, default_value = "estimated")]
    orientation: OrientationArg,
    /// How the model stores its samples for prediction.
    #[arg(long, value_enum, default_value = "projected")]
    storage: StorageArg,
    /// How the kernel machines are trained: `exact` (SMO, the paper's), or `nystrom`, which
    /// approximates the RBF kernel on --landmarks rows per machine, with a linear classifier
    /// and kernel ridge regressors on those features: training time and memory linear in the
    /// rows, a model and a query that do not grow with them, within 0.08 m RTE 5 s of the
    /// exact solver on the Tyrex protocol (docs/benchmarks.md).
    #[arg(long, value_enum, default_value = "exact")]
    solver: SolverArg,
    /// Landmarks per machine of `--solver nystrom` (rows drawn at random with `--seed`:
    /// the classifier's from all rows, each placement's regressors' from its own), 2 to 16384:
    /// more approximate the kernel machines more closely, at a cost per query linear in them
    /// and in training quadratic. Default 2048; only with `--solver nystrom`.
    #[arg(long, value_name = "N", value_parser = |s: &str| count(s, 2, Nystrom::MAX_LANDMARKS))]
    landmarks: Option<usize>,
    /// Seed of training's random draws (the grid's folds; with `--solver nystrom`, its
    /// landmarks and its classifier's sweep order): models trained with other seeds show how
    /// much a result owes to them. The exact solver with `--grid none` draws nothing, so the
    /// seed changes nothing there.
    #[arg(long, value_name = "N", default_value_t = 0)]
    seed: u64,
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
    #[arg(long, value_parser = |s: &str| count(s, 1, ridi::MAX_JOBS))]
    pub(crate) jobs: Option<usize>,
}

/// Largest `--turned-copies`: copy `j` of a window is turned by `j / N` of a full turn, so a few
/// dozen copies already cover the circle every few degrees, while each copy costs a full set of
/// training rows (memory and time grow without limit).
const MAX_TURNED_COPIES: usize = 32;

/// Smallest `--window`: 0.1 s at 200 Hz, about the feature smoothing's kernel (17 taps at sigma 2).
const MIN_WINDOW: usize = 20;

/// Largest `--window`: 3 s at 200 Hz. Features grow with the window (3,600 values here, 1,200
/// for the paper's 1 s), and so do their memory and the projected storage's covariance and
/// eigendecomposition (quadratic and cubic in it); 400 frames were measured, and were worse.
const MAX_WINDOW: usize = 600;

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
    /// times faster queries; velocities move by about as much as half precision moves them);
    /// with `--solver nystrom`, whose kernel is computed on them, 90 %.
    Projected,
    /// Every feature value in half precision.
    Half,
}

impl StorageArg {
    fn storage(self, solver: &Solver) -> Storage {
        match self {
            StorageArg::Projected => Storage::projected_for(solver),
            StorageArg::Half => Storage::Half,
        }
    }
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
enum SolverArg {
    /// The exact kernel machines (SMO).
    Exact,
    /// Nyström approximation: linear machines on kernel features of the landmarks.
    Nystrom,
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

/// Rows above which `ridi train` points the exact solver's user to `--solver nystrom`: the
/// exact solver took 80 s on 49,884 rows and 34-37 min on 99,716 (2 cores, the latter with
/// other work running; docs/benchmarks.md, "Training at scale: the Nyström solver" and the
/// sample step's lever row).
const EXACT_SOLVER_NOTE_ROWS: usize = 60_000;

/// The one-line note for `windows` training rows on the exact solver, if they are many.
fn exact_solver_note(windows: usize) -> Option<String> {
    (windows > EXACT_SOLVER_NOTE_ROWS).then(|| {
        format!(
            "note: {windows} training windows: the exact solver's time grows faster than their \
             square (on 2 cores 49884 took 80 s, 99716 over 30 min); `--solver nystrom` trains \
             in time linear in them (99716 in 40 s) for 0.03-0.08 m more RTE 5 s on the Tyrex \
             protocol (docs/benchmarks.md)"
        )
    })
}

/// Flags that contradict each other, which clap's own rules cannot see (`--solver` has a
/// default): a usage error, exit code 2, as clap's.
pub(crate) fn usage_error(args: &Args) -> Option<&'static str> {
    (args.landmarks.is_some() && matches!(args.solver, SolverArg::Exact)).then_some(
        "--landmarks is for --solver nystrom: the exact solver keeps every training window",
    )
}

pub(crate) fn run(args: Args) -> Result<()> {
    let out = &args.out;
    check_output_file(out)?;
    let entries = ListEntry::read(&args.list)?;
    let mut read = args.list.clone();
    read.extend(entries.iter().map(|e| e.path.clone()));
    // A map file is read too (a named map such as `tyrex4` names no file there).
    read.extend(args.placement_map.iter().map(PathBuf::from));
    check_not_input(out, &ReadFiles::of(&read), &[])?;
    let listed = crate::load_listed(entries, args.placement_map.as_deref(), Purpose::Training)?;
    for w in ridi::training_warnings(listed.sequences()) {
        errln!("warning: {}", shown(&w));
    }
    let defaults = TrainOptions::default();
    let mut opts = TrainOptions {
        standardize: !args.no_standardize,
        turned_copies: args.turned_copies,
        features: FeatureConfig {
            step: args.step.unwrap_or(ridi::default_step(args.turned_copies)),
            window: args.window.unwrap_or(defaults.features.window),
            up_axis: args.up_axis.into(),
            orientation: args.orientation.into(),
            ..defaults.features.clone()
        },
        ..defaults
    };
    opts.cascade.classifier_c = args.classifier_c;
    opts.cascade.regressors = GridChoice::from(args.grid).regressors();
    opts.cascade.speed = !args.no_speed;
    opts.cascade.solver = match args.solver {
        SolverArg::Exact => Solver::Exact,
        SolverArg::Nystrom => Solver::Nystrom(Nystrom::new(
            args.landmarks.unwrap_or(Nystrom::DEFAULT_LANDMARKS),
            0,
        )?),
    };
    opts.cascade.set_seed(args.seed);
    opts.cascade.storage = args.storage.storage(&opts.cascade.solver);
    if opts.cascade.solver == Solver::Exact {
        let windows = ridi::training_windows(listed.sequences(), &opts)?;
        if let Some(note) = exact_solver_note(windows) {
            errln!("{note}");
        }
    }
    let model = with_progress(|progress| ridi::train(listed.sequences(), &opts, progress))
        .map_err(|e| {
            let e = e.locate_in(&listed);
            let folds = matches!(
                e,
                PipelineError::Regress(RegressError::TooFewSequences { .. })
            );
            let e = anyhow::Error::from(e);
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
    ridi::save_model(&model, out).with_context(|| format!("cannot write {}", shown(out)))?;
    outln!("model: {}", shown(out));
    Ok(())
}

/// Runs `train` with a progress bar (on stderr) that follows its stages.
pub(crate) fn with_progress(
    train: impl FnOnce(&mut dyn ridi::regress::Progress) -> ridi::Result<Cascade>,
) -> ridi::Result<Cascade> {
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{prefix:>24} [{bar:30}] {pos}/{len} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let mut progress = |e: &ProgressEvent<'_>| {
        let stage = match e.stage {
            Stage::Classifier => "placement classifier".to_string(),
            Stage::Grid { placement } => format!("grid {}", shown(placement)),
            Stage::Regressors { placement } => format!("regressors {}", shown(placement)),
        };
        bar.set_prefix(stage);
        bar.set_length(e.total as u64);
        bar.set_position(e.done as u64);
        true
    };
    let model = train(&mut progress)?;
    bar.finish_and_clear();
    Ok(model)
}

/// What the trained model is, as `ridi inspect` says it.
pub(crate) fn print_training(model: &Cascade) {
    out!("{}", ridi::inspect_model(model));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_exact_solver_note_names_the_rows_and_the_way_out_only_past_the_bound() {
        assert_eq!(exact_solver_note(EXACT_SOLVER_NOTE_ROWS), None);
        let note = exact_solver_note(99_716).unwrap();
        assert!(note.starts_with("note: 99716 training windows"), "{note}");
        assert!(
            note.contains("`--solver nystrom`") && !note.contains('\n'),
            "{note}"
        );
    }
}
