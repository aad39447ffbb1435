//! `ridi.LiveTracker` and `ridi.Update`.

use std::sync::{Arc, Mutex, MutexGuard};

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyFloat, PySequence, PyString};
use ridi::correct::Update as RidiUpdate;
use ridi::features::Orientation;
use ridi::frames::{DeviceVec, WorldFromDevice};
use ridi::regress::Cascade;
use ridi::{Recorded, SensorReading};

use crate::arrays::{described, dtype_kind};
use crate::errors;
use crate::model::Model;
use crate::options;
use crate::track::Regressions;

/// One frame's pose as a stream knows it: what ``LiveTracker.push`` returns.
#[pyclass(frozen, module = "ridi")]
pub(crate) struct Update {
    /// Stream index of the frame (from 0, across restarts).
    #[pyo3(get)]
    frame: u64,
    /// Timestamp, seconds.
    #[pyo3(get)]
    time: f64,
    /// Position ``(x, y, z)``, metres from the start, world frame.
    #[pyo3(get)]
    position: (f64, f64, f64),
    /// Velocity ``(x, y, z)``, m/s, world frame.
    #[pyo3(get)]
    velocity: (f64, f64, f64),
    /// The bias correction added to the linear acceleration from this frame on ``(x, y, z)``
    /// (minus the accelerometer's estimated bias), m/s², device frame.
    #[pyo3(get)]
    bias: (f64, f64, f64),
    /// True when this sample started a new segment after a gap longer than 0.1 s.
    #[pyo3(get)]
    restarted: bool,
}

/// What a pickled [`Update`] holds: its fields in order.
type Triple = (f64, f64, f64);
type UpdateState = (u64, f64, Triple, Triple, Triple, bool);

fn triple(v: [f64; 3]) -> (f64, f64, f64) {
    (v[0], v[1], v[2])
}

impl From<RidiUpdate> for Update {
    fn from(u: RidiUpdate) -> Self {
        Self {
            frame: u.frame,
            time: u.pose.time,
            position: triple(u.pose.position.to_array()),
            velocity: triple(u.pose.velocity.to_array()),
            bias: triple(u.bias.to_array()),
            restarted: u.restarted,
        }
    }
}

#[pymethods]
impl Update {
    /// Pickled as its fields (for ``multiprocessing``).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, UpdateState)> {
        let u = slf.get();
        let state = (u.frame, u.time, u.position, u.velocity, u.bias, u.restarted);
        Ok((slf.get_type().getattr("_from_state")?, state))
    }

    /// The update [`Self::__reduce__`] pickled.
    #[staticmethod]
    fn _from_state(
        frame: u64,
        time: f64,
        position: (f64, f64, f64),
        velocity: (f64, f64, f64),
        bias: (f64, f64, f64),
        restarted: bool,
    ) -> Self {
        Self {
            frame,
            time,
            position,
            velocity,
            bias,
            restarted,
        }
    }

    fn __repr__(&self) -> String {
        let p = self.position;
        format!(
            "Update(frame={}, time={}, position=({:.3}, {:.3}, {:.3}))",
            self.frame, self.time, p.0, p.1, p.2
        )
    }
}

