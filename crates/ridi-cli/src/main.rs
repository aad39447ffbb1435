//! The `ridi` command line. Thin: the arguments (one module per command, with its argument
//! types), progress bars, printing, and errors as one line and an exit code. What is read,
//! checked and written, and how, is the `ridi` library's (its output policy and [`ridi::Demo`]).

use std::path::Path;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{CommandFactory, Parser, Subcommand, ValueEnum};

use ridi::correct::PlacementSmoother;
use ridi::data::{ListEntry, Listed, ReadOptions, shown};
use ridi::eval::AlignWindow;
use ridi::regress::Cascade;
use ridi::{EvalPlots, GridChoice, PlacementMap, Purpose};

/// `println!` that ignores a closed stdout (`ridi train ... | head`): the command's results are
/// its files, which must still be written, and printing must never abort it with a panic.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

/// `eprintln!` that ignores a closed or dead stderr (`ridi train ... 2>&1 | head`, a closed
/// terminal): a warning that cannot be shown must not abort the run before its files are
/// written, nor keep the signal handler from exiting.
macro_rules! errln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// `print!` that ignores a closed stdout, as [`outln!`].
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stdout(), $($arg)*);
    }};
}

/// Prints `text`, a command's result, to stdout (`ridi inspect`, `ridi compare`, whose
/// results are no files): a failed write is an error (a full disk under `> out.json` must not
/// pass for success), but a reader that stopped reading (`| head`) is not.
fn print_result(text: &str) -> Result<()> {
    use std::io::Write as _;
    let mut stdout = std::io::stdout().lock();
    match stdout
        .write_all(text.as_bytes())
        .and_then(|()| stdout.flush())
    {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(anyhow::anyhow!("cannot write the result to stdout: {e}"))
        }
        _ => Ok(()),
    }
}

