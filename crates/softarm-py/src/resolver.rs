//! `Gains`, `Resolver`, `StepResult` and `Solution` for Python (redundancy paper eq. 7,
//! 13, 20, 23–25). Conversion only: the resolver lives in softarm-core.

use nalgebra::{Matrix4, Vector3};
use numpy::{PyArray1, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple, PyType};
use softarm_core::distance::Obstacle;
use softarm_core::error::MAX_ITERATIONS;
use softarm_core::resolver::{self as core, Mode, Schedule, SolveOptions, Target};
use softarm_core::SoftArm as CoreArm;

use crate::body::Body;
use crate::convert::{array, as_array, shape_err, shape_str, type_of, wrong_type};
use crate::distance::obstacle_from;
use crate::errors::{
    fielded, given_text, parameter_err, range_err, unknown_termination, Given, InputError,
    IntoPyResult, ParameterError,
};
use crate::kinematics::SoftArm;

/// The core's declaration of a float gain named `name`.
fn float_field(name: &str) -> Option<&'static core::gains::FloatField> {
    core::Gains::FLOAT_FIELDS.iter().find(|f| f.name == name)
}

/// Every field name of `Gains`: the floats, then `schedule` and `axis_mask`.
fn field_names() -> impl Iterator<Item = &'static str> {
    core::Gains::FLOAT_FIELDS
        .iter()
        .map(|f| f.name)
        .chain(core::Gains::OTHER_FIELDS.iter().copied())
}

/// Applies keyword overrides to `g`, then validates the result.
fn apply(mut g: core::Gains, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<core::Gains> {
    if let Some(kw) = kwargs {
        for (k, v) in kw.iter() {
            let name: String = k.extract()?;
            if let Some(f) = float_field(&name) {
                let x = v
                    .extract::<f64>()
                    .map_err(|_| parameter_err(&name, &v, "a float"))?;
                (f.set)(&mut g, x);
            } else if name == "schedule" {
                let s: String = v
                    .extract()
                    .map_err(|_| parameter_err("schedule", &v, "a str"))?;
                g.schedule = Schedule::parse(&s).py()?;
            } else if name == "axis_mask" {
                let m: Vec<bool> = v
                    .extract()
                    .map_err(|_| parameter_err("axis_mask", &v, "3 bools"))?;
                g.axis_mask = <[bool; 3]>::try_from(m.as_slice()).map_err(|_| {
                    shape_err("axis_mask", "3 bools".to_owned(), m.len().to_string())
                })?;
            } else {
                let expected = format!("one of {}", field_names().collect::<Vec<_>>().join(", "));
                let msg = format!("{name}: unknown gain; expected {expected}");
                return Err(fielded(
                    ParameterError::new_err(msg),
                    &name,
                    Given::Text(name.clone()),
                    &expected,
                ));
            }
        }
    }
    g.validate().py()?;
    Ok(g)
}

/// Tuning parameters of the resolver (see the stub for units).
#[pyclass(module = "softarm._core", frozen, eq, from_py_object)]
#[derive(Clone, PartialEq)]
pub struct Gains {
    pub(crate) inner: core::Gains,
}

/// The float fields' properties are added at registration, from the core's one list
/// ([`add_float_properties`]); the methods below are the rest.
#[pymethods]
impl Gains {
    /// The default gains for actuators lagging `tau_s` (s, sensor filter included)
    /// behind commands sent every `period_s` (s): the closed-loop α cap at that lag.
    #[staticmethod]
    fn for_lag(tau_s: f64, period_s: f64) -> PyResult<Self> {
        Ok(Gains {
            inner: core::Gains::for_lag(tau_s, period_s).py()?,
        })
    }

    /// Gains from a dict of fields (as `as_dict` returns); missing fields keep the
    /// defaults.
    #[classmethod]
    fn from_dict(_cls: &Bound<'_, pyo3::types::PyType>, d: &Bound<'_, PyDict>) -> PyResult<Self> {
        Ok(Gains {
            inner: apply(core::Gains::blackberry(), Some(d))?,
        })
    }

    /// Pickling and `copy.deepcopy`: rebuilt from `as_dict` through `from_dict`.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyDict>,))> {
        let from_dict = slf.get_type().getattr("from_dict")?;
        Ok((from_dict, (slf.get().as_dict(slf.py())?,)))
    }

    #[new]
    #[pyo3(signature = (**kwargs))]
    fn new(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        Ok(Gains {
            inner: apply(core::Gains::blackberry(), kwargs)?,
        })
    }

    /// The paper's gains, eq. (23)–(25).
    #[staticmethod]
    fn paper() -> Self {
        Gains {
            inner: core::Gains::paper(),
        }
    }

    /// A copy with some fields changed.
    #[pyo3(signature = (**kwargs))]
    fn replace(&self, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        Ok(Gains {
            inner: apply(self.inner, kwargs)?,
        })
    }

    /// "step" or "smooth".
    #[getter]
    fn schedule(&self) -> &'static str {
        self.inner.schedule.name()
    }

    /// Controlled orientation axes (x, y, z) of the base frame.
    #[getter]
    fn axis_mask(&self) -> (bool, bool, bool) {
        let m = self.inner.axis_mask;
        (m[0], m[1], m[2])
    }

    /// Every field as a dict.
    fn as_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for f in core::Gains::FLOAT_FIELDS {
            d.set_item(f.name, (f.get)(&self.inner))?;
        }
        d.set_item("schedule", self.inner.schedule.name())?;
        d.set_item("axis_mask", PyTuple::new(py, self.inner.axis_mask)?)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        let g = &self.inner;
        format!(
            "Gains(hybrid_alpha={}, hybrid_position={}, hybrid_orientation={}, hybrid_gamma={}, \
             hybrid_switch={}, schedule={:?}, axis_mask={:?}, ...)",
            g.hybrid_alpha,
            g.hybrid_position,
            g.hybrid_orientation,
            g.hybrid_gamma,
            g.hybrid_switch,
            g.schedule.name(),
            g.axis_mask
        )
    }
}

