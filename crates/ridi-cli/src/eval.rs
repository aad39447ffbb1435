//! `ridi eval`: RIDI and the baselines on labelled recordings, into a report folder; and the
//! printing of an evaluation, which `ridi demo` shares.

use std::path::{Path, PathBuf};

use anyhow::Result;
use indicatif::ProgressBar;

use ridi::ReadFiles;
use ridi::data::{ListEntry, counted, shown};
use ridi::eval::{AlignWindow, EvalConfig};
use ridi::{EvalFolder, EvalOptions, EvalPlots, EvalWritten, Method, Purpose, Report};

use crate::{Plots, Tracking, count, parse_align};

#[derive(clap::Args)]
pub(crate) struct Args {
    /// List files of the sequences to evaluate (ground truth required).
    #[arg(long, required = true, num_args = 1..)]
    list: Vec<PathBuf>,
    /// Model file from `ridi train` [default: the bundled model, trained on every shared
    /// Tyrex run; docs/model-card.md].
    #[arg(long)]
    model: Option<PathBuf>,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Methods to compare (comma-separated).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "ridi,raw,pdr,ridi_mag,ridi_ori,velocity,still"
    )]
    methods: Vec<Method>,
    /// Group placement labels as at training (`tyrex4` or a `label,class` file).
    #[arg(long)]
    placement_map: Option<String>,
    /// Plot format, or `none`.
    #[arg(long, value_enum, default_value = "png")]
    plots: Plots,
    /// Worker threads (default: all cores).
    #[arg(long, value_parser = |s: &str| count(s, 1, ridi::MAX_JOBS))]
    pub(crate) jobs: Option<usize>,
    #[command(flatten)]
    tracking: Tracking,
    /// Stretch every trajectory is aligned to the ground truth on (2D rigid, no scale):
    /// its first SECONDS, as in the paper, or `all` for the whole run (a best case that
    /// hides initial-heading errors).
    #[arg(long, value_name = "SECONDS|all", default_value = "10", value_parser = parse_align)]
    align: AlignWindow,
}

pub(crate) fn run(args: Args) -> Result<()> {
    let folder = EvalFolder::new(&args.out, args.plots.into())?;
    let mut methods: Vec<Method> = Vec::new();
    for &m in &args.methods {
        if !methods.contains(&m) {
            methods.push(m);
        }
    }
    let model = crate::model_or_bundled(args.model.as_deref())?;
    let listed = crate::load_listed(
        ListEntry::read(&args.list)?,
        args.placement_map.as_deref(),
        Purpose::Evaluation,
    )?;
    let mut read = args.list.clone();
    read.extend(args.model.clone());
    read.extend(args.placement_map.iter().map(PathBuf::from));
    read.extend(listed.entries().iter().map(|e| e.path.clone()));
    let folder = folder.reading(ReadFiles::of(&read));
    let opts = EvalOptions {
        methods,
        track: args.tracking.options(false),
        config: EvalConfig {
            align: args.align,
            ..EvalConfig::default()
        },
    };
    let seqs = listed.sequences();
    let (mut report, traces) = with_spinner(seqs.len(), || ridi::evaluate(seqs, &model, &opts))
        .map_err(|e| e.locate_in(&listed))?;
    if let Some(p) = &mut report.provenance {
        p.model_source = Some(match &args.model {
            Some(path) => path.display().to_string(),
            None => "bundled".to_string(),
        });
        p.placement_map = args.placement_map.clone();
    }
    let written = folder
        .write(&report, &traces, None)
        .map_err(|e| e.locate_in(&listed))?;
    print_written(&report, &written, &folder);
    Ok(())
}

/// Runs `evaluate` (of `n` sequences) with a spinner on stderr.
pub(crate) fn with_spinner<T>(n: usize, evaluate: impl FnOnce() -> T) -> T {
    let spinner = ProgressBar::new_spinner();
    spinner.set_message(format!("evaluating {}", counted(n, "sequence")));
    spinner.enable_steady_tick(std::time::Duration::from_millis(200));
    let result = evaluate();
    spinner.finish_and_clear();
    result
}

