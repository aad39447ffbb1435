//! `ridi.track`, `ridi.regress`, `ridi.Track` and `ridi.Regressions`.

use std::path::PathBuf;

use numpy::ndarray::ArrayView2;
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use ridi::PipelineError;
use ridi::correct::FrameVelocity;
use ridi::data::shown;
use ridi::frames::StabHorizontal;

use crate::arrays::{rows_out, vecs, vecs_out, vector_out};
use crate::errors;
use crate::model::Model;
use crate::options::{self, MAX_FRAMES_APART};
use crate::sequence::Sequence;

/// The regressed velocities a correction follows: one per regression, at its frame.
///
/// ``velocity`` is ``[S-x, S-z]`` in m/s (S: the gravity-stabilized device frame, +y up;
/// forward is -z), ``placement`` the placement class each was regressed for.
#[pyclass(frozen, module = "ridi")]
pub(crate) struct Regressions {
    frame: Vec<usize>,
    velocity: Vec<[f64; 2]>,
    placement: Vec<String>,
}

impl Regressions {
    pub(crate) fn of(
        regressions: &[FrameVelocity],
        placements: &[usize],
        names: &[String],
    ) -> Self {
        Self {
            frame: regressions.iter().map(|r| r.frame).collect(),
            velocity: regressions.iter().map(|r| r.velocity.to_array()).collect(),
            placement: placements
                .iter()
                .map(|&p| names.get(p).cloned().unwrap_or_default())
                .collect(),
        }
    }
}

/// What pickled [`Regressions`] hold: frames, velocities, placements.
type RegressionsState = (Vec<usize>, Vec<[f64; 2]>, Vec<String>);

#[pymethods]
impl Regressions {
    /// Pickled as its frames, velocities and placements (for ``multiprocessing``).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, RegressionsState)> {
        let r = slf.get();
        let state = (r.frame.clone(), r.velocity.clone(), r.placement.clone());
        Ok((slf.get_type().getattr("_from_state")?, state))
    }

    /// The regressions [`Self::__reduce__`] pickled.
    #[staticmethod]
    fn _from_state(
        frame: Vec<usize>,
        velocity: Vec<[f64; 2]>,
        placement: Vec<String>,
    ) -> PyResult<Self> {
        if frame.len() != velocity.len() || frame.len() != placement.len() {
            return Err(errors::value("not the state of pickled ridi.Regressions"));
        }
        Ok(Self {
            frame,
            velocity,
            placement,
        })
    }

    /// Frame index of each regression, shape (M,), int64.
    #[getter]
    fn frame<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let frames: Vec<i64> = self.frame.iter().map(|&f| f as i64).collect();
        frames.into_pyarray(py)
    }

    /// Regressed velocity ``[S-x, S-z]``, m/s, shape (M, 2).
    #[getter]
    fn velocity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        rows_out(py, self.velocity.iter().copied())
    }

    /// Placement class of each regression.
    #[getter]
    fn placement(&self) -> Vec<String> {
        self.placement.clone()
    }

    fn __len__(&self) -> usize {
        self.frame.len()
    }

    fn __repr__(&self) -> String {
        format!("Regressions({} velocities)", self.frame.len())
    }
}

/// A tracked sequence: one pose per frame, in the world frame of the device orientation
/// (z up), metres from the start; what ``ridi track`` writes as its CSV.
#[pyclass(frozen, module = "ridi")]
pub(crate) struct Track {
    inner: ridi::Track,
}

/// What a pickled [`Track`] holds: its numbers as little-endian f64 bytes (frames and
/// regressions, time, position, velocity, bias, then frame, velocity and placement per
/// regression), and the placement names.
type TrackState<'py> = (Bound<'py, PyBytes>, Vec<String>);

