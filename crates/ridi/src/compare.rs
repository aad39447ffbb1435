//! Two evaluations of the same sequences set side by side (`ridi compare`): each method's
//! means in both and their paired difference, sequence by sequence, with its 95 % interval,
//! as a report gives `ridi` against each other method.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

use ridi_eval::{Interval, Metric};
use serde::Serialize;

use crate::evaluate::{Report, with_interval};

/// One method and metric of a [`Comparison`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComparedFigure {
    /// Method key (`ridi`, `pdr`, ...).
    pub method: String,
    /// Metric key (`rte_5s_m`, ...).
    pub metric: String,
    /// Sequences where both reports have the figure.
    pub sequences: usize,
    /// Its mean over those sequences in the first report.
    pub before: f64,
    /// Its mean over them in the second.
    pub after: f64,
    /// `after - before`, paired by sequence: its mean and, with
    /// [`ridi_eval::MIN_INTERVAL_RUNS`] runs or more, its 95 % interval (the parts of a run
    /// drawn together).
    pub difference: f64,
    /// The difference's 95 % interval; `None` with too few runs.
    pub interval: Option<Interval>,
}

/// The second of two reports against the first, over the sequences both hold.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Comparison {
    /// Sequences both reports hold, by name.
    pub sequences: usize,
    /// Runs among them ([`ridi_eval::run_of`]).
    pub runs: usize,
    /// What produced the two reports that differs, one item each (`model: ... against ...`):
    /// what the differences measure.
    pub settings: Vec<String>,
    /// Every method both reports have, every metric, in report order.
    pub figures: Vec<ComparedFigure>,
    /// What to know before reading the differences: sequences in one report only, settings
    /// that differ, too few runs for intervals.
    pub warnings: Vec<String>,
}

/// Compares `after` with `before` sequence by sequence (by name): for each method both have
/// and each metric, the paired difference `after - before`. Settings that make the figures
/// incomparable (another alignment or metric window) are warnings, not errors: the
/// comparison still says what differs.
pub fn compare_reports(before: &Report, after: &Report) -> Comparison {
    let by_name = |r: &Report| -> BTreeMap<String, usize> {
        r.sequences
            .iter()
            .enumerate()
            .map(|(i, s)| (s.name.clone(), i))
            .collect()
    };
    let (a, b) = (by_name(before), by_name(after));
    let both: Vec<&String> = a.keys().filter(|n| b.contains_key(*n)).collect();
    let mut warnings = Vec::new();
    let only_in = |x: &BTreeMap<String, usize>, y: &BTreeMap<String, usize>| -> Vec<String> {
        x.keys()
            .filter(|n| !y.contains_key(*n))
            .map(ridi_data::shown)
            .collect()
    };
    for (which, only) in [
        ("the first", only_in(&a, &b)),
        ("the second", only_in(&b, &a)),
    ] {
        if !only.is_empty() {
            warnings.push(format!(
                "{} only in {which} report, left out: {}",
                ridi_data::counted(only.len(), "sequence"),
                ridi_data::first_few(only.into_iter(), 5)
            ));
        }
    }
    if before.config != after.config {
        warnings.push(format!(
            "the reports' alignment or metric windows differ ({:?} against {:?}): their \
             figures measure different things",
            before.config, after.config
        ));
    }
    let settings = differing_settings(before, after);
    let runs: BTreeSet<&str> = both.iter().map(|n| ridi_eval::run_of(n)).collect();
    if runs.len() < ridi_eval::MIN_INTERVAL_RUNS {
        warnings.push(format!(
            "{} in both reports ({}): too few for 95 % intervals, which need {} runs",
            ridi_data::counted(both.len(), "sequence"),
            ridi_data::counted(runs.len(), "run"),
            ridi_eval::MIN_INTERVAL_RUNS
        ));
    }
    let mut figures = Vec::new();
    for method in before.methods.iter().filter(|m| after.methods.contains(m)) {
        for metric in Metric::ALL {
            let mut rows: Vec<(f64, f64, &str)> = Vec::new();
            for name in &both {
                let value = |r: &Report, i: usize| {
                    r.sequences[i]
                        .methods
                        .get(method)
                        .and_then(|m| metric.value(m))
                        .filter(|v| v.is_finite())
                };
                if let (Some(x), Some(y)) = (value(before, a[*name]), value(after, b[*name])) {
                    rows.push((x, y, ridi_eval::run_of(name)));
                }
            }
            if rows.is_empty() {
                continue;
            }
            let n = rows.len() as f64;
            let diffs: Vec<f64> = rows.iter().map(|(x, y, _)| y - x).collect();
            let clusters: Vec<&str> = rows.iter().map(|r| r.2).collect();
            figures.push(ComparedFigure {
                method: method.clone(),
                metric: metric.key().to_string(),
                sequences: rows.len(),
                before: rows.iter().map(|r| r.0).sum::<f64>() / n,
                after: rows.iter().map(|r| r.1).sum::<f64>() / n,
                difference: diffs.iter().sum::<f64>() / n,
                interval: ridi_eval::mean_interval(&diffs, &clusters),
            });
        }
    }
    Comparison {
        sequences: both.len(),
        runs: runs.len(),
        settings,
        figures,
        warnings,
    }
}