/// Prints what an evaluation found and wrote: warnings on stderr, the summary table and the
/// files written on stdout.
pub(crate) fn print_written(report: &Report, written: &EvalWritten, folder: &EvalFolder) {
    for w in &written.warnings {
        errln!("warning: {}", shown(w));
    }
    print_summary(report);
    let stale = written.stale_plots;
    outln!(
        "wrote {} files into {} (report.md, report.json{}{}){}",
        written.plots.len() + written.reports.len() + usize::from(written.model.is_some()),
        shown(folder.dir()),
        if folder.plots() != EvalPlots::None {
            ", plots/"
        } else {
            ""
        },
        written
            .model
            .as_deref()
            .and_then(Path::file_name)
            .map_or(String::new(), |m| format!(", {}", shown(m))),
        if stale > 0 {
            format!(
                "; removed {} of an earlier evaluation from plots/",
                counted(stale, "plot")
            )
        } else {
            String::new()
        }
    );
}

fn print_summary(report: &Report) {
    const RTE_5S: &str = ridi::eval::Metric::Rte5sM.key();
    for w in &report.warnings {
        errln!("warning: {}", shown(w));
    }
    let mse = match report.velocity_mse {
        [x, z] if x.is_finite() && z.is_finite() => format!("S-x {x:.3} S-z {z:.3} (m/s)^2"),
        _ => "- (no regressions)".to_owned(),
    };
    outln!(
        "\n{}; velocity MSE {mse}; placement accuracy {}",
        counted(report.sequences.len(), "sequence"),
        report
            .placement_accuracy
            .map_or("-".into(), |a| format!("{a:.3}"))
    );
    let c = &report.config;
    let bounded = report.has_intervals();
    outln!(
        "{:<10} {:>26} {:>9} {:>10} {:>9} {:>17}",
        "method",
        format!(
            "RTE {} s m{}",
            c.short_rte_window_s,
            if bounded { " [95 %]" } else { "" }
        ),
        "ATE m",
        format!("RTE {} s m", c.rte_window_s),
        "MPE m",
        "path length ratio"
    );
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
    for key in &report.methods {
        if let Some(m) = report.summary.get(key) {
            let interval = report
                .intervals
                .get(key)
                .and_then(|i| i.get(RTE_5S))
                .filter(|i| i.is_bounded());
            let rte_5s = match interval {
                Some(i) => format!("{:.3} [{:.3}, {:.3}]", m.rte_5s_m, i.low, i.high),
                None => format!("{:.3}", m.rte_5s_m),
            };
            outln!(
                "{key:<10} {rte_5s:>26} {:>9.3} {:>10.3} {:>9.3} {:>17}",
                m.ate_m,
                m.rte_m,
                m.mpe_m,
                opt(m.path_length_ratio)
            );
        }
    }
    if let Some(d) = report
        .ridi_minus
        .get(ridi::Method::Pdr.key())
        .and_then(|d| d.get(RTE_5S))
    {
        let bounds = if d.is_bounded() {
            format!(" [{:+.3}, {:+.3}]", d.low, d.high)
        } else {
            " (too few runs for an interval)".to_string()
        };
        outln!(
            "ridi - pdr, RTE {} s: {:+.3} m{bounds} (paired over sequences; every difference \
             in report.md)",
            c.short_rte_window_s,
            d.mean,
        );
    }
    // A test set that spans phones says how each fared: the question a new phone asks.
    let devices = report.per_device();
    if devices.len() > 1 {
        outln!("\nRTE 5 s per device (m):");
        for d in &devices {
            let methods: Vec<String> = report
                .methods
                .iter()
                .filter_map(|key| {
                    let m = d.summary.get(key)?;
                    Some(format!("{key} {:.3}", m.rte_5s_m))
                })
                .collect();
            outln!(
                "  {} ({}): {}",
                shown(&d.group),
                counted(d.sequences, "sequence"),
                methods.join(", ")
            );
        }
    }
}
