//! `ridi convert`: recordings to the RIDI processed layout, with list files.

use std::path::PathBuf;

use anyhow::Result;
use clap::ValueEnum;

use ridi::data::{Format, ReadOptions};

#[derive(clap::Args)]
pub(crate) struct Args {
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

pub(crate) fn run(
    Args {
        source,
        out,
        from,
        rate,
    }: Args,
) -> Result<()> {
    let opts = ridi::convert::ConvertOptions {
        from: from.map(Format::from),
        read: ReadOptions::default(),
        rate_hz: rate,
    };
    ridi::check_output_folder(&out)?;
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
    Ok(())
}
