//! The options of the `ridi` commands as keyword arguments: their names (flag spelled as a
//! Python name), defaults and bounds are the command line's (crates/ridi-cli), and they become
//! the same facade options the commands build.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use ridi::PlacementMap;
use ridi::correct::{InitialVelocity, PlacementSmoother};
use ridi::data::{ReadOptions, Sequence as RidiSequence};
use ridi::eval::AlignWindow;

use crate::errors;
use crate::sequence::Sequence;

/// Largest `regress_every` and training `step`: one minute at 200 Hz (`ridi`'s
/// `MAX_FRAMES_APART`).
pub(crate) const MAX_FRAMES_APART: usize = 12_000;
/// Largest `turned_copies` (`ridi train --turned-copies`).
pub(crate) const MAX_TURNED_COPIES: usize = 32;
/// Smallest and largest training `window` (`ridi train --window`).
pub(crate) const WINDOW_RANGE: (usize, usize) = (20, 600);

/// `value` of the option `name`, one of `choices` (`(name, value)` pairs), or a `ValueError`
/// listing them.
pub(crate) fn choice<T: Copy>(name: &str, value: &str, choices: &[(&str, T)]) -> PyResult<T> {
    match choices.iter().find(|(n, _)| *n == value) {
        Some((_, v)) => Ok(*v),
        None => {
            let names: Vec<String> = choices.iter().map(|(n, _)| format!("'{n}'")).collect();
            Err(errors::value(format!(
                "`{name}` is '{value}'; expected one of {}",
                names.join(", ")
            )))
        }
    }
}

/// A whole number in `min..=max` for option `name` (taken as `i64`, so that a negative one
/// gets this error rather than an `OverflowError` that names no option).
pub(crate) fn count(name: &str, value: i64, min: usize, max: usize) -> PyResult<usize> {
    match usize::try_from(value) {
        Ok(v) if (min..=max).contains(&v) => Ok(v),
        _ => Err(errors::value(format!(
            "`{name}` is {value}; expected a whole number from {min} to {max}"
        ))),
    }
}

/// A finite number above 0 for option `name`.
pub(crate) fn positive(name: &str, value: f64) -> PyResult<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(errors::value(format!(
            "`{name}` is {value}; expected a finite number above 0"
        )))
    }
}

/// `placement_window` (seconds; 0 turns the majority vote off), as `--placement-window`.
pub(crate) fn placement_smoothing(window_s: f64) -> PyResult<Option<PlacementSmoother>> {
    if !(window_s.is_finite() && window_s >= 0.0) {
        return Err(errors::value(format!(
            "`placement_window` is {window_s}; expected a finite number of at least 0"
        )));
    }
    Ok((window_s > 0.0).then_some(PlacementSmoother { window_s }))
}

/// `heading`: `"corrected"` (the gyro's heading drift corrected by the recorded orientation's
/// slow heading) or `"gyro"`, as `--heading`.
pub(crate) fn recorded_heading(heading: &str) -> PyResult<Option<ridi::frames::HeadingConfig>> {
    choice(
        "heading",
        heading,
        &[
            ("corrected", Some(ridi::frames::HeadingConfig::default())),
            ("gyro", None),
        ],
    )
}

/// A `model` argument (`from_py_with`): a `ridi.Model`, or a `TypeError` saying how to get
/// one from what was given (a path is loaded, not taken as a model).
pub(crate) fn model<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Bound<'py, crate::model::Model>> {
    instance(
        obj,
        "model",
        "load a model file with ridi.load(path)",
        "train one (ridi.train), load a model file (ridi.load) or take the bundled one \
         (ridi.bundled_model())",
    )
}

/// A `sequence` argument (`from_py_with`), as [`model`].
pub(crate) fn sequence<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Bound<'py, Sequence>> {
    instance(
        obj,
        "sequence",
        "read a recording with ridi.read(path)",
        "read a recording (ridi.read) or build one from arrays (ridi.Sequence)",
    )
}