/// Tracks a live stream with a trained model: push each sample as it arrives, get the poses
/// that became known (``ridi::LiveTracker``). Pushing a whole recording gives exactly the poses
/// of ``ridi.track(seq, model, online=True)`` and ``ridi track --online``.
///
/// A model trained on the recorded orientation needs ``orientation`` (``[w, x, y, z]``),
/// ``gravity`` and ``linacce`` with every sample; one trained with
/// ``orientation="estimated"`` estimates its own from gyro and accelerometer, and its first
/// frames come out together once it knows the initial tilt (``finish`` releases what a short
/// stream leaves); given the phone's ``orientation`` too, it corrects the gyro's heading drift
/// by that orientation's slow heading (``heading="corrected"``, the default; ``"gyro"`` keeps
/// the gyro's). A refused sample (non-finite, beyond any phone sensor, not after the
/// previous one) raises ``ValueError`` and leaves the tracking as it was; from the 201st
/// sample on, the last 200 samples' median rate (200 Hz within 10 %), |gyro| and |acce| are
/// judged, so a stream in milliseconds, deg/s or g is refused by then (refused samples count
/// towards the last 200), and so are the ``gravity`` and ``linacce`` pushed against the
/// orientation and accelerometer, as ``ridi.Sequence`` judges a recording (gravity negated or
/// in g, gravity left in ``linacce``); once consecutive samples with an ``orientation`` cover
/// 10 s, a gyro turning against it (a sign flipped, most quaternions in x, y, z, w order) is
/// refused, and stays so.
/// A gap longer than 0.1 s starts a new segment (``Update.restarted``); pushing after
/// ``finish()`` raises.
///
/// >>> live = ridi.LiveTracker(model)                      # doctest: +SKIP
/// >>> for i in range(len(seq)):                           # doctest: +SKIP
/// ...     for u in live.push(seq.time[i], seq.gyro[i], seq.acce[i],
/// ...                        orientation=seq.orientation[i],
/// ...                        gravity=seq.gravity[i], linacce=seq.linacce[i]):
/// ...         print(u.time, u.position)
#[pyclass(frozen, module = "ridi")]
pub(crate) struct LiveTracker {
    // Declared before `model`, so dropped before it: the tracker borrows the model.
    live: Mutex<ridi::LiveTracker<'static>>,
    model: Arc<Cascade>,
}

impl LiveTracker {
    fn lock(&self) -> MutexGuard<'_, ridi::LiveTracker<'static>> {
        // A panic inside the tracker is a bug that pyo3 already reported; the state it left is
        // the tracker's own business, as for a refused sample.
        self.live.lock().unwrap_or_else(|p| p.into_inner())
    }
}

