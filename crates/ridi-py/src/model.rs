//! `ridi.Model`, `ridi.load` and `ridi.train`.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use ridi::data::{ListEntry, shown};
use ridi::features::FeatureConfig;
use ridi::features::Orientation;
use ridi::frames::UpAxis;
use ridi::regress::{Cascade, Nystrom, ProgressEvent, RegressError, Solver, Stage, Storage};
use ridi::{GridChoice, PipelineError, Purpose, TrainOptions, load_listed};

use crate::errors;
use crate::options::{self, Inputs, MAX_FRAMES_APART, MAX_TURNED_COPIES, WINDOW_RANGE, choice};

/// A trained model: the placement classifier and the per-placement velocity regressors, with
/// the feature configuration they were trained on (window, definition of S, orientation).
///
/// Made by ``ridi.train`` or ``ridi.load``; ``str(model)`` describes it as ``ridi inspect``
/// does, ``model.describe()`` as ``ridi inspect --json`` does. Models pickle (as the bytes of
/// their file).
///
/// >>> model = ridi.load("model.ridi")   # doctest: +SKIP
/// >>> model.placement_names             # doctest: +SKIP
/// ['hand', 'pocket', 'running', 'swing']
#[pyclass(frozen, module = "ridi")]
pub(crate) struct Model {
    pub(crate) inner: Arc<Cascade>,
}

impl Model {
    fn of(model: Cascade) -> Self {
        Self {
            inner: Arc::new(model),
        }
    }
}

/// `--orientation` values.
const ORIENTATIONS: [(&str, Orientation); 2] = [
    ("recorded", Orientation::Recorded),
    ("estimated", Orientation::Estimated),
];

/// `--up-axis` values.
const UP_AXES: [(&str, UpAxis); 2] = [
    ("plus-or-minus-y", UpAxis::PlusOrMinusY),
    ("plus-y", UpAxis::PlusY),
];

fn name_of<T: PartialEq + Copy>(choices: &[(&'static str, T)], value: T) -> &'static str {
    choices
        .iter()
        .find(|(_, v)| *v == value)
        .map_or("", |(n, _)| n)
}

#[pymethods]
impl Model {
    /// Writes the model file to `path` (atomically, as ``ridi train --out`` does).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let model = &self.inner;
        options::detached(py, || ridi::save_model(model, &path))?
            .map_err(|e| errors::pipeline_in(e, Some(format!("cannot write {}", shown(&path)))))
    }

    /// The placement classes, in the order of the classifier.
    #[getter]
    fn placement_names(&self) -> Vec<String> {
        self.inner.placement_names().to_vec()
    }

    /// Frames per feature window (200, 1 s at 200 Hz, unless trained with ``window``).
    #[getter]
    fn window(&self) -> usize {
        self.inner.feature_config().window
    }

    /// The orientation it was trained on and tracks with: ``recorded`` or ``estimated``.
    #[getter]
    fn orientation(&self) -> &'static str {
        name_of(&ORIENTATIONS, self.inner.feature_config().orientation)
    }

    /// The device axis S is built on: ``plus-or-minus-y`` or ``plus-y``.
    #[getter]
    fn up_axis(&self) -> &'static str {
        name_of(&UP_AXES, self.inner.feature_config().up_axis)
    }

    /// What ``ridi inspect --json`` says of the model: placements, window, S, orientation,
    /// fingerprint (a report's ``model_fingerprint``), solver (``"exact"`` or ``"nystrom"``),
    /// regressors, stored samples, cross-validation table (``cross_validation``).
    fn describe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let json = serde_json::to_string(&ridi::inspect_model(&self.inner))
            .map_err(|e| errors::value(e.to_string()))?;
        py.import("json")?.call_method1("loads", (json,))
    }

    /// The bytes of the model file.
    fn to_bytes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let model = &self.inner;
        let bytes = options::detached(py, || model.to_bytes())?
            .map_err(|e| errors::value(e.to_string()))?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// A model from the bytes of a model file (checked as ``ridi.load`` checks a file).
    #[staticmethod]
    fn from_bytes(py: Python<'_>, data: &[u8]) -> PyResult<Self> {
        // Decoding half-precision rows runs on worker threads.
        options::detached(py, || Cascade::from_bytes(data))?
            .map(Self::of)
            .map_err(|e| errors::value(format!("cannot load model: {e}")))
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyBytes>,))> {
        let from_bytes = slf.get_type().getattr("from_bytes")?;
        Ok((from_bytes, (slf.get().to_bytes(slf.py())?,)))
    }

    fn __str__(&self) -> String {
        ridi::inspect_model(&self.inner).to_string()
    }

    fn __repr__(&self) -> String {
        format!(
            "Model(placements={:?}, window={}, orientation='{}')",
            self.inner.placement_names(),
            self.window(),
            self.orientation()
        )
    }
}

