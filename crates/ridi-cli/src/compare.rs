//! `ridi compare`: two evaluations of the same sequences, sequence by sequence.

use std::path::PathBuf;

use anyhow::Result;

#[derive(clap::Args)]
pub(crate) struct Args {
    /// The first evaluation: a `ridi eval` output folder, or its report.json.
    first: PathBuf,
    /// The second evaluation, of the same sequences (another model, other flags).
    second: PathBuf,
    /// Print JSON instead of the markdown table.
    #[arg(long)]
    json: bool,
}

pub(crate) fn run(
    Args {
        first,
        second,
        json,
    }: Args,
) -> Result<()> {
    let before = ridi::Report::read(&first)?;
    let after = ridi::Report::read(&second)?;
    let comparison = ridi::compare_reports(&before, &after)?;
    crate::print_result(&if json {
        crate::inspect::json_text(&comparison)?
    } else {
        comparison.to_markdown()
    })
}
