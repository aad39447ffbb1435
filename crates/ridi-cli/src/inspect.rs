//! `ridi inspect`: describe a recording or a model file.

use std::path::{Path, PathBuf};

use anyhow::Result;

use ridi::data::ReadOptions;
use ridi::regress::MODEL_MAGIC;

#[derive(clap::Args)]
pub(crate) struct Args {
    /// A RIDI data.csv, data_plain.txt, RIDI raw folder, Tyrex sequence folder, Indoor
    /// Location Competition path file, or a model file of `ridi train`.
    sequence: PathBuf,
    /// Print JSON instead of text: one object, or an array of the parts of a recording
    /// split at its gaps (each with the reader's warnings).
    #[arg(long)]
    json: bool,
}

pub(crate) fn run(Args { sequence, json }: Args) -> Result<()> {
    if is_model_file(&sequence) {
        let model = crate::load_model(&sequence)?;
        let report = ridi::inspect::inspect_model(&model);
        if json {
            outln!("{}", serde_json::to_string_pretty(&report)?);
        } else {
            out!("{report}");
        }
        return Ok(());
    }
    // A recording that streams is summed up as it is read, in memory that does not grow with
    // its length.
    if ridi::data::detect(&sequence).is_ok_and(|f| f.streams()) {
        let rows = ridi::data::RowReader::open(&sequence, &ReadOptions::default())?;
        let report = ridi::inspect::inspect_stream(rows)?;
        if json {
            outln!("{}", serde_json::to_string_pretty(&report)?);
        } else {
            out!("{report}");
        }
        return Ok(());
    }
    let loaded = ridi::read_any(&sequence, None, &ReadOptions::default())?;
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
    Ok(())
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