mod compare;
mod convert;
mod demo;
mod eval;
mod inspect;
mod track;
mod train;

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
    Inspect(inspect::Args),
    /// Convert recordings to the RIDI processed layout, with list files.
    #[command(after_help = "Examples:\n  \
        ridi convert ../shared/data/raw/tyrex-attitude-smartphones --out converted\n  \
        ridi convert my_capture/ --from ridi-raw --out converted\n  \
        ridi convert indoor-location-competition-20/data --from ilc --out converted\n  \
        ridi convert phone_at_100hz/ --out converted --rate 200   (train, track and eval need 200 Hz)\n\n\
        Writes <out>/<name>/processed/data.csv per sequence and list files \
        (`path,placement` per line): list_all.txt, list_<device>.txt per device (when the sources name \
        theirs) and, for Tyrex runs, list_<person>.txt per person.")]
    Convert(convert::Args),

    /// Train the placement classifier and velocity regressors on labelled recordings.
    #[command(after_help = "Examples:\n  \
        ridi train --list datasets/sample/list_train.txt --out model.ridi --grid small \
        --placement-map tyrex4\n  \
        ridi train --list ridi/list_train_publish_v2.txt --out ridi.model --grid paper --jobs 2\n  \
        ridi train --list list.txt --out paper.ridi --turned-copies 0 --no-speed --up-axis plus-y   (the paper's cascade; \
        add --no-standardize for the original's raw features)\n\n\
        Every sequence needs ground truth and a placement (the list's second column).")]
    Train(train::Args),
    /// Track a recording with a trained model: one pose per frame.
    #[command(after_help = "Examples:\n  \
        ridi track datasets/sample/Thibaud_Nexus5_NoDist_Texting --model model.ridi --out traj.csv \
        --plot traj.png\n  \
        ridi track capture/ --model model.ridi --out traj.csv --online\n\n\
        The CSV has time,pos_x,pos_y,pos_z,vel_x,vel_y,vel_z,placement,bias_x,bias_y,bias_z \
        (world frame of the device orientation, metres from the start).")]
    Track(track::Args),
    /// Evaluate RIDI and the baselines on labelled recordings: report.json, report.md, plots.
    #[command(after_help = "Examples:\n  \
        ridi eval --list datasets/sample/list_test.txt --model model.ridi --out report \
        --placement-map tyrex4\n  \
        ridi eval --list test.txt --model model.ridi --out report --methods ridi,pdr,still\n  \
        ridi eval --list test.txt --model model.ridi --out report-whole --align all\n\n\
        Methods: ridi, raw, pdr, ridi_mag, ridi_ori, velocity, still.")]
    Eval(eval::Args),
    /// Compare two evaluations of the same sequences: each figure's paired difference.
    #[command(after_help = "Examples:\n  \
        ridi compare eval-before eval-after\n  \
        ridi compare a/report.json b/report.json --json\n\n\
        Pairs the sequences by name: for each method both evaluated and each figure, the means \
        in both and the second minus the first with its 95 % interval (a bootstrap over the \
        runs, from 5 runs on; bold when it leaves out 0).")]
    Compare(compare::Args),
    /// Train on the bundled sample (two people) and evaluate on the held-out person.
    #[command(after_help = "Example:\n  ridi demo --out demo-out\n\n\
        Uses datasets/sample (list_train.txt, list_test.txt) with the four Tyrex placement \
        groups; writes the model, report.json, report.md and plots into --out.")]
    Demo(demo::Args),
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
enum Plots {
    Png,
    Svg,
    None,
}

impl From<Plots> for EvalPlots {
    fn from(p: Plots) -> EvalPlots {
        match p {
            Plots::Png => EvalPlots::Png,
            Plots::Svg => EvalPlots::Svg,
            Plots::None => EvalPlots::None,
        }
    }
}

/// Largest `--step` and `--regress-every`: one minute at 200 Hz. Windows further apart leave
/// too few training rows, or too few regressions for the correction, to mean anything.
const MAX_FRAMES_APART: usize = 12_000;

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

/// `--heading`: where tracking with a model on the estimated orientation takes its heading.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Heading {
    /// The gyro's, its drift corrected by the slow part of the recorded orientation's.
    Corrected,
    /// The gyro's alone.
    Gyro,
}

impl Heading {
    /// [`TrackOptions::recorded_heading`](ridi::TrackOptions::recorded_heading).
    fn recorded_heading(self) -> Option<ridi::frames::HeadingConfig> {
        match self {
            Heading::Corrected => Some(ridi::frames::HeadingConfig::default()),
            Heading::Gyro => None,
        }
    }
}

/// The tracking flags of `ridi track` and `ridi eval`: [`ridi::TrackOptions`].
#[derive(clap::Args)]
pub(crate) struct Tracking {
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
    /// label within it (centred on it; with `ridi track --online` the seconds before it); 0
    /// keeps each window's own label, as in the paper.
    #[arg(long, value_name = "SECONDS", default_value_t = 10.0, value_parser = non_negative)]
    placement_window: f64,
    /// With a model on the estimated orientation: `corrected` turns the gyro's heading onto
    /// the slow part of the recorded orientation's, so that its drift does not bend the track
    /// (resets and magnetic corrections pass at 0.1 rad/s at most); `gyro` keeps the gyro's
    /// heading. A model on the recorded orientation tracks with that.
    #[arg(long, value_enum, default_value = "corrected")]
    heading: Heading,
}

impl Tracking {
    /// The facade's options with these flags (`online` for `ridi track --online`).
    pub(crate) fn options(&self, online: bool) -> ridi::TrackOptions {
        let mut opts = ridi::TrackOptions {
            regress_every: self.regress_every,
            online,
            // 0 (clap checked it is finite and at least 0) turns the majority vote off.
            placement_smoothing: (self.placement_window > 0.0).then_some(PlacementSmoother {
                window_s: self.placement_window,
            }),
            recorded_heading: self.heading.recorded_heading(),
            ..ridi::TrackOptions::default()
        };
        opts.correction.lambda = self.lambda;
        if self.estimate_initial_velocity {
            opts.correction.initial_velocity = ridi::correct::InitialVelocity::Estimate;
        }
        opts
    }
}

