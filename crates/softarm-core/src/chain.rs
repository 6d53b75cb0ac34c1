//! The kinematics engine shared by every serial chain of constant-curvature sections.
//!
//! A model (see [`SectionModel`]) says, for each section `i`, how its own coordinates
//! `q_i` map to arc parameters (length, bending vector) and which rigid transform follows
//! the arc. The engine turns that into forward kinematics (redundancy paper eq. 3 /
//! planning paper eq. 4), the end-effector Jacobian (eq. 4–6) and the Jacobian of any
//! backbone point (planning paper eq. 5–6), all analytic.

use nalgebra::{DMatrix, Matrix3xX};

use crate::arc::ArcParams;
use crate::error::{
    check_bounded, check_count, check_len, check_range, Error, Result, MAX_COORDINATE, MAX_SAMPLES,
};
use crate::math::{Frame, Mat3, Mat4, Vec3};

/// What one section contributes, at one configuration.
#[derive(Debug, Clone, Copy)]
pub struct SectionState {
    /// The arc.
    pub arc: ArcParams,
    /// ∂(L, ux, uy)/∂q_i: rows are arc parameters, columns the section's coordinates.
    pub d_arc: Mat3,
    /// Translation along the tip's z axis after the arc (plate or gripper offset `b_i`).
    pub offset: f64,
    /// (cos, sin) of the rotation about the tip's z axis after the arc (`β_i`, or `φ_i`
    /// for an arc chain); kept as a pair so that constant twists cost no trigonometry.
    pub twist: (f64, f64),
    /// ∂twist/∂q_i.
    pub d_twist: Vec3,
}

impl SectionState {
    /// The frame after this section, given the frame `f` at its base.
    #[inline]
    fn advance(&self, f: &Frame) -> Frame {
        f.compose(&self.tip_then_tail(&self.arc.frame(1.0)))
    }

    /// `tip · tail` with the z rotation applied by mixing two columns instead of a full
    /// 3×3 product.
    #[inline]
    fn tip_then_tail(&self, tip: &Frame) -> Frame {
        let (c, s) = self.twist;
        let (r0, r1, r2) = (tip.rot.column(0), tip.rot.column(1), tip.rot.column(2));
        Frame {
            rot: Mat3::from_columns(&[r0 * c + r1 * s, r1 * c - r0 * s, r2.into_owned()]),
            pos: tip.pos + r2 * self.offset,
        }
    }
}

/// A serial chain of constant-curvature sections with three coordinates each.
pub trait SectionModel {
    /// Number of sections.
    fn n_sections(&self) -> usize;

    /// The state of section `i` given its three coordinates `qi`.
    fn section_state(&self, i: usize, qi: &[f64]) -> SectionState;

    /// Number of coordinates (3 per section).
    fn n_dofs(&self) -> usize {
        3 * self.n_sections()
    }
}

/// Checks a configuration vector: length, finiteness, and magnitude at most
/// [`MAX_COORDINATE`] (beyond it products in the kinematics could overflow).
#[inline]
pub fn check_q<M: SectionModel + ?Sized>(model: &M, q: &[f64]) -> Result<()> {
    check_len("q", q, model.n_dofs())?;
    check_bounded("q", q, MAX_COORDINATE)
}

/// [`check_q`], and that every section is a real arc: a positive arc length. Distance
/// queries need it (the closed forms of [`crate::distance`] take `L > 0`; a negative length
/// mirrors the arc and its distances stop being the backbone's).
pub fn check_q_arcs<M: SectionModel + ?Sized>(model: &M, q: &[f64]) -> Result<()> {
    check_q(model, q)?;
    for i in 0..model.n_sections() {
        let length = state(model, q, i).arc.length;
        if length.is_nan() || length <= 0.0 {
            return Err(Error::parameter(
                &format!("q[{}..{}]", 3 * i, 3 * i + 3),
                length,
                format!("gives section {i} a non-positive arc length"),
            ));
        }
    }
    Ok(())
}

