//! One mapping from core errors to the Python exception classes of `softarm.errors`
//! (defined once, in Python, so that Python code raises the very same classes).

use pyo3::import_exception;
use pyo3::PyErr;
use softarm_core::Error;

import_exception!(softarm.errors, InputError);
import_exception!(softarm.errors, ShapeError);
import_exception!(softarm.errors, NonFiniteError);
import_exception!(softarm.errors, OutOfRangeError);
import_exception!(softarm.errors, ParameterError);
import_exception!(softarm.errors, PoseError);

/// Converts a core error into the matching `softarm.errors` exception.
pub fn to_py(err: Error) -> PyErr {
    let msg = err.to_string();
    match err {
        Error::Shape { .. } => ShapeError::new_err(msg),
        Error::NonFinite { .. } => NonFiniteError::new_err(msg),
        Error::OutOfRange { .. } => OutOfRangeError::new_err(msg),
        Error::Parameter { .. } | Error::Choice { .. } => ParameterError::new_err(msg),
        Error::Pose { .. } => PoseError::new_err(msg),
    }
}

/// `result.map_err(to_py)` in method form.
pub trait IntoPyResult<T> {
    /// Converts the error into a Python exception.
    fn py(self) -> pyo3::PyResult<T>;
}

impl<T> IntoPyResult<T> for Result<T, Error> {
    #[inline]
    fn py(self) -> pyo3::PyResult<T> {
        self.map_err(to_py)
    }
}
