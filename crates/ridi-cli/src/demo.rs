//! `ridi demo`: train on the bundled sample and evaluate on its held-out person
//! ([`ridi::Demo`] does the work; this prints it).

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

use ridi::data::{counted, shown};

use crate::{Grid, Plots, eval, train};

#[derive(clap::Args)]
pub(crate) struct Args {
    /// Output folder.
    #[arg(long, default_value = "demo-out")]
    out: PathBuf,
    /// The bundled sample folder, holding list_train.txt and list_test.txt (default:
    /// datasets/sample of the current folder, else of the checkout this binary was built from).
    #[arg(long)]
    data: Option<PathBuf>,
    /// Regressor hyper-parameter search.
    #[arg(long, value_enum, default_value = "none")]
    grid: Grid,
    /// Plot format, or `none`.
    #[arg(long, value_enum, default_value = "png")]
    plots: Plots,
}

pub(crate) fn run(args: Args) -> Result<()> {
    let given = args.data.is_some();
    let data = args.data.unwrap_or_else(bundled_sample);
    if !data.join("list_train.txt").is_file() {
        if given {
            bail!(
                "{}: no list_train.txt here: --data takes a folder laid out as the bundled \
                 sample (list_train.txt and list_test.txt beside the recordings they list)",
                shown(&data)
            );
        }
        bail!(
            "no bundled sample at {} (give its folder with --data)",
            shown(&data)
        );
    }
    let demo = ridi::Demo::prepare(&data, &args.out, args.grid.into(), args.plots.into())?;
    let train = demo.train_sequences();
    outln!(
        "demo: training on {} ({:.0} s), testing on {} held out",
        counted(train.len(), "sequence"),
        train.iter().map(|s| s.duration()).sum::<f64>(),
        demo.test_sequences().len()
    );
    let started = std::time::Instant::now();
    let model = train::with_progress(|progress| demo.train(progress))?;
    outln!("trained in {:.1} s", started.elapsed().as_secs_f64());
    train::print_training(&model);
    let (report, traces) =
        eval::with_spinner(demo.test_sequences().len(), || demo.evaluate(&model))?;
    let written = demo.write(&model, &report, &traces)?;
    eval::print_written(&report, &written, demo.folder());
    Ok(())
}

/// `datasets/sample` of the working folder when it holds the sample, else that of the
/// checkout this binary was built from.
fn bundled_sample() -> PathBuf {
    let here = PathBuf::from("datasets/sample");
    if here.join("list_train.txt").is_file() {
        here
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets/sample")
    }
}
