//! `ridi track`: one recording with a trained model, one pose per frame.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};

use ridi::ReadFiles;
use ridi::data::{ReadOptions, counted, shown};
use ridi::{PipelineError, TrackOutput, apply_orientation};

use crate::Tracking;

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
    #[command(flatten)]
    tracking: Tracking,
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
    let opts = args.tracking.options(args.online);
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
    let mut loaded = ridi::read_to_track(&args.sequence, None, &ReadOptions::default())?;
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
