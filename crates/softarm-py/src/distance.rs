//! Obstacles (`PolynomialCurve`, `Segment`, `PointCloud`, `TriangleMesh`), `Closest` and
//! `closest()` for Python. Each obstacle class holds a core `Obstacle`, so queries borrow
//! it without copying (a cloud's BVH is built once, in the constructor).

use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyType;
use softarm_core::chain::SectionModel;
use softarm_core::distance::{self as dist, Obstacle};
use softarm_core::{self as core, Vec3};

use crate::convert::{array, count, points_out, real, reshape, vec3_out, vector, wrong_type};
use crate::errors::{fielded, Given, InputError, IntoPyResult};
use crate::kinematics::{ArcChain, SoftArm};

/// An arm model taken from Python: a `SoftArm` or an `ArcChain`.
pub enum Model {
    /// Actuator space.
    Soft(core::SoftArm),
    /// Configuration space.
    Chain(core::ArcChain),
}

impl Model {
    /// Reads `obj` (argument `arg`) as an arm model.
    pub fn from_py(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<Self> {
        if let Ok(a) = obj.cast::<SoftArm>() {
            return Ok(Model::Soft(a.get().inner.clone()));
        }
        if let Ok(c) = obj.cast::<ArcChain>() {
            return Ok(Model::Chain(c.get().inner.clone()));
        }
        Err(wrong_type(obj, arg, "a SoftArm or an ArcChain"))
    }

    /// Number of coordinates.
    pub fn n_dofs(&self) -> usize {
        match self {
            Model::Soft(m) => m.n_dofs(),
            Model::Chain(m) => m.n_dofs(),
        }
    }
}

fn vec3_arg(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<Vec3> {
    let v = vector(obj, arg, 3)?;
    Ok(Vec3::new(v[0], v[1], v[2]))
}

fn points_arg(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<Vec<Vec3>> {
    let (flat, _) = array(obj, arg, &[None, Some(3)])?;
    Ok(flat
        .chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect())
}

/// A polynomial space curve F(u) = Σ c_k u^k over [u_min, u_max] (planning paper eq. 10).
#[pyclass(module = "softarm._core", frozen)]
pub struct PolynomialCurve {
    pub(crate) obstacle: Obstacle,
    curve: dist::PolynomialCurve,
}

impl PolynomialCurve {
    fn curve(&self) -> &dist::PolynomialCurve {
        &self.curve
    }

    /// Wraps a core curve.
    pub fn from_core(curve: dist::PolynomialCurve) -> Self {
        PolynomialCurve {
            obstacle: Obstacle::Curve(curve.clone()),
            curve,
        }
    }
}

#[pymethods]
impl PolynomialCurve {
    /// `coeffs` (3, d + 1): ascending powers of u, row 0 is x(u); `u_range` (u_min, u_max).
    #[new]
    fn new(coeffs: &Bound<'_, PyAny>, u_range: &Bound<'_, PyAny>) -> PyResult<Self> {
        let (flat, _) = array(coeffs, "coeffs", &[Some(3), None])?;
        let r = vector(u_range, "u_range", 2)?;
        let c = dist::PolynomialCurve::from_rows(&flat, (r[0], r[1])).py()?;
        Ok(PolynomialCurve {
            obstacle: Obstacle::Curve(c.clone()),
            curve: c,
        })
    }

    /// Coefficients (3, d + 1), ascending powers.
    #[getter]
    fn coeffs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let c = self.curve().coeffs();
        let m = c.len();
        let mut flat = vec![0.0; 3 * m];
        for (k, v) in c.iter().enumerate() {
            for r in 0..3 {
                flat[r * m + k] = v[r];
            }
        }
        reshape(py, flat, [3, m])
    }

    /// (u_min, u_max).
    #[getter]
    fn u_range(&self) -> (f64, f64) {
        self.curve().u_range()
    }

    /// Polynomial degree.
    #[getter]
    fn degree(&self) -> usize {
        self.curve().degree()
    }

    /// Points at the parameters `u` (scalar → (3,), array (N,) → (N, 3)), each inside
    /// `u_range`: the curve is defined there, and its evaluation is only checked to be
    /// finite there.
    fn __call__<'py>(&self, py: Python<'py>, u: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let (lo, hi) = self.curve().u_range();
        if let Ok(v) = real(u, "u") {
            core::error::check_range("u", v, lo, hi).py()?;
            return Ok(vec3_out(py, &self.curve().eval(v)).into_any());
        }
        let (us, _) = array(u, "u", &[None])?;
        if let Some(i) = us.iter().position(|v| !(lo..=hi).contains(v)) {
            core::error::check_range(&format!("u[{i}]"), us[i], lo, hi).py()?;
        }
        let pts: Vec<Vec3> = us.iter().map(|&v| self.curve().eval(v)).collect();
        Ok(points_out(py, &pts)?.into_any())
    }

    /// `n` points evenly spaced in u (the paper's point model of the curve), (n, 3).
    fn sample<'py>(
        &self,
        py: Python<'py>,
        n: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = count(n, "n", 0, core::error::MAX_SAMPLES)?;
        points_out(py, &self.curve().sample(n).py()?)
    }

