//! Two evaluations of the same sequences set side by side (`ridi compare`): each method's
//! means in both and their paired difference, sequence by sequence, with its 95 % interval,
//! as a report gives `ridi` against each other method.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

use ridi_eval::{Interval, Metric};
use serde::Serialize;

use crate::SequenceResult;
use crate::error::{PipelineError, Result};
use crate::evaluate::{Report, interval_text};

/// A figure two reports are compared on: a method's trajectory metric, or one of the model's
/// own, which a report gives per sequence beside `ridi`'s trajectory.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Figure {
    Trajectory(Metric),
    /// Velocity MSE of the regressions, channel 0 (S-x) or 1 (S-z).
    VelocityMse(usize),
    PlacementAccuracy,
}

impl Figure {
    /// Every figure, in the order of the comparison's rows.
    fn all() -> impl Iterator<Item = Figure> {
        Metric::ALL.into_iter().map(Figure::Trajectory).chain([
            Figure::VelocityMse(0),
            Figure::VelocityMse(1),
            Figure::PlacementAccuracy,
        ])
    }

    /// Its key in [`ComparedFigure::metric`].
    fn key(self) -> &'static str {
        match self {
            Figure::Trajectory(m) => m.key(),
            Figure::VelocityMse(0) => "velocity_mse_x",
            Figure::VelocityMse(_) => "velocity_mse_z",
            Figure::PlacementAccuracy => "placement_accuracy",
        }
    }

    fn label(self) -> &'static str {
        match self {
            Figure::Trajectory(m) => m.label(),
            Figure::VelocityMse(0) => "velocity MSE S-x ((m/s)^2)",
            Figure::VelocityMse(_) => "velocity MSE S-z ((m/s)^2)",
            Figure::PlacementAccuracy => "placement accuracy",
        }
    }

    /// Its value for `method` on sequence `s`: the model's figures are `ridi`'s.
    fn value(self, s: &SequenceResult, method: &str) -> Option<f64> {
        match self {
            Figure::Trajectory(m) => s.methods.get(method).and_then(|t| m.value(t)),
            Figure::VelocityMse(c) => (method == "ridi").then(|| s.velocity_mse[c]),
            Figure::PlacementAccuracy => s.placement_accuracy.filter(|_| method == "ridi"),
        }
        .filter(|v| v.is_finite())
    }

    /// As the report prints it: velocity MSE with 4 decimals, as report.md's.
    fn format(self, v: Option<f64>) -> String {
        match (self, v) {
            (Figure::Trajectory(m), v) => m.format(v),
            (Figure::VelocityMse(_), Some(v)) => format!("{v:.4}"),
            (_, v) => Metric::AteM.format(v),
        }
    }
}

/// One method and metric of a [`Comparison`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComparedFigure {
    /// Method key (`ridi`, `pdr`, ...).
    pub method: String,
    /// Figure key: a metric's (`rte_5s_m`, ...), or for `ridi` also `velocity_mse_x`,
    /// `velocity_mse_z` and `placement_accuracy`, the model's own.
    pub metric: String,
    /// Sequences where both reports have the figure.
    pub sequences: usize,
    /// Its mean over those sequences in the first report.
    pub first: f64,
    /// Its mean over them in the second.
    pub second: f64,
    /// The mean over those sequences of `second - first`, paired by sequence.
    pub difference: f64,
    /// The difference's 95 % interval: a bootstrap over the runs, the parts of a run drawn
    /// together; `None` with fewer than [`ridi_eval::MIN_INTERVAL_RUNS`] runs.
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
    /// Every method both reports have, every metric, in the first report's order.
    pub figures: Vec<ComparedFigure>,
    /// What to know before reading the differences: sequences in one report only or named
    /// twice in one, a sequence whose ground truth differs between the two, a figure one
    /// report lacks for some sequences, a report that does not record what produced it, too
    /// few runs for intervals.
    pub warnings: Vec<String>,
}