/// `obj` as a `T` for argument `name`, or a `TypeError` with `for_path` (given a str or a
/// path-like) or `otherwise` as its remedy.
fn instance<'py, T: pyo3::PyClass + pyo3::type_object::PyTypeInfo>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    for_path: &str,
    otherwise: &str,
) -> PyResult<Bound<'py, T>> {
    if let Ok(it) = obj.cast::<T>() {
        return Ok(it.clone());
    }
    let path = obj.is_instance_of::<pyo3::types::PyString>() || obj.hasattr("__fspath__")?;
    Err(PyTypeError::new_err(format!(
        "`{name}` is {}, not a ridi.{}: {}",
        crate::arrays::described(obj),
        T::NAME,
        if path { for_path } else { otherwise }
    )))
}

/// A number argument (`from_py_with`): what Python and numpy read as one, but not a bool,
/// which would read as 0 or 1 (`align=True`: an alignment on 1 s) where a number was meant.
pub(crate) fn real(obj: &Bound<'_, PyAny>) -> PyResult<f64> {
    not_bool(obj)?;
    obj.extract()
}

/// A whole-number argument, as [`real`].
pub(crate) fn whole(obj: &Bound<'_, PyAny>) -> PyResult<i64> {
    not_bool(obj)?;
    obj.extract()
}

/// A whole-number argument of any size, as [`whole`] (`seed`: a value past `u64` is named by
/// its own check).
pub(crate) fn whole_wide(obj: &Bound<'_, PyAny>) -> PyResult<i128> {
    not_bool(obj)?;
    obj.extract()
}

/// An optional [`real`]: `None` stays `None`.
pub(crate) fn opt_real(obj: &Bound<'_, PyAny>) -> PyResult<Option<f64>> {
    (!obj.is_none()).then(|| real(obj)).transpose()
}

/// An optional [`whole`]: `None` stays `None`.
pub(crate) fn opt_whole(obj: &Bound<'_, PyAny>) -> PyResult<Option<i64>> {
    (!obj.is_none()).then(|| whole(obj)).transpose()
}

/// Refuses a Python bool, a numpy bool and a 0-d bool array (`np.array(True)`).
pub(crate) fn not_bool(obj: &Bound<'_, PyAny>) -> PyResult<()> {
    let numpy_bool = crate::arrays::dtype_kind(obj).is_some_and(|(k, _)| k == b'b');
    if obj.is_instance_of::<pyo3::types::PyBool>() || numpy_bool {
        return Err(PyTypeError::new_err(format!(
            "expected a number, not a bool ({})",
            obj.repr()
                .map_or_else(|_| "?".to_owned(), |r| r.to_string())
        )));
    }
    Ok(())
}

/// `align`: seconds, or `"all"` for the whole run, as `ridi eval --align`.
pub(crate) fn align(value: &Bound<'_, PyAny>) -> PyResult<AlignWindow> {
    if let Ok(text) = value.extract::<String>() {
        if text.eq_ignore_ascii_case("all") {
            return Ok(AlignWindow::All);
        }
        return Err(errors::value(format!(
            "`align` is '{text}'; expected seconds above 0 or 'all'"
        )));
    }
    // `True` would read as 1 s, and change every figure.
    let bool_ = not_bool(value).is_err();
    let seconds: f64 = value.extract().ok().filter(|_| !bool_).ok_or_else(|| {
        PyTypeError::new_err("`align` must be a number of seconds or 'all'".to_string())
    })?;
    Ok(AlignWindow::Seconds(positive("align", seconds)?))
}