/// Checks a (section, s) pair for backbone-point queries.
pub fn check_point_args<M: SectionModel + ?Sized>(model: &M, section: usize, s: f64) -> Result<()> {
    let n = model.n_sections();
    if section >= n {
        return Err(Error::OutOfRange {
            arg: "section".into(),
            value: section as f64,
            min: 0.0,
            max: (n as f64) - 1.0,
        });
    }
    check_range("s", s, 0.0, 1.0)
}

#[inline(always)]
fn state<M: SectionModel + ?Sized>(model: &M, q: &[f64], i: usize) -> SectionState {
    model.section_state(i, &q[3 * i..3 * i + 3])
}

/// Base frame of every section followed by the end-effector frame.
/// `q` must already be checked.
pub fn frames_unchecked<M: SectionModel + ?Sized>(model: &M, q: &[f64]) -> Vec<Frame> {
    let n = model.n_sections();
    let mut out = Vec::with_capacity(n + 1);
    let mut f = Frame::identity();
    out.push(f);
    for i in 0..n {
        let st = state(model, q, i);
        f = st.advance(&f);
        out.push(f);
    }
    out
}

/// End-effector frame (eq. 3). `q` must already be checked.
#[inline]
pub fn forward_unchecked<M: SectionModel + ?Sized>(model: &M, q: &[f64]) -> Frame {
    let mut f = Frame::identity();
    for i in 0..model.n_sections() {
        let st = state(model, q, i);
        f = st.advance(&f);
    }
    f
}

/// Walks the first `upto` sections, writing for each of their coordinates the twist it
/// gives the rest of the chain into `jac` (6×n): rows 0–2 hold `v_tip − w × p_tip` (the
/// velocity of the material point at the base origin), rows 3–5 the angular velocity `w`.
/// Returns the frame after section `upto − 1` (the base of section `upto`, or the end
/// effector when `upto` is the number of sections).
///
/// Each coordinate moves its section's tip frame with the twist (v_tip, w): ∂p/∂q from
/// the arc, and `w = (∂R/∂q Rᵀ)^∨` (redundancy paper eq. 5). Everything after the tip is
/// rigid, so a point `x` further along moves with `v_tip + w × (x − p_tip)`; storing the
/// origin form lets the caller add `w × x` once `x` is known.
fn sweep<M: SectionModel + ?Sized>(
    model: &M,
    q: &[f64],
    upto: usize,
    jac: &mut DMatrix<f64>,
) -> Frame {
    // Column-major 6×n: column j is the slice [6j, 6j + 6).
    let mut cols = jac.as_mut_slice().chunks_exact_mut(6);
    if upto == 0 {
        return Frame::identity();
    }
    // The first section's base is the chain's base: its twists need none of the
    // rotations into a base frame (a third of the sweep's products for three sections).
    let mut f = section_twists(&ChainBase, &state(model, q, 0), &mut cols);
    for i in 1..upto {
        f = section_twists(&f, &state(model, q, i), &mut cols);
    }
    f
}

/// The frame a section's twists are expressed from: the chain's base (the identity,
/// [`ChainBase`]) or the frame after the sections before it.
trait SectionBase {
    fn rotate(&self, v: Vec3) -> Vec3;
    fn rotate_all(&self, m: &Mat3) -> Mat3;
    fn place(&self, p: &Vec3) -> Vec3;
    fn then(&self, next: Frame) -> Frame;
}

/// The identity frame at the chain's base.
struct ChainBase;

impl SectionBase for ChainBase {
    #[inline(always)]
    fn rotate(&self, v: Vec3) -> Vec3 {
        v
    }
    #[inline(always)]
    fn rotate_all(&self, m: &Mat3) -> Mat3 {
        *m
    }
    #[inline(always)]
    fn place(&self, p: &Vec3) -> Vec3 {
        *p
    }
    #[inline(always)]
    fn then(&self, next: Frame) -> Frame {
        next
    }
}

