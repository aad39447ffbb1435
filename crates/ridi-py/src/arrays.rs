//! numpy arrays in and out.
//!
//! In: float64 arrays of any layout (C or Fortran order, strided slices, negative strides) are
//! read in place through an ndarray view, without a contiguous copy first; the one copy made is
//! into the `Sequence`'s own storage. A view that is unaligned or strided off whole elements (a
//! field of a record array, bytes at an odd offset) is copied first. Arrays of other real dtypes and array-likes (lists,
//! pandas) are converted to float64 by numpy first. A dtype that is not a real number is a
//! `TypeError`, another shape a `ValueError`, both naming the argument; values (NaN, units) are checked by the facade's own
//! validation, which names the array and the frame.
//!
//! Out: each array is built once in Rust and handed to numpy without a further copy.

use numpy::ndarray::{Array2, ArrayView1, ArrayView2};
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyArrayDescrMethods, PyArrayMethods, PyReadonlyArray1,
    PyReadonlyArray2, PyUntypedArray, PyUntypedArrayMethods, dtype,
};
use pyo3::exceptions::{PyMemoryError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyString};
use ridi::frames::{Frame, Vec3, WorldFromDevice};

use crate::errors;

/// `shape` as numpy prints it: `(100, 3)`, `(100,)`.
fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => {
            let dims: Vec<String> = shape.iter().map(usize::to_string).collect();
            format!("({})", dims.join(", "))
        }
    }
}

/// `obj` as a numpy array of float64, or a `TypeError` naming the argument `name`.
///
/// A float64 array is taken as it is (read in place), unless it is unaligned, strided off
/// whole elements or empty (copied: ndarray's view needs an aligned pointer). Another array of real numbers (float32,
/// integers, objects that are numbers: a pandas nullable column) and what numpy reads as one
/// (a list, a pandas column or frame, an `array.array`) are converted as `np.asarray(obj,
/// dtype=np.float64)` would: a copy, exact for every float32 and for integers up to 2^53.
/// `time` alone refuses float16 and float32: their 11 or 24 bits have rounded the timestamps
/// already (to 0.24 ms an hour into a recording, to minutes at Unix times).
fn float64<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Bound<'py, PyUntypedArray>> {
    let py = obj.py();
    let not_numbers = |why: String| {
        PyTypeError::new_err(format!(
            "`{name}` must be an array of numbers (a numpy array, a list of numbers or a pandas \
             column), not {}{why}",
            described(obj)
        ))
    };
    // A masked array's masked values would be read as the values under the mask.
    if obj.hasattr("mask")?
        && py
            .import("numpy")?
            .getattr("ma")?
            .call_method1("is_masked", (obj,))?
            .is_truthy()?
    {
        return Err(PyTypeError::new_err(format!(
            "`{name}` is a masked array with masked values: fill them (`{name}.filled(...)`) or \
             drop those frames first"
        )));
    }
    let array = match obj.cast::<PyUntypedArray>() {
        Ok(array) => array.clone(),
        // Text is a sequence numpy would read as one string, not numbers.
        Err(_) if obj.is_instance_of::<PyString>() || obj.is_instance_of::<PyBytes>() => {
            return Err(not_numbers(String::new()));
        }
        Err(_) => py
            .import("numpy")?
            .call_method1("asarray", (obj,))
            .map_err(|e| not_numbers(format!(" (numpy: {e})")))?
            .cast_into::<PyUntypedArray>()?,
    };
    let found = array.dtype();
    if found.is_equiv_to(&dtype::<f64>(py)) {
        // A view the element type cannot be read through as it lies (a field of a record
        // array, bytes at an odd offset): rust-numpy divides strides by 8 and reads unaligned,
        // so such a view is copied (a new array is aligned; `ascontiguousarray` would return a
        // contiguous unaligned one as it is).
        // numpy calls every empty array aligned, whatever its pointer.
        let aligned = array.getattr("flags")?.getattr("aligned")?.is_truthy()?;
        if !aligned || array.is_empty() || array.strides().iter().any(|s| s % 8 != 0) {
            return Ok(array.call_method0("copy")?.cast_into::<PyUntypedArray>()?);
        }
        return Ok(array);
    }
    let kind = found.kind();
    if kind == b'O' {
        object_elements(&array, name)?;
    }
    let coarse_time = name == "time" && kind == b'f' && found.itemsize() < 8;
    if matches!(kind, b'f' | b'i' | b'u' | b'O') && !coarse_time {
        return match array.call_method1("astype", ("float64",)) {
            Ok(converted) => Ok(converted.cast_into::<PyUntypedArray>()?),
            Err(e) => Err(PyTypeError::new_err(format!(
                "`{name}` has dtype {found} and values that are not real numbers (numpy: {e})"
            ))),
        };
    }
    let convert = match kind {
        // Numpy dates and durations: a cast to float64 would give nanoseconds, not seconds.
        b'M' if name == "time" => {
            format!("seconds as float64: ({name} - {name}[0]) / np.timedelta64(1, 's')")
        }
        b'm' if name == "time" => format!("seconds as float64: {name} / np.timedelta64(1, 's')"),
        b'M' | b'm' => {
            "dates and durations are for `time`; a sensor's readings are numbers".to_string()
        }
        _ if coarse_time => "its bits have rounded the timestamps already (to 0.24 ms an hour \
             into a recording, to minutes at Unix times): compute them in float64"
            .to_string(),
        _ => "an array of real numbers".to_string(),
    };
    Err(PyTypeError::new_err(format!(
        "`{name}` has dtype {found}; ridi takes float64 ({convert})"
    )))
}

