//! `ridi convert`: recordings to the RIDI processed layout, with list files.

use std::path::PathBuf;

use anyhow::Result;

use ridi::data::{Format, ReadOptions, shown};

#[derive(clap::Args)]
pub(crate) struct Args {
    /// A sequence (file or folder), a folder of sequences (RIDI, RoNIN), a Tyrex dataset root,
    /// or a folder searched for Indoor Location Competition path files.
    source: PathBuf,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Source format (detected when omitted).
    #[arg(long, value_name = "FORMAT", value_parser = from_format())]
    from: Option<Format>,
    /// Resample every sequence to this rate, 1.001 to 9990 Hz (linear interpolation, slerp
    /// for rotations); a gap longer than 5 frame intervals is refused: split it first
    /// (--split-at-gaps).
    #[arg(long, value_name = "HZ", value_parser = rate_hz)]
    rate: Option<f64>,
    /// Cut every sequence at each gap longer than this (before --rate), into parts named
    /// `<name>_part1`, `_part2`, ... (the plain name when one is left); parts shorter than 1 s
    /// are dropped with a warning. 0.1 cuts where `ridi track` refuses a gap. Below 1 s: a
    /// recording paused for longer is read across its pauses and cut at them (processed files,
    /// Tyrex, the competition's paths; a RIDI raw or RoNIN folder paused that long is refused).
    #[arg(long, value_name = "SECONDS", value_parser = gap_s)]
    split_at_gaps: Option<f64>,
}

/// `--from`: a [`Format`] by its key (`ridi-csv`, ...), each listed in `--help` with what
/// `ridi convert` takes of it.
fn from_format() -> impl clap::builder::TypedValueParser<Value = Format> {
    use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser as _};
    PossibleValuesParser::new(Format::ALL.map(|f| PossibleValue::new(f.key()).help(from_help(f))))
        .try_map(|key| key.parse::<Format>())
}

fn from_help(format: Format) -> &'static str {
    match format {
        Format::RidiCsv => {
            "RIDI processed data.csv (or data_plain.txt where a folder has no data.csv)"
        }
        Format::RidiPlain => {
            "RIDI processed data_plain.txt (also of a folder that has a data.csv, which detection \
             prefers)"
        }
        Format::RidiRaw => "RIDI raw recorder folder (gyro.txt, acce.txt, ..., pose.txt)",
        Format::Tyrex => "Tyrex smartphone benchmark (a run folder or the dataset root)",
        Format::Ilc => {
            "Indoor Location Competition 2.0 path files (a file, or a folder searched recursively)"
        }
        Format::Ronin => {
            "RoNIN sequence folders (data.hdf5 and info.json; one, or a folder of them)"
        }
    }
}

/// `--rate`: within [`ridi::data::RESAMPLE_RATE_RANGE_HZ`], the rates whose frames the readers accept
/// (less than 1 s apart, at least 0.1 ms in the median); phone sensors deliver 5-500 Hz.
fn rate_hz(text: &str) -> std::result::Result<f64, String> {
    let (min, max) = ridi::data::RESAMPLE_RATE_RANGE_HZ;
    match text.parse::<f64>() {
        Ok(x) if (min..=max).contains(&x) => Ok(x),
        _ => Err(format!(
            "`{text}` is not a rate from {min} to {max} Hz: resampled frames must be less than \
             1 s apart (the longest gap a recording may have) and at least 0.1 ms apart (the \
             shortest step the readers accept)"
        )),
    }
}

/// `--split-at-gaps`: a positive number of seconds below the readers' longest gap (1 s), or
/// nothing would ever be cut.
fn gap_s(text: &str) -> std::result::Result<f64, String> {
    let max = ReadOptions::default().validation.max_gap_s;
    match text.parse::<f64>() {
        Ok(x) if x > 0.0 && x < max => Ok(x),
        _ => Err(format!(
            "`{text}` is not a number of seconds above 0 and below {max} (the longest gap the \
             readers accept)"
        )),
    }
}

pub(crate) fn run(
    Args {
        source,
        out,
        from,
        rate,
        split_at_gaps,
    }: Args,
) -> Result<()> {
    let opts = ridi::ConvertOptions {
        from,
        read: ReadOptions::default(),
        rate_hz: rate,
        split_at_gaps_s: split_at_gaps,
    };
    ridi::check_output_folder(&out)?;
    let summary = ridi::convert(&source, &out, &opts)?;
    for w in &summary.warnings {
        errln!("warning: {}", shown(w));
    }
    for c in &summary.sequences {
        outln!(
            "{}  {}",
            shown(&c.path),
            c.placement.as_deref().map_or("-".into(), shown)
        );
    }
    for l in &summary.lists {
        outln!("list: {}", shown(l));
    }
    if let Some(w) = &summary.warnings_file {
        outln!("warnings: {}", shown(w));
    }
    Ok(())
}
