//! The building blocks of an evaluation report: per-sequence metrics (serde, as `report.json`
//! holds them), per-method means and markdown tables. `ridi::Report` assembles them
//! into `report.json` and `report.md`. Method and sequence order is kept as given, so tables
//! read in the order the pipeline ran things.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use crate::bootstrap::Interval;
use crate::metrics::{ConfusionMatrix, TrajectoryMetrics};

/// One field of [`TrajectoryMetrics`], to pick a column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// `mpe_m`
    MpeM,
    /// `mpe_pct`
    MpePct,
    /// `ate_m`
    AteM,
    /// `rte_m`
    RteM,
    /// `ate_ronin_m`
    AteRoninM,
    /// `rte_ronin_m`
    RteRoninM,
    /// `rte_5s_m`
    #[serde(rename = "rte_5s_m")]
    Rte5sM,
    /// `path_length_ratio`
    PathLengthRatio,
}

impl Metric {
    /// Every metric, in report column order.
    pub const ALL: [Self; 8] = [
        Self::MpeM,
        Self::MpePct,
        Self::AteM,
        Self::RteM,
        Self::AteRoninM,
        Self::RteRoninM,
        Self::Rte5sM,
        Self::PathLengthRatio,
    ];

    /// The JSON key of this metric in [`TrajectoryMetrics`].
    pub const fn key(self) -> &'static str {
        match self {
            Self::MpeM => "mpe_m",
            Self::MpePct => "mpe_pct",
            Self::AteM => "ate_m",
            Self::RteM => "rte_m",
            Self::AteRoninM => "ate_ronin_m",
            Self::RteRoninM => "rte_ronin_m",
            Self::Rte5sM => "rte_5s_m",
            Self::PathLengthRatio => "path_length_ratio",
        }
    }

    /// Human-readable column header with unit.
    pub fn label(self) -> &'static str {
        match self {
            Self::MpeM => "MPE (m)",
            Self::MpePct => "MPE (%)",
            Self::AteM => "ATE (m)",
            Self::RteM => "RTE (m)",
            Self::AteRoninM => "ATE RoNIN (m)",
            Self::RteRoninM => "RTE RoNIN (m)",
            Self::Rte5sM => "RTE 5 s (m)",
            Self::PathLengthRatio => "path length ratio",
        }
    }

    /// The value of this metric, `None` where the metric is undefined.
    pub fn value(self, m: &TrajectoryMetrics) -> Option<f64> {
        match self {
            Self::MpeM => Some(m.mpe_m),
            Self::MpePct => m.mpe_pct,
            Self::AteM => Some(m.ate_m),
            Self::RteM => Some(m.rte_m),
            Self::AteRoninM => Some(m.ate_ronin_m),
            Self::RteRoninM => Some(m.rte_ronin_m),
            Self::Rte5sM => Some(m.rte_5s_m),
            Self::PathLengthRatio => m.path_length_ratio,
        }
    }

    /// The value as report tables print it: 3 decimals (2 for MPE in %), `n/a` when missing.
    pub fn format(self, v: Option<f64>) -> String {
        match (self, v) {
            (_, None) => "n/a".to_owned(),
            (Self::MpePct, Some(v)) => format!("{v:.2}"),
            (_, Some(v)) => format!("{v:.3}"),
        }
    }
}

/// Metrics of one method on one sequence.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MethodMetrics {
    /// Method name (e.g. `ridi`, `pdr`, `raw`).
    pub method: String,
    /// Its metrics.
    pub metrics: TrajectoryMetrics,
}

/// All methods evaluated on one sequence.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SequenceReport {
    /// Sequence name.
    pub sequence: String,
    /// Device placement of the sequence, when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placement: Option<String>,
    /// Number of evaluated frames.
    pub frames: usize,
    /// One entry per method, in evaluation order.
    pub methods: Vec<MethodMetrics>,
}

/// Mean of one method's metrics over the sequences it was evaluated on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MethodSummary {
    /// Method name.
    pub method: String,
    /// Number of sequences averaged.
    pub sequences: usize,
    /// Field-wise arithmetic mean. Optional fields average the sequences where they are
    /// defined and are `None` only if they are undefined everywhere.
    pub mean: TrajectoryMetrics,
}