/// Refuses an object array whose elements numpy would convert but ridi should not take:
/// numbers as text (`"1.5"`: a column read without parsing, where a typo converts or fails
/// far from its cause), bools (as a bool array is refused) and, for `time`, numpy
/// float16/float32 scalars (rounded as a float32 array's are).
fn object_elements(array: &Bound<'_, PyUntypedArray>, name: &str) -> PyResult<()> {
    let py = array.py();
    let builtins = py.import("builtins")?;
    let types = builtins
        .getattr("map")?
        .call1((builtins.getattr("type")?, array.getattr("flat")?))?;
    let types = builtins.getattr("set")?.call1((types,))?;
    let numpy = py.import("numpy")?;
    let coarse = [numpy.getattr("float16")?, numpy.getattr("float32")?];
    for t in types.try_iter()? {
        let t = t?;
        let type_name = t.getattr("__name__")?.to_string();
        if t.is(py.get_type::<PyString>()) || t.is(py.get_type::<PyBytes>()) {
            return Err(PyTypeError::new_err(format!(
                "`{name}` has dtype object and holds text ({type_name}): parse the numbers \
                 first (`np.asarray({name}, dtype=np.float64)`, or `pd.to_numeric` for a column \
                 read as text), so that a value that is no number fails where it is read"
            )));
        }
        if t.is(py.get_type::<pyo3::types::PyBool>()) || t.is(numpy.getattr("bool_")?) {
            return Err(PyTypeError::new_err(format!(
                "`{name}` has dtype object and holds bools; ridi takes float64 (an array of real \
                 numbers)"
            )));
        }
        if name == "time" && coarse.iter().any(|c| t.is(c)) {
            return Err(PyTypeError::new_err(format!(
                "`time` has dtype object and holds numpy {type_name} values, whose bits have \
                 rounded the timestamps already (to 0.24 ms an hour into a recording, to \
                 minutes at Unix times): compute them in float64"
            )));
        }
    }
    Ok(())
}

/// The kind (`b'f'`, `b'i'`, `b'b'`, `b'O'`, ...) and item size of `obj`'s numpy dtype, when it
/// has one (an array or a numpy scalar).
pub(crate) fn dtype_kind(obj: &Bound<'_, PyAny>) -> Option<(u8, usize)> {
    let dtype = obj.getattr("dtype").ok()?;
    let kind = dtype.getattr("kind").ok()?.extract::<String>().ok()?;
    let size = dtype.getattr("itemsize").ok()?.extract::<usize>().ok()?;
    Some((*kind.as_bytes().first()?, size))
}

/// What `obj` is, for a message: its type, and its shape when it has one.
pub(crate) fn described(obj: &Bound<'_, PyAny>) -> String {
    let kind = obj
        .get_type()
        .name()
        .map_or_else(|_| "?".to_owned(), |n| n.to_string());
    match obj.getattr("shape") {
        Ok(shape) => format!("{kind} of shape {shape}"),
        Err(_) => match obj.len() {
            Ok(n) => format!("{kind} of length {n}"),
            Err(_) => kind,
        },
    }
}

