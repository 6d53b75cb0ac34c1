//! `SoftArm`, `Section` and `ArcChain` for Python. Both arm classes get the same
//! kinematic methods from one macro, so the two can never drift apart.

use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple, PyType};
use softarm_core::chain::{forward_jacobian_into, forward_unchecked, SectionModel};
use softarm_core::{self as core, Kinematics};

use crate::convert::type_of;
use crate::convert::{
    array, count, dmatrix_out, mat4_out, matrix3x_out, points_out, real, vec3_out, vector,
    write_dmatrix, write_frame, write_mat4,
};
use crate::errors::{fielded, InputError, IntoPyResult};

/// `q` as a vector of the model's length that gives every section a geometry: finite,
/// bounded, and a positive arc length (a non-positive one is a `ParameterError` naming
/// `q[3i..3i+3]`). Values outside the actuator limits that still have a geometry pass.
fn geometric_q<M: SectionModel>(model: &M, q: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let q = vector(q, "q", model.n_dofs())?;
    softarm_core::chain::check_q_arcs(model, &q).py()?;
    Ok(q)
}

/// Converts a Python section index, rejecting negative and too large values by name.
fn section_index<M: SectionModel>(model: &M, section: &Bound<'_, PyAny>) -> PyResult<usize> {
    count(section, "section", 0, model.n_sections().saturating_sub(1))
}

/// The `sections` argument: a list or tuple of `Section`, anything else named.
fn sections_arg(obj: &Bound<'_, PyAny>) -> PyResult<Vec<core::Section>> {
    let items = if let Ok(l) = obj.cast::<PyList>() {
        l.iter().collect::<Vec<_>>()
    } else if let Ok(t) = obj.cast::<PyTuple>() {
        t.iter().collect()
    } else {
        let msg = format!(
            "sections: expected a list of Section, got {}",
            obj.get_type().name()?
        );
        return Err(fielded(
            InputError::new_err(msg),
            "sections",
            type_of(obj),
            "a list of Section",
        ));
    };
    items
        .iter()
        .enumerate()
        .map(|(k, item)| match item.cast::<Section>() {
            Ok(s) => Ok(s.get().inner),
            Err(_) => {
                let arg = format!("sections[{k}]");
                let msg = format!("{arg}: expected a Section, got {}", item.get_type().name()?);
                Err(fielded(
                    InputError::new_err(msg),
                    &arg,
                    type_of(item),
                    "a Section",
                ))
            }
        })
        .collect()
}

/// An (N, n) batch of configurations, checked and copied. The copy is taken while the GIL
/// is held, so that another thread writing the caller's array after validation (while
/// the batch runs without the GIL) can neither put NaN into the output nor race with the
/// read: the batch only ever reads memory it owns. One memcpy per call, small beside the
/// kinematics of each row.
fn batch_input<M: SectionModel>(model: &M, qs: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let (flat, _) = array(qs, "qs", &[None, Some(model.n_dofs())])?;
    core::error::check_bounded("qs", &flat, core::error::MAX_COORDINATE).py()?;
    for (k, q) in flat.chunks_exact(model.n_dofs()).enumerate() {
        // A row without geometry is named as qs[row, 3i..3i+3].
        softarm_core::chain::check_q_arcs(model, q)
            .map_err(|e| match e {
                core::Error::Parameter { arg, value, reason } => core::Error::Parameter {
                    arg: format!("qs[{k}, {}", arg.trim_start_matches("q[")),
                    value,
                    reason,
                },
                other => other,
            })
            .py()?;
    }
    Ok(flat)
}

