//! `ridi.Sequence`, `ridi.read`, `ridi.read_any` and `ridi.read_list`.

use std::path::PathBuf;

use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use ridi::data::{
    DeviceInfo, Format, GroundTruth, ListEntry, Listed, OrientationSource,
    Sequence as RidiSequence, SequenceError, SequenceParts, Validation,
};
use ridi::frames::{FilterConfig, Frame, STANDARD_GRAVITY, Vec3, gravity_in_device};
use ridi::{Purpose, load_listed};

use crate::arrays::{matrix, rotations, rotations_out, values, vecs, vecs_out, vector, vector_out};
use crate::errors;
use crate::options::{self, choice};

/// One recording on one timeline: IMU channels, device orientation and, where present, ground
/// truth, as numpy arrays (each property returns a new float64 array).
///
/// Read one with ``ridi.read(path)``, or build one from arrays: the arrays are validated as any
/// reader's input is (equal lengths, finite values, increasing time without long gaps,
/// plausible units, time in seconds, gravity along the orientation's up axis), and an error
/// names the array and the frame. Frames: the device frame is Android's sensor frame,
/// orientations are Hamilton world-from-device quaternions in ``[w, x, y, z]`` order, the world
/// frame has z up, gravity points up (as Android's gravity sensor reports it). Without
/// ``gravity`` it is the orientation's up axis; without either, both are estimated from gyro
/// and accelerometer (``orientation_source`` ``"estimated"``, the heading the gyro's alone), as
/// models on the estimated orientation (the bundled one, ``ridi train``'s default) estimate
/// them anyway. A phone at another rate than 200 Hz: ``resampled(ridi.RATE_HZ)``.
///
/// Example:
///
/// >>> import numpy as np, ridi
/// >>> n = 400
/// >>> t = np.arange(n) / 200.0
/// >>> up = np.tile([0.0, 9.81, 0.0], (n, 1))          # phone upright, at rest
/// >>> q = np.tile([0.7071068, 0.7071068, 0.0, 0.0], (n, 1))  # device y axis up
/// >>> seq = ridi.Sequence(t, np.zeros((n, 3)), up, up, q, name="still")
/// >>> seq.gravity.shape, round(seq.duration, 3)
/// ((400, 3), 1.995)
/// >>> bare = ridi.Sequence(t, np.zeros((n, 3)), up)   # no orientation: estimated
/// >>> bare.orientation_source, np.round(bare.gravity[-1], 2)
/// ('estimated', array([0.  , 9.81, 0.  ]))
#[pyclass(frozen, module = "ridi")]
pub(crate) struct Sequence {
    pub(crate) inner: RidiSequence,
    format: Option<Format>,
}

impl Sequence {
    pub(crate) fn of(inner: RidiSequence, format: Option<Format>) -> Self {
        Self { inner, format }
    }
}