/// The worker threads of the whole run, started before any work ([`ridi::start_workers`]):
/// `--jobs` (train, eval), else `RAYON_NUM_THREADS` when set.
fn start_workers(jobs: Option<usize>) -> Result<()> {
    if let Some(warning) = ridi::start_workers(jobs)?.warning {
        errln!("warning: {}", shown(warning));
    }
    Ok(())
}

/// The sequences of the list `entries` for `purpose`, their labels grouped by
/// `--placement-map` when given.
fn load_listed(entries: Vec<ListEntry>, map: Option<&str>, purpose: Purpose) -> Result<Listed> {
    let map = map.map(PlacementMap::from_arg).transpose()?;
    Ok(ridi::load_listed(
        entries,
        map.as_ref(),
        purpose,
        &ReadOptions::default(),
    )?)
}

fn load_model(path: &Path) -> Result<Cascade> {
    Cascade::load(path).map_err(|e| {
        anyhow::Error::from_boxed(e.under(path))
            .context(format!("cannot load model {}", shown(path)))
    })
}

/// The model at `path`, or without one the bundled model, saying so in one line on stderr.
fn model_or_bundled(path: Option<&Path>) -> Result<Cascade> {
    match path {
        Some(p) => load_model(p),
        None => {
            errln!("no --model: using {}", ridi::BUNDLED_MODEL_SUMMARY);
            ridi::bundled_model().context("cannot decode the bundled model")
        }
    }
}

/// One line: the outermost context and every cause, as users asked for
/// ([`ridi::data::one_line`], which the Python package prints too).
fn one_line(e: &anyhow::Error) -> String {
    ridi::data::one_line(e.as_ref())
}

/// Ctrl-C (SIGINT), SIGTERM and SIGHUP: the temporary files and staging folders of the run are
/// removed ([`ridi::data::remove_temporaries_for_exit`], which lets a folder commit under way
/// finish first), then the program exits with 128 + the signal's number (130 for Ctrl-C), as
/// a shell reports a program a signal ended. Signals are the binary's business, not the
/// library's. Without a handler (it could not be installed), a signal ends the program as by
/// default, and the next run removes what it left.
fn clean_up_on_signals() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return;
    };
    let spawned = std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                ridi::data::remove_temporaries_for_exit();
                let name = match signal {
                    SIGINT => "SIGINT",
                    SIGTERM => "SIGTERM",
                    _ => "SIGHUP",
                };
                errln!("error: interrupted ({name}); the run's temporary files are removed");
                std::process::exit(128 + signal);
            }
        });
    drop(spawned);
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if let Command::Train(args) = &cli.command
        && let Some(message) = train::usage_error(args)
    {
        let mut cmd = Cli::command();
        cmd.build();
        let train = cmd.find_subcommand_mut("train").expect("a subcommand");
        train
            .error(clap::error::ErrorKind::ArgumentConflict, message)
            .exit();
    }
    clean_up_on_signals();
    let jobs = match &cli.command {
        Command::Train(args) => args.jobs,
        Command::Eval(args) => args.jobs,
        _ => None,
    };
    let result = start_workers(jobs).and_then(|()| match cli.command {
        Command::Inspect(args) => inspect::run(args),
        Command::Convert(args) => convert::run(args),
        Command::Train(args) => train::run(args),
        Command::Track(args) => track::run(args),
        Command::Eval(args) => eval::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Demo(args) => demo::run(args),
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            errln!("error: {}", shown(one_line(&e)));
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
        let repeated = anyhow::anyhow!("cannot write m.ridi: the folder x does not exist")
            .context("cannot write m.ridi");
        assert_eq!(
            one_line(&repeated),
            "cannot write m.ridi: the folder x does not exist"
        );
    }
}
