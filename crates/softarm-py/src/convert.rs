//! numpy ↔ Rust conversions. Inputs accept any array-like (a fast path for contiguous
//! float64 arrays, `numpy.asarray` otherwise); outputs are new float64 numpy arrays.

use nalgebra::{DMatrix, Matrix3xX};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyDict;
use softarm_core::{Frame, Mat4, Vec3};

use crate::errors::{InputError, ShapeError};

static ASARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();

/// A float64, C-contiguous array view of `obj` (converted with `numpy.asarray` when it
/// is not one already), kept alive by the returned handle.
pub fn as_array<'py>(obj: &Bound<'py, PyAny>, arg: &str) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>() {
        if a.is_c_contiguous() {
            return Ok(a.clone());
        }
    }
    let py = obj.py();
    let asarray = ASARRAY.get_or_try_init(py, || -> PyResult<Py<PyAny>> {
        Ok(py.import("numpy")?.getattr("ascontiguousarray")?.unbind())
    })?;
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", "float64")?;
    let converted = asarray.bind(py).call((obj,), Some(&kwargs)).map_err(|e| {
        InputError::new_err(format!("{arg}: cannot be read as a float array ({e})"))
    })?;
    converted
        .cast_into::<PyArrayDyn<f64>>()
        .map_err(|_| InputError::new_err(format!("{arg}: cannot be read as a float array")))
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
        return Err(ShapeError::new_err(format!(
            "{arg}: expected shape ({len},), got {}",
            shape_str(a.shape())
        )));
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
        return Err(ShapeError::new_err(format!(
            "{arg}: expected shape ({}), got {}",
            want.join(", "),
            shape_str(actual)
        )));
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