/// One step's result.
#[pyclass(module = "softarm._core", frozen)]
pub struct StepResult {
    q: Vec<f64>,
    unclamped: Vec<f64>,
    info: core::StepInfo,
}

#[pymethods]
impl StepResult {
    /// The next command (n,), inside [lower, upper].
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.q)
    }
    /// The command before clamping (n,).
    #[getter]
    fn unclamped<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.unclamped)
    }
    /// Whether the command was clamped into the limits.
    #[getter]
    fn saturated(&self) -> bool {
        self.info.saturated
    }
    /// ‖e_p‖ (m) at the input state.
    #[getter]
    fn position_error(&self) -> f64 {
        self.info.position_error
    }
    /// Masked ‖e_ζ‖ (rad) at the input state.
    #[getter]
    fn orientation_error(&self) -> f64 {
        self.info.orientation_error
    }
    /// Smallest surface gap (m) to the obstacles within the influence distance; inf
    /// when none is.
    #[getter]
    fn clearance(&self) -> f64 {
        self.info.clearance
    }
    /// Pickling and `copy.deepcopy`, through `_core._rebuild_step_result`.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        (
            Bound<'py, PyArray1<f64>>,
            Bound<'py, PyArray1<f64>>,
            bool,
            f64,
            f64,
            f64,
        ),
    )> {
        let f = py
            .import("softarm._core")?
            .getattr("_rebuild_step_result")?;
        let i = &self.info;
        Ok((
            f,
            (
                self.q(py),
                self.unclamped(py),
                i.saturated,
                i.position_error,
                i.orientation_error,
                i.clearance,
            ),
        ))
    }
    fn __repr__(&self) -> String {
        format!(
            "StepResult(saturated={}, position_error={:.3e}, orientation_error={:.3e})",
            py_bool(self.info.saturated),
            self.info.position_error,
            self.info.orientation_error
        )
    }
}

/// The result of `Resolver.solve`.
#[pyclass(module = "softarm._core", frozen)]
pub struct Solution {
    inner: core::Solution,
}