#[pymethods]
impl LiveTracker {
    #[new]
    #[pyo3(signature = (
        model, *, regress_every=50, lambda_=0.1, estimate_initial_velocity=false,
        placement_window=10.0, heading="corrected",
    ))]
    fn new(
        #[pyo3(from_py_with = crate::options::model)] model: Bound<'_, Model>,
        #[pyo3(from_py_with = crate::options::whole)] regress_every: i64,
        #[pyo3(from_py_with = crate::options::real)] lambda_: f64,
        estimate_initial_velocity: bool,
        #[pyo3(from_py_with = crate::options::real)] placement_window: f64,
        heading: &str,
    ) -> PyResult<Self> {
        let opts = options::track_options(
            true,
            regress_every,
            lambda_,
            estimate_initial_velocity,
            placement_window,
            heading,
        )?;
        let model = Arc::clone(&model.get().inner);
        // SAFETY: the cascade lives in `model`'s heap allocation, which this tracker keeps
        // alive (and never moves or mutates) for as long as `live` exists: `live` is dropped
        // first (field order), and neither field is ever replaced.
        let cascade: &'static Cascade = unsafe { &*Arc::as_ptr(&model) };
        let live = ridi::LiveTracker::new(cascade, &opts).map_err(errors::pipeline)?;
        Ok(Self {
            live: Mutex::new(live),
            model,
        })
    }

    /// Adds one sample: ``time`` in seconds, ``gyro`` (rad/s) and ``acce`` (m/s², with
    /// gravity) as 3 values in the device frame, and the phone's ``orientation`` ``[w, x, y, z]``,
    /// ``gravity`` and ``linacce`` (needed by a model trained on the recorded orientation; one
    /// on the estimated orientation takes only the slow heading of ``orientation``, which may
    /// come alone).
    /// Returns the updates of the frames whose pose became known (one, except while an
    /// estimated orientation starts up).
    #[pyo3(signature = (time, gyro, acce, *, orientation=None, gravity=None, linacce=None))]
    #[allow(clippy::too_many_arguments)]
    fn push(
        &self,
        py: Python<'_>,
        time: &Bound<'_, PyAny>,
        gyro: &Bound<'_, PyAny>,
        acce: &Bound<'_, PyAny>,
        orientation: Option<&Bound<'_, PyAny>>,
        gravity: Option<&Bound<'_, PyAny>>,
        linacce: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Vec<Update>> {
        // As `Sequence` refuses them: a bool is no reading, a float16/32 time is rounded.
        for (name, obj) in [
            ("time", Some(time)),
            ("gyro", Some(gyro)),
            ("acce", Some(acce)),
        ]
        .into_iter()
        .chain([
            ("orientation", orientation),
            ("gravity", gravity),
            ("linacce", linacce),
        ]) {
            if let Some(obj) = obj {
                refuse_unreadable(obj, name)?;
            }
        }
        let time: f64 = time.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "`time` must be one number, seconds (push takes one sample), not {}",
                described(time)
            ))
        })?;
        let (gyro, acce) = (values::<3>(gyro, "gyro")?, values::<3>(acce, "acce")?);
        let orientation = orientation
            .map(|o| values::<4>(o, "orientation"))
            .transpose()?;
        let gravity = gravity.map(|g| values::<3>(g, "gravity")).transpose()?;
        let linacce = linacce.map(|l| values::<3>(l, "linacce")).transpose()?;
        let estimated = self.model.feature_config().orientation == Orientation::Estimated;
        let quaternion = |q: [f64; 4]| {
            WorldFromDevice::from_wxyz_as_given(q)
                .map_err(|e| errors::value(format!("`orientation` at t = {time} s: {e}")))
        };
        let recorded = match (orientation, gravity, linacce) {
            (None, None, None) => None,
            (Some(q), Some(g), Some(l)) => Some(Recorded {
                orientation: quaternion(q)?,
                gravity: DeviceVec::from_array(g),
                linacce: DeviceVec::from_array(l),
            }),
            // Only the heading is taken from it: gravity and linear acceleration follow.
            (Some(q), None, None) if estimated => {
                let orientation = quaternion(q)?;
                let (gravity, linacce) =
                    ridi::frames::gravity_and_linacce(orientation, DeviceVec::from_array(acce));
                Some(Recorded {
                    orientation,
                    gravity,
                    linacce,
                })
            }
            _ => {
                return Err(errors::value(
                    "give `orientation`, `gravity` and `linacce` together, or none of them \
                     (a model on the estimated orientation takes `orientation` alone)",
                ));
            }
        };
        if recorded.is_none() && self.model.feature_config().orientation == Orientation::Recorded {
            return Err(errors::value(
                "the model was trained on the recorded orientation: give `orientation`, \
                 `gravity` and `linacce` with every sample (or train with \
                 orientation=\"estimated\")",
            ));
        }
        let sample = SensorReading {
            time,
            gyro: DeviceVec::from_array(gyro),
            acce: DeviceVec::from_array(acce),
            recorded,
        };
        let mut out = Vec::with_capacity(1);
        py.detach(|| self.lock().push(&sample, &mut out))
            .map_err(errors::pipeline)?;
        Ok(out.into_iter().map(Update::from).collect())
    }

    /// Ends the stream: the updates of frames still waiting for an estimated orientation.
    fn finish(&self, py: Python<'_>) -> PyResult<Vec<Update>> {
        let mut out = Vec::new();
        py.detach(|| self.lock().finish(&mut out))
            .map_err(errors::pipeline)?;
        Ok(out.into_iter().map(Update::from).collect())
    }

    /// Every regression made so far (frames are stream indices).
    #[getter]
    fn regressions(&self) -> Regressions {
        let live = self.lock();
        let (velocities, placements) = live.regressions();
        Regressions::of(velocities, placements, self.model.placement_names())
    }

    fn __repr__(&self) -> String {
        format!(
            "LiveTracker(placements={:?}, {} regressions so far)",
            self.model.placement_names(),
            self.lock().regressions().0.len()
        )
    }
}