    /// Pickling and `copy.deepcopy`: rebuilt from its coefficients and range.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyType>, (Bound<'py, PyArray2<f64>>, (f64, f64)))> {
        let me = slf.get();
        Ok((slf.get_type(), (me.coeffs(slf.py())?, me.u_range())))
    }

    fn __repr__(&self) -> String {
        let (a, b) = self.curve().u_range();
        format!(
            "PolynomialCurve(degree={}, u_range=({a}, {b}))",
            self.curve().degree()
        )
    }
}

/// A line segment from `a` to `b`; its parameter u is the fraction from a to b.
#[pyclass(module = "softarm._core", frozen)]
pub struct Segment {
    pub(crate) obstacle: Obstacle,
    a: Vec3,
    b: Vec3,
}

#[pymethods]
impl Segment {
    #[new]
    fn new(a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<Self> {
        let (a, b) = (vec3_arg(a, "a")?, vec3_arg(b, "b")?);
        let s = dist::Segment::new(a, b).py()?;
        Ok(Segment {
            obstacle: Obstacle::Segment(s),
            a,
            b,
        })
    }

    /// First end point, (3,).
    #[getter]
    fn a<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec3_out(py, &self.a)
    }

    /// Second end point, (3,).
    #[getter]
    fn b<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec3_out(py, &self.b)
    }

    /// Pickling and `copy.deepcopy`: rebuilt from its end points.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> (
        Bound<'py, PyType>,
        (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>),
    ) {
        let (py, me) = (slf.py(), slf.get());
        (slf.get_type(), (me.a(py), me.b(py)))
    }

    fn __repr__(&self) -> String {
        format!(
            "Segment(a={:?}, b={:?})",
            self.a.as_slice(),
            self.b.as_slice()
        )
    }
}

/// A point cloud (N, 3) with a bounding-volume hierarchy (parry3d) built once.
#[pyclass(module = "softarm._core", frozen)]
pub struct PointCloud {
    pub(crate) obstacle: Obstacle,
}

#[pymethods]
impl PointCloud {
    #[new]
    fn new(points: &Bound<'_, PyAny>) -> PyResult<Self> {
        let pts = points_arg(points, "points")?;
        Ok(PointCloud {
            obstacle: Obstacle::Cloud(dist::PointCloud::new(pts).py()?),
        })
    }

    /// The points, (N, 3).
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        match &self.obstacle {
            Obstacle::Cloud(c) => points_out(py, c.points()),
            _ => points_out(py, &[]),
        }
    }

    fn __len__(&self) -> usize {
        match &self.obstacle {
            Obstacle::Cloud(c) => c.len(),
            _ => 0,
        }
    }

    /// Pickling and `copy.deepcopy`: rebuilt from its points (the hierarchy is rebuilt).
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyType>, (Bound<'py, PyArray2<f64>>,))> {
        Ok((slf.get_type(), (slf.get().points(slf.py())?,)))
    }

    fn __repr__(&self) -> String {
        format!("PointCloud(n={})", self.__len__())
    }
}

/// A triangle mesh (parry3d TriMesh); arcs meet it as chords within `tolerance` (m),
/// and reported distances are conservative by that bound.
#[pyclass(module = "softarm._core", frozen)]
pub struct TriangleMesh {
    pub(crate) obstacle: Obstacle,
}