#[pymethods]
impl Solution {
    /// Best configuration found (n,).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.inner.q)
    }
    /// Whether the controlled errors are within tolerance at `q`.
    #[getter]
    fn converged(&self) -> bool {
        self.inner.converged
    }
    /// Steps run: the last configuration evaluated is `q0` after `steps` steps.
    #[getter]
    fn steps(&self) -> usize {
        self.inner.steps
    }
    /// The step at which `q` was reached (`q0` after `best_step` steps).
    #[getter]
    fn best_step(&self) -> usize {
        self.inner.best_step
    }
    /// ‖e_p‖ at `q` (m).
    #[getter]
    fn position_error(&self) -> f64 {
        self.inner.position_error
    }
    /// Masked ‖e_ζ‖ at `q` (rad).
    #[getter]
    fn orientation_error(&self) -> f64 {
        self.inner.orientation_error
    }
    /// Why the iteration stopped: "converged", "stuck" (a step left q unchanged: the
    /// resolver cannot leave it) or "step_limit".
    #[getter]
    fn termination(&self) -> &'static str {
        self.inner.termination.name()
    }
    /// Pickling and `copy.deepcopy`, through `_core._rebuild_solution`.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        (
            Bound<'py, PyArray1<f64>>,
            bool,
            usize,
            f64,
            f64,
            &'static str,
            usize,
        ),
    )> {
        let f = py.import("softarm._core")?.getattr("_rebuild_solution")?;
        let s = &self.inner;
        Ok((
            f,
            (
                self.q(py),
                s.converged,
                s.steps,
                s.position_error,
                s.orientation_error,
                s.termination.name(),
                s.best_step,
            ),
        ))
    }
    fn __repr__(&self) -> String {
        format!(
            "Solution(converged={}, steps={}, best_step={}, position_error={:.3e}, \
             orientation_error={:.3e}, termination={:?})",
            py_bool(self.inner.converged),
            self.inner.steps,
            self.inner.best_step,
            self.inner.position_error,
            self.inner.orientation_error,
            self.inner.termination.name()
        )
    }
}

/// A bool as Python writes it in a repr (`True`, not Rust's `true`).
pub(crate) fn py_bool(b: bool) -> &'static str {
    if b {
        "True"
    } else {
        "False"
    }
}

/// Reads a (4, 4) pose or (in modes that accept one) a (3,) point.
fn target(obj: &Bound<'_, PyAny>) -> PyResult<Target> {
    let a = as_array(obj, "target")?;
    let shape = a.shape().to_vec();
    let ro = a.readonly();
    let flat = ro.as_slice()?;
    match shape.as_slice() {
        [4, 4] => Ok(Target::Pose(Matrix4::from_row_slice(flat))),
        [3] => Ok(Target::Position(Vector3::from_column_slice(flat))),
        _ => Err(shape_err(
            "target",
            "shape (4, 4) or (3,)".to_owned(),
            shape_str(&shape),
        )),
    }
}

fn pose(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<Matrix4<f64>> {
    let (flat, _) = array(obj, arg, &[Some(4), Some(4)])?;
    Ok(Matrix4::from_row_slice(&flat))
}

/// Reads `obstacles=`: None, or an iterable of obstacles (curves, segments, clouds,
/// meshes, points (3,)). A lone obstacle object is accepted too.
fn obstacle_list(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<Obstacle>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(Vec::new());
    };
    if let Ok(one) = obstacle_from(obj, "obstacles") {
        // A single obstacle object; a bare (3,) array reads as one point.
        let is_seq_of_points = obj
            .getattr("ndim")
            .and_then(|d| d.extract::<usize>())
            .is_ok_and(|d| d > 1);
        if !is_seq_of_points {
            return Ok(vec![one]);
        }
    }
    let iter = obj.try_iter().map_err(|_| {
        let got = type_of(obj);
        let expected = "a sequence of obstacles";
        let msg = format!("obstacles: expected {expected}, got {}", given_text(&got));
        fielded(InputError::new_err(msg), "obstacles", got, expected)
    })?;
    let mut out = Vec::new();
    for (i, item) in iter.enumerate() {
        if i >= MAX_OBSTACLES {
            let msg = format!("obstacles: more than {MAX_OBSTACLES} obstacles");
            let bounds = (0.0, MAX_OBSTACLES as f64);
            return Err(range_err(
                msg,
                "obstacles",
                Given::Text("more".to_owned()),
                bounds,
            ));
        }
        out.push(obstacle_from(&item?, &format!("obstacles[{i}]"))?);
    }
    Ok(out)
}