#[pymethods]
impl Track {
    /// Timestamps, seconds, shape (N,).
    #[getter]
    fn time<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_out(py, self.inner.time.clone())
    }

    /// Position, metres, world frame, shape (N, 3).
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vecs_out(py, &self.inner.position)
    }

    /// Velocity, m/s, world frame, shape (N, 3).
    #[getter]
    fn velocity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vecs_out(py, &self.inner.velocity)
    }

    /// The bias correction added to the linear acceleration (minus the accelerometer's
    /// estimated bias), m/s², device frame, shape (N, 3).
    #[getter]
    fn bias<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vecs_out(py, &self.inner.bias)
    }

    /// The regressed velocities the correction followed.
    #[getter]
    fn regressions(&self) -> Regressions {
        Regressions::of(
            &self.inner.regressions,
            &self.inner.placements,
            &self.inner.placement_names,
        )
    }

    /// The model's placement classes.
    #[getter]
    fn placement_names(&self) -> Vec<String> {
        self.inner.placement_names.clone()
    }

    /// Writes the trajectory CSV of ``ridi track``:
    /// ``time,pos_x,pos_y,pos_z,vel_x,vel_y,vel_z,placement,bias_x,bias_y,bias_z``.
    fn write_csv(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let track = &self.inner;
        py.detach(|| track.write_csv(&path))
            .map_err(|e| errors::pipeline_in(e, Some(format!("cannot write {}", shown(&path)))))
    }

    fn __len__(&self) -> usize {
        self.inner.time.len()
    }

    /// Pickled (for ``multiprocessing``, ``copy``) as its numbers, bit for bit.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, TrackState<'py>)> {
        let t = &slf.get().inner;
        let mut bytes = Vec::new();
        let mut put = |v: f64| bytes.extend_from_slice(&v.to_le_bytes());
        put(t.time.len() as f64);
        put(t.regressions.len() as f64);
        t.time.iter().for_each(|&v| put(v));
        let vectors = t.position.iter().chain(&t.velocity).map(|v| v.to_array());
        for v in vectors.chain(t.bias.iter().map(|v| v.to_array())) {
            v.into_iter().for_each(&mut put);
        }
        for (r, &p) in t.regressions.iter().zip(&t.placements) {
            put(r.frame as f64);
            r.velocity.to_array().into_iter().for_each(&mut put);
            put(p as f64);
        }
        let rebuild = slf.get_type().getattr("_from_state")?;
        Ok((
            rebuild,
            (PyBytes::new(slf.py(), &bytes), t.placement_names.clone()),
        ))
    }

    /// The track [`Self::__reduce__`] pickled.
    #[staticmethod]
    fn _from_state(bytes: &[u8], placement_names: Vec<String>) -> PyResult<Self> {
        let corrupt = || errors::value("not the state of a pickled ridi.Track");
        let v: Vec<f64> = bytes
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap_or_default()))
            .collect();
        let count = |x: f64| {
            (x >= 0.0 && x.fract() == 0.0 && x <= v.len() as f64)
                .then_some(x as usize)
                .ok_or_else(corrupt)
        };
        if !bytes.len().is_multiple_of(8) || v.len() < 2 {
            return Err(corrupt());
        }
        let (n, m) = (count(v[0])?, count(v[1])?);
        if v.len() != 2 + n * 10 + m * 4 {
            return Err(corrupt());
        }
        let time = v[2..2 + n].to_vec();
        // Position, velocity and bias: `n` rows of 3 each, in that order.
        let rows = |k: usize| {
            let from = 2 + n + 3 * n * k;
            ArrayView2::from_shape((n, 3), &v[from..from + 3 * n]).map_err(|_| corrupt())
        };
        let (position, velocity, bias) = (
            vecs(rows(0)?, "position")?,
            vecs(rows(1)?, "velocity")?,
            vecs(rows(2)?, "bias")?,
        );
        let mut regressions = Vec::with_capacity(m);
        let mut placements = Vec::with_capacity(m);
        for r in v[2 + 10 * n..].chunks_exact(4) {
            let (frame, placement) = (count(r[0])?, count(r[3])?);
            if frame >= n || placement >= placement_names.len() {
                return Err(corrupt());
            }
            regressions.push(FrameVelocity {
                frame,
                velocity: StabHorizontal::new(r[1], r[2]),
            });
            placements.push(placement);
        }
        Ok(Self {
            inner: ridi::Track {
                time,
                position,
                velocity,
                bias,
                regressions,
                placements,
                placement_names,
            },
        })
    }

    fn __repr__(&self) -> String {
        let end = self
            .inner
            .position
            .last()
            .map_or([0.0; 3], |p| p.to_array());
        format!(
            "Track({} frames, {} regressions, ends at ({:.2}, {:.2}) m)",
            self.inner.time.len(),
            self.inner.regressions.len(),
            end[0],
            end[1]
        )
    }
}

