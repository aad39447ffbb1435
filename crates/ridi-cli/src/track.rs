//! `ridi track`: one recording with a trained model, one pose per frame.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};

use ridi::ReadFiles;
use ridi::data::{ReadOptions, counted, shown};
use ridi::{PipelineError, TrackOptions, TrackOutput, apply_orientation};

use crate::{Heading, MAX_FRAMES_APART, count, non_negative, placement_smoothing, positive};

#[derive(clap::Args)]
pub(crate) struct Args {
    /// A RIDI data.csv, data_plain.txt, raw folder, Tyrex run, Indoor Location Competition
    /// path file, or RoNIN sequence folder (data.hdf5, info.json).
    sequence: PathBuf,
    /// Model file from `ridi train` [default: the bundled model, trained on every shared
    /// Tyrex run; docs/model-card.md].
    #[arg(long)]
    model: Option<PathBuf>,
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
    /// With a model on the estimated orientation: `corrected` turns the gyro's heading onto
    /// the slow part of the recorded orientation's, so that its drift does not bend the track
    /// (resets and magnetic corrections pass at 0.1 rad/s at most); `gyro` keeps the gyro's
    /// heading. A model on the recorded orientation tracks with that.
    #[arg(long, value_enum, default_value = "corrected")]
    heading: Heading,
}

pub(crate) fn run(args: Args) -> Result<()> {
    // Every output is checked before any work, so that a bad --plot cannot leave the
    // trajectory written and the command failed.
    let inputs = ReadFiles::of(std::iter::once(&args.sequence).chain(&args.model));
    let mut output = TrackOutput::new(&args.out, &inputs)?;
    if let Some(plot) = &args.plot {
        output = output.with_plot(plot, &inputs)?;
    }
    let model = crate::model_or_bundled(args.model.as_deref())?;
    let opts = track_options(&args);
    // Online, a recording that streams is tracked as it is read, in memory that does not grow
    // with its length but for a plot's points.
    if args.online && ridi::data::detect(&args.sequence).is_ok_and(|f| f.streams()) {
        let rows = ridi::data::RowReader::open(&args.sequence, &ReadOptions::default())?;
        let track = output
            .write_stream(rows, &model, &opts)
            .map_err(|e| match e {
                e @ (PipelineError::Data(_) | PipelineError::Output(_)) => anyhow::Error::from(e),
                e => anyhow::Error::from(e)
                    .context(format!("cannot track {}", shown(&args.sequence))),
            })?;
        print_tracked(&args, &track.name, track.frames, track.regressions);
        return Ok(());
    }
    let mut loaded = ridi::read_any(&args.sequence, None, &ReadOptions::default())?;
    for w in &loaded.warnings {
        errln!("warning: {}", shown(w));
    }
    // The model's orientation, once, so that the plot shows what was tracked.
    apply_orientation(
        model.feature_config().orientation,
        opts.recorded_heading.as_ref(),
        &mut loaded.sequences,
    )?;
    let [seq] = &loaded.sequences[..] else {
        let names = loaded.sequences.iter().map(|s| shown(s.name()));
        bail!(
            "{} holds {} (cut at gaps in the recording: {}): `ridi convert {} --out <folder>` \
             writes each as a recording of its own, to track one by one",
            shown(&args.sequence),
            ridi::data::counted(loaded.sequences.len(), "sequence"),
            ridi::data::first_few(names, 3),
            shell_word(&shown(&args.sequence)),
        );
    };
    let track = ridi::track(seq, &model, &opts)
        .with_context(|| format!("cannot track {}", shown(&args.sequence)))?;
    output.write(seq, &track)?;
    print_tracked(&args, seq.name(), track.time.len(), track.regressions.len());
    Ok(())
}

/// Prints what was tracked, `frames` frames of `name` with `n` regressions, and where it went.
fn print_tracked(args: &Args, name: &str, frames: usize, n: usize) {
    outln!(
        "{}: {}, {} -> {}",
        shown(name),
        counted(frames, "frame"),
        counted(n, "regression"),
        shown(&args.out)
    );
    if let Some(plot) = &args.plot {
        outln!("plot: {}", shown(plot));
    }
}

/// The tracking options `args` ask for.
fn track_options(args: &Args) -> TrackOptions {
    let mut opts = TrackOptions {
        regress_every: args.regress_every,
        online: args.online,
        placement_smoothing: placement_smoothing(args.placement_window),
        recorded_heading: args.heading.recorded_heading(),
        ..TrackOptions::default()
    };
    opts.correction.lambda = args.lambda;
    if args.estimate_initial_velocity {
        opts.correction.initial_velocity = ridi::correct::InitialVelocity::Estimate;
    }
    opts
}

/// `text` as one shell word, to copy into a command line: as it is when no shell treats any of
/// its characters specially, else in single quotes.
fn shell_word(text: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "/._-+,:@%=".contains(c);
    if !text.is_empty() && text.chars().all(plain) {
        text.to_string()
    } else {
        format!("'{}'", text.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::shell_word;

    #[test]
    fn a_path_is_one_shell_word() {
        assert_eq!(shell_word("runs/a_b-1.csv"), "runs/a_b-1.csv");
        assert_eq!(shell_word("my runs/x"), "'my runs/x'");
        assert_eq!(shell_word("it's"), r"'it'\''s'");
        assert_eq!(shell_word(""), "''");
    }
}
