//! `PotentialFieldPlanner`, `Plan`, `path_clearance` and the paper's scenarios for Python.
//! `plan()` runs the whole loop in Rust with the GIL released.

use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use softarm_core::planner::{self as pl, scenarios};
use softarm_core::{self as core, Vec3};

use crate::convert::{array, count, points_out, real, reshape, type_of, vec3_out, vector};
use crate::distance::{obstacle_from, Model, PolynomialCurve};
use crate::errors::{fielded, given_text, unknown_termination, InputError, IntoPyResult};
use crate::kinematics::{ArcChain, SoftArm};
use softarm_core::error::MAX_ITERATIONS;

enum Planner {
    Soft(pl::PotentialFieldPlanner<core::SoftArm>),
    Chain(pl::PotentialFieldPlanner<core::ArcChain>),
}

/// Potential-field planner of the planning paper, eq. (9), on a SoftArm or an ArcChain.
#[pyclass(module = "softarm._core", frozen)]
pub struct PotentialFieldPlanner {
    inner: Planner,
    options: pl::PlannerOptions,
    n_dofs: usize,
}

fn obstacles_from(obj: &Bound<'_, PyAny>) -> PyResult<Vec<core::Obstacle>> {
    let mut out = Vec::new();
    for (k, item) in obj.try_iter()?.enumerate() {
        out.push(obstacle_from(&item?, &format!("obstacles[{k}]"))?);
    }
    Ok(out)
}