#[pymethods]
impl Sequence {
    #[new]
    #[pyo3(signature = (
        time, gyro, acce, gravity=None, orientation=None, *, linacce=None, name="sequence",
        placement=None, magnet=None, ground_truth_position=None, ground_truth_orientation=None,
        steps=None, orientation_source=None, device=None, device_imu_rate_hz=None,
    ))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        time: &Bound<'_, PyAny>,
        gyro: &Bound<'_, PyAny>,
        acce: &Bound<'_, PyAny>,
        gravity: Option<&Bound<'_, PyAny>>,
        orientation: Option<&Bound<'_, PyAny>>,
        linacce: Option<&Bound<'_, PyAny>>,
        name: &str,
        placement: Option<String>,
        magnet: Option<&Bound<'_, PyAny>>,
        ground_truth_position: Option<&Bound<'_, PyAny>>,
        ground_truth_orientation: Option<&Bound<'_, PyAny>>,
        steps: Option<&Bound<'_, PyAny>>,
        orientation_source: Option<&str>,
        device: Option<&str>,
        #[pyo3(from_py_with = crate::options::opt_real)] device_imu_rate_hz: Option<f64>,
    ) -> PyResult<Self> {
        let time = vector(time, "time", None)?;
        let n = time.as_array().len();
        fn three<F: Frame>(obj: &Bound<'_, PyAny>, name: &str, n: usize) -> PyResult<Vec<Vec3<F>>> {
            matrix(obj, name, 3, Some(n)).and_then(|a| vecs(a.as_array(), name))
        }
        let four = |obj: &Bound<'_, PyAny>, name: &str| {
            matrix(obj, name, 4, Some(n)).and_then(|a| rotations(a.as_array(), name))
        };
        let (gyro, acce) = (three(gyro, "gyro", n)?, three(acce, "acce", n)?);
        let time = values(time.as_array(), "time")?;
        let (orientation, gravity, estimated) = match (orientation, gravity) {
            (Some(q), Some(g)) => (four(q, "orientation")?, three(g, "gravity", n)?, false),
            // Gravity as Android's gravity sensor gives it: the orientation's up axis.
            (Some(q), None) => {
                let q = four(q, "orientation")?;
                let g = q
                    .iter()
                    .map(|&q| gravity_in_device(q, STANDARD_GRAVITY))
                    .collect();
                (q, g, false)
            }
            // Estimated below, once the parts are whole.
            (None, None) => (Vec::new(), Vec::new(), true),
            (None, Some(_)) => {
                return Err(errors::value(
                    "`gravity` without `orientation`: give both, the orientation alone \
                     (gravity is then its up axis), or neither (both are then estimated from \
                     gyro and accelerometer)",
                ));
            }
        };
        let linacce = linacce.map(|l| three(l, "linacce", n)).transpose()?;
        let ground_truth = match (ground_truth_position, ground_truth_orientation) {
            (None, None) => None,
            (Some(p), Some(q)) => Some(GroundTruth {
                position: three(p, "ground_truth_position", n)?,
                orientation: four(q, "ground_truth_orientation")?,
            }),
            _ => {
                return Err(errors::value(
                    "ground truth needs both `ground_truth_position` and \
                     `ground_truth_orientation`",
                ));
            }
        };
        let orientation_source = orientation_source
            .map(|key| {
                let keys: Vec<(&str, OrientationSource)> = OrientationSource::ALL
                    .iter()
                    .map(|s| (s.key(), *s))
                    .collect();
                choice("orientation_source", key, &keys)
            })
            .transpose()?;
        if estimated && orientation_source.is_some_and(|s| s != OrientationSource::Estimated) {
            return Err(errors::value(
                "`orientation_source` names a recorded orientation, but none was given: the \
                 one estimated from gyro and accelerometer is 'estimated'",
            ));
        }
        let device = match device {
            None if device_imu_rate_hz.is_some() => {
                return Err(errors::value(
                    "`device_imu_rate_hz` without `device`: name the phone whose IMU sampled at \
                     that rate (`device=\"Pixel 7\"`, say)",
                ));
            }
            None => None,
            Some(model) => {
                let d = DeviceInfo::new(model).map_err(|e| errors::value(e.to_string()))?;
                Some(match device_imu_rate_hz {
                    Some(rate) => d
                        .with_imu_rate(rate)
                        .map_err(|e| errors::value(e.to_string()))?,
                    None => d,
                })
            }
        };
        let mut parts = SequenceParts {
            time,
            gyro,
            acce,
            // Set below, once gravity is known.
            linacce: Vec::new(),
            gravity,
            magnet: magnet.map(|m| three(m, "magnet", n)).transpose()?,
            orientation,
            orientation_source,
            ground_truth,
            steps: steps
                .map(|s| vector(s, "steps", Some(n)).and_then(|s| values(s.as_array(), "steps")))
                .transpose()?,
            device,
            placement,
            name: name.to_string(),
        };
        if estimated {
            estimate_into(&mut parts)?;
        }
        // Accelerometer minus gravity, as the RIDI files define it, unless given.
        parts.linacce = linacce.unwrap_or_else(|| {
            let (a, g) = (&parts.acce, &parts.gravity);
            a.iter().zip(g).map(|(&a, &g)| a - g).collect()
        });
        let name = parts.name.clone();
        let inner = RidiSequence::new(parts).map_err(|e| {
            // The Rust field `ground_truth.position` is the keyword `ground_truth_position` here.
            let e = with_remedy(&e).replace("`ground_truth.", "`ground_truth_");
            errors::value(format!("sequence `{name}`: {e}"))
        })?;
        Ok(Self::of(inner, None))
    }

    /// The sequence's name (its folder or file name when read).
    #[getter]
    fn name(&self) -> &str {
        self.inner.name()
    }

    /// Placement label (`Texting`, `hand`, ...), or None.
    #[getter]
    fn placement(&self) -> Option<&str> {
        self.inner.placement()
    }

    /// The format it was read from (`ridi-csv`, `ridi-plain`, `ridi-raw`, `tyrex`, `ilc`, `ronin`) by
    /// ``ridi.read``, or None (built from arrays, read from a list).
    #[getter]
    fn format(&self) -> Option<&'static str> {
        self.format.map(Format::key)
    }

    /// Timestamps, seconds, shape (N,).
    #[getter]
    fn time<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vector_out(py, self.inner.time().to_vec())
    }

    /// Gyroscope, rad/s, device frame, shape (N, 3).
    #[getter]
    fn gyro<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vecs_out(py, self.inner.gyro())
    }

    /// Accelerometer including gravity, m/s², device frame, shape (N, 3).
    #[getter]
    fn acce<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vecs_out(py, self.inner.acce())
    }

    /// Linear acceleration (accelerometer minus gravity), m/s², device frame, shape (N, 3).
    #[getter]
    fn linacce<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vecs_out(py, self.inner.linacce())
    }

    /// Gravity, pointing up (about +9.8 along the upward axis at rest), m/s², device frame,
    /// shape (N, 3).
    #[getter]
    fn gravity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vecs_out(py, self.inner.gravity())
    }

    /// Magnetometer, µT, device frame, shape (N, 3), or None.
    #[getter]
    fn magnet<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<f64>>> {
        self.inner.magnet().map(|m| vecs_out(py, m))
    }

    /// Device orientation, world-from-device quaternions `[w, x, y, z]`, shape (N, 4).
    #[getter]
    fn orientation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        rotations_out(py, self.inner.orientation())
    }

    /// Where the orientation comes from (`game-rotation-vector`, `rotation-vector`,
    /// `core-motion-attitude`, `estimated`, `ground-truth`, `gyro-integration`, `ekf`), or
    /// None.
    #[getter]
    fn orientation_source(&self) -> Option<&'static str> {
        self.inner.orientation_source().map(|s| s.key())
    }

    /// Ground-truth device position, metres, shape (N, 3), or None.
    #[getter]
    fn ground_truth_position<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<f64>>> {
        self.inner.ground_truth().map(|g| vecs_out(py, &g.position))
    }

    /// Ground-truth device orientation, `[w, x, y, z]`, shape (N, 4), or None.
    #[getter]
    fn ground_truth_orientation<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<f64>>> {
        self.inner
            .ground_truth()
            .map(|g| rotations_out(py, &g.orientation))
    }

    /// Step counter (steps since the start), shape (N,), or None.
    #[getter]
    fn steps<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.inner.steps().map(|s| vector_out(py, s.to_vec()))
    }

    /// The phone model it was recorded with (`Nexus 5`), or None.
    #[getter]
    fn device(&self) -> Option<&str> {
        self.inner.device().map(|d| d.model())
    }

    /// The rate the phone's IMU sampled at before any resampling, Hz, or None.
    #[getter]
    fn device_imu_rate_hz(&self) -> Option<f64> {
        self.inner.device().and_then(|d| d.imu_rate_hz())
    }

    /// Duration, seconds (last timestamp minus first).
    #[getter]
    fn duration(&self) -> f64 {
        self.inner.duration()
    }

    /// Mean rate, Hz: frame intervals over duration, `(N - 1) / duration`.
    #[getter]
    fn rate_hz(&self) -> f64 {
        self.inner.rate_hz()
    }

    /// Rate, Hz, one over the median frame interval (what tracking checks: 200 Hz ± 10 %).
    #[getter]
    fn median_rate_hz(&self) -> f64 {
        self.inner.median_rate_hz()
    }

    /// A copy with the placement label `placement` (None removes it): what training needs
    /// of a sequence read without a list file.
    #[pyo3(signature = (placement))]
    fn with_placement(&self, placement: Option<String>) -> Self {
        let mut inner = self.inner.clone();
        inner.set_placement(placement);
        Self::of(inner, self.format)
    }

    /// The sequence cut at every gap longer than ``max_gap_s`` seconds (``ridi.track``
    /// refuses one over 0.1 s): the parts at least ``min_duration_s`` long, in order, named as
    /// ``ridi convert --split-at-gaps`` names them (``<name>_part1``, ``_part2``, ...; the
    /// plain name when one is left). Without such a gap, a list of the sequence itself (empty
    /// when it is shorter than ``min_duration_s``).
    #[pyo3(signature = (max_gap_s, min_duration_s=0.0))]
    fn split_at_gaps(
        &self,
        #[pyo3(from_py_with = crate::options::real)] max_gap_s: f64,
        #[pyo3(from_py_with = crate::options::real)] min_duration_s: f64,
    ) -> PyResult<Vec<Self>> {
        let split = self
            .inner
            .clone()
            .split_at_gaps(max_gap_s, min_duration_s)
            .map_err(|e| errors::value(e.to_string()))?;
        Ok(split
            .parts
            .into_iter()
            .map(|s| Self::of(s, self.format))
            .collect())
    }

    /// The sequence on a uniform timeline at ``rate_hz`` (models take 200 Hz, ``ridi.RATE_HZ``),
    /// as ``ridi convert --rate`` resamples: vectors linearly interpolated, orientations by
    /// slerp, from the first frame to at most the last. A gap longer than ``max_gap_s``
    /// (default: 5 of the sequence's median frame intervals) is refused rather than filled
    /// with invented frames: cut the sequence there first (``split_at_gaps``).
    ///
    /// >>> seq50 = ridi.Sequence(t, gyro, acce, gravity, orientation)  # doctest: +SKIP
    /// >>> seq = seq50.resampled(ridi.RATE_HZ)                          # doctest: +SKIP
    #[pyo3(signature = (rate_hz, max_gap_s=None))]
    fn resampled(
        &self,
        #[pyo3(from_py_with = crate::options::real)] rate_hz: f64,
        #[pyo3(from_py_with = crate::options::opt_real)] max_gap_s: Option<f64>,
    ) -> PyResult<Self> {
        let max_gap = max_gap_s.unwrap_or_else(|| ridi::resample_max_gap(&self.inner));
        let median_step = 1.0 / self.inner.median_rate_hz();
        // Not a gap limit of no sequence (0, NaN): the resampler names those.
        if max_gap_s.is_some() && max_gap > 0.0 && max_gap < median_step {
            return Err(errors::value(format!(
                "`max_gap_s` is {max_gap} s, below the median frame interval of sequence `{}` \
                 ({} s): every frame would be a gap; give at least that (the default is 5 \
                 intervals)",
                self.inner.name(),
                ridi::data::short(median_step)
            )));
        }
        let resampled = self
            .inner
            .resampled(rate_hz, max_gap)
            .map_err(|e| match e {
                SequenceError::Gap { .. } => errors::value(format!(
                    "sequence `{}`: {e}: cut it there first (`split_at_gaps({})`), or give a \
                 larger `max_gap_s` to interpolate across",
                    self.inner.name(),
                    ridi::data::short(ridi::split_limit(max_gap))
                )),
                e => errors::value(format!("sequence `{}`: {e}", self.inner.name())),
            })?;
        Ok(Self::of(resampled, self.format))
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }

    /// Pickled (for ``multiprocessing``, ``copy``) as the constructor call that rebuilds it:
    /// its arrays and metadata; the format it was read from is not kept.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let kwargs = PyDict::new(py);
        for key in [
            "linacce",
            "name",
            "placement",
            "magnet",
            "ground_truth_position",
            "ground_truth_orientation",
            "steps",
            "orientation_source",
            "device",
            "device_imu_rate_hz",
        ] {
            kwargs.set_item(key, slf.getattr(key)?)?;
        }
        let mut args = vec![slf.get_type().into_any()];
        for key in ["time", "gyro", "acce", "gravity", "orientation"] {
            args.push(slf.getattr(key)?);
        }
        let rebuild = py
            .import("functools")?
            .getattr("partial")?
            .call(PyTuple::new(py, args)?, Some(&kwargs))?;
        Ok((rebuild, PyTuple::empty(py)))
    }

    fn __repr__(&self) -> String {
        format!(
            "Sequence('{}', {} frames, {:.2} s, placement={}, ground truth: {})",
            // Escaped as every message is: a name may hold a line break or a terminal escape.
            ridi::data::shown(self.inner.name()),
            self.inner.len(),
            self.inner.duration(),
            self.inner
                .placement()
                .map_or("None".to_string(), |p| format!(
                    "'{}'",
                    ridi::data::shown(p)
                )),
            if self.inner.ground_truth().is_some() {
                "yes"
            } else {
                "no"
            }
        )
    }
}