/// Field-wise mean of each method's metrics over `sequences`, methods in order of first
/// appearance. A method missing from some sequences is averaged over those that have it.
///
/// For each field `m` and method `k`: `mean_k(m) = (1/|S_k|) Σ_{s ∈ S_k} m(s, k)`, where `S_k`
/// is the set of sequences with a result for `k` (and, for optional fields, a defined value).
pub fn summarize(sequences: &[SequenceReport]) -> Vec<MethodSummary> {
    let mut order: Vec<&str> = Vec::new();
    for s in sequences {
        for m in &s.methods {
            if !order.contains(&m.method.as_str()) {
                order.push(&m.method);
            }
        }
    }
    order
        .into_iter()
        .map(|method| {
            let rows: Vec<&TrajectoryMetrics> = sequences
                .iter()
                .flat_map(|s| &s.methods)
                .filter(|m| m.method == method)
                .map(|m| &m.metrics)
                .collect();
            let mean_of = |metric: Metric| mean(rows.iter().filter_map(|m| metric.value(m)));
            // Required fields are present in every row and `rows` is non-empty, so their mean
            // is always defined.
            let required = |metric: Metric| mean_of(metric).unwrap_or(f64::NAN);
            MethodSummary {
                method: method.to_owned(),
                sequences: rows.len(),
                mean: TrajectoryMetrics {
                    mpe_m: required(Metric::MpeM),
                    mpe_pct: mean_of(Metric::MpePct),
                    ate_m: required(Metric::AteM),
                    rte_m: required(Metric::RteM),
                    ate_ronin_m: required(Metric::AteRoninM),
                    rte_ronin_m: required(Metric::RteRoninM),
                    rte_5s_m: required(Metric::Rte5sM),
                    path_length_ratio: mean_of(Metric::PathLengthRatio),
                },
            }
        })
        .collect()
}

/// The run a sequence belongs to: its name without the `_partN` suffixes of a recording split
/// at its gaps (a reader's part, `_part2`, split again at a gap, `_part2_part1`). A bootstrap
/// draws a run's parts together.
pub fn run_of(sequence: &str) -> &str {
    let mut run = sequence;
    while let Some((before, n)) = run.rsplit_once("_part") {
        if n.is_empty() || !n.bytes().all(|b| b.is_ascii_digit()) {
            break;
        }
        run = before;
    }
    run
}

/// Per method and metric key, the 95 % interval of the method's mean over `sequences`
/// ([`mean_interval`](crate::mean_interval), the parts of a run drawn together), over the
/// sequences where the metric is defined; none for a metric defined nowhere, and the mean
/// unbounded ([`Interval::unbounded`]) over fewer runs than an interval needs.
pub fn summary_intervals(
    sequences: &[SequenceReport],
) -> BTreeMap<String, BTreeMap<String, Interval>> {
    per_method(sequences, |s, method| {
        s.methods
            .iter()
            .find(|m| m.method == method)
            .map(|m| &m.metrics)
            .map(|m| Metric::ALL.map(|metric| metric.value(m)))
    })
}

/// Per method other than `reference` and per metric key, the paired difference `reference -
/// method`: its mean over the sequences where both have the metric and its 95 % interval
/// ([`mean_interval`](crate::mean_interval), the parts of a run drawn together; unbounded
/// over fewer runs than an interval needs). An interval that leaves out 0 tells the two apart
/// on these runs.
pub fn paired_differences(
    sequences: &[SequenceReport],
    reference: &str,
) -> BTreeMap<String, BTreeMap<String, Interval>> {
    let mut out = per_method(sequences, |s, method| {
        let of = |name: &str| {
            s.methods
                .iter()
                .find(|m| m.method == name)
                .map(|m| &m.metrics)
        };
        let (r, m) = (of(reference)?, of(method)?);
        Some(Metric::ALL.map(|metric| Some(metric.value(r)? - metric.value(m)?)))
    });
    out.remove(reference);
    out
}