impl SectionBase for Frame {
    #[inline(always)]
    fn rotate(&self, v: Vec3) -> Vec3 {
        self.rot * v
    }
    #[inline(always)]
    fn rotate_all(&self, m: &Mat3) -> Mat3 {
        self.rot * m
    }
    #[inline(always)]
    fn place(&self, p: &Vec3) -> Vec3 {
        self.pos + self.rot * p
    }
    #[inline(always)]
    fn then(&self, next: Frame) -> Frame {
        self.compose(&next)
    }
}

/// One section's three twist columns (see [`sweep`]) written into the next three of
/// `cols`; returns the frame after the section.
#[inline(always)]
fn section_twists<B: SectionBase>(
    base: &B,
    st: &SectionState,
    cols: &mut std::slice::ChunksExactMut<'_, f64>,
) -> Frame {
    let (tip, d_pos, d_rot) = st.arc.frame_with_derivatives(1.0);
    let next = base.then(st.tip_then_tail(&tip));
    let p_tip = base.place(&tip.pos);
    // The tip's derivatives along (L, ux, uy), rotated into the base frame once;
    // ∂ω/∂L = 0, so the angular part has two columns.
    let dp = base.rotate_all(&d_pos);
    let w_ux = base.rotate(d_rot.column(1).into_owned());
    let w_uy = base.rotate(d_rot.column(2).into_owned());
    // The velocity of the point at the base origin, v_tip + p_tip × w, per parameter.
    let v = Mat3::from_columns(&[
        dp.column(0).into_owned(),
        dp.column(1) + p_tip.cross(&w_ux),
        dp.column(2) + p_tip.cross(&w_uy),
    ]);
    // The tip's z axis: the twist after the arc turns about it.
    let z = next.rot.column(2);
    for (k, col) in cols.by_ref().take(3).enumerate() {
        let a = st.d_arc.column(k);
        let (mut vk, mut wk) = (v * a, w_ux * a[1] + w_uy * a[2]);
        // A model's twist either varies with a coordinate or not; the test is decided
        // at compile time for each model, and a constant twist costs nothing.
        if st.d_twist[k] != 0.0 {
            wk += z * st.d_twist[k];
            vk += p_tip.cross(&z) * st.d_twist[k];
        }
        col.copy_from_slice(&[vk.x, vk.y, vk.z, wk.x, wk.y, wk.z]);
    }
    next
}

/// Forward kinematics and the 6×n Jacobian (rows vx, vy, vz, wx, wy, wz in the base
/// frame; eq. 4–6) written into `jac`, in one pass. `q` must already be checked and
/// `jac` be 6×n.
pub fn forward_jacobian_into<M: SectionModel + ?Sized>(
    model: &M,
    q: &[f64],
    jac: &mut DMatrix<f64>,
) -> Frame {
    let f = sweep(model, q, model.n_sections(), jac);
    // Move each twist's reference point from the base origin to the end effector.
    for col in jac.as_mut_slice().chunks_exact_mut(6) {
        let dv = Vec3::new(col[3], col[4], col[5]).cross(&f.pos);
        col[0] += dv.x;
        col[1] += dv.y;
        col[2] += dv.z;
    }
    f
}

/// The backbone point at fraction `s` of `section` and its 3×n Jacobian (planning paper
/// eq. 5–6). Columns of later sections are zero. Arguments must already be checked.
pub fn point_unchecked<M: SectionModel + ?Sized>(
    model: &M,
    q: &[f64],
    section: usize,
    s: f64,
) -> (Vec3, Matrix3xX<f64>) {
    let n = model.n_dofs();
    let mut twists = DMatrix::zeros(6, n);
    let f = sweep(model, q, section, &mut twists);
    let st = state(model, q, section);
    let pt = st.arc.point_with_derivatives(s);
    let point = f.pos + f.rot * pt.pos;
    let mut jac = Matrix3xX::zeros(n);
    for col in 0..3 * section {
        let v = twists.fixed_view::<3, 1>(0, col);
        let w = twists.fixed_view::<3, 1>(3, col);
        jac.set_column(col, &(v + w.cross(&point)));
    }
    let own = f.rot * pt.d_params * st.d_arc;
    jac.fixed_view_mut::<3, 3>(0, 3 * section).copy_from(&own);
    (point, jac)
}