/// Gives `parts` without an orientation the estimate of gyro and accelerometer that models on
/// the estimated orientation make themselves (`ridi train`'s default), its heading the gyro's
/// alone. Time is checked first, so that time in milliseconds is named as such and not by the
/// estimator.
fn estimate_into(parts: &mut SequenceParts) -> PyResult<()> {
    let failed = |name: &str, e: String| errors::value(format!("sequence `{name}`: {e}"));
    // Time that goes back is named as such by the estimate's own checks, not as a unit.
    if parts.time.windows(2).all(|w| w[1] > w[0]) {
        Validation::default()
            .check_time_step(&parts.time)
            .map_err(|e| failed(&parts.name, e.to_string()))?;
    }
    parts
        .estimate_orientation(&FilterConfig::default())
        .map_err(|e| match e {
            SequenceError::Estimate { .. } => failed(
                &parts.name,
                format!("no orientation was given, and it cannot be estimated: {e}"),
            ),
            e => failed(&parts.name, with_remedy(&e)),
        })
}

/// `e` with what to do about it in numpy, where the arrays (not a sequence) are at fault: a
/// `Sequence` cannot be built to be split or cleaned.
fn with_remedy(e: &SequenceError) -> String {
    let remedy = match e {
        SequenceError::TimeNotIncreasing { previous, next, .. } if previous == next => {
            ": a repeated timestamp; drop the repeated rows first (`keep = np.r_[True, \
             np.diff(time) > 0]`, then index every array with `keep`)"
        }
        SequenceError::TimeNotIncreasing { .. } => {
            ": time goes back; if the rows are merely out of order, sort every array by \
             `np.argsort(time, kind=\"stable\")` first"
        }
        SequenceError::Gap { .. } => {
            ": build a Sequence of each side (the arrays before that frame and from it on); \
             `split_at_gaps` cuts the shorter gaps of a Sequence"
        }
        _ => "",
    };
    format!("{e}{remedy}")
}