/// For each method of `sequences`, the interval of each metric's mean over the values `values`
/// gives per sequence (`None`: the sequence has no value for that method).
fn per_method(
    sequences: &[SequenceReport],
    values: impl Fn(&SequenceReport, &str) -> Option<[Option<f64>; 8]>,
) -> BTreeMap<String, BTreeMap<String, Interval>> {
    let methods: std::collections::BTreeSet<&str> = sequences
        .iter()
        .flat_map(|s| s.methods.iter().map(|m| m.method.as_str()))
        .collect();
    let mut out = BTreeMap::new();
    for method in methods {
        let rows: Vec<(&str, [Option<f64>; 8])> = sequences
            .iter()
            .filter_map(|s| Some((run_of(&s.sequence), values(s, method)?)))
            .collect();
        let mut metrics = BTreeMap::new();
        for (k, metric) in Metric::ALL.iter().enumerate() {
            let (v, runs): (Vec<f64>, Vec<&str>) = rows
                .iter()
                .filter_map(|(run, row)| Some((row[k]?, *run)))
                .unzip();
            // Too few runs for bounds: the mean, unbounded, so that it is not lost.
            let finite = !v.is_empty() && v.iter().all(|x| x.is_finite());
            let interval = crate::mean_interval(&v, &runs)
                .or_else(|| finite.then(|| Interval::unbounded(crate::ordered_mean(&v))));
            if let Some(i) = interval {
                metrics.insert(metric.key().to_owned(), i);
            }
        }
        out.insert(method.to_owned(), metrics);
    }
    out
}

fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let values: Vec<f64> = values.collect();
    (!values.is_empty()).then(|| crate::bootstrap::ordered_mean(&values))
}

/// Markdown-safe cell text: pipes would split the cell, newlines would end the row.
fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace(['\n', '\r'], " ")
}

fn row(out: &mut String, cells: &[String]) {
    out.push('|');
    for c in cells {
        out.push(' ');
        out.push_str(c);
        out.push_str(" |");
    }
    out.push('\n');
}

fn header(out: &mut String, cells: &[String]) {
    row(out, cells);
    row(out, &vec!["---".to_owned(); cells.len()]);
}

/// Markdown table with one row per (sequence, method) and one column per [`Metric`], followed
/// by one `mean` row per method ([`summarize`]).
pub fn markdown_table(sequences: &[SequenceReport]) -> String {
    let mut out = String::new();
    let mut head = vec!["sequence".to_owned(), "method".to_owned()];
    head.extend(Metric::ALL.iter().map(|m| m.label().to_owned()));
    header(&mut out, &head);
    let metric_cells = |m: &TrajectoryMetrics| {
        Metric::ALL
            .iter()
            .map(|k| k.format(k.value(m)))
            .collect::<Vec<_>>()
    };
    for s in sequences {
        for m in &s.methods {
            let mut cells = vec![cell(&s.sequence), cell(&m.method)];
            cells.extend(metric_cells(&m.metrics));
            row(&mut out, &cells);
        }
    }
    for summary in summarize(sequences) {
        let mut cells = vec![
            format!("**mean** ({})", summary.sequences),
            cell(&summary.method),
        ];
        cells.extend(metric_cells(&summary.mean));
        row(&mut out, &cells);
    }
    out
}

/// Markdown table of one metric: one row per sequence, one column per method, and a final
/// `mean` row. Cells are `n/a` where a method has no result or the metric is undefined.
pub fn markdown_metric_table(sequences: &[SequenceReport], metric: Metric) -> String {
    let summary = summarize(sequences);
    let mut out = String::new();
    let mut head = vec![format!("sequence ({})", metric.label())];
    head.extend(summary.iter().map(|s| cell(&s.method)));
    header(&mut out, &head);
    for s in sequences {
        let mut cells = vec![cell(&s.sequence)];
        cells.extend(summary.iter().map(|k| {
            let value = s
                .methods
                .iter()
                .find(|m| m.method == k.method)
                .and_then(|m| metric.value(&m.metrics));
            metric.format(value)
        }));
        row(&mut out, &cells);
    }
    let mut cells = vec!["**mean**".to_owned()];
    cells.extend(summary.iter().map(|k| metric.format(metric.value(&k.mean))));
    row(&mut out, &cells);
    out
}