/// Compares `second` with `first` sequence by sequence (by name): for each method both have
/// and each metric, the paired difference `second - first`.
///
/// # Errors
/// The two reports hold no sequence of the same name.
pub fn compare_reports(first: &Report, second: &Report) -> Result<Comparison> {
    let mut warnings = Vec::new();
    // The same report twice (one folder given for both, say): every difference is 0. As JSON,
    // where a NaN equals itself.
    if let (Ok(a), Ok(b)) = (serde_json::to_value(first), serde_json::to_value(second))
        && a == b
    {
        warnings.push(
            "the two reports are identical (the same folder twice?): every difference is 0"
                .to_string(),
        );
    }
    let (a, b) = (
        by_name(first, "first", &mut warnings),
        by_name(second, "second", &mut warnings),
    );
    let both: Vec<&str> = a.keys().filter(|n| b.contains_key(*n)).copied().collect();
    if both.is_empty() {
        return Err(PipelineError::NoSequences(
            "compare: the two reports share no sequence name",
        ));
    }
    let only_in = |x: &BTreeMap<&str, usize>, y: &BTreeMap<&str, usize>| -> Vec<String> {
        x.keys()
            .filter(|n| !y.contains_key(*n))
            .map(ridi_data::shown)
            .collect()
    };
    for (which, only) in [("first", only_in(&a, &b)), ("second", only_in(&b, &a))] {
        if !only.is_empty() {
            warnings.push(format!(
                "{} only in the {which} report, left out: {}",
                ridi_data::counted(only.len(), "sequence"),
                ridi_data::first_few(only.into_iter(), 5)
            ));
        }
    }
    // Paired by name: the same name over another ground truth is another recording, or the
    // same one read otherwise.
    let other_truth: Vec<String> = both
        .iter()
        .filter(|n| {
            let (x, y) = (
                first.sequences[a[**n]].path_length_m,
                second.sequences[b[**n]].path_length_m,
            );
            (x - y).abs() > 1e-6 * x.abs().max(y.abs()).max(1.0)
        })
        .map(ridi_data::shown)
        .collect();
    if !other_truth.is_empty() {
        warnings.push(format!(
            "{} a ground-truth path of another length in each report (another recording, or \
             the same read otherwise): {}",
            ridi_data::counted(other_truth.len(), "sequence has"),
            ridi_data::first_few(other_truth.into_iter(), 5)
        ));
    }
    for (which, r) in [("first", first), ("second", second)] {
        if r.provenance
            .as_ref()
            .is_some_and(|p| p.correction.is_none())
        {
            warnings.push(format!(
                "the {which} report does not record its correction (a report of an older ridi, \
                 whose commands corrected with lambda 0.1, a knot every 50 frames, from rest): \
                 a difference there is not listed"
            ));
        }
        if r.provenance.is_none() {
            warnings.push(format!(
                "the {which} report does not record its model and tracking settings (a report \
                 of an older ridi): what differs between the two is known only in part"
            ));
        }
    }
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
    // Figures one report has for a sequence and the other lacks: compared over fewer sequences.
    let mut one_sided = Vec::new();
    let shared: Vec<&String> = first
        .methods
        .iter()
        .filter(|m| second.methods.contains(m))
        .collect();
    for &method in &shared {
        for figure in Figure::all() {
            let mut rows: Vec<(f64, f64, &str)> = Vec::new();
            let mut lacking = 0;
            for name in &both {
                let value = |r: &Report, i: usize| figure.value(&r.sequences[i], method);
                match (value(first, a[name]), value(second, b[name])) {
                    (Some(x), Some(y)) => rows.push((x, y, ridi_eval::run_of(name))),
                    (None, None) => {}
                    _ => lacking += 1,
                }
            }
            if lacking > 0 {
                one_sided.push(format!(
                    "{method} {}: {lacking} of {}",
                    figure.label(),
                    rows.len() + lacking
                ));
            }
            if rows.is_empty() {
                continue;
            }
            let diffs: Vec<f64> = rows.iter().map(|(x, y, _)| y - x).collect();
            let clusters: Vec<&str> = rows.iter().map(|r| r.2).collect();
            let column = |f: fn(&(f64, f64, &str)) -> f64| rows.iter().map(f).collect::<Vec<_>>();
            figures.push(ComparedFigure {
                method: method.clone(),
                metric: figure.key().to_string(),
                sequences: rows.len(),
                first: ridi_eval::ordered_mean(&column(|r| r.0)),
                second: ridi_eval::ordered_mean(&column(|r| r.1)),
                difference: ridi_eval::ordered_mean(&diffs),
                interval: ridi_eval::mean_interval(&diffs, &clusters),
            });
        }
    }
    if shared.is_empty() {
        warnings.push(format!(
            "the two reports share no method ({} against {}): no figure to compare",
            first.methods.join(", "),
            second.methods.join(", ")
        ));
    }
    if !one_sided.is_empty() {
        warnings.push(format!(
            "figures one report has and the other lacks (missing or not finite) for some \
             sequences, each compared over the sequences that have it in both: {}",
            ridi_data::first_few(one_sided.into_iter(), 5)
        ));
    }
    Ok(Comparison {
        sequences: both.len(),
        runs: runs.len(),
        settings: differing_settings(first, second),
        figures,
        warnings,
    })
}