/// Emits the readers' (or an evaluation's) warnings as Python `UserWarning`s, as the command
/// line prints them.
pub(crate) fn warn(py: Python<'_>, warnings: &[String]) -> PyResult<()> {
    let category = py.get_type::<PyUserWarning>();
    for w in warnings {
        // Escaped as the command line prints them; `shown` escapes NUL too.
        let text = std::ffi::CString::new(ridi::data::shown(w)).expect("NUL is escaped");
        PyErr::warn(py, &category, &text, 1)?;
    }
    Ok(())
}

/// Every sequence at `path` (several for a Tyrex run split at a long motion-capture loss).
fn read_sequences(
    py: Python<'_>,
    path: &std::path::Path,
    format: Option<&str>,
    split_at_gaps: Option<f64>,
) -> PyResult<Vec<Sequence>> {
    let formats = Format::ALL.map(|f| (f.key(), f));
    let from = format.map(|f| choice("format", f, &formats)).transpose()?;
    let read = options::read_options();
    let loaded = options::detached(py, || match split_at_gaps {
        Some(max_gap) => ridi::read_split(path, from, &read, max_gap),
        None => ridi::read_any(path, from, &read),
    })?
    .map_err(errors::data)?;
    warn(py, &loaded.warnings)?;
    let format = loaded.format;
    Ok(loaded
        .sequences
        .into_iter()
        .map(|s| Sequence::of(s, Some(format)))
        .collect())
}