/// Markdown confusion matrix (rows: truth, columns: prediction) with per-class recall and the
/// overall accuracy below it.
pub fn markdown_confusion(cm: &ConfusionMatrix) -> String {
    let mut out = String::new();
    let mut head = vec!["truth \\ predicted".to_owned()];
    head.extend(cm.classes.iter().map(|c| cell(c)));
    head.push("recall".to_owned());
    header(&mut out, &head);
    for (i, (name, counts)) in cm.classes.iter().zip(&cm.counts).enumerate() {
        let mut cells = vec![cell(name)];
        cells.extend(counts.iter().map(ToString::to_string));
        cells.push(percent(cm.recall(i)));
        row(&mut out, &cells);
    }
    let _ = writeln!(
        out,
        "\nAccuracy: {} over {} samples.",
        percent(cm.accuracy()),
        cm.total()
    );
    out
}

fn percent(v: Option<f64>) -> String {
    v.map_or_else(|| "n/a".to_owned(), |v| format!("{:.2} %", 100.0 * v))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn metrics(base: f64, pct: Option<f64>) -> TrajectoryMetrics {
        TrajectoryMetrics {
            mpe_m: base,
            mpe_pct: pct,
            ate_m: base + 1.0,
            rte_m: base + 2.0,
            ate_ronin_m: base + 3.0,
            rte_ronin_m: base + 4.0,
            rte_5s_m: base + 5.0,
            path_length_ratio: pct.map(|_| 1.0),
        }
    }

    fn sample() -> Vec<SequenceReport> {
        vec![
            SequenceReport {
                sequence: "hang_leg1".into(),
                placement: Some("leg".into()),
                frames: 100,
                methods: vec![
                    MethodMetrics {
                        method: "ridi".into(),
                        metrics: metrics(1.0, Some(2.0)),
                    },
                    MethodMetrics {
                        method: "pdr".into(),
                        metrics: metrics(10.0, Some(20.0)),
                    },
                ],
            },
            SequenceReport {
                sequence: "a|b".into(),
                placement: None,
                frames: 50,
                methods: vec![MethodMetrics {
                    method: "ridi".into(),
                    metrics: metrics(3.0, None),
                }],
            },
        ]
    }

    #[test]
    fn json_keys_are_exact() {
        let json = serde_json::to_value(metrics(1.0, Some(2.0))).unwrap();
        let obj = json.as_object().unwrap();
        let mut keys: Vec<&str> = obj.keys().map(String::as_str).collect();
        keys.sort_unstable();
        let mut expected: Vec<&str> = Metric::ALL.iter().map(|m| m.key()).collect();
        expected.sort_unstable();
        assert_eq!(keys, expected);
        for m in Metric::ALL {
            assert_eq!(
                serde_json::to_value(m).unwrap(),
                serde_json::Value::String(m.key().into())
            );
        }
    }

    #[test]
    fn intervals_hold_the_means_and_differences_pair_the_sequences() {
        // Two runs: too few for any bounds; the means stay.
        let i = summary_intervals(&sample());
        assert!(
            i.values()
                .flat_map(BTreeMap::values)
                .all(|i| !i.is_bounded()),
            "{i:?}"
        );
        assert_eq!(i["ridi"]["mpe_m"].mean, 2.0);
        // Six runs: ridi's MPE alternates 1 and 3, pdr's is ridi's plus 9 on every run, and
        // MPE % is defined on the first run alone.
        let runs: Vec<SequenceReport> = (0..6)
            .map(|k| {
                let base = if k % 2 == 0 { 1.0 } else { 3.0 };
                let pct = (k == 0).then_some(2.0);
                SequenceReport {
                    sequence: format!("run{k}"),
                    placement: None,
                    frames: 100,
                    methods: vec![
                        MethodMetrics {
                            method: "ridi".into(),
                            metrics: metrics(base, pct),
                        },
                        MethodMetrics {
                            method: "pdr".into(),
                            metrics: metrics(base + 9.0, pct),
                        },
                    ],
                }
            })
            .collect();
        let i = summary_intervals(&runs);
        let mpe = i["ridi"]["mpe_m"];
        assert_eq!(mpe.mean, 2.0);
        assert!(
            mpe.low >= 1.0 && mpe.high <= 3.0 && mpe.contains(2.0),
            "{mpe:?}"
        );
        assert!(!i["ridi"]["mpe_pct"].is_bounded());
        let d = paired_differences(&runs, "ridi");
        assert!(!d.contains_key("ridi"));
        let rte = d["pdr"]["rte_5s_m"];
        assert_eq!((rte.mean, rte.low, rte.high), (-9.0, -9.0, -9.0));
        assert!(paired_differences(&runs, "nothing")["ridi"].is_empty());
    }

    #[test]
    fn parts_of_a_split_recording_are_one_run() {
        assert_eq!(run_of("walk_part2"), "walk");
        assert_eq!(run_of("walk_part12"), "walk");
        assert_eq!(run_of("walk_part2_part1"), "walk");
        for whole in ["walk", "walk_part", "walk_partial", "walk_part2b", "part3"] {
            assert_eq!(run_of(whole), whole);
        }
    }

    #[test]
    fn summary_means_over_available_values() {
        let s = summarize(&sample());
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].method, "ridi");
        assert_eq!(s[0].sequences, 2);
        assert_eq!(s[0].mean.mpe_m, 2.0);
        assert_eq!(s[0].mean.rte_5s_m, 7.0);
        // Only the first sequence defines the percentage.
        assert_eq!(s[0].mean.mpe_pct, Some(2.0));
        assert_eq!(s[1].method, "pdr");
        assert_eq!(s[1].sequences, 1);
        assert_eq!(s[1].mean.ate_m, 11.0);
        assert!(summarize(&[]).is_empty());
    }

    #[test]
    fn undefined_metrics_are_explicit_nulls_in_json() {
        let text = serde_json::to_string(&sample()).unwrap();
        let back: Vec<SequenceReport> = serde_json::from_str(&text).unwrap();
        assert_eq!(back, sample());
        assert!(text.contains("\"mpe_pct\":null"));
    }

    #[test]
    fn markdown_long_table() {
        let md = markdown_table(&sample());
        let lines: Vec<&str> = md.lines().collect();
        // Header, separator, 3 result rows, 2 mean rows.
        assert_eq!(lines.len(), 7);
        assert!(lines[0].starts_with("| sequence | method | MPE (m) | MPE (%) |"));
        assert_eq!(
            lines[2],
            "| hang_leg1 | ridi | 1.000 | 2.00 | 2.000 | 3.000 | 4.000 | 5.000 | 6.000 | 1.000 |"
        );
        assert!(lines[4].starts_with("| a\\|b | ridi | 3.000 | n/a |"));
        assert!(lines[5].starts_with("| **mean** (2) | ridi | 2.000 | 2.00 |"));
        // Every row has the same number of cells.
        let cols = |l: &str| l.replace("\\|", "").matches('|').count();
        assert!(lines.iter().all(|l| cols(l) == cols(lines[0])));
    }

    #[test]
    fn markdown_single_metric_table() {
        let md = markdown_metric_table(&sample(), Metric::AteM);
        assert_eq!(
            md,
            "| sequence (ATE (m)) | ridi | pdr |\n\
             | --- | --- | --- |\n\
             | hang_leg1 | 2.000 | 11.000 |\n\
             | a\\|b | 4.000 | n/a |\n\
             | **mean** | 3.000 | 11.000 |\n"
        );
    }

    #[test]
    fn markdown_confusion_matrix_and_full_report() {
        let cm = ConfusionMatrix::from_names(
            &["leg", "bag", "bag", "bag"],
            &["leg", "bag", "leg", "bag"],
            &["leg", "bag"],
        )
        .unwrap();
        let md = markdown_confusion(&cm);
        assert!(md.contains("| leg | 1 | 0 | 100.00 % |"));
        assert!(md.contains("| bag | 1 | 2 | 66.67 % |"));
        assert!(md.contains("Accuracy: 75.00 % over 4 samples."));
    }
}