#[pymethods]
impl TriangleMesh {
    #[new]
    #[pyo3(
        signature = (vertices, triangles, tolerance = None),
        text_signature = "(vertices, triangles, tolerance=0.0001)"
    )]
    fn new(
        vertices: &Bound<'_, PyAny>,
        triangles: &Bound<'_, PyAny>,
        tolerance: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let tolerance = tolerance.map_or(Ok(1e-4), |t| real(t, "tolerance"))?;
        let verts = points_arg(vertices, "vertices")?;
        let (flat, _) = array(triangles, "triangles", &[None, Some(3)])?;
        let mut tris = Vec::with_capacity(flat.len() / 3);
        for c in flat.chunks_exact(3) {
            let mut t = [0u32; 3];
            for (k, &v) in c.iter().enumerate() {
                if !(v >= 0.0 && v.fract() == 0.0 && v < u32::MAX as f64) {
                    let expected = "non-negative integer vertex indices";
                    let msg = format!("triangles: expected {expected}, got {v}");
                    return Err(fielded(
                        InputError::new_err(msg),
                        "triangles",
                        Given::Float(v),
                        expected,
                    ));
                }
                t[k] = v as u32;
            }
            tris.push(t);
        }
        let m = dist::TriangleMesh::new(&verts, &tris, tolerance).py()?;
        Ok(TriangleMesh {
            obstacle: Obstacle::Mesh(m),
        })
    }

    /// Chord tolerance (m).
    #[getter]
    fn tolerance(&self) -> f64 {
        self.mesh().tolerance()
    }

    /// The vertices, (N, 3).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let v: Vec<Vec3> = self
            .mesh()
            .mesh()
            .vertices()
            .iter()
            .map(|p| Vec3::new(p.x, p.y, p.z))
            .collect();
        points_out(py, &v)
    }

    /// The triangles' vertex indices, (M, 3) int64.
    #[getter]
    fn triangles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let t = self.mesh().mesh().indices();
        let flat: Vec<i64> = t.iter().flatten().map(|&i| i64::from(i)).collect();
        let arr = numpy::ndarray::Array2::from_shape_vec([t.len(), 3], flat).map_err(|e| {
            pyo3::exceptions::PyValueError::new_err(format!("internal shape mismatch: {e}"))
        })?;
        Ok(numpy::IntoPyArray::into_pyarray(arr, py))
    }

    /// Pickling and `copy.deepcopy`: rebuilt from its vertices, triangles and tolerance.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(
        Bound<'py, PyType>,
        (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>, f64),
    )> {
        let (py, me) = (slf.py(), slf.get());
        Ok((
            slf.get_type(),
            (me.vertices(py)?, me.triangles(py)?, me.tolerance()),
        ))
    }
}

impl TriangleMesh {
    fn mesh(&self) -> &dist::TriangleMesh {
        match &self.obstacle {
            Obstacle::Mesh(m) => m,
            // The constructor only ever stores a mesh.
            _ => unreachable!("a TriangleMesh holds a mesh"),
        }
    }
}

/// Reads one obstacle: an obstacle object or a point (3,).
pub fn obstacle_from(obj: &Bound<'_, PyAny>, arg: &str) -> PyResult<Obstacle> {
    if let Ok(c) = obj.cast::<PolynomialCurve>() {
        return Ok(c.get().obstacle.clone());
    }
    if let Ok(s) = obj.cast::<Segment>() {
        return Ok(s.get().obstacle.clone());
    }
    if let Ok(c) = obj.cast::<PointCloud>() {
        return Ok(c.get().obstacle.clone());
    }
    if let Ok(m) = obj.cast::<TriangleMesh>() {
        return Ok(m.get().obstacle.clone());
    }
    // The point is validated by the core query (`Obstacle::validate`, the one check of
    // every obstacle form), like every obstacle the core receives.
    match vector(obj, arg, 3) {
        Ok(v) => Ok(Obstacle::Point(Vec3::new(v[0], v[1], v[2]))),
        Err(_) => Err(wrong_type(
            obj,
            arg,
            "a PolynomialCurve, Segment, PointCloud, TriangleMesh or a point (3,)",
        )),
    }
}