/// Loads a model file written by ``ridi train`` or ``Model.save``.
///
/// Raises ``OSError`` when the file cannot be read, ``ValueError`` when it is no valid model.
#[pyfunction]
pub(crate) fn load(py: Python<'_>, path: PathBuf) -> PyResult<Model> {
    options::detached(py, || Cascade::load(&path))?
        .map(Model::of)
        .map_err(|e| errors::model_file(e, "cannot load model", &path))
}

/// The model bundled with ridi-rs: trained on every shared Tyrex run (a Nexus 5 and an iPhone
/// 4S, three people), for phones of your own without training (its card:
/// ``docs/model-card.md``); what ``ridi track`` uses without ``--model``.
#[pyfunction]
pub(crate) fn bundled_model(py: Python<'_>) -> PyResult<Model> {
    options::detached(py, ridi::bundled_model)?
        .map(Model::of)
        .map_err(|e| errors::value(format!("cannot decode the bundled model: {e}")))
}

/// A progress callback, and what it did: the first exception it raised, or whether it asked
/// to stop.
struct Callback<'a> {
    callback: Option<Py<PyAny>>,
    /// Set on Ctrl-C ([`options::interruptible`]): the training stops at its next report.
    cancel: &'a AtomicBool,
    raised: Mutex<Option<PyErr>>,
    stopped: Mutex<bool>,
}

impl Callback<'_> {
    /// Called by the training, from any thread, with the GIL released: calls the callback
    /// with `(stage, done, total)`; `false` stops the training.
    fn report(&self, e: &ProgressEvent<'_>) -> bool {
        let Some(f) = &self.callback else {
            return !self.cancel.load(Ordering::Relaxed);
        };
        let outcome = Python::attach(|py| {
            let stage = match e.stage {
                Stage::Classifier => "placement classifier".to_string(),
                Stage::Grid { placement } => format!("grid {placement}"),
                Stage::Regressors { placement } => format!("regressors {placement}"),
            };
            f.call1(py, (stage, e.done, e.total)).map(|r| {
                // Only an explicit `False` stops; `None` (no return) goes on.
                !r.bind(py).is_instance_of::<pyo3::types::PyBool>()
                    || r.extract::<bool>(py).unwrap_or(true)
            })
        });
        match outcome {
            // Ctrl-C may have come while the callback ran.
            Ok(true) => !self.cancel.load(Ordering::Relaxed),
            Ok(false) => {
                *self.stopped.lock().unwrap_or_else(|p| p.into_inner()) = true;
                false
            }
            Err(err) => {
                self.raise(err);
                false
            }
        }
    }

    /// Keeps `err` as the exception the training ends with, unless one came first.
    fn raise(&self, err: PyErr) {
        self.raised
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .get_or_insert(err);
    }

    /// The Python exception for a training that ended with `e`.
    fn error(self, e: PipelineError) -> PyErr {
        if let Some(raised) = self.raised.into_inner().unwrap_or_else(|p| p.into_inner()) {
            return raised;
        }
        if self.stopped.into_inner().unwrap_or_else(|p| p.into_inner()) {
            return PyRuntimeError::new_err(
                "training cancelled: the progress callback returned False",
            );
        }
        let folds = matches!(
            e,
            PipelineError::Regress(RegressError::TooFewSequences { .. })
        ) || matches!(&e, PipelineError::Listed { source, .. }
            if matches!(**source, PipelineError::Regress(RegressError::TooFewSequences { .. })));
        if folds {
            return errors::value(format!(
                "the grid search cross-validates over each placement's sequences (`grid=\"none\"` \
                 trains without it): {}",
                ridi::data::one_line(&e)
            ));
        }
        errors::pipeline(e)
    }
}