/// The tracking options of `ridi track` and `ridi eval`: the facade's defaults with the flags
/// given.
pub(crate) fn track_options(
    online: bool,
    regress_every: i64,
    lambda: f64,
    estimate_initial_velocity: bool,
    placement_window: f64,
    heading: &str,
) -> PyResult<ridi::TrackOptions> {
    let mut opts = ridi::TrackOptions {
        regress_every: count("regress_every", regress_every, 1, MAX_FRAMES_APART)?,
        online,
        placement_smoothing: placement_smoothing(placement_window)?,
        recorded_heading: recorded_heading(heading)?,
        ..ridi::TrackOptions::default()
    };
    opts.correction.lambda = positive("lambda_", lambda)?;
    if estimate_initial_velocity {
        opts.correction.initial_velocity = InitialVelocity::Estimate;
    }
    Ok(opts)
}

/// `placement_map`: `"tyrex4"` or a file of `label,class` lines, as `--placement-map`.
pub(crate) fn placement_map(map: Option<PathBuf>) -> PyResult<Option<PlacementMap>> {
    map.map(|m| PlacementMap::from_arg(m).map_err(errors::pipeline))
        .transpose()
}

/// The `ReadOptions` every command reads with.
pub(crate) fn read_options() -> ReadOptions {
    ReadOptions::default()
}

/// What training and evaluation take: list files (as `--list`), or sequences already read.
pub(crate) enum Inputs {
    /// List files, read as one list.
    Lists(Vec<PathBuf>),
    /// Sequences (copies: the facade takes a slice of them).
    Sequences(Vec<RidiSequence>),
}

impl Inputs {
    /// `data`: a list file (`str` or `os.PathLike`), several, or `Sequence`s.
    pub(crate) fn extract(data: &Bound<'_, PyAny>) -> PyResult<Inputs> {
        if let Ok(path) = data.extract::<PathBuf>() {
            return Ok(Inputs::Lists(vec![path]));
        }
        let wrong = || {
            PyTypeError::new_err(
                "expected a list file (str or os.PathLike), a list of them, or a list of \
                 ridi.Sequence",
            )
        };
        let items: Vec<Bound<'_, PyAny>> = data
            .try_iter()
            .map_err(|_| wrong())?
            .collect::<PyResult<_>>()?;
        if items.iter().all(|i| i.cast::<Sequence>().is_ok()) && !items.is_empty() {
            let seqs: Vec<RidiSequence> = items
                .iter()
                .map(|i| Ok(i.cast::<Sequence>()?.get().inner.clone()))
                .collect::<PyResult<_>>()?;
            // Errors, warnings and reports name sequences by their names, as lists do by
            // their entries: two of one name (arrays built without `name=`) could not be told
            // apart.
            let mut first = std::collections::HashMap::new();
            for (j, later) in seqs.iter().enumerate() {
                if let Some(i) = first.insert(later.name(), j) {
                    return Err(errors::value(format!(
                        "sequences {i} and {j} are both named `{}`: give each its own name \
                         (`ridi.Sequence(..., name=...)`), by which errors and reports name them",
                        later.name()
                    )));
                }
            }
            return Ok(Inputs::Sequences(seqs));
        }
        let lists = items
            .iter()
            .map(|i| i.extract::<PathBuf>().map_err(|_| wrong()))
            .collect::<PyResult<Vec<_>>>()?;
        if lists.is_empty() {
            return Err(errors::value("no list file and no sequence given"));
        }
        Ok(Inputs::Lists(lists))
    }
}

/// The process the module was loaded in, and the worker threads of its global pool (started
/// then, or those rayon starts at its first parallel call).
static LOADED_IN: std::sync::OnceLock<(u32, usize)> = std::sync::OnceLock::new();

/// Notes the process the module is loaded in, and starts the worker threads
/// `RAYON_NUM_THREADS` asks for (at import; [`ridi::start_workers`]): rayon would start them
/// at the first parallel call, without a bound, and panic there and at every later call if the
/// system refused them. A count out of range is a `UserWarning`, a refusal an `ImportError`.
pub(crate) fn note_process(py: Python<'_>) -> PyResult<()> {
    let workers = ridi::start_workers(None)
        .map_err(|e| pyo3::exceptions::PyImportError::new_err(ridi::data::shown(e.to_string())))?;
    LOADED_IN.get_or_init(|| (std::process::id(), workers.threads));
    crate::sequence::warn(py, workers.warning.as_slice())
}