macro_rules! kinematic_methods {
    ($ty:ident, { $($extra:tt)* }) => {
        #[pymethods]
        impl $ty {
            $($extra)*

            /// Number of sections.
            #[getter]
            fn n_sections(&self) -> usize {
                self.inner.n_sections()
            }

            /// Number of coordinates (3 per section).
            #[getter]
            fn n_dofs(&self) -> usize {
                self.inner.n_dofs()
            }

            /// Lower limit of every coordinate, shape (n,).
            #[getter]
            fn lower<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
                PyArray1::from_slice(py, self.inner.lower())
            }

            /// Upper limit of every coordinate, shape (n,).
            #[getter]
            fn upper<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
                PyArray1::from_slice(py, self.inner.upper())
            }

            /// End-effector pose (4, 4) in the base frame.
            ///
            /// A `q` outside the limits is still computed while every section keeps a
            /// positive arc length; one without (a non-positive arc length) raises
            /// `ParameterError` naming `q[3i..3i+3]`, as every kinematic call does.
            fn forward<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                let q = geometric_q(&self.inner, q)?;
                let t = self.inner.forward(&q).py()?;
                Ok(mat4_out(py, &t))
            }

            /// Jacobian (6, n): rows vx, vy, vz, wx, wy, wz in the base frame.
            fn jacobian<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                let q = geometric_q(&self.inner, q)?;
                let j = self.inner.jacobian(&q).py()?;
                Ok(dmatrix_out(py, &j))
            }

            /// Pose (4, 4) and Jacobian (6, n) from one pass.
            fn forward_jacobian<'py>(
                &self,
                py: Python<'py>,
                q: &Bound<'py, PyAny>,
            ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
                let q = geometric_q(&self.inner, q)?;
                let (t, j) = self.inner.forward_jacobian(&q).py()?;
                Ok((mat4_out(py, &t), dmatrix_out(py, &j)))
            }

            /// Backbone point at fraction s of a section (0 = proximal), shape (3,), and
            /// its Jacobian, shape (3, n).
            fn point<'py>(
                &self,
                py: Python<'py>,
                q: &Bound<'py, PyAny>,
                section: &Bound<'py, PyAny>,
                s: &Bound<'py, PyAny>,
            ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>)> {
                let q = geometric_q(&self.inner, q)?;
                let section = section_index(&self.inner, section)?;
                let s = real(s, "s")?;
                let (p, j) = self.inner.point(&q, section, s).py()?;
                Ok((vec3_out(py, &p), matrix3x_out(py, &j)?))
            }

            /// Base frame of every section, then the end effector: (n_sections + 1, 4, 4).
            fn frames<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray3<f64>>> {
                let q = geometric_q(&self.inner, q)?;
                let frames = self.inner.frames(&q).py()?;
                let out = PyArray3::<f64>::zeros(py, [frames.len(), 4, 4], false);
                {
                    let mut rw = out.readwrite();
                    let o = rw.as_slice_mut()?;
                    for (k, f) in frames.iter().enumerate() {
                        write_mat4(f, &mut o[16 * k..16 * k + 16]);
                    }
                }
                Ok(out)
            }

            /// `samples` points per section along the backbone, ends included:
            /// (n_sections * samples, 3).
            #[pyo3(signature = (q, samples = None), text_signature = "(self, q, samples=20)")]
            fn backbone<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>, samples: Option<&Bound<'py, PyAny>>) -> PyResult<Bound<'py, PyArray2<f64>>> {
                let q = geometric_q(&self.inner, q)?;
                let samples = match samples {
                    Some(v) => count(v, "samples", 2, core::error::MAX_SAMPLES)?,
                    None => 20,
                };
                let pts = self.inner.backbone(&q, samples).py()?;
                points_out(py, &pts)
            }

            /// Poses of a batch of configurations: (N, n) → (N, 4, 4). Releases the GIL.
            fn forward_batch<'py>(&self, py: Python<'py>, qs: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray3<f64>>> {
                let flat = batch_input(&self.inner, qs)?;
                let n = self.inner.n_dofs();
                let rows = flat.len() / n;
                let out = PyArray3::<f64>::zeros(py, [rows, 4, 4], false);
                {
                    let mut rw = out.readwrite();
                    let o = rw.as_slice_mut()?;
                    let model = &self.inner;
                    py.detach(|| {
                        for (q, dst) in flat.chunks_exact(n).zip(o.chunks_exact_mut(16)) {
                            write_frame(&forward_unchecked(model, q), dst);
                        }
                    });
                }
                Ok(out)
            }

            /// Jacobians of a batch of configurations: (N, n) → (N, 6, n). Releases the GIL.
            fn jacobian_batch<'py>(&self, py: Python<'py>, qs: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray3<f64>>> {
                let flat = batch_input(&self.inner, qs)?;
                let n = self.inner.n_dofs();
                let rows = flat.len() / n;
                let out = PyArray3::<f64>::zeros(py, [rows, 6, n], false);
                {
                    let mut rw = out.readwrite();
                    let o = rw.as_slice_mut()?;
                    let model = &self.inner;
                    py.detach(|| {
                        let mut jac = nalgebra::DMatrix::zeros(6, n);
                        for (q, dst) in flat.chunks_exact(n).zip(o.chunks_exact_mut(6 * n)) {
                            forward_jacobian_into(model, q, &mut jac);
                            write_dmatrix(&jac, dst);
                        }
                    });
                }
                Ok(out)
            }
        }
    };
}