/// The `(frames, cols)` float64 array `obj`, argument `name`; `frames` is the length of `time`
/// when known.
pub(crate) fn matrix<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    cols: usize,
    frames: Option<usize>,
) -> PyResult<PyReadonlyArray2<'py, f64>> {
    let array = float64(obj, name)?;
    let shape = array.shape();
    let fits = shape.len() == 2 && shape[1] == cols && frames.is_none_or(|n| shape[0] == n);
    if !fits {
        let (rows, per_frame) = match frames {
            Some(n) => (n.to_string(), ", one row per frame of `time`"),
            None => ("N".to_string(), ""),
        };
        return Err(errors::value(format!(
            "`{name}` must have shape ({rows}, {cols}){per_frame}; it has shape {}",
            shape_text(shape)
        )));
    }
    Ok(array.cast::<PyArray2<f64>>()?.readonly())
}

/// The 1-D float64 array `obj`, argument `name`, of `frames` values when given.
pub(crate) fn vector<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    frames: Option<usize>,
) -> PyResult<PyReadonlyArray1<'py, f64>> {
    let array = float64(obj, name)?;
    let shape = array.shape();
    if shape.len() != 1 || frames.is_some_and(|n| shape[0] != n) {
        let rows = frames.map_or("N".to_string(), |n| format!("{n}"));
        return Err(errors::value(format!(
            "`{name}` must have shape ({rows},); it has shape {}",
            shape_text(shape)
        )));
    }
    Ok(array.cast::<PyArray1<f64>>()?.readonly())
}

/// Room for `n` values of argument `name`, or `MemoryError`: a numpy view (a broadcast, a
/// stride trick) can describe more frames than memory holds, and a failed allocation would
/// abort the interpreter.
fn room<T>(n: usize, name: &str) -> PyResult<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| {
        PyMemoryError::new_err(format!(
            "`{name}` has {n} frames, more than memory holds a copy of"
        ))
    })?;
    Ok(v)
}

/// The values of 1-D `view`, argument `name`.
pub(crate) fn values(view: ArrayView1<'_, f64>, name: &str) -> PyResult<Vec<f64>> {
    let mut out = room(view.len(), name)?;
    out.extend(view.iter().copied());
    Ok(out)
}

/// The rows of `(N, 3)` `view`, argument `name`, as vectors of frame `F`.
pub(crate) fn vecs<F: Frame>(view: ArrayView2<'_, f64>, name: &str) -> PyResult<Vec<Vec3<F>>> {
    let mut out = room(view.nrows(), name)?;
    out.extend(view.rows().into_iter().map(|r| Vec3::new(r[0], r[1], r[2])));
    Ok(out)
}

/// The rows of `(N, 4)` `view` as orientations, `[w, x, y, z]` (the order of RIDI's files);
/// a row that is not a unit quaternion is an error naming `name` and the frame.
pub(crate) fn rotations(view: ArrayView2<'_, f64>, name: &str) -> PyResult<Vec<WorldFromDevice>> {
    let mut out = room(view.nrows(), name)?;
    for (i, r) in view.rows().into_iter().enumerate() {
        // As given when unit to round-off, so that a sequence rebuilt from another's
        // arrays (or unpickled) tracks exactly as the original.
        out.push(
            WorldFromDevice::from_wxyz_as_given([r[0], r[1], r[2], r[3]])
                .map_err(|e| errors::value(format!("`{name}` at frame {i}: {e}")))?,
        );
    }
    Ok(out)
}

/// `rows` as a `(N, C)` float64 array.
pub(crate) fn rows_out<'py, const C: usize>(
    py: Python<'py>,
    rows: impl ExactSizeIterator<Item = [f64; C]>,
) -> Bound<'py, PyArray2<f64>> {
    let n = rows.len();
    let flat: Vec<f64> = rows.flat_map(|r| r.into_iter()).collect();
    Array2::from_shape_vec((n, C), flat)
        .expect("n rows of C values")
        .into_pyarray(py)
}

/// Vectors as a `(N, 3)` float64 array.
pub(crate) fn vecs_out<'py, F: Frame>(py: Python<'py>, v: &[Vec3<F>]) -> Bound<'py, PyArray2<f64>> {
    rows_out(py, v.iter().map(|x| x.to_array()))
}

/// Orientations as a `(N, 4)` float64 array, `[w, x, y, z]`.
pub(crate) fn rotations_out<'py>(
    py: Python<'py>,
    q: &[WorldFromDevice],
) -> Bound<'py, PyArray2<f64>> {
    rows_out(py, q.iter().map(|q| q.to_wxyz()))
}

/// Values as a 1-D float64 array.
pub(crate) fn vector_out<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    v.into_pyarray(py)
}