/// Tracks `sequence` with `model`, as ``ridi track`` does: velocities regressed every
/// ``regress_every`` frames, the accelerometer bias corrected so that the integrated velocity
/// follows them, and integrated twice. ``online=True`` is ``ridi track --online`` (a
/// correction every 200 frames over the latest 1,000; the poses a ``LiveTracker`` gives).
/// ``lambda_`` (``--lambda``), ``estimate_initial_velocity``, ``placement_window``
/// (seconds, 0 for each window's own label) and ``heading`` (``"corrected"``: a model on the
/// estimated orientation takes the recorded orientation's slow heading to correct the gyro's
/// drift; ``"gyro"``: the gyro's alone) are the command's options, with its defaults.
///
/// Raises ``ValueError`` naming the sequence for one at another rate than 200 Hz, no longer
/// than the model's window or with a gap longer than 0.1 s; with ``online=True`` also for a
/// second of it in another rate or unit (``LiveTracker``'s check).
///
/// >>> track = ridi.track(seq, model)          # doctest: +SKIP
/// >>> track.position[-1]                     # doctest: +SKIP
/// array([ 3.1, -12.4,  0.2])
#[pyfunction]
#[pyo3(signature = (
    sequence, model, online=false, *, regress_every=50, lambda_=0.1,
    estimate_initial_velocity=false, placement_window=10.0, heading="corrected",
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn track(
    py: Python<'_>,
    #[pyo3(from_py_with = crate::options::sequence)] sequence: Bound<'_, Sequence>,
    #[pyo3(from_py_with = crate::options::model)] model: Bound<'_, Model>,
    online: bool,
    #[pyo3(from_py_with = crate::options::whole)] regress_every: i64,
    #[pyo3(from_py_with = crate::options::real)] lambda_: f64,
    estimate_initial_velocity: bool,
    #[pyo3(from_py_with = crate::options::real)] placement_window: f64,
    heading: &str,
) -> PyResult<Track> {
    let opts = options::track_options(
        online,
        regress_every,
        lambda_,
        estimate_initial_velocity,
        placement_window,
        heading,
    )?;
    let (seq, model) = (&sequence.get().inner, &model.get().inner);
    // `ridi::track` gives the sequence the model's orientation itself.
    options::detached(py, || ridi::track(seq, model, &opts))?
        .map(|inner| Track { inner })
        .map_err(|e| errors::of_sequence(e, "cannot track", seq.name()))
}

/// The velocities `model` regresses for `sequence` every ``regress_every`` frames from the
/// first whole window, each with the majority placement within ``placement_window`` seconds:
/// what ``ridi.track`` corrects with, without the correction. Raises ``ValueError`` naming
/// the sequence for what ``ridi.track`` refuses.
#[pyfunction]
#[pyo3(signature = (sequence, model, *, regress_every=50, placement_window=10.0))]
pub(crate) fn regress(
    py: Python<'_>,
    #[pyo3(from_py_with = crate::options::sequence)] sequence: Bound<'_, Sequence>,
    #[pyo3(from_py_with = crate::options::model)] model: Bound<'_, Model>,
    #[pyo3(from_py_with = crate::options::whole)] regress_every: i64,
    #[pyo3(from_py_with = crate::options::real)] placement_window: f64,
) -> PyResult<Regressions> {
    let opts = ridi::TrackOptions {
        regress_every: options::count("regress_every", regress_every, 1, MAX_FRAMES_APART)?,
        placement_smoothing: options::placement_smoothing(placement_window)?,
        ..ridi::TrackOptions::default()
    };
    let (seq, model) = (&sequence.get().inner, &model.get().inner);
    let (velocities, placements) =
        options::detached(py, || ridi::regress_sequence(seq, model, &opts))?
            .map_err(|e: PipelineError| errors::of_sequence(e, "cannot regress", seq.name()))?;
    Ok(Regressions::of(
        &velocities,
        &placements,
        model.placement_names(),
    ))
}
