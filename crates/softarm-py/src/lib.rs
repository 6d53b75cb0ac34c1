//! `softarm._core`: thin pyo3 bindings over softarm-core. This crate only converts
//! (numpy ↔ nalgebra, core errors → `softarm.errors` exceptions) and releases the GIL
//! around batch work; all math lives in softarm-core.

mod body;
mod convert;
mod distance;
mod errors;
mod kinematics;
mod planner;
mod resolver;

use pyo3::prelude::*;

/// The native module.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    kinematics::register(m)?;
    resolver::register(m)?;
    distance::register(m)?;
    planner::register(m)?;
    body::register(m)?;
    Ok(())
}