/// The index of each sequence of `r` by name; a name held twice keeps its first sequence, and
/// a warning says so.
fn by_name<'r>(r: &'r Report, which: &str, warnings: &mut Vec<String>) -> BTreeMap<&'r str, usize> {
    let mut index = BTreeMap::new();
    let mut twice = Vec::new();
    for (i, s) in r.sequences.iter().enumerate() {
        if index.contains_key(s.name.as_str()) {
            twice.push(ridi_data::shown(&s.name));
        } else {
            index.insert(s.name.as_str(), i);
        }
    }
    if !twice.is_empty() {
        warnings.push(format!(
            "the {which} report names {} twice; each is compared by its first: {}",
            ridi_data::counted(twice.len(), "sequence"),
            ridi_data::first_few(twice.into_iter(), 5)
        ));
    }
    index
}

/// Whether `r`'s heading settings were used: its model is on the estimated orientation, or
/// the report does not say.
fn heading_matters(r: &Report) -> bool {
    r.provenance
        .as_ref()
        .is_none_or(|p| p.orientation != Some(ridi_features::Orientation::Recorded))
}

/// The settings of two reports that differ, as `name: first against second`.
fn differing_settings(first: &Report, second: &Report) -> Vec<String> {
    SETTINGS
        .iter()
        // A setting one report does not record is no difference it can show.
        .filter_map(|(name, of)| Some((name, of(first)?, of(second)?)))
        .filter(|(_, a, b)| a != b)
        .map(|(name, a, b)| format!("{name}: {a} against {b}"))
        .collect()
}

/// The correction `r` records.
fn correction(r: &Report) -> Option<&ridi_correct::CorrectionConfig> {
    r.provenance.as_ref()?.correction.as_ref()
}

