//! numpy ↔ Rust conversions. Inputs accept any array-like (a fast path for contiguous
//! float64 arrays, `numpy.asarray` otherwise); outputs are new float64 numpy arrays.

use nalgebra::{DMatrix, Matrix3xX};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyOverflowError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt};
use softarm_core::{Frame, Mat4, Vec3};

use crate::errors::{fielded, given_text, range_err, Given, InputError, ShapeError};

static ASARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
static CONTIGUOUS: PyOnceLock<Py<PyAny>> = PyOnceLock::new();

/// Array kinds accepted as real numbers: signed and unsigned integers and floats. Complex
/// (whose imaginary part a float conversion would drop), strings (which numpy would parse),
/// booleans, objects and dates are refused by name.
const REAL_KINDS: &str = "iuf";

/// `numpy.asarray(obj)` (shape kept, no dtype forced), refused unless its dtype is real.
fn real_asarray<'py>(obj: &Bound<'py, PyAny>, arg: &str) -> PyResult<Bound<'py, PyAny>> {
    let py = obj.py();
    let asarray = ASARRAY.get_or_try_init(py, || -> PyResult<Py<PyAny>> {
        Ok(py.import("numpy")?.getattr("asarray")?.unbind())
    })?;
    let a = asarray
        .bind(py)
        .call1((obj,))
        .map_err(|e| unreadable(obj, arg, Some(&e)))?;
    let dtype = a.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    if !REAL_KINDS.contains(kind.as_str()) {
        let got = format!("dtype {}", dtype.str()?);
        let msg = format!("{arg}: expected real numbers, got {got}");
        return Err(fielded(
            InputError::new_err(msg),
            arg,
            Given::Text(got),
            "real numbers",
        ));
    }
    Ok(a)
}

/// A float64, C-contiguous array view of `obj` (converted with `numpy.asarray` when it
/// is not one already), kept alive by the returned handle. Only real dtypes are converted.
pub fn as_array<'py>(obj: &Bound<'py, PyAny>, arg: &str) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>() {
        if a.is_c_contiguous() {
            return Ok(a.clone());
        }
    }
    let py = obj.py();
    let real = real_asarray(obj, arg)?;
    let contiguous = CONTIGUOUS.get_or_try_init(py, || -> PyResult<Py<PyAny>> {
        Ok(py.import("numpy")?.getattr("ascontiguousarray")?.unbind())
    })?;
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", "float64")?;
    let converted = contiguous
        .bind(py)
        .call((real,), Some(&kwargs))
        .map_err(|e| unreadable(obj, arg, Some(&e)))?;
    converted
        .cast_into::<PyArrayDyn<f64>>()
        .map_err(|_| unreadable(obj, arg, None))
}

/// The [`InputError`] of an argument that numpy cannot read as a float array (`cause`:
/// numpy's error), its `value` the type of the object given.
fn unreadable(obj: &Bound<'_, PyAny>, arg: &str, cause: Option<&PyErr>) -> PyErr {
    let msg = match cause {
        Some(e) => format!("{arg}: cannot be read as a float array ({e})"),
        None => format!("{arg}: cannot be read as a float array"),
    };
    fielded(InputError::new_err(msg), arg, type_of(obj), "a float array")
}

/// The name of `obj`'s type, as the `value` of a type error.
pub fn type_of(obj: &Bound<'_, PyAny>) -> Given {
    Given::Text(
        obj.get_type()
            .name()
            .map_or_else(|_| "?".to_owned(), |n| n.to_string()),
    )
}

/// `obj` as Python shows it, as the `value` of an error.
fn shown(obj: &Bound<'_, PyAny>) -> String {
    obj.str().map_or_else(|_| "?".to_owned(), |s| s.to_string())
}