// The docstring below and docs/python.md give the default number of landmarks.
const _: () = assert!(Nystrom::DEFAULT_LANDMARKS == 2048);

/// Trains a model, as ``ridi train`` does, with its options and defaults.
///
/// ``data`` is a list file (``path,placement`` per line), several, or a list of
/// ``ridi.Sequence`` (each with ground truth and a placement label). The options are the
/// command's flags: ``grid`` (``"paper"``, ``"small"``, ``"none"``), ``placement_map``
/// (``"tyrex4"`` or a ``label,class`` file), ``orientation`` (``"recorded"``,
/// ``"estimated"``), ``storage`` (``"projected"``: 99.99 % of the variance, 90 % with the
/// Nyström solver; ``"half"``), ``solver`` (``"exact"``,
/// ``"nystrom"``), ``landmarks`` (with ``"nystrom"`` only, default 2048), ``seed`` (of the grid's folds and the Nyström draws),
/// ``turned_copies``, ``step`` (default ``10 * (turned_copies +
/// 1)``), ``window`` (default 200), ``speed`` (``False`` for ``--no-speed``), ``up_axis``
/// (``"plus-or-minus-y"``, ``"plus-y"``), ``standardize`` (``False`` for
/// ``--no-standardize``), ``classifier_c`` and ``jobs`` (worker threads, default all cores).
///
/// ``progress``, when given, is called as ``progress(stage, done, total)`` at the start of each
/// stage and after each step (``stage`` is ``"placement classifier"``, ``"grid <placement>"``
/// or ``"regressors <placement>"``); returning ``False`` cancels the training
/// (``RuntimeError``), and an exception it raises ends the training with that exception.
/// Ctrl-C stops the training at its next progress step (``KeyboardInterrupt``): seconds
/// between steps, but the last fit of each placement's regressors reports only as it ends.
///
/// >>> model = ridi.train("datasets/sample/list_Guillaume.txt", grid="none",
/// ...                    placement_map="tyrex4")                     # doctest: +SKIP
/// >>> model.save("model.ridi")                                      # doctest: +SKIP
#[pyfunction]
#[pyo3(signature = (
    data, *, grid="paper", placement_map=None, orientation="estimated", storage="projected",
    solver="exact", landmarks=None, seed=0, turned_copies=1, step=None,
    window=None, speed=true, up_axis="plus-or-minus-y", standardize=true, classifier_c=10.0,
    jobs=None, progress=None,
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn train(
    py: Python<'_>,
    data: &Bound<'_, PyAny>,
    grid: &str,
    placement_map: Option<PathBuf>,
    orientation: &str,
    storage: &str,
    solver: &str,
    #[pyo3(from_py_with = crate::options::opt_whole)] landmarks: Option<i64>,
    #[pyo3(from_py_with = crate::options::whole_wide)] seed: i128,
    #[pyo3(from_py_with = crate::options::whole)] turned_copies: i64,
    #[pyo3(from_py_with = crate::options::opt_whole)] step: Option<i64>,
    #[pyo3(from_py_with = crate::options::opt_whole)] window: Option<i64>,
    speed: bool,
    up_axis: &str,
    standardize: bool,
    #[pyo3(from_py_with = crate::options::real)] classifier_c: f64,
    #[pyo3(from_py_with = crate::options::opt_whole)] jobs: Option<i64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Model> {
    let inputs = Inputs::extract(data)?;
    let grid = choice(
        "grid",
        grid,
        &[
            ("paper", GridChoice::Paper),
            ("small", GridChoice::Small),
            ("none", GridChoice::None),
        ],
    )?;
    let turned_copies = options::count("turned_copies", turned_copies, 0, MAX_TURNED_COPIES)?;
    let defaults = TrainOptions::default();
    let mut opts = TrainOptions {
        standardize,
        turned_copies,
        features: FeatureConfig {
            step: match step {
                Some(s) => options::count("step", s, 1, MAX_FRAMES_APART)?,
                None => ridi::default_step(turned_copies),
            },
            window: match window {
                Some(w) => options::count("window", w, WINDOW_RANGE.0, WINDOW_RANGE.1)?,
                None => defaults.features.window,
            },
            up_axis: choice("up_axis", up_axis, &UP_AXES)?,
            orientation: choice("orientation", orientation, &ORIENTATIONS)?,
            ..defaults.features.clone()
        },
        ..defaults
    };
    opts.cascade.classifier_c = options::positive("classifier_c", classifier_c)?;
    opts.cascade.regressors = grid.regressors();
    opts.cascade.speed = speed;
    let landmarks = landmarks
        .map(|l| options::count("landmarks", l, 2, Nystrom::MAX_LANDMARKS))
        .transpose()?;
    opts.cascade.solver = match choice("solver", solver, &[("exact", false), ("nystrom", true)])? {
        // As `ridi train --landmarks` with the exact solver: a value that would be ignored.
        false if landmarks.is_some() => {
            return Err(errors::value(
                "`landmarks` is for solver=\"nystrom\": the exact solver keeps every training \
                 window",
            ));
        }
        false => Solver::Exact,
        true => Solver::Nystrom(
            Nystrom::new(landmarks.unwrap_or(Nystrom::DEFAULT_LANDMARKS), 0)
                .map_err(|e| errors::value(e.to_string()))?,
        ),
    };
    opts.cascade.set_seed(u64::try_from(seed).map_err(|_| {
        errors::value(format!(
            "`seed` is {seed}; expected a whole number from 0 to {}",
            u64::MAX
        ))
    })?);
    let projected = Storage::projected_for(&opts.cascade.solver);
    opts.cascade.storage = choice(
        "storage",
        storage,
        &[("projected", projected), ("half", Storage::Half)],
    )?;
    let map = options::placement_map(placement_map)?;
    let trained = options::interruptible(py, jobs, |cancel| {
        let callback = Callback {
            callback: progress,
            cancel,
            raised: Mutex::new(None),
            stopped: Mutex::new(false),
        };
        // The training set's warnings (`ridi::training_warnings`), before training, as `ridi
        // train` prints them; one that raises (`-W error`) stops it.
        let warned = |seqs: &[ridi::data::Sequence]| {
            let warnings = ridi::training_warnings(seqs);
            Python::attach(|py| crate::sequence::warn(py, &warnings)).map_err(|e| {
                callback.raise(e);
                PipelineError::Regress(RegressError::Cancelled)
            })
        };
        let trained = (|| -> ridi::Result<Cascade> {
            let mut report = |e: &ProgressEvent<'_>| callback.report(e);
            match inputs {
                Inputs::Lists(lists) => {
                    let listed = ListEntry::read(&lists)
                        .map_err(PipelineError::from)
                        .and_then(|entries| {
                            load_listed(
                                entries,
                                map.as_ref(),
                                Purpose::Training,
                                &options::read_options(),
                            )
                        })?;
                    // Reading a long list can take a while before training's first report.
                    if cancel.load(Ordering::Relaxed) {
                        return Err(PipelineError::Regress(RegressError::Cancelled));
                    }
                    warned(listed.sequences())?;
                    ridi::train(listed.sequences(), &opts, &mut report)
                        .map_err(|e| e.locate_in(&listed))
                }
                Inputs::Sequences(mut seqs) => {
                    if let Some(map) = &map {
                        map.check(&seqs)?;
                        map.apply(&mut seqs);
                    }
                    warned(&seqs)?;
                    ridi::train(&seqs, &opts, &mut report)
                }
            }
        })();
        trained.map_err(|e| callback.error(e))
    })??;
    Ok(Model::of(trained))
}

/// A dict from the JSON text `json` (what `report.json` holds).
pub(crate) fn json_dict<'py>(py: Python<'py>, json: &str) -> PyResult<Bound<'py, PyDict>> {
    Ok(py
        .import("json")?
        .call_method1("loads", (json,))?
        .cast_into::<PyDict>()?)
}
