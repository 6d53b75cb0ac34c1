//! One mapping from core errors to the Python exception classes of `softarm.errors`
//! (defined once, in Python, so that Python code raises the very same classes).
//!
//! Every exception carries what the core error names, as attributes a program can read
//! (issue 27 item 6): `argument` (the argument's name), `value` (the rejected value: a
//! float, a string for a shape or a name, `None` for a pose) and `expected` (what is
//! accepted, in words); an out-of-range error adds `bounds = (min, max)` and a non-finite
//! one `index`.

use pyo3::import_exception;
use pyo3::prelude::*;
use pyo3::PyErr;
use softarm_core::Error;

import_exception!(softarm.errors, InputError);
import_exception!(softarm.errors, ShapeError);
import_exception!(softarm.errors, NonFiniteError);
import_exception!(softarm.errors, OutOfRangeError);
import_exception!(softarm.errors, ParameterError);
import_exception!(softarm.errors, PoseError);

/// The rejected value an exception shows as `value`.
#[derive(Debug, Clone, PartialEq)]
pub enum Given {
    /// A number.
    Float(f64),
    /// A count or an index.
    Int(i64),
    /// A shape, a name, or the type of an object given.
    Text(String),
    /// No single value (a malformed pose).
    Nothing,
}

/// Converts a core error into the matching `softarm.errors` exception, its fields set as
/// attributes.
pub fn to_py(err: Error) -> PyErr {
    let msg = err.to_string();
    match err {
        Error::Shape { arg, expected, got } => {
            fielded(ShapeError::new_err(msg), &arg, Given::Text(got), &expected)
        }
        Error::NonFinite { arg, index, value } => {
            let e = fielded(
                NonFiniteError::new_err(msg),
                &arg,
                Given::Float(value),
                "a finite value",
            );
            with_extra(e, "index", |py| Ok(index.into_pyobject(py)?.into_any()))
        }
        Error::OutOfRange {
            arg,
            value,
            min,
            max,
        } => range_err(msg, &arg, Given::Float(value), (min, max)),
        Error::Parameter { arg, value, reason } => fielded(
            ParameterError::new_err(msg),
            &arg,
            Given::Float(value),
            &reason,
        ),
        Error::Choice { arg, value, reason } => fielded(
            ParameterError::new_err(msg),
            &arg,
            Given::Text(value),
            &reason,
        ),
        Error::Pose { arg, reason } => {
            fielded(PoseError::new_err(msg), &arg, Given::Nothing, &reason)
        }
    }
}

/// An [`OutOfRangeError`] with message `msg`, its fields and `bounds = (min, max)`.
pub fn range_err(msg: String, argument: &str, value: Given, (min, max): (f64, f64)) -> PyErr {
    let e = fielded(
        OutOfRangeError::new_err(msg),
        argument,
        value,
        &format!("a value in [{min}, {max}]"),
    );
    with_extra(e, "bounds", |py| {
        Ok((min, max).into_pyobject(py)?.into_any())
    })
}

/// `err` with `argument`, `value` and `expected` set as attributes. Setting an attribute
/// fails only when Python itself does (no memory): that error is then the one to raise.
pub fn fielded(err: PyErr, argument: &str, value: Given, expected: &str) -> PyErr {
    Python::attach(|py| {
        let result = set_fields(err.value(py).as_any(), argument, &value, expected);
        match result {
            Ok(()) => err,
            Err(e) => e,
        }
    })
}

fn set_fields(
    exc: &Bound<'_, PyAny>,
    argument: &str,
    value: &Given,
    expected: &str,
) -> PyResult<()> {
    exc.setattr("argument", argument)?;
    match value {
        Given::Float(v) => exc.setattr("value", *v)?,
        Given::Int(v) => exc.setattr("value", *v)?,
        Given::Text(v) => exc.setattr("value", v.as_str())?,
        Given::Nothing => exc.setattr("value", exc.py().None())?,
    }
    exc.setattr("expected", expected)
}

/// `err` with one more attribute, `name`, made by `make` (see [`fielded`]).
fn with_extra(
    err: PyErr,
    name: &str,
    make: impl for<'py> FnOnce(Python<'py>) -> PyResult<Bound<'py, PyAny>>,
) -> PyErr {
    Python::attach(|py| {
        let result = make(py).and_then(|v| err.value(py).setattr(name, v));
        match result {
            Ok(()) => err,
            Err(e) => e,
        }
    })
}

/// The text of a [`Given`] (for a message).
pub fn given_text(g: &Given) -> String {
    match g {
        Given::Float(v) => v.to_string(),
        Given::Int(v) => v.to_string(),
        Given::Text(t) => t.clone(),
        Given::Nothing => "nothing".to_owned(),
    }
}

/// A [`ParameterError`] "`name`: expected `expected`, got `v`", its fields set.
pub fn parameter_err(name: &str, v: &Bound<'_, PyAny>, expected: &str) -> PyErr {
    let shown = v.str().map_or_else(|_| "?".to_owned(), |s| s.to_string());
    let msg = format!("{name}: expected {expected}, got {shown}");
    fielded(
        ParameterError::new_err(msg),
        name,
        Given::Text(shown),
        expected,
    )
}

/// The [`InputError`] of an unknown termination name in a pickle.
pub fn unknown_termination(name: &str) -> PyErr {
    let msg = format!("termination: unknown {name:?}");
    fielded(
        InputError::new_err(msg),
        "termination",
        Given::Text(name.to_owned()),
        "a termination name",
    )
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