/// A real scalar argument: a Python float or int, or a numpy real scalar or 0-d array.
/// Booleans, complex numbers, strings and arrays are refused by name, never coerced.
pub fn real(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<f64> {
    if let Ok(f) = obj.cast::<PyFloat>() {
        return Ok(f.value());
    }
    if obj.is_instance_of::<PyInt>() && !obj.is_instance_of::<PyBool>() {
        return obj.extract::<f64>().map_err(|_| {
            let shown = shown(obj);
            let msg = format!("{arg} = {shown} is beyond the float range");
            range_err(msg, arg, Given::Text(shown), (f64::MIN, f64::MAX))
        });
    }
    let not_real = || -> PyResult<PyErr> {
        let msg = format!(
            "{arg}: expected a real number, got {}",
            obj.get_type().name()?
        );
        Ok(fielded(
            InputError::new_err(msg),
            arg,
            type_of(obj),
            "a real number",
        ))
    };
    if obj.is_instance_of::<PyBool>() {
        return Err(not_real()?);
    }
    let Ok(a) = real_asarray(obj, arg) else {
        return Err(not_real()?);
    };
    if a.getattr("ndim")?.extract::<usize>()? != 0 {
        return Err(not_real()?);
    }
    a.call_method0("item")?.extract::<f64>()
}

/// A count argument: a Python or numpy integer in `[min, max]`. A float, a bool or another
/// type is an [`InputError`]; an integer out of range (however large, or negative) is an
/// [`OutOfRangeError`] that shows the value given.
pub fn count(obj: &Bound<'_, PyAny>, arg: &str, min: usize, max: usize) -> PyResult<usize> {
    let out_of_range = || {
        let shown = shown(obj);
        let msg = format!("{arg} = {shown} is out of range [{min}, {max}]");
        let value = match shown.parse::<i64>() {
            Ok(v) => Given::Int(v),
            Err(_) => Given::Text(shown),
        };
        range_err(msg, arg, value, (min as f64, max as f64))
    };
    let not_integer = || -> PyResult<PyErr> {
        let msg = format!("{arg}: expected an integer, got {}", obj.get_type().name()?);
        Ok(fielded(
            InputError::new_err(msg),
            arg,
            type_of(obj),
            "an integer",
        ))
    };
    if obj.is_instance_of::<PyBool>() || obj.is_instance_of::<PyFloat>() {
        return Err(not_integer()?);
    }
    match obj.extract::<i64>() {
        Ok(v) => usize::try_from(v)
            .ok()
            .filter(|&v| v >= min && v <= max)
            .ok_or_else(out_of_range),
        Err(e) if e.is_instance_of::<PyOverflowError>(obj.py()) => Err(out_of_range()),
        Err(_) => Err(not_integer()?),
    }
}

/// The [`ShapeError`] "`arg`: expected `expected`, got `got`", its fields set.
pub fn shape_err(arg: &str, expected: String, got: String) -> PyErr {
    let msg = format!("{arg}: expected {expected}, got {got}");
    fielded(ShapeError::new_err(msg), arg, Given::Text(got), &expected)
}

/// The [`InputError`] "`arg`: expected `expected`, got <type of `obj`>", its fields set:
/// an argument of the wrong kind of object.
pub fn wrong_type(obj: &Bound<'_, PyAny>, arg: &str, expected: &str) -> PyErr {
    let value = type_of(obj);
    let msg = format!("{arg}: expected {expected}, got {}", given_text(&value));
    fielded(InputError::new_err(msg), arg, value, expected)
}

/// Shape of an array as a readable string, e.g. `(3, 4)`.
pub fn shape_str(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// Reads a 1-D array of exactly `len` elements into a Vec.
pub fn vector(obj: &Bound<'_, PyAny>, arg: &str, len: usize) -> PyResult<Vec<f64>> {
    let a = as_array(obj, arg)?;
    if a.shape() != [len] {
        return Err(shape_err(
            arg,
            format!("shape ({len},)"),
            shape_str(a.shape()),
        ));
    }
    let ro = a.readonly();
    Ok(ro.as_slice()?.to_vec())
}

/// A float64, C-contiguous array of the given shape (`None` = any extent), without
/// copying when `obj` already is one.
pub fn array_view<'py>(
    obj: &Bound<'py, PyAny>,
    arg: &str,
    shape: &[Option<usize>],
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let a = as_array(obj, arg)?;
    let actual = a.shape();
    let ok = actual.len() == shape.len()
        && actual
            .iter()
            .zip(shape)
            .all(|(n, want)| want.is_none_or(|w| w == *n));
    if !ok {
        let want: Vec<String> = shape
            .iter()
            .map(|d| d.map_or("N".to_owned(), |v| v.to_string()))
            .collect();
        let expected = format!("shape ({})", want.join(", "));
        return Err(shape_err(arg, expected, shape_str(actual)));
    }
    Ok(a)
}

/// Reads an array of the given shape (`None` = any extent) as a flat row-major Vec,
/// returning it with its actual shape.
pub fn array(
    obj: &Bound<'_, PyAny>,
    arg: &str,
    shape: &[Option<usize>],
) -> PyResult<(Vec<f64>, Vec<usize>)> {
    let a = array_view(obj, arg, shape)?;
    let ro = a.readonly();
    Ok((ro.as_slice()?.to_vec(), a.shape().to_vec()))
}

/// A 4×4 matrix as a new (4, 4) float64 array.
pub fn mat4_out<'py>(py: Python<'py>, m: &Mat4) -> Bound<'py, PyArray2<f64>> {
    let out = PyArray2::<f64>::zeros(py, [4, 4], false);
    {
        let mut rw = out.readwrite();
        if let Ok(s) = rw.as_slice_mut() {
            write_mat4(m, s);
        }
    }
    out
}