/// The settings of two reports that differ, as `name: first against second`.
fn differing_settings(before: &Report, after: &Report) -> Vec<String> {
    let shown = |v: Option<String>| v.unwrap_or_else(|| "(not recorded)".to_string());
    let p = |r: &Report, f: &dyn Fn(&crate::Provenance) -> String| r.provenance.as_ref().map(f);
    let window = |w: Option<f64>| w.map_or("per regression".to_string(), |w| format!("{w} s"));
    let fields: [(&str, Option<String>, Option<String>); 6] = [
        (
            "model",
            p(before, &|p| {
                format!("{} ({})", p.model, p.model_fingerprint)
            }),
            p(after, &|p| format!("{} ({})", p.model, p.model_fingerprint)),
        ),
        (
            "regressions every",
            p(before, &|p| format!("{} frames", p.regress_every)),
            p(after, &|p| format!("{} frames", p.regress_every)),
        ),
        (
            "placement window",
            p(before, &|p| window(p.placement_window_s)),
            p(after, &|p| window(p.placement_window_s)),
        ),
        (
            "heading",
            Some(format!("{:?}", before.recorded_heading)),
            Some(format!("{:?}", after.recorded_heading)),
        ),
        (
            "methods",
            Some(before.methods.join(", ")),
            Some(after.methods.join(", ")),
        ),
        (
            "ridi version",
            p(before, &|p| p.ridi_version.clone()),
            p(after, &|p| p.ridi_version.clone()),
        ),
    ];
    fields
        .into_iter()
        .filter(|(_, a, b)| a != b)
        .map(|(name, a, b)| format!("{name}: {} against {}", shown(a), shown(b)))
        .collect()
}

impl Comparison {
    /// The comparison as markdown: the warnings, then one table row per method and metric.
    pub fn to_markdown(&self) -> String {
        let mut out = format!(
            "# Comparison: second report minus first\n\n{} in both ({}); differences paired by \
             sequence, 95 % intervals by a bootstrap over the runs; bold: the interval leaves \
             out 0.\n\n",
            ridi_data::counted(self.sequences, "sequence"),
            ridi_data::counted(self.runs, "run")
        );
        for w in &self.warnings {
            let _ = writeln!(out, "**Warning**: {w}.\n");
        }
        if self.settings.is_empty() {
            out.push_str("The two were produced alike (model, tracking settings, methods).\n\n");
        } else {
            out.push_str("What differs between the two:\n\n");
            for s in &self.settings {
                let _ = writeln!(out, "- {s}");
            }
            out.push('\n');
        }
        out.push_str("| method | figure | sequences | first | second | second - first |\n");
        out.push_str("| --- | --- | --- | --- | --- | --- |\n");
        for f in &self.figures {
            let Some(metric) = Metric::ALL.into_iter().find(|m| m.key() == f.metric) else {
                continue;
            };
            let _ = writeln!(
                out,
                "| {} | {} | {} | {} | {} | {} |",
                f.method,
                metric.label(),
                f.sequences,
                metric.format(Some(f.before)),
                metric.format(Some(f.after)),
                with_interval(metric, Some(f.difference), f.interval.as_ref(), true)
            );
        }
        out.split('\n')
            .map(ridi_data::shown)
            .collect::<Vec<_>>()
            .join("\n")
    }
}
