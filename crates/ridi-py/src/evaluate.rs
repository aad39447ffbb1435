//! `ridi.evaluate`.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use ridi::eval::EvalConfig;
use ridi::{EvalOptions, Method, PipelineError, Purpose, Report, load_listed};

use crate::errors;
use crate::model::{Model, json_dict};
use crate::options::{self, Inputs};

/// Evaluates RIDI and its baselines against ground truth, as ``ridi eval`` does, and returns
/// the report as a dict with the keys of its ``report.json`` (``sequences``, ``summary``,
/// ``intervals``, ``ridi_minus``, ``velocity_mse``, ``placement_accuracy``,
/// ``placement_confusion``, ``config``, ``recorded_heading``, ``methods``, ``warnings``,
/// ``provenance``; a NaN is None, as ``null`` in the file). Nothing is written. The report's
/// warnings are also emitted as ``UserWarning``\ s.
///
/// ``data`` is a list file, several, or a list of ``ridi.Sequence`` with ground truth.
/// ``methods`` are keys of ``ridi.METHODS``, one or a list (default: all, in that order); ``placement_map``,
/// ``regress_every``, ``lambda_``, ``estimate_initial_velocity`` (the correction's, as
/// ``ridi.track``'s), ``placement_window`` (seconds, 0 for the paper's per-window labels),
/// ``align`` (seconds, or ``"all"``), ``heading`` (``"corrected"`` or ``"gyro"``, as
/// ``ridi.track``'s) and ``jobs`` are ``ridi eval``'s options with its defaults. Ctrl-C stops the evaluation once the
/// sequences under way are done (``KeyboardInterrupt``).
///
/// >>> report = ridi.evaluate("datasets/sample/list_test.txt", model,
/// ...                        placement_map="tyrex4")           # doctest: +SKIP
/// >>> report["summary"]["ridi"]["rte_5s_m"]                   # doctest: +SKIP
/// 1.02
#[pyfunction]
#[pyo3(signature = (
    data, model, *, methods=None, placement_map=None, regress_every=50, lambda_=0.1,
    estimate_initial_velocity=false, placement_window=10.0, align=None, heading="corrected",
    jobs=None,
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn evaluate<'py>(
    py: Python<'py>,
    data: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = crate::options::model)] model: Bound<'py, Model>,
    methods: Option<&Bound<'py, PyAny>>,
    placement_map: Option<PathBuf>,
    #[pyo3(from_py_with = crate::options::whole)] regress_every: i64,
    #[pyo3(from_py_with = crate::options::real)] lambda_: f64,
    estimate_initial_velocity: bool,
    #[pyo3(from_py_with = crate::options::real)] placement_window: f64,
    align: Option<&Bound<'py, PyAny>>,
    heading: &str,
    #[pyo3(from_py_with = crate::options::opt_whole)] jobs: Option<i64>,
) -> PyResult<Bound<'py, PyDict>> {
    let inputs = Inputs::extract(data)?;
    let methods = match methods {
        None => Method::ALL.to_vec(),
        Some(names) => {
            // One name alone, as a str is no list of names.
            let names: Vec<String> = match names.extract::<String>() {
                Ok(one) => vec![one],
                Err(_) => names.extract().map_err(|_| {
                    errors::value(format!(
                        "`methods` is {}; expected a list of the names in ridi.METHODS",
                        names.repr().map_or_else(|_| "?".into(), |r| r.to_string())
                    ))
                })?,
            };
            if names.is_empty() {
                return Err(errors::value(
                    "`methods` is empty; give one of ridi.METHODS at least, or None for all",
                ));
            }
            let mut methods: Vec<Method> = Vec::new();
            for m in &names {
                let m = m.parse::<Method>().map_err(errors::value)?;
                if !methods.contains(&m) {
                    methods.push(m);
                }
            }
            methods
        }
    };
    let opts = EvalOptions {
        methods,
        track: options::track_options(
            false,
            regress_every,
            lambda_,
            estimate_initial_velocity,
            placement_window,
            heading,
        )?,
        config: EvalConfig {
            align: match align {
                Some(a) => options::align(a)?,
                None => EvalConfig::default().align,
            },
            ..EvalConfig::default()
        },
    };
    let map_name = placement_map.as_ref().map(|p| p.display().to_string());
    let map = options::placement_map(placement_map)?;
    let model = &model.get().inner;
    let mut report = options::interruptible(py, jobs, |cancel| -> ridi::Result<Report> {
        match inputs {
            Inputs::Lists(lists) => {
                let entries = ridi::data::ListEntry::read(&lists).map_err(PipelineError::from)?;
                let listed = load_listed(
                    entries,
                    map.as_ref(),
                    Purpose::Evaluation,
                    &options::read_options(),
                )?;
                ridi::evaluate_cancellable(listed.sequences(), model, &opts, cancel)
                    .map(|(report, _)| report)
                    .map_err(|e| e.locate_in(&listed))
            }
            Inputs::Sequences(mut seqs) => {
                if let Some(map) = &map {
                    map.check(&seqs)?;
                    map.apply(&mut seqs);
                }
                ridi::evaluate_cancellable(&seqs, model, &opts, cancel).map(|(report, _)| report)
            }
        }
    })?
    .map_err(errors::pipeline)?;
    // Also in the report's `warnings`, but a caller reading one figure would not see them.
    crate::sequence::warn(py, &report.warnings)?;
    if let Some(p) = &mut report.provenance {
        p.placement_map = map_name;
    }
    let json = serde_json::to_string(&report).map_err(|e| errors::value(e.to_string()))?;
    json_dict(py, &json)
}