/// Refuses a pushed value numpy or Python would read as numbers but a sample cannot hold:
/// bools (`True` read as 1), and for `time` a float16/float32 scalar (rounded already: to
/// minutes at Unix times).
fn refuse_unreadable(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<()> {
    // The common case, a Python float (a `time`), needs no look at a dtype: pushed per sample.
    if obj.is_exact_instance_of::<PyFloat>() {
        return Ok(());
    }
    // The items of what is read as a sequence of numbers (a list, a tuple, a deque, an object
    // array; text is no reading), at most 4: a reading has 3, and any other count is refused
    // later. An array of numbers says by its dtype. Other iterables are not walked: an endless
    // one would never end; a 0-d object array is its one item.
    let own = dtype_kind(obj);
    let objects = own.is_some_and(|(k, _)| k == b'O');
    let zero_d = objects && obj.getattr("ndim")?.extract::<usize>()? == 0;
    let walk = (objects && !zero_d)
        || (own.is_none()
            && obj.cast::<PySequence>().is_ok()
            && !obj.is_instance_of::<PyString>()
            && !obj.is_instance_of::<PyBytes>());
    let items: Vec<Bound<'_, PyAny>> = if walk {
        obj.try_iter()?.take(4).collect::<PyResult<_>>()?
    } else if zero_d {
        vec![obj.call_method0("item")?]
    } else {
        vec![obj.clone()]
    };
    for item in items.iter().chain(std::iter::once(obj)) {
        if crate::options::not_bool(item).is_err() {
            return Err(PyTypeError::new_err(format!(
                "`{name}` holds bools; a sample's readings are numbers"
            )));
        }
        match dtype_kind(item) {
            Some((b'f', size)) if name == "time" && size < 8 => {
                return Err(PyTypeError::new_err(format!(
                    "`time` is a float{}: its bits have rounded the timestamp already (to 0.24 \
                     ms an hour into a recording, to minutes at Unix times): give it as a \
                     Python float or float64",
                    size * 8
                )));
            }
            _ => {}
        }
    }
    Ok(())
}

/// `N` numbers of one sample for argument `name`, or a `TypeError` that says so (pyo3's own
/// names neither the argument nor what it wants).
fn values<const N: usize>(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<[f64; N]> {
    obj.extract().map_err(|_| {
        let message = format!(
            "`{name}` must be {N} numbers (push takes one sample; push a chunk row by row), not \
             {}",
            described(obj)
        );
        // Numbers of another count (or a chunk's rows) are a wrong value, as a wrong shape is
        // for `Sequence`; anything else is a wrong type.
        match reads_as_numbers(obj, 0) {
            true => errors::value(message),
            false => PyTypeError::new_err(message),
        }
    })
}

/// Whether `obj` is numbers (`depth` 0), or rows of them: a numeric array, or a sequence whose
/// first items (at most 4) are numbers, or at `depth` 0 such rows; a single number is not.
/// Judged by a look, not a copy: a chunk pushed by mistake may hold more rows than memory
/// holds a copy of.
fn reads_as_numbers(obj: &Bound<'_, PyAny>, depth: u8) -> bool {
    let numeric = dtype_kind(obj).is_some_and(|(k, _)| matches!(k, b'f' | b'i' | b'u'));
    // A numpy scalar (0-d) at the top is one number, as a Python float is.
    let array = obj
        .getattr("ndim")
        .is_ok_and(|n| n.extract::<usize>().is_ok_and(|n| n > 0));
    if numeric && (depth > 0 || array) {
        return true;
    }
    if depth > 0 && obj.extract::<f64>().is_ok() {
        return true;
    }
    let walkable = depth < 2
        && obj.cast::<PySequence>().is_ok()
        && !obj.is_instance_of::<PyString>()
        && !obj.is_instance_of::<PyBytes>();
    let first = walkable
        .then(|| {
            obj.try_iter()
                .ok()?
                .take(4)
                .collect::<PyResult<Vec<_>>>()
                .ok()
        })
        .flatten()
        .unwrap_or_default();
    !first.is_empty() && first.iter().all(|item| reads_as_numbers(item, depth + 1))
}