/// Most obstacles one step takes (each costs an exact distance query per step).
const MAX_OBSTACLES: usize = 10_000;

/// Gain-scheduled task-priority resolver for a `SoftArm`.
#[pyclass(module = "softarm._core", frozen)]
pub struct Resolver {
    inner: core::Resolver<CoreArm>,
}

#[pymethods]
impl Resolver {
    #[new]
    #[pyo3(signature = (arm, mode = None, gains = None, body = None))]
    fn new(
        arm: PyRef<'_, SoftArm>,
        mode: Option<&Bound<'_, PyAny>>,
        gains: Option<PyRef<'_, Gains>>,
        body: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        // None is the default mode; anything but a string is a typed error naming `mode`.
        let mode: String = match mode.filter(|m| !m.is_none()) {
            None => "hybrid".to_owned(),
            Some(m) => m.extract().map_err(|_| {
                let got = type_of(m);
                let msg = format!("mode: expected a string, got {}", given_text(&got));
                fielded(InputError::new_err(msg), "mode", got, "a string")
            })?,
        };
        let mode = Mode::parse(&mode).py()?;
        let gains = gains.map_or_else(core::Gains::blackberry, |g| g.inner);
        // None measures the arm's default body; anything but a Body names `body`.
        let body = match body.filter(|b| !b.is_none()) {
            None => None,
            Some(b) => Some(
                b.cast::<Body>()
                    .map_err(|_| wrong_type(b, "body", "a Body"))?
                    .get()
                    .inner
                    .clone(),
            ),
        };
        let inner = core::Resolver::new(arm.inner.clone(), mode, gains).py()?;
        let inner = match body {
            Some(b) => inner.with_body(b).py()?,
            None => inner,
        };
        Ok(Resolver { inner })
    }

    /// The body the obstacle repulsion measures.
    #[getter]
    fn body(&self) -> Body {
        Body {
            inner: self.inner.body().clone(),
        }
    }