/// Compares two evaluations of the same sequences, as ``ridi compare`` does: ``first`` and
/// ``second`` are reports of ``ridi.evaluate`` (dicts) or of ``ridi eval`` (a report.json, or
/// the folder holding it). Returns a dict: ``sequences`` and ``runs`` both hold, ``settings``
/// (what differs between the two: model, frames between regressions
/// (``provenance.regress_every``), correction (``provenance.correction``), placement window,
/// heading, alignment, methods, version),
/// ``figures`` (per method both have and metric, ``ridi`` also with the model's
/// ``velocity_mse_x``, ``velocity_mse_z`` and ``placement_accuracy``: the ``first`` and
/// ``second`` means over the
/// shared sequences, ``difference``, second minus first paired
/// by sequence, and its 95 % ``interval``, None with fewer than 5 runs) and ``warnings``
/// (also emitted as ``UserWarning``\ s).
#[pyfunction]
pub(crate) fn compare<'py>(
    py: Python<'py>,
    first: &Bound<'py, PyAny>,
    second: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let before = report_of(py, first, "first")?;
    let after = report_of(py, second, "second")?;
    let comparison = ridi::compare_reports(&before, &after).map_err(errors::pipeline)?;
    crate::sequence::warn(py, &comparison.warnings)?;
    let json = serde_json::to_string(&comparison).map_err(|e| errors::value(e.to_string()))?;
    json_dict(py, &json)
}

/// Argument `name` of [`compare`] as a report: a dict of `ridi.evaluate`, or a path.
fn report_of(py: Python<'_>, obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Report> {
    if let Ok(dict) = obj.cast::<PyDict>() {
        // NaN as report.json writes it (null), not as JSON cannot hold it.
        let kwargs = PyDict::new(py);
        kwargs.set_item("allow_nan", false)?;
        let text: String = py
            .import("json")?
            .call_method("dumps", (dict,), Some(&kwargs))
            .map_err(|e| {
                let hint = if e.to_string().contains("Out of range float") {
                    " (NaN and infinity are None there, as report.json's null)"
                } else {
                    ""
                };
                errors::value(format!(
                    "`{name}` is not a report of `ridi.evaluate`: {e}{hint}"
                ))
            })?
            .extract()?;
        let report: Report = serde_json::from_str(&text).map_err(|e| {
            errors::value(format!(
                "`{name}` is not a report of `ridi.evaluate` (a dict of report.json's keys): {e}"
            ))
        })?;
        // Checked as a report.json file is (a negative figure, a window that is not positive).
        report
            .validate()
            .map_err(|e| errors::value(format!("`{name}`: {e}")))?;
        return Ok(report);
    }
    let path: PathBuf = obj.extract().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "`{name}` must be a report of `ridi.evaluate` (a dict) or the path of a report.json \
             (or of its folder)"
        ))
    })?;
    Report::read(&path).map_err(errors::pipeline)
}