/// Reads the recording at `path`: a RIDI ``data.csv`` (or ``.csv.gz``), ``data_plain.txt``,
/// RIDI raw recorder folder, Tyrex run folder, Indoor Location Competition path file or RoNIN
/// sequence folder, as ``ridi inspect`` reads it (a Tyrex run that mocap losses split is
/// several sequences here: ``read_any``). ``format`` forces one (``ridi-csv``, ``ridi-plain``, ``ridi-raw``,
/// ``tyrex``, ``ilc``, ``ronin``) instead of detecting it. The readers' warnings are ``UserWarning``\ s.
///
/// ``split_at_gaps`` (seconds, above 0 and below 1) cuts the recording at every gap longer than that, as
/// ``ridi convert --split-at-gaps`` does: a pause longer than the 1 s the readers accept is
/// read and cut too (in every format but a RIDI raw or RoNIN folder), parts shorter than 1 s are
/// dropped with a warning; read the parts with ``ridi.read_any``.
///
/// Raises ``OSError`` when the file cannot be read, ``ValueError`` naming the file, line and
/// field when its content is wrong, and ``ValueError`` when the source holds several
/// sequences (read those with ``ridi.read_any``).
///
/// >>> seq = ridi.read("datasets/sample/Jakob_Nexus5_NoDist_Texting")  # doctest: +SKIP
/// >>> seq.gyro.shape                                                    # doctest: +SKIP
/// (4800, 3)
#[pyfunction]
#[pyo3(signature = (path, format=None, *, split_at_gaps=None))]
pub(crate) fn read(
    py: Python<'_>,
    path: PathBuf,
    format: Option<&str>,
    #[pyo3(from_py_with = crate::options::opt_real)] split_at_gaps: Option<f64>,
) -> PyResult<Sequence> {
    let mut seqs = read_sequences(py, &path, format, split_at_gaps)?;
    if seqs.is_empty() {
        // Every part cut at the gaps was shorter than a part may be (the warning said so).
        return Err(errors::value(format!(
            "{}: no part left once cut at its gaps, each shorter than a sequence may be: cut \
             at longer gaps (a larger `split_at_gaps`)",
            ridi::data::shown(&path)
        )));
    }
    if seqs.len() != 1 {
        return Err(errors::value(format!(
            "{} holds {} sequences; read them with `ridi.read_any`, or convert it with `ridi \
             convert`",
            path.display(),
            seqs.len()
        )));
    }
    Ok(seqs.remove(0))
}

