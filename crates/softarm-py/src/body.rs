//! The arm's body (`Body`, the radii `ACTUATOR_RADIUS`, `GRIPPER_RADIUS`, `CANE_RADIUS`)
//! and the laws of the measurement chain beside `LagModel` (`play`, `lead_gain`,
//! `predicted_loop_alpha`) for Python: declared once in softarm-core.

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyType;
use softarm_core::body as core;
use softarm_core::resolver as lag;

use crate::convert::array;
use crate::distance::{with_obstacle, Model};
use crate::errors::IntoPyResult;
use crate::kinematics::SoftArm;

/// The arm's body: each section's tube (ring radius + one actuator), the inner sections'
/// end plates (their section's radius), and the gripper as a capsule along the
/// end-effector's z axis from `gripper_back` behind its frame to `grasp_offset` ahead.
#[pyclass(module = "softarm._core", frozen, eq)]
#[derive(PartialEq)]
pub struct Body {
    pub(crate) inner: core::Body,
}

#[pymethods]
impl Body {
    #[new]
    fn new(
        section_radii: &Bound<'_, PyAny>,
        gripper_radius: f64,
        gripper_back: f64,
        grasp_offset: f64,
    ) -> PyResult<Self> {
        let (radii, _) = array(section_radii, "section_radii", &[None])?;
        Ok(Body {
            inner: core::Body::new(radii, gripper_radius, gripper_back, grasp_offset).py()?,
        })
    }
    /// The body of `arm`: ring radius + `ACTUATOR_RADIUS` per section, a gripper of
    /// `GRIPPER_RADIUS` from the distal arc's tip to `grasp_offset` (m) ahead of the
    /// end-effector frame.
    #[staticmethod]
    fn for_arm(arm: PyRef<'_, SoftArm>, grasp_offset: f64) -> PyResult<Self> {
        Ok(Body {
            inner: core::Body::for_arm(&arm.inner, grasp_offset).py()?,
        })
    }
    /// Each section's surface radius about its backbone (m), proximal first.
    #[getter]
    fn section_radii<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.section_radii())
    }
    /// The gripper capsule's radius (m).
    #[getter]
    fn gripper_radius(&self) -> f64 {
        self.inner.gripper_radius()
    }
    /// How far (m) behind the end-effector frame the gripper starts.
    #[getter]
    fn gripper_back(&self) -> f64 {
        self.inner.gripper_back()
    }
    /// How far (m) ahead of the end-effector frame the gripper reaches.
    #[getter]
    fn grasp_offset(&self) -> f64 {
        self.inner.grasp_offset()
    }
    /// The widest surface radius of the body (m).
    #[getter]
    fn widest(&self) -> f64 {
        self.inner.widest()
    }
    /// Smallest surface gap (m) between the body on `arm` (SoftArm or ArcChain) at `q`
    /// and `obstacles` (a sequence), each of radius `obstacle_radius` (m); inf for none,
    /// below zero when the surfaces overlap. Exact.
    #[pyo3(signature = (arm, q, obstacles, obstacle_radius = core::CANE_RADIUS))]
    fn gap(
        &self,
        arm: &Bound<'_, PyAny>,
        q: &Bound<'_, PyAny>,
        obstacles: &Bound<'_, PyAny>,
        obstacle_radius: f64,
    ) -> PyResult<f64> {
        let model = Model::from_py(arm, "arm")?;
        let q = crate::convert::vector(q, "q", model.n_dofs())?;
        let mut best = f64::INFINITY;
        for ob in obstacles.try_iter()? {
            let g = with_obstacle(&ob?, |o| match &model {
                Model::Soft(m) => self.inner.gap(m, &q, o, obstacle_radius),
                Model::Chain(m) => self.inner.gap(m, &q, o, obstacle_radius),
            })?
            .py()?;
            best = best.min(g.gap);
        }
        Ok(best)
    }
    /// Pickling and `copy.deepcopy`.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> (
        Bound<'py, PyType>,
        (Bound<'py, PyArray1<f64>>, f64, f64, f64),
    ) {
        let b = &slf.get().inner;
        (
            slf.get_type(),
            (
                PyArray1::from_slice(slf.py(), b.section_radii()),
                b.gripper_radius(),
                b.gripper_back(),
                b.grasp_offset(),
            ),
        )
    }
    fn __repr__(&self) -> String {
        let b = &self.inner;
        format!(
            "Body(section_radii={:?}, gripper_radius={}, gripper_back={}, grasp_offset={})",
            b.section_radii(),
            b.gripper_radius(),
            b.gripper_back(),
            b.grasp_offset()
        )
    }
}

/// The play operator on every channel: `clip(output, input - width/2, input + width/2)`
/// (a new array).
#[pyfunction]
fn play<'py>(
    py: Python<'py>,
    output: &Bound<'py, PyAny>,
    input: &Bound<'py, PyAny>,
    width: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (mut y, _) = array(output, "output", &[None])?;
    let (x, _) = array(input, "input", &[None])?;
    let (w, _) = array(width, "width", &[None])?;
    lag::play_into(&mut y, &x, &w).py()?;
    Ok(PyArray1::from_vec(py, y))
}

/// The regulators' pre-compensation gain: half of `a/(1 - a)`, `a = exp(-T/tau)`, at most
/// `cap`; 0 for `tau_s = 0`.
#[pyfunction]
#[pyo3(signature = (tau_s, period_s, cap = lag::LEAD_GAIN_CAP))]
fn lead_gain(tau_s: f64, period_s: f64, cap: f64) -> PyResult<f64> {
    lag::lead_gain(tau_s, period_s, cap).py()
}

/// The resolver's gain for the loop closed through the lag model, for a chain lagging
/// `lag_s` (s): `PREDICTED_ALPHA_LAG_S / lag_s` within [`PREDICTED_ALPHA_MIN`,
/// `PREDICTED_ALPHA_MAX`].
#[pyfunction]
fn predicted_loop_alpha(lag_s: f64) -> PyResult<f64> {
    lag::predicted_loop_alpha(lag_s).py()
}

/// Registers `Body`, the radii and the laws.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Body>()?;
    m.add("ACTUATOR_RADIUS", core::ACTUATOR_RADIUS)?;
    m.add("GRIPPER_RADIUS", core::GRIPPER_RADIUS)?;
    m.add("CANE_RADIUS", core::CANE_RADIUS)?;
    m.add("LEAD_GAIN_CAP", lag::LEAD_GAIN_CAP)?;
    m.add("PREDICTED_ALPHA_MAX", lag::PREDICTED_ALPHA_MAX)?;
    m.add("PREDICTED_ALPHA_LAG_S", lag::PREDICTED_ALPHA_LAG_S)?;
    m.add("PREDICTED_ALPHA_MIN", lag::predicted_alpha_min())?;
    m.add_function(wrap_pyfunction!(play, m)?)?;
    m.add_function(wrap_pyfunction!(lead_gain, m)?)?;
    m.add_function(wrap_pyfunction!(predicted_loop_alpha, m)?)?;
    Ok(())
}