/// Writes a 4×4 matrix row-major into `out[..16]`.
#[inline]
pub fn write_mat4(m: &Mat4, out: &mut [f64]) {
    for r in 0..4 {
        for c in 0..4 {
            out[4 * r + c] = m[(r, c)];
        }
    }
}

/// Writes a rigid frame as a row-major 4×4 homogeneous matrix into `out[..16]`.
#[inline]
pub fn write_frame(f: &Frame, out: &mut [f64]) {
    for r in 0..3 {
        out[4 * r] = f.rot[(r, 0)];
        out[4 * r + 1] = f.rot[(r, 1)];
        out[4 * r + 2] = f.rot[(r, 2)];
        out[4 * r + 3] = f.pos[r];
    }
    out[12..16].copy_from_slice(&[0.0, 0.0, 0.0, 1.0]);
}

/// Writes an r×c column-major nalgebra matrix row-major into `out`.
#[inline]
pub fn write_dmatrix(m: &DMatrix<f64>, out: &mut [f64]) {
    let cols = m.ncols();
    for r in 0..m.nrows() {
        for c in 0..cols {
            out[r * cols + c] = m[(r, c)];
        }
    }
}

/// A dynamic matrix as a new row-major float64 array.
pub fn dmatrix_out<'py>(py: Python<'py>, m: &DMatrix<f64>) -> Bound<'py, PyArray2<f64>> {
    let out = PyArray2::<f64>::zeros(py, [m.nrows(), m.ncols()], false);
    {
        let mut rw = out.readwrite();
        if let Ok(s) = rw.as_slice_mut() {
            write_dmatrix(m, s);
        }
    }
    out
}

/// A 3×n matrix as a new (3, n) float64 array.
pub fn matrix3x_out<'py>(
    py: Python<'py>,
    m: &Matrix3xX<f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let cols = m.ncols();
    let mut flat = vec![0.0; 3 * cols];
    for r in 0..3 {
        for c in 0..cols {
            flat[r * cols + c] = m[(r, c)];
        }
    }
    reshape(py, flat, [3, cols])
}

/// A 3-vector as a new (3,) float64 array.
pub fn vec3_out<'py>(py: Python<'py>, v: &Vec3) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, v.as_slice())
}

/// Points as a new (N, 3) float64 array.
pub fn points_out<'py>(py: Python<'py>, pts: &[Vec3]) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let flat: Vec<f64> = pts.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    reshape(py, flat, [pts.len(), 3])
}

/// A flat row-major Vec as a new 2-D array of the given shape.
pub fn reshape(
    py: Python<'_>,
    flat: Vec<f64>,
    shape: [usize; 2],
) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let arr = Array2::from_shape_vec(shape, flat)
        .map_err(|e| PyValueError::new_err(format!("internal shape mismatch: {e}")))?;
    Ok(arr.into_pyarray(py))
}