/// Applies `f` to the obstacle held by `obj` without copying it (a point is built).
pub(crate) fn with_obstacle<R>(
    obj: &Bound<'_, PyAny>,
    f: impl FnOnce(&Obstacle) -> R,
) -> PyResult<R> {
    if let Ok(c) = obj.cast::<PolynomialCurve>() {
        return Ok(f(&c.get().obstacle));
    }
    if let Ok(s) = obj.cast::<Segment>() {
        return Ok(f(&s.get().obstacle));
    }
    if let Ok(c) = obj.cast::<PointCloud>() {
        return Ok(f(&c.get().obstacle));
    }
    if let Ok(m) = obj.cast::<TriangleMesh>() {
        return Ok(f(&m.get().obstacle));
    }
    let ob = obstacle_from(obj, "obstacle")?;
    Ok(f(&ob))
}

/// The closest pair between an arm and an obstacle.
#[pyclass(module = "softarm._core", frozen)]
pub struct Closest {
    inner: dist::Closest,
}

#[pymethods]
impl Closest {
    /// Distance (m); 0 when touching or crossing. Conservative for meshes.
    #[getter]
    fn distance(&self) -> f64 {
        self.inner.distance
    }
    /// Section of the arm point (0 = proximal).
    #[getter]
    fn section(&self) -> usize {
        self.inner.section
    }
    /// Fraction along the section.
    #[getter]
    fn s(&self) -> f64 {
        self.inner.s
    }
    /// Obstacle parameter: curve u, segment fraction, cloud point or mesh triangle index.
    #[getter]
    fn u(&self) -> f64 {
        self.inner.u
    }
    /// Arm point (3,).
    #[getter]
    fn arm_point<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec3_out(py, &self.inner.arm_point)
    }
    /// Obstacle point (3,).
    #[getter]
    fn obstacle_point<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec3_out(py, &self.inner.obstacle_point)
    }
    /// Pickling and `copy.deepcopy`, through `_core._rebuild_closest`.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        (
            f64,
            usize,
            f64,
            f64,
            Bound<'py, PyArray1<f64>>,
            Bound<'py, PyArray1<f64>>,
        ),
    )> {
        let c = &self.inner;
        let f = py.import("softarm._core")?.getattr("_rebuild_closest")?;
        Ok((
            f,
            (
                c.distance,
                c.section,
                c.s,
                c.u,
                self.arm_point(py),
                self.obstacle_point(py),
            ),
        ))
    }

    fn __repr__(&self) -> String {
        let c = &self.inner;
        format!(
            "Closest(distance={}, section={}, s={}, u={})",
            c.distance, c.section, c.s, c.u
        )
    }
}

/// Closest pair between the arm `arm` (SoftArm or ArcChain) at `q` and `obstacle`
/// (planning paper eq. 12–18: global over sections, s and u).
#[pyfunction]
fn closest(
    arm: &Bound<'_, PyAny>,
    q: &Bound<'_, PyAny>,
    obstacle: &Bound<'_, PyAny>,
) -> PyResult<Closest> {
    let model = Model::from_py(arm, "arm")?;
    let q = vector(q, "q", model.n_dofs())?;
    let inner = with_obstacle(obstacle, |ob| match &model {
        Model::Soft(m) => dist::closest(m, &q, ob),
        Model::Chain(m) => dist::closest(m, &q, ob),
    })?
    .py()?;
    Ok(Closest { inner })
}

/// Rebuilds a `Closest` from its fields (the unpickler of `Closest.__reduce__`).
#[pyfunction]
fn _rebuild_closest(
    distance: f64,
    section: usize,
    s: f64,
    u: f64,
    arm_point: &Bound<'_, PyAny>,
    obstacle_point: &Bound<'_, PyAny>,
) -> PyResult<Closest> {
    let a = vector(arm_point, "arm_point", 3)?;
    let o = vector(obstacle_point, "obstacle_point", 3)?;
    Ok(Closest {
        inner: dist::Closest::new(
            section,
            s,
            Vec3::new(a[0], a[1], a[2]),
            u,
            Vec3::new(o[0], o[1], o[2]),
            distance,
        ),
    })
}

/// Registers the distance classes and `closest`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PolynomialCurve>()?;
    m.add_class::<Segment>()?;
    m.add_class::<PointCloud>()?;
    m.add_class::<TriangleMesh>()?;
    m.add_class::<Closest>()?;
    m.add_function(wrap_pyfunction!(closest, m)?)?;
    m.add_function(wrap_pyfunction!(_rebuild_closest, m)?)?;
    Ok(())
}