/// Reads every sequence at `path` (``ridi.read`` for sources that hold several, such as a
/// Tyrex run split at a long motion-capture loss, or a recording cut by ``split_at_gaps``),
/// in order.
///
/// >>> parts = ridi.read_any("walk/data.csv", split_at_gaps=0.1)  # doctest: +SKIP
#[pyfunction]
#[pyo3(signature = (path, format=None, *, split_at_gaps=None))]
pub(crate) fn read_any(
    py: Python<'_>,
    path: PathBuf,
    format: Option<&str>,
    #[pyo3(from_py_with = crate::options::opt_real)] split_at_gaps: Option<f64>,
) -> PyResult<Vec<Sequence>> {
    read_sequences(py, &path, format, split_at_gaps)
}

/// Reads the sequences of list files (``path,placement`` per line, ``#`` comments, paths
/// relative to the list), in order, several lists as one, as ``ridi train --list`` and
/// ``ridi eval --list`` do.
///
/// ``placement_map`` (``"tyrex4"`` or a file of ``label,class`` lines) relabels the
/// placements; ``purpose`` (``"training"`` or ``"evaluation"``) checks what that needs of each
/// sequence (ground truth; a placement label for training). Every error names the list file and
/// line.
///
/// >>> seqs = ridi.read_list("datasets/sample/list_test.txt", placement_map="tyrex4")  # doctest: +SKIP
/// >>> [s.placement for s in seqs][:2]                                               # doctest: +SKIP
/// ['hand', 'pocket']
#[pyfunction]
#[pyo3(signature = (lists, *, placement_map=None, purpose=None))]
pub(crate) fn read_list(
    py: Python<'_>,
    lists: &Bound<'_, PyAny>,
    placement_map: Option<PathBuf>,
    purpose: Option<&str>,
) -> PyResult<Vec<Sequence>> {
    let options::Inputs::Lists(lists) = options::Inputs::extract(lists)? else {
        return Err(pyo3::exceptions::PyTypeError::new_err(
            "`lists` must be a list file (str or os.PathLike) or a list of them",
        ));
    };
    let map = options::placement_map(placement_map)?;
    let purpose = purpose
        .map(|p| {
            choice(
                "purpose",
                p,
                &[
                    ("training", Purpose::Training),
                    ("evaluation", Purpose::Evaluation),
                ],
            )
        })
        .transpose()?;
    let listed = options::detached(py, || -> ridi::Result<Listed> {
        let entries = ListEntry::read(&lists)?;
        let read = options::read_options();
        match purpose {
            Some(purpose) => load_listed(entries, map.as_ref(), purpose, &read),
            None => {
                // The labels written in the lists, checked as `load_listed` checks them.
                if let Some(map) = &map {
                    for e in &entries {
                        if let Some(label) = &e.placement {
                            map.class_at(label, e.location())?;
                        }
                    }
                }
                let mut listed = Listed::load(entries, &read)?;
                if let Some(map) = &map {
                    map.apply(listed.sequences_mut());
                }
                Ok(listed)
            }
        }
    })?
    .map_err(errors::pipeline)?;
    Ok(listed
        .into_sequences()
        .into_iter()
        .map(|s| Sequence::of(s, None))
        .collect())
}