#[pymethods]
impl PotentialFieldPlanner {
    #[new]
    #[pyo3(
        signature = (
            arm, *, attraction_gain = None, max_tip_step = None, repulsion_gain = None,
            influence_distance = None, max_step_fraction = None, damping = None,
            goal_tolerance = None, max_iterations = None, stall_window = None,
            stall_tolerance = None, arm_samples = None
        ),
        text_signature = "(arm, *, attraction_gain=1.0, max_tip_step=0.15, repulsion_gain=3e-05, influence_distance=0.1, max_step_fraction=0.04, damping=0.05, goal_tolerance=0.01, max_iterations=500, stall_window=20, stall_tolerance=0.001, arm_samples=None)"
    )]
    #[allow(clippy::too_many_arguments)]
    fn new(
        arm: &Bound<'_, PyAny>,
        attraction_gain: Option<&Bound<'_, PyAny>>,
        max_tip_step: Option<&Bound<'_, PyAny>>,
        repulsion_gain: Option<&Bound<'_, PyAny>>,
        influence_distance: Option<&Bound<'_, PyAny>>,
        max_step_fraction: Option<&Bound<'_, PyAny>>,
        damping: Option<&Bound<'_, PyAny>>,
        goal_tolerance: Option<&Bound<'_, PyAny>>,
        max_iterations: Option<&Bound<'_, PyAny>>,
        stall_window: Option<&Bound<'_, PyAny>>,
        stall_tolerance: Option<&Bound<'_, PyAny>>,
        arm_samples: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let d = pl::PlannerOptions::default();
        let f = |v: Option<&Bound<'_, PyAny>>, arg: &str, default: f64| {
            v.map_or(Ok(default), |v| real(v, arg))
        };
        // Counts are read with their bounds, so that a huge or negative Python int is a
        // typed error naming the option, not an OverflowError from the conversion.
        let n = |v: Option<&Bound<'_, PyAny>>, arg: &str, min, max, default| {
            v.map_or(Ok(default), |v| count(v, arg, min, max))
        };
        let options = pl::PlannerOptions {
            attraction_gain: f(attraction_gain, "attraction_gain", d.attraction_gain)?,
            max_tip_step: f(max_tip_step, "max_tip_step", d.max_tip_step)?,
            repulsion_gain: f(repulsion_gain, "repulsion_gain", d.repulsion_gain)?,
            influence_distance: f(
                influence_distance,
                "influence_distance",
                d.influence_distance,
            )?,
            max_step_fraction: f(max_step_fraction, "max_step_fraction", d.max_step_fraction)?,
            damping: f(damping, "damping", d.damping)?,
            goal_tolerance: f(goal_tolerance, "goal_tolerance", d.goal_tolerance)?,
            max_iterations: n(
                max_iterations,
                "max_iterations",
                0,
                MAX_ITERATIONS,
                d.max_iterations,
            )?,
            stall_window: n(
                stall_window,
                "stall_window",
                1,
                MAX_ITERATIONS,
                d.stall_window,
            )?,
            stall_tolerance: f(stall_tolerance, "stall_tolerance", d.stall_tolerance)?,
            arm_samples: match arm_samples {
                Some(v) if !v.is_none() => Some(count(v, "arm_samples", 2, pl::MAX_ARM_SAMPLES)?),
                _ => None,
            },
        };
        let model = Model::from_py(arm, "arm")?;
        let n_dofs = model.n_dofs();
        let inner = match model {
            Model::Soft(m) => Planner::Soft(pl::PotentialFieldPlanner::new(m, options).py()?),
            Model::Chain(m) => Planner::Chain(pl::PotentialFieldPlanner::new(m, options).py()?),
        };
        Ok(PotentialFieldPlanner {
            inner,
            options,
            n_dofs,
        })
    }

    /// The options as a dict.
    #[getter]
    fn options<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let o = &self.options;
        let d = PyDict::new(py);
        d.set_item("attraction_gain", o.attraction_gain)?;
        d.set_item("max_tip_step", o.max_tip_step)?;
        d.set_item("repulsion_gain", o.repulsion_gain)?;
        d.set_item("influence_distance", o.influence_distance)?;
        d.set_item("max_step_fraction", o.max_step_fraction)?;
        d.set_item("damping", o.damping)?;
        d.set_item("goal_tolerance", o.goal_tolerance)?;
        d.set_item("max_iterations", o.max_iterations)?;
        d.set_item("stall_window", o.stall_window)?;
        d.set_item("stall_tolerance", o.stall_tolerance)?;
        d.set_item("arm_samples", o.arm_samples)?;
        Ok(d)
    }

    /// Plans from `q0` to the tip position `goal` (3,) among `obstacles` (any mix of
    /// curves, segments, point clouds, meshes and points). Releases the GIL.
    #[pyo3(signature = (q0, goal, obstacles = None))]
    fn plan(
        &self,
        py: Python<'_>,
        q0: &Bound<'_, PyAny>,
        goal: &Bound<'_, PyAny>,
        obstacles: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Plan> {
        let q0 = vector(q0, "q0", self.n_dofs)?;
        let g = vector(goal, "goal", 3)?;
        let goal = Vec3::new(g[0], g[1], g[2]);
        let obs = match obstacles {
            Some(o) => obstacles_from(o)?,
            None => Vec::new(),
        };
        let plan = py
            .detach(|| match &self.inner {
                Planner::Soft(p) => p.plan(&q0, &goal, &obs),
                Planner::Chain(p) => p.plan(&q0, &goal, &obs),
            })
            .py()?;
        Ok(Plan { inner: plan })
    }

    /// Pickling and `copy.deepcopy`: `functools.partial(PotentialFieldPlanner,
    /// **options)(arm)`.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyAny>,))> {
        let py = slf.py();
        let me = slf.get();
        let arm = match &me.inner {
            Planner::Soft(p) => Bound::new(
                py,
                SoftArm {
                    inner: p.model().clone(),
                },
            )?
            .into_any(),
            Planner::Chain(p) => Bound::new(
                py,
                ArcChain {
                    inner: p.model().clone(),
                },
            )?
            .into_any(),
        };
        let partial = py
            .import("functools")?
            .getattr("partial")?
            .call((slf.get_type(),), Some(&me.options(py)?))?;
        Ok((partial, (arm,)))
    }

    fn __repr__(&self) -> String {
        format!("PotentialFieldPlanner(n_dofs={})", self.n_dofs)
    }
}

/// A planned path.
#[pyclass(module = "softarm._core", frozen)]
pub struct Plan {
    inner: pl::Plan,
}

#[pymethods]
impl Plan {
    /// Configurations along the path, (iterations + 1, n), q0 first.
    #[getter]
    fn path<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let rows = self.inner.path.len();
        let n = self.inner.path.first().map_or(0, Vec::len);
        reshape(py, self.inner.path.concat(), [rows, n])
    }
    /// Tip positions along the path, (iterations + 1, 3).
    #[getter]
    fn tip_path<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        points_out(py, &self.inner.tip_path)
    }
    /// Whether the tip ended within the goal tolerance.
    #[getter]
    fn reached(&self) -> bool {
        self.inner.reached
    }
    /// Number of iterations of eq. (9).
    #[getter]
    fn iterations(&self) -> usize {
        self.inner.iterations
    }
    /// Smallest exact distance of the whole backbone to any obstacle along the path (m).
    #[getter]
    fn min_clearance(&self) -> f64 {
        self.inner.min_clearance
    }
    /// "reached", "stalled" or "iteration_limit".
    #[getter]
    fn termination(&self) -> &'static str {
        self.inner.termination.name()
    }
    /// Pickling and `copy.deepcopy`, through `_core._rebuild_plan`.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        (
            Bound<'py, PyArray2<f64>>,
            Bound<'py, PyArray2<f64>>,
            usize,
            f64,
            &'static str,
        ),
    )> {
        let f = py.import("softarm._core")?.getattr("_rebuild_plan")?;
        Ok((
            f,
            (
                self.path(py)?,
                self.tip_path(py)?,
                self.inner.iterations,
                self.inner.min_clearance,
                self.termination(),
            ),
        ))
    }

    fn __repr__(&self) -> String {
        format!(
            "Plan(reached={}, iterations={}, min_clearance={}, termination={:?})",
            crate::resolver::py_bool(self.inner.reached),
            self.inner.iterations,
            self.inner.min_clearance,
            self.inner.termination.name()
        )
    }
}