/// Backbone points: `samples` evenly spaced fractions (0 and 1 included) of each section.
pub fn backbone_unchecked<M: SectionModel + ?Sized>(
    model: &M,
    q: &[f64],
    samples: usize,
) -> Vec<Vec3> {
    let n = model.n_sections();
    let mut out = Vec::with_capacity(n * samples);
    let mut f = Frame::identity();
    let denom = (samples.max(2) - 1) as f64;
    for i in 0..n {
        let st = state(model, q, i);
        for j in 0..samples {
            let s = if samples == 1 { 1.0 } else { j as f64 / denom };
            out.push(f.pos + f.rot * st.arc.point(s));
        }
        f = st.advance(&f);
    }
    out
}

/// The arc of `section` expressed in the base frame: its base frame and parameters.
/// Used by distance queries, which need the arc as a geometric object.
pub fn section_arc_unchecked<M: SectionModel + ?Sized>(
    model: &M,
    q: &[f64],
    section: usize,
) -> (Frame, ArcParams) {
    let mut f = Frame::identity();
    for i in 0..section {
        let st = state(model, q, i);
        f = st.advance(&f);
    }
    (f, state(model, q, section).arc)
}

/// Allocating, checked forward kinematics as a 4×4 matrix.
pub fn forward<M: SectionModel + ?Sized>(model: &M, q: &[f64]) -> Result<Mat4> {
    check_q(model, q)?;
    Ok(forward_unchecked(model, q).to_matrix())
}

/// Allocating, checked 6×n Jacobian.
pub fn jacobian<M: SectionModel + ?Sized>(model: &M, q: &[f64]) -> Result<DMatrix<f64>> {
    check_q(model, q)?;
    let mut jac = DMatrix::zeros(6, model.n_dofs());
    forward_jacobian_into(model, q, &mut jac);
    Ok(jac)
}

/// Checked forward kinematics and Jacobian together.
pub fn forward_jacobian<M: SectionModel + ?Sized>(
    model: &M,
    q: &[f64],
) -> Result<(Mat4, DMatrix<f64>)> {
    check_q(model, q)?;
    let mut jac = DMatrix::zeros(6, model.n_dofs());
    let f = forward_jacobian_into(model, q, &mut jac);
    Ok((f.to_matrix(), jac))
}

/// Checked backbone point and its Jacobian.
pub fn point<M: SectionModel + ?Sized>(
    model: &M,
    q: &[f64],
    section: usize,
    s: f64,
) -> Result<(Vec3, Matrix3xX<f64>)> {
    check_q(model, q)?;
    check_point_args(model, section, s)?;
    Ok(point_unchecked(model, q, section, s))
}

/// Checked frames as 4×4 matrices.
pub fn frames<M: SectionModel + ?Sized>(model: &M, q: &[f64]) -> Result<Vec<Mat4>> {
    check_q(model, q)?;
    Ok(frames_unchecked(model, q)
        .iter()
        .map(Frame::to_matrix)
        .collect())
}

/// Checked backbone sampling.
pub fn backbone<M: SectionModel + ?Sized>(
    model: &M,
    q: &[f64],
    samples: usize,
) -> Result<Vec<Vec3>> {
    check_q(model, q)?;
    check_count("samples", samples, 2, MAX_SAMPLES)?;
    Ok(backbone_unchecked(model, q, samples))
}