/// Geometry and limits of one pneumatic section.
#[pyclass(module = "softarm._core", frozen, eq, from_py_object)]
#[derive(Clone, PartialEq)]
pub struct Section {
    pub(crate) inner: core::Section,
}

#[pymethods]
impl Section {
    #[new]
    #[pyo3(
        signature = (radius, rest_length, lower, upper, offset = None, twist = None),
        text_signature = "(radius, rest_length, lower, upper, offset=0.0, twist=0.0)"
    )]
    fn new(
        radius: &Bound<'_, PyAny>,
        rest_length: &Bound<'_, PyAny>,
        lower: &Bound<'_, PyAny>,
        upper: &Bound<'_, PyAny>,
        offset: Option<&Bound<'_, PyAny>>,
        twist: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let opt = |v: Option<&Bound<'_, PyAny>>, arg: &str| v.map_or(Ok(0.0), |v| real(v, arg));
        let inner = core::Section::new(
            real(radius, "radius")?,
            real(rest_length, "rest_length")?,
            real(lower, "lower")?,
            real(upper, "upper")?,
            opt(offset, "offset")?,
            opt(twist, "twist")?,
        )
        .py()?;
        Ok(Section { inner })
    }

    /// Pickling and `copy.deepcopy`: rebuilt through the validating constructor.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> (Bound<'py, PyType>, (f64, f64, f64, f64, f64, f64)) {
        let s = &slf.get().inner;
        (
            slf.get_type(),
            (s.radius, s.rest_length, s.lower, s.upper, s.offset, s.twist),
        )
    }

    /// Actuator distance from the centre line (m).
    #[getter]
    fn radius(&self) -> f64 {
        self.inner.radius
    }
    /// Actuator rest length L0 (m).
    #[getter]
    fn rest_length(&self) -> f64 {
        self.inner.rest_length
    }
    /// Smallest elongation (m).
    #[getter]
    fn lower(&self) -> f64 {
        self.inner.lower
    }
    /// Largest elongation (m).
    #[getter]
    fn upper(&self) -> f64 {
        self.inner.upper
    }
    /// Offset b along z after the section (m).
    #[getter]
    fn offset(&self) -> f64 {
        self.inner.offset
    }
    /// Twist β about z after the section (rad).
    #[getter]
    fn twist(&self) -> f64 {
        self.inner.twist
    }

    fn __repr__(&self) -> String {
        let s = &self.inner;
        format!(
            "Section(radius={}, rest_length={}, lower={}, upper={}, offset={}, twist={})",
            s.radius, s.rest_length, s.lower, s.upper, s.offset, s.twist
        )
    }
}

/// A pneumatic continuum arm in actuator space (redundancy paper eq. 1–6).
#[pyclass(module = "softarm._core", frozen)]
pub struct SoftArm {
    pub(crate) inner: core::SoftArm,
}