/// Exact clearance of the arm along `path` (N, n) to `obstacles`, also checking
/// `substeps - 1` interpolated configurations between consecutive rows.
#[pyfunction]
#[pyo3(
    signature = (arm, path, obstacles, substeps = None),
    text_signature = "(arm, path, obstacles, substeps=1)"
)]
fn path_clearance(
    py: Python<'_>,
    arm: &Bound<'_, PyAny>,
    path: &Bound<'_, PyAny>,
    obstacles: &Bound<'_, PyAny>,
    substeps: Option<&Bound<'_, PyAny>>,
) -> PyResult<f64> {
    let substeps = substeps.map_or(Ok(1), |v| count(v, "substeps", 1, pl::MAX_SUBSTEPS))?;
    let model = Model::from_py(arm, "arm")?;
    let n = model.n_dofs();
    let (flat, _) = array(path, "path", &[None, Some(n)])?;
    let rows: Vec<Vec<f64>> = flat.chunks_exact(n.max(1)).map(<[f64]>::to_vec).collect();
    let obs = obstacles_from(obstacles)?;
    py.detach(|| match &model {
        Model::Soft(m) => pl::path_clearance(m, &rows, &obs, substeps),
        Model::Chain(m) => pl::path_clearance(m, &rows, &obs, substeps),
    })
    .py()
}

/// The planning paper's simulation `name` ("line", "curve", "tree"): (goal (3,), curves).
#[pyfunction]
fn paper_scenario<'py>(
    py: Python<'py>,
    name: &Bound<'py, PyAny>,
) -> PyResult<(Bound<'py, numpy::PyArray1<f64>>, Vec<PolynomialCurve>)> {
    let name = name.cast::<pyo3::types::PyString>().map_err(|_| {
        let got = type_of(name);
        let msg = format!("name: expected a str, got {}", given_text(&got));
        fielded(InputError::new_err(msg), "name", got, "a str")
    })?;
    let sc = scenarios::scenario(name.to_str()?).py()?;
    let curves = sc
        .curves
        .iter()
        .map(|c| PolynomialCurve::from_core(c.clone()))
        .collect();
    Ok((vec3_out(py, &sc.goal), curves))
}

/// Rebuilds a `Plan` (the unpickler of `Plan.__reduce__`).
#[pyfunction]
fn _rebuild_plan(
    path: &Bound<'_, PyAny>,
    tip_path: &Bound<'_, PyAny>,
    iterations: usize,
    min_clearance: f64,
    termination: &str,
) -> PyResult<Plan> {
    let (flat, shape) = array(path, "path", &[None, None])?;
    let n = shape[1];
    let (tips, _) = array(tip_path, "tip_path", &[Some(shape[0]), Some(3)])?;
    let termination = [
        pl::Termination::Reached,
        pl::Termination::Stalled,
        pl::Termination::IterationLimit,
        pl::Termination::NonFiniteStep,
    ]
    .into_iter()
    .find(|t| t.name() == termination)
    .ok_or_else(|| unknown_termination(termination))?;
    Ok(Plan {
        inner: pl::Plan {
            path: flat.chunks_exact(n.max(1)).map(<[f64]>::to_vec).collect(),
            tip_path: tips
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect(),
            reached: termination == pl::Termination::Reached,
            iterations,
            min_clearance,
            termination,
        },
    })
}

/// Registers the planner classes and functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PotentialFieldPlanner>()?;
    m.add_class::<Plan>()?;
    m.add_function(wrap_pyfunction!(path_clearance, m)?)?;
    m.add_function(wrap_pyfunction!(paper_scenario, m)?)?;
    m.add_function(wrap_pyfunction!(_rebuild_plan, m)?)?;
    Ok(())
}
