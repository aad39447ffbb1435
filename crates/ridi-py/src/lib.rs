//! `import ridi`: ridi-rs from Python, on top of the `ridi` facade.
//!
//! Each Python function calls the facade function the matching `ridi` command calls, with the
//! command's defaults, so that a notebook and the command line give the same numbers:
//! `read` is `ridi::read_any`, `read_list` is `ridi::load_listed`, `train` is
//! `ridi::train` with `ridi train`'s options, `track` is `ridi::track`, `LiveTracker` is
//! `ridi::LiveTracker`, `evaluate` is `ridi::evaluate_cancellable` and its dict is
//! `report.json`.
//!
//! The GIL is released while Rust reads, trains, tracks and evaluates (`Python::detach`), so
//! other Python threads run meanwhile; training and evaluation run on a thread of their own
//! while the caller's watches for Ctrl-C (`options::interruptible`).

use pyo3::prelude::*;

mod arrays;
mod errors;
mod evaluate;
mod live;
mod model;
mod options;
mod sequence;
mod track;

/// The native module; `python/ridi/__init__.py` re-exports it as `ridi`.
#[pymodule]
fn _ridi(m: &Bound<'_, PyModule>) -> PyResult<()> {
    options::note_process(m.py())?;
    m.add_class::<sequence::Sequence>()?;
    m.add_class::<model::Model>()?;
    m.add_class::<track::Track>()?;
    m.add_class::<track::Regressions>()?;
    m.add_class::<live::LiveTracker>()?;
    m.add_class::<live::Update>()?;
    m.add_function(wrap_pyfunction!(sequence::read, m)?)?;
    m.add_function(wrap_pyfunction!(sequence::read_any, m)?)?;
    m.add_function(wrap_pyfunction!(sequence::read_list, m)?)?;
    m.add_function(wrap_pyfunction!(model::load, m)?)?;
    m.add_function(wrap_pyfunction!(model::bundled_model, m)?)?;
    m.add_function(wrap_pyfunction!(model::train, m)?)?;
    m.add_function(wrap_pyfunction!(track::regress, m)?)?;
    m.add_function(wrap_pyfunction!(track::track, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate::evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate::compare, m)?)?;
    let methods: Vec<&str> = ridi::Method::ALL.iter().map(|m| m.key()).collect();
    m.add("METHODS", pyo3::types::PyTuple::new(m.py(), methods)?)?;
    m.add("RATE_HZ", ridi::TRACK_RATE_HZ)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