/// Whether this is a child forked from the process the module was loaded in (`multiprocessing`'s
/// default start method on Linux): rayon's global worker threads stayed in the parent, and work
/// handed to them would wait for ever.
fn forked() -> bool {
    LOADED_IN
        .get()
        .is_some_and(|&(pid, _)| pid != std::process::id())
}

/// Runs `f` on `jobs` worker threads (all cores when `None`), as `--jobs` does for a command;
/// in a forked child on threads of its own ([`forked`]).
pub(crate) fn with_jobs<T: Send>(jobs: Option<i64>, f: impl FnOnce() -> T + Send) -> PyResult<T> {
    let threads = match jobs {
        None if !forked() => return Ok(f()),
        // The parent's count (one per core, or `RAYON_NUM_THREADS`'s as checked at import).
        None => LOADED_IN.get().map_or(0, |&(_, threads)| threads),
        Some(n) => count("jobs", n, 1, ridi::MAX_JOBS)?,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| {
            errors::pipeline(ridi::PipelineError::Workers {
                threads,
                variable: None,
                reason: e.to_string(),
            })
        })?;
    Ok(pool.install(f))
}

/// Runs `f(cancel)` without the GIL on a thread of its own, with [`with_jobs`]'s workers, while
/// the calling thread watches for Ctrl-C: Python runs signal handlers on the main thread only,
/// and the work's own threads never are it. On a signal, `cancel` is set for `f` to stop at its
/// next check, and the handler's exception (`KeyboardInterrupt`) is raised once `f` returns.
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    jobs: Option<i64>,
    f: impl FnOnce(&AtomicBool) -> T + Send,
) -> PyResult<T> {
    let cancel = AtomicBool::new(false);
    let mut caught = None;
    let done = py.detach(|| {
        std::thread::scope(|scope| {
            let (tx, rx) = mpsc::channel();
            let cancel = &cancel;
            let work = std::thread::Builder::new()
                .spawn_scoped(scope, move || tx.send(with_jobs(jobs, || f(cancel))))
                // As a refused worker pool (`with_jobs`): a RuntimeError.
                .map_err(|e| {
                    errors::pipeline(ridi::PipelineError::Workers {
                        threads: 1,
                        variable: None,
                        reason: e.to_string(),
                    })
                })?;
            loop {
                match rx.recv_timeout(SIGNAL_POLL) {
                    Ok(done) => return done,
                    // `f` panicked: passed on with its own message.
                    Err(mpsc::RecvTimeoutError::Disconnected) => match work.join() {
                        Err(panic) => std::panic::resume_unwind(panic),
                        Ok(_) => unreachable!("the thread ends after sending"),
                    },
                    Err(mpsc::RecvTimeoutError::Timeout) if caught.is_none() => {
                        // The flag is set while the GIL is held, before a callback the handler
                        // woke can look at it.
                        caught = Python::attach(|py| {
                            py.check_signals()
                                .inspect_err(|_| cancel.store(true, Ordering::Relaxed))
                                .err()
                        });
                    }
                    Err(mpsc::RecvTimeoutError::Timeout) => {}
                }
            }
        })
    });
    match caught {
        Some(e) => Err(e),
        None => done,
    }
}

/// How often [`interruptible`] looks for a signal: well under a person's patience, and a wake-up
/// that costs nothing beside the work.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// Runs `f` without the GIL, on the worker threads [`with_jobs`] gives by default.
pub(crate) fn detached<T: Send>(py: Python<'_>, f: impl FnOnce() -> T + Send) -> PyResult<T> {
    py.detach(|| with_jobs(None, f))
}