    /// "conventional", "position", "orientation" or "hybrid".
    #[getter]
    fn mode(&self) -> &'static str {
        self.inner.mode().name()
    }

    /// The gains.
    #[getter]
    fn gains(&self) -> Gains {
        Gains {
            inner: *self.inner.gains(),
        }
    }

    /// The arm model.
    #[getter]
    fn arm(&self) -> SoftArm {
        SoftArm {
            inner: self.inner.arm().clone(),
        }
    }

    /// One step from `q` towards `target`; `current` is the measured pose or None;
    /// `obstacles` repel the arm (eq. 9, below every task); `plant_q` is a lag model's
    /// prediction of the elongations reached (Smith predictor).
    #[pyo3(signature = (q, target, current = None, *, obstacles = None, plant_q = None))]
    fn step(
        &self,
        q: &Bound<'_, PyAny>,
        target: &Bound<'_, PyAny>,
        current: Option<&Bound<'_, PyAny>>,
        obstacles: Option<&Bound<'_, PyAny>>,
        plant_q: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<StepResult> {
        let n = softarm_core::chain::SectionModel::n_dofs(self.inner.arm());
        let q = crate::convert::vector(q, "q", n)?;
        let t = self::target(target)?;
        let current = current
            .filter(|c| !c.is_none())
            .map(|c| pose(c, "current"))
            .transpose()?;
        let plant_q = plant_q
            .filter(|p| !p.is_none())
            .map(|p| crate::convert::vector(p, "plant_q", n))
            .transpose()?;
        let obstacles = obstacle_list(obstacles)?;
        let input = core::StepInput {
            current: current.as_ref(),
            plant_q: plant_q.as_deref(),
            obstacles: &obstacles,
        };
        let s = self.inner.step_with(&q, &t, &input).py()?;
        Ok(StepResult {
            q: s.q,
            unclamped: s.unclamped,
            info: s.info,
        })
    }

    /// Iterates steps on the model to tolerance. Releases the GIL.
    #[pyo3(signature = (q0, target, max_steps = None, position_tolerance = None,
                        orientation_tolerance = None, *, obstacles = None),
           text_signature = "(self, q0, target, max_steps=1000, position_tolerance=0.0001, \
                             orientation_tolerance=0.0017453292519943296, *, obstacles=None)")]
    #[allow(clippy::too_many_arguments)]
    fn solve(
        &self,
        py: Python<'_>,
        q0: &Bound<'_, PyAny>,
        target: &Bound<'_, PyAny>,
        max_steps: Option<&Bound<'_, PyAny>>,
        position_tolerance: Option<&Bound<'_, PyAny>>,
        orientation_tolerance: Option<&Bound<'_, PyAny>>,
        obstacles: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Solution> {
        // Counts and tolerances go through the bindings' one converter: a typed error
        // naming the argument for a float count, a huge int or a string; None = default.
        let defaults = SolveOptions::default();
        let max_steps = match max_steps.filter(|v| !v.is_none()) {
            Some(v) => crate::convert::count(v, "max_steps", 0, MAX_ITERATIONS)?,
            None => defaults.max_steps,
        };
        let position_tolerance = match position_tolerance.filter(|v| !v.is_none()) {
            Some(v) => crate::convert::real(v, "position_tolerance")?,
            None => defaults.position_tolerance,
        };
        let orientation_tolerance = match orientation_tolerance.filter(|v| !v.is_none()) {
            Some(v) => crate::convert::real(v, "orientation_tolerance")?,
            None => defaults.orientation_tolerance,
        };
        let obstacles = obstacle_list(obstacles)?;
        let n = softarm_core::chain::SectionModel::n_dofs(self.inner.arm());
        let q0 = crate::convert::vector(q0, "q0", n)?;
        let t = self::target(target)?;
        let opts = SolveOptions {
            max_steps,
            position_tolerance,
            orientation_tolerance,
        };
        let res = &self.inner;
        let sol = py
            .detach(|| res.solve_with(&q0, &t, &opts, &obstacles))
            .py()?;
        Ok(Solution { inner: sol })
    }

    fn __repr__(&self) -> String {
        format!("Resolver(mode={:?})", self.inner.mode().name())
    }

    /// Pickles as `Resolver(arm, mode, gains)`: the resolver holds no other state.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> (Bound<'py, PyType>, (SoftArm, &'static str, Gains, Body)) {
        let r = slf.get();
        (
            slf.get_type(),
            (
                SoftArm {
                    inner: r.inner.arm().clone(),
                },
                r.inner.mode().name(),
                Gains {
                    inner: *r.inner.gains(),
                },
                Body {
                    inner: r.inner.body().clone(),
                },
            ),
        )
    }
}

/// A first-order lag model of the actuators (the predictor of the lag-aware loop).
#[pyclass(module = "softarm._core")]
pub struct LagModel {
    inner: core::LagModel,
}

#[pymethods]
impl LagModel {
    #[new]
    fn new(tau_s: f64, period_s: f64, q0: &Bound<'_, PyAny>) -> PyResult<Self> {
        let (q0, _) = array(q0, "q0", &[None])?;
        if q0.is_empty() || q0.len() > 1024 {
            return Err(shape_err(
                "q0",
                "1 to 1024 elongations".to_owned(),
                q0.len().to_string(),
            ));
        }
        Ok(LagModel {
            inner: core::LagModel::new(tau_s, period_s, &q0).py()?,
        })
    }
    /// Predicted elongations now (n,).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.state())
    }
    /// One period with `command` held; returns the predicted elongations after it.
    fn advance<'py>(
        &mut self,
        py: Python<'py>,
        command: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.inner.state().len();
        let c = crate::convert::vector(command, "command", n)?;
        Ok(PyArray1::from_slice(py, self.inner.advance(&c).py()?))
    }
    /// Settles the model at `q`.
    fn reset(&mut self, q: &Bound<'_, PyAny>) -> PyResult<()> {
        let n = self.inner.state().len();
        let q = crate::convert::vector(q, "q", n)?;
        self.inner.reset(&q).py()
    }
    /// Pickling and `copy.deepcopy`: `LagModel(tau_s, period_s, q)` with the predicted
    /// elongations as `q0`, which is the whole state (the gain follows from the lag).
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> (Bound<'py, PyType>, (f64, f64, Bound<'py, PyArray1<f64>>)) {
        let m = slf.borrow();
        (
            slf.get_type(),
            (
                m.inner.tau_s(),
                m.inner.period_s(),
                PyArray1::from_slice(slf.py(), m.inner.state()),
            ),
        )
    }
    fn __repr__(&self) -> String {
        format!(
            "LagModel(tau_s={}, period_s={})",
            self.inner.tau_s(),
            self.inner.period_s()
        )
    }
}