/// A setting [`differing_settings`] compares: its name, and its value in a report (`None`
/// where the report does not record it).
type Setting = (&'static str, fn(&Report) -> Option<String>);

/// Every setting that makes two reports' figures differ, in the order they are listed.
const SETTINGS: [Setting; 14] = [
    ("model", |r| {
        let p = r.provenance.as_ref()?;
        Some(format!("{} ({})", p.model, p.model_fingerprint))
    }),
    ("regressions every", |r| {
        Some(format!("{} frames", r.provenance.as_ref()?.regress_every))
    }),
    ("placement", |r| {
        let window = r.provenance.as_ref()?.placement_window_s;
        Some(window.map_or("per regression".to_string(), |w| format!("{w} s")))
    }),
    // The correction, field by field, so that only what differs is listed.
    ("correction lambda", |r| {
        Some(correction(r)?.lambda.to_string())
    }),
    ("correction knots", |r| {
        Some(format!("every {} frames", correction(r)?.knot_spacing))
    }),
    ("correction weights", |r| {
        let c = correction(r)?;
        Some(format!(
            "{} / {} (horizontal / vertical)",
            c.horizontal_weight, c.vertical_weight
        ))
    }),
    ("initial velocity", |r| {
        Some(crate::evaluate::initial_velocity_text(
            correction(r)?.initial_velocity,
        ))
    }),
    ("largest time step", |r| {
        Some(format!("{} s", correction(r)?.max_dt))
    }),
    ("placement map", |r| {
        let map = r.provenance.as_ref()?.placement_map.clone();
        Some(map.unwrap_or_else(|| "none".to_string()))
    }),
    // The heading settings change nothing for models on the recorded orientation.
    ("heading", |r| heading_matters(r).then(|| r.heading_text())),
    ("alignment", |r| Some(r.alignment_text())),
    ("RTE windows", |r| {
        let c = &r.config;
        Some(format!(
            "{} s and {} s",
            c.rte_window_s, c.short_rte_window_s
        ))
    }),
    ("methods", |r| {
        let mut m = r.methods.clone();
        m.sort_unstable();
        Some(m.join(", "))
    }),
    ("ridi version", |r| {
        Some(r.provenance.as_ref()?.ridi_version.clone())
    }),
];

impl Comparison {
    /// The comparison as markdown: the warnings, what differs, then one table row per method
    /// and metric.
    pub fn to_markdown(&self) -> String {
        let with_intervals = self.figures.iter().any(|f| f.interval.is_some());
        let mut out = format!(
            "# Comparison: second report minus first\n\n{} in both ({}); differences paired by \
             sequence{}.\n\n",
            ridi_data::counted(self.sequences, "sequence"),
            ridi_data::counted(self.runs, "run"),
            if with_intervals {
                ", 95 % intervals by a bootstrap over the runs; bold: the interval leaves out 0"
            } else {
                "; too few runs for intervals"
            }
        );
        for w in &self.warnings {
            let _ = writeln!(out, "**Warning**: {w}.\n");
        }
        if self.settings.is_empty() {
            out.push_str(
                "Nothing recorded differs between the two (model, tracking settings, methods).\n\n",
            );
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
            let Some(figure) = Figure::all().find(|g| g.key() == f.metric) else {
                continue;
            };
            let difference = figure.format(Some(f.difference));
            let _ = writeln!(
                out,
                "| {} | {} | {} | {} | {} | {} |",
                f.method,
                figure.label(),
                f.sequences,
                figure.format(Some(f.first)),
                figure.format(Some(f.second)),
                interval_text(difference, Some(f.difference), f.interval.as_ref(), true)
            );
        }
        out.split('\n')
            .map(ridi_data::shown)
            .collect::<Vec<_>>()
            .join("\n")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SequenceResult;
    use ridi_eval::TrajectoryMetrics;
    use ridi_features::Orientation;

    fn report(rows: &[(&str, f64)]) -> Report {
        let metrics = |rte| TrajectoryMetrics {
            mpe_m: rte,
            mpe_pct: None,
            ate_m: rte,
            rte_m: rte,
            ate_ronin_m: rte,
            rte_ronin_m: rte,
            rte_5s_m: rte,
            path_length_ratio: Some(1.0),
        };
        Report::of_sequences(
            rows.iter()
                .map(|&(name, rte)| SequenceResult {
                    name: name.into(),
                    run: ridi_eval::run_of(name).into(),
                    placement: None,
                    device: None,
                    path_length_m: 10.0,
                    alignment_extent_m: 5.0,
                    placement_accuracy: None,
                    velocity_mse: [f64::NAN; 2],
                    methods: [("ridi".to_string(), metrics(rte))].into(),
                })
                .collect(),
        )
    }

    #[test]
    fn the_models_own_figures_are_compared_as_ridis() {
        let names = ["a", "b", "c", "d", "e"];
        let with = |mse: f64, accuracy: f64| {
            let mut r = report(&names.map(|n| (n, 1.0)));
            for (i, s) in r.sequences.iter_mut().enumerate() {
                s.velocity_mse = [mse + i as f64 * 0.01, 2.0 * mse];
                s.placement_accuracy = Some(accuracy);
            }
            r
        };
        let c = compare_reports(&with(0.1, 0.5), &with(0.2, 0.9)).unwrap();
        let figure = |key: &str| c.figures.iter().find(|f| f.metric == key).unwrap();
        assert!((figure("velocity_mse_x").difference - 0.1).abs() < 1e-12);
        assert!((figure("velocity_mse_z").difference - 0.2).abs() < 1e-12);
        let accuracy = figure("placement_accuracy");
        assert_eq!((accuracy.method.as_str(), accuracy.sequences), ("ridi", 5));
        assert!((accuracy.difference - 0.4).abs() < 1e-12);
        let markdown = c.to_markdown();
        assert!(
            markdown.contains(
                "| ridi | placement accuracy | 5 | 0.500 | 0.900 | **+0.400 [0.40, 0.40]** |"
            ),
            "{markdown}"
        );
        assert!(markdown.contains("| ridi | velocity MSE S-x ((m/s)^2) | 5 |"));
        // A resolved difference too small for two decimals is not printed as [0.00, 0.00]: with
        // more decimals, or in scientific notation.
        let row = |d: f64| {
            let c = compare_reports(&with(0.1, 0.5), &with(0.1 + d, 0.5)).unwrap();
            let markdown = c.to_markdown();
            let line = markdown.lines().find(|l| l.contains("MSE S-x")).unwrap();
            line.rsplit(" | ")
                .next()
                .unwrap()
                .trim_end_matches(" |")
                .to_string()
        };
        assert_eq!(row(6e-5), "**+0.0001 [0.0001, 0.0001]**");
        assert_eq!(row(2e-7), "**+2.0e-7 [2.0e-7, 2.0e-7]**");
    }

    #[test]
    fn pairs_by_name_and_says_what_it_cannot_pair() {
        let first = report(&[("a", 1.0), ("b", 2.0), ("c_part1", 3.0), ("c_part2", 3.0)]);
        let mut second = report(&[("b", 2.5), ("a", 1.5), ("c_part1", 3.5), ("c_part2", 3.5)]);
        second.sequences.push(second.sequences[0].clone());
        second.sequences[4]
            .methods
            .get_mut("ridi")
            .unwrap()
            .rte_5s_m = 99.0;
        second.sequences.push(SequenceResult {
            name: "d".into(),
            ..second.sequences[0].clone()
        });
        // A figure one report lacks for a sequence: compared over the others, and said.
        second.sequences[1]
            .methods
            .get_mut("ridi")
            .unwrap()
            .path_length_ratio = None;
        let c = compare_reports(&first, &second).unwrap();
        assert_eq!((c.sequences, c.runs), (4, 3));
        let ratio = c.figures.iter().find(|f| f.metric == "path_length_ratio");
        assert_eq!(ratio.unwrap().sequences, 3);
        let rte = c.figures.iter().find(|f| f.metric == "rte_5s_m").unwrap();
        // Every pair 0.5 apart; `b` named twice is compared by its first row, not the 99.
        assert_eq!((rte.first, rte.second, rte.difference), (2.25, 2.75, 0.5));
        assert_eq!(rte.interval, None);
        let warnings = c.warnings.join("\n");
        for expected in [
            "1 sequence only in the second report, left out: d",
            "the second report names 1 sequence twice; each is compared by its first: b",
            "the first report does not record its model and tracking settings",
            "(3 runs): too few for 95 % intervals, which need 5 runs",
            "figures one report has and the other lacks (missing or not finite) for some \
             sequences, each compared over the sequences that have it in both: ridi path \
             length ratio: 1 of 4",
        ] {
            assert!(warnings.contains(expected), "{expected}: {warnings}");
        }
        assert!(!warnings.contains("identical"), "{warnings}");
        let same = compare_reports(&first, &first).unwrap();
        assert!(
            same.warnings[0].starts_with("the two reports are identical"),
            "{:?}",
            same.warnings
        );
        // Nothing recorded but what both reports hold: no claim about the model.
        assert!(c.settings.is_empty(), "{:?}", c.settings);
        assert!(
            c.to_markdown()
                .contains("| ridi | RTE 5 s (m) | 4 | 2.250 | 2.750 | +0.500 |")
        );
        // The heading matters only for models on the estimated orientation.
        let with = |orientation, heading| Report {
            provenance: Some(crate::Provenance {
                orientation: Some(orientation),
                ..Default::default()
            }),
            recorded_heading: heading,
            ..report(&[("a", 1.0)])
        };
        let corrected = Some(ridi_frames::HeadingConfig::default());
        let (recorded, estimated) = (Orientation::Recorded, Orientation::Estimated);
        let recorded = compare_reports(&with(recorded, None), &with(recorded, corrected));
        assert!(recorded.unwrap().settings.is_empty());
        let estimated = compare_reports(&with(estimated, None), &with(estimated, corrected));
        let settings = estimated.unwrap().settings;
        assert!(
            settings.len() == 1 && settings[0].starts_with("heading: the gyro's alone against"),
            "{settings:?}"
        );
        // A figure's key left out of a hand-edited report reads as a missing figure.
        let mut edited = serde_json::to_value(report(&[("a", 1.0), ("b", 2.0)])).unwrap();
        let ridi = &mut edited["sequences"][1]["methods"]["ridi"];
        ridi.as_object_mut().unwrap().remove("rte_5s_m");
        let edited: Report = serde_json::from_value(edited).unwrap();
        let c = compare_reports(&report(&[("a", 1.0), ("b", 2.0)]), &edited).unwrap();
        let rte = c.figures.iter().find(|f| f.metric == "rte_5s_m").unwrap();
        assert_eq!(rte.sequences, 1);
        assert!(
            c.warnings
                .iter()
                .any(|w| w.contains("ridi RTE 5 s (m): 1 of 2"))
        );
        // What no evaluation writes is refused when read: a negative figure, a window of 0.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("report.json");
        for (edit, expected) in [
            (
                (
                    "/sequences/0/methods/ridi/rte_5s_m",
                    serde_json::json!(-5.0),
                ),
                "sequence `a`, method `ridi`: `rte_5s_m` is -5, a figure that cannot be negative",
            ),
            (
                ("/config/rte_window_s", serde_json::json!(0.0)),
                "`config.rte_window_s` is 0; an evaluation's is a positive number",
            ),
        ] {
            let mut v = serde_json::to_value(report(&[("a", 1.0)])).unwrap();
            *v.pointer_mut(edit.0).unwrap() = edit.1;
            std::fs::write(&path, v.to_string()).unwrap();
            let e = Report::read(&path).unwrap_err().to_string();
            assert!(e.ends_with(expected), "{e}");
        }
        // No method in common: said, as nothing is compared.
        let mut other = report(&[("a", 1.0)]);
        other.methods = vec!["pdr".into()];
        let c = compare_reports(&report(&[("a", 1.0)]), &other).unwrap();
        assert!(c.figures.is_empty());
        assert!(
            c.warnings
                .iter()
                .any(|w| w.starts_with("the two reports share no method (ridi against pdr)")),
            "{:?}",
            c.warnings
        );
        // No name in common: nothing to pair.
        let other = report(&[("x", 1.0)]);
        assert!(matches!(
            compare_reports(&first, &other),
            Err(PipelineError::NoSequences(_))
        ));
    }
}