kinematic_methods!(SoftArm, {
    #[new]
    fn new(sections: &Bound<'_, PyAny>) -> PyResult<Self> {
        let secs = sections_arg(sections)?;
        Ok(SoftArm {
            inner: core::SoftArm::new(secs).py()?,
        })
    }

    /// The default three-section blackberry arm (dimensions in the class docs).
    #[staticmethod]
    fn blackberry() -> Self {
        SoftArm {
            inner: core::SoftArm::blackberry(),
        }
    }

    /// Number of actuators (3 per section).
    #[getter]
    fn n_actuators(&self) -> usize {
        self.inner.n_actuators()
    }

    /// The sections, proximal first.
    #[getter]
    fn sections(&self) -> Vec<Section> {
        self.inner
            .sections()
            .iter()
            .map(|&inner| Section { inner })
            .collect()
    }

    /// Eq. (1) per section: rows of (arc length, bending angle, bending direction),
    /// shape (n_sections, 3). The direction is 0 for a straight section.
    fn configuration<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let q = geometric_q(&self.inner, q)?;
        let cfg = self.inner.polar_configs(&q).py()?;
        let flat: Vec<f64> = cfg
            .iter()
            .flat_map(|c| [c.length, c.bend, c.direction])
            .collect();
        crate::convert::reshape(py, flat, [cfg.len(), 3])
    }

    /// Pickling and `copy.deepcopy`: rebuilt from its sections.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> (Bound<'py, PyType>, (Vec<Section>,)) {
        let sections = slf
            .get()
            .inner
            .sections()
            .iter()
            .map(|&inner| Section { inner })
            .collect();
        (slf.get_type(), (sections,))
    }

    /// `SoftArm([Section(...), ...])`: its geometry, section by section.
    fn __repr__(&self) -> String {
        let sections: Vec<String> = self
            .inner
            .sections()
            .iter()
            .map(|&inner| Section { inner }.__repr__())
            .collect();
        format!("SoftArm([{}])", sections.join(", "))
    }

    /// Equal when the sections are (a pickled or deep copy compares equal).
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<SoftArm>()
            .is_ok_and(|o| o.get().inner.sections() == self.inner.sections())
    }

    /// Consistent with `__eq__`: hashes the bits of every section parameter (0.0 and -0.0
    /// hash alike, as they compare equal).
    fn __hash__(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        for s in self.inner.sections() {
            for v in [s.radius, s.rest_length, s.lower, s.upper, s.offset, s.twist] {
                (v + 0.0).to_bits().hash(&mut h);
            }
        }
        h.finish()
    }
});

/// An arc chain in configuration space, q_i = [L_i, Θ_i, φ_i] (planning paper eq. 1–5).
#[pyclass(module = "softarm._core", frozen)]
pub struct ArcChain {
    pub(crate) inner: core::ArcChain,
}

kinematic_methods!(ArcChain, {
    #[new]
    #[pyo3(signature = (lengths, lower = None, upper = None))]
    fn new(
        lengths: &Bound<'_, PyAny>,
        lower: Option<&Bound<'_, PyAny>>,
        upper: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let (lengths, _) = array(lengths, "lengths", &[None])?;
        let mut inner = core::ArcChain::new(&lengths).py()?;
        if lower.is_some() || upper.is_some() {
            let n = inner.n_dofs();
            let lo = match lower {
                Some(l) => vector(l, "lower", n)?,
                None => inner.lower().to_vec(),
            };
            let hi = match upper {
                Some(u) => vector(u, "upper", n)?,
                None => inner.upper().to_vec(),
            };
            inner = inner.with_limits(&lo, &hi).py()?;
        }
        Ok(ArcChain { inner })
    }

    /// Static segment lengths, shape (n_sections,).
    #[getter]
    fn lengths<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.lengths())
    }

    /// The straight configuration at the static lengths, shape (n,).
    fn straight<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.straight())
    }

    /// Pickling and `copy.deepcopy`: rebuilt from its lengths and limits.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> (
        Bound<'py, PyType>,
        (
            Bound<'py, PyArray1<f64>>,
            Bound<'py, PyArray1<f64>>,
            Bound<'py, PyArray1<f64>>,
        ),
    ) {
        let py = slf.py();
        let c = &slf.get().inner;
        (
            slf.get_type(),
            (
                PyArray1::from_slice(py, c.lengths()),
                PyArray1::from_slice(py, c.lower()),
                PyArray1::from_slice(py, c.upper()),
            ),
        )
    }

    fn __repr__(&self) -> String {
        format!("ArcChain(lengths={:?})", self.inner.lengths())
    }
});

/// Registers the kinematics classes.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Section>()?;
    m.add_class::<SoftArm>()?;
    m.add_class::<ArcChain>()?;
    Ok(())
}