/// Adds a read-only property to `Gains` for every float field of the core's list
/// ([`core::Gains::FLOAT_FIELDS`]), documented by the field's doc comment and range.
fn add_float_properties(py: Python<'_>) -> PyResult<()> {
    let cls = py.get_type::<Gains>();
    let property = py.import("builtins")?.getattr("property")?;
    for f in core::Gains::FLOAT_FIELDS {
        let get = f.get;
        let getter = pyo3::types::PyCFunction::new_closure(
            py,
            None,
            None,
            move |args: &Bound<'_, PyTuple>,
                  _kwargs: Option<&Bound<'_, PyDict>>|
                  -> PyResult<f64> {
                let slf = args.get_item(0)?;
                let g = slf.cast::<Gains>()?;
                Ok(get(&g.get().inner))
            },
        )?;
        let doc: Vec<&str> = f.doc.lines().map(str::trim).collect();
        let doc = format!("{}\n\nAccepted range: {}.", doc.join("\n"), f.range);
        cls.setattr(f.name, property.call1((getter, py.None(), py.None(), doc))?)?;
    }
    Ok(())
}

/// Reads a pickled `(n,)` vector of 1 to 1024 finite values.
fn pickled_vector(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<Vec<f64>> {
    let (v, _) = array(obj, arg, &[None])?;
    if v.is_empty() || v.len() > 1024 {
        return Err(shape_err(
            arg,
            "1 to 1024 values".to_owned(),
            v.len().to_string(),
        ));
    }
    Ok(v)
}

/// Rebuilds a `StepResult` from its fields (the unpickler of `StepResult.__reduce__`).
#[pyfunction]
fn _rebuild_step_result(
    q: &Bound<'_, PyAny>,
    unclamped: &Bound<'_, PyAny>,
    saturated: bool,
    position_error: f64,
    orientation_error: f64,
    clearance: f64,
) -> PyResult<StepResult> {
    let q = pickled_vector(q, "q")?;
    let unclamped = crate::convert::vector(unclamped, "unclamped", q.len())?;
    Ok(StepResult {
        q,
        unclamped,
        info: core::StepInfo {
            saturated,
            position_error,
            orientation_error,
            clearance,
        },
    })
}

/// Rebuilds a `Solution` from its fields (the unpickler of `Solution.__reduce__`); a
/// pickle from before `best_step` existed rebuilds with `best_step = steps`.
#[pyfunction]
#[pyo3(signature = (q, converged, steps, position_error, orientation_error, termination,
                    best_step = None))]
fn _rebuild_solution(
    q: &Bound<'_, PyAny>,
    converged: bool,
    steps: usize,
    position_error: f64,
    orientation_error: f64,
    termination: &str,
    best_step: Option<usize>,
) -> PyResult<Solution> {
    let termination = [
        core::SolveTermination::Converged,
        core::SolveTermination::Stuck,
        core::SolveTermination::StepLimit,
    ]
    .into_iter()
    .find(|t| t.name() == termination)
    .ok_or_else(|| unknown_termination(termination))?;
    Ok(Solution {
        inner: core::Solution {
            q: pickled_vector(q, "q")?,
            converged,
            steps,
            best_step: best_step.unwrap_or(steps),
            position_error,
            orientation_error,
            termination,
        },
    })
}

/// Registers the resolver classes.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Gains>()?;
    add_float_properties(m.py())?;
    m.add_class::<Resolver>()?;
    m.add_class::<StepResult>()?;
    m.add_class::<Solution>()?;
    m.add_class::<LagModel>()?;
    m.add_function(wrap_pyfunction!(_rebuild_step_result, m)?)?;
    m.add_function(wrap_pyfunction!(_rebuild_solution, m)?)?;
    Ok(())
}
