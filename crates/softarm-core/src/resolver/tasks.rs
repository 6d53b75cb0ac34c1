//! The tasks of one resolver step (redundancy paper eq. 7, 13, 17, 20) and the null-space
//! terms below them (eq. 14, planning paper eq. 9).
//!
//! Three-row task Jacobians are kept as lists of 3-vector columns, so that every
//! product is a loop of fixed-size 3-vector operations and every pseudo-inverse goes
//! through a 3×3 normal matrix ([`super::pinv::normal_inverse3`]). The projectors
//! `I − J⁺J` are never formed: `(I − J⁺J) η = η − Jᵀ P (J η)`.

use nalgebra::DMatrix;

use super::avoid;
use super::joint_limits;
use super::pinv::{normal_inverse3, pinv_general};
use super::step::Workspace;
use super::Resolver;
use crate::kinematics::Kinematics;
use crate::math::{Mat3, Vec3};

/// (singular threshold, damping) of the damped pseudo-inverses ([`normal_inverse3`]).
pub(super) type Dls = (f64, f64);

/// What one round's tasks are scaled by: the task gain α and the damped least squares'
/// singular threshold ε and largest damping λ (the model's or the closed loop's,
/// [`crate::resolver::Gains::dls`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Scale {
    pub alpha: f64,
    pub eps: f64,
    pub lam: f64,
}

/// Σ_k c_k c_kᵀ.
#[inline]
fn gram(c: &[Vec3]) -> Mat3 {
    c.iter().fold(Mat3::zeros(), |g, v| g + v * v.transpose())
}

/// Σ_k c_k x_k  (the 3-row matrix times a vector).
#[inline]
fn mul(c: &[Vec3], x: &[f64]) -> Vec3 {
    c.iter()
        .zip(x)
        .fold(Vec3::zeros(), |s, (v, &xk)| s + v * xk)
}

/// out += s · (Cᵀ y), i.e. out_k += s · c_k · y.
#[inline]
fn add_tr_mul(out: &mut [f64], s: f64, c: &[Vec3], y: &Vec3) {
    for (o, v) in out.iter_mut().zip(c) {
        *o += s * v.dot(y);
    }
}

/// `v ← v − A⁺(A v) − T⁺(T v)` with `A⁺ = Aᵀ pa` and, if given, `T⁺ = Tᵀ pt`: the
/// projection onto the null space of the tasks above (eq. 9, 13, 20).
fn project(v: &mut [f64], a: &[Vec3], pa: &Mat3, t: Option<(&[Vec3], &Mat3)>) {
    let u = pa * mul(a, v);
    let w = t.map(|(t, pt)| pt * mul(t, v));
    add_tr_mul(v, -1.0, a, &u);
    if let (Some((t, _)), Some(w)) = (t, w) {
        add_tr_mul(v, -1.0, t, &w);
    }
}

impl<K: Kinematics> Resolver<K> {
    /// The task Jacobians' columns of the free coordinates (the fixed ones zeroed):
    /// `ws.a` = J_v, `ws.b` = the masked J_ω.
    pub(super) fn load_task_columns(&self, ws: &mut Workspace) {
        let mask = self.gains.axis_mask;
        for k in 0..ws.a.len() {
            let c = ws.jac.column(k);
            let f = if ws.free[k] { 1.0 } else { 0.0 };
            ws.a[k] = Vec3::new(c[0], c[1], c[2]) * f;
            ws.b[k] = Vec3::new(
                if mask[0] { c[3] * f } else { 0.0 },
                if mask[1] { c[4] * f } else { 0.0 },
                if mask[2] { c[5] * f } else { 0.0 },
            );
        }
    }

    /// eq. (13), task 1 (position) over task 3 (joint limits) and the obstacles.
    pub(super) fn position_task(
        &self,
        ws: &mut Workspace,
        q: &[f64],
        e_p: &Vec3,
        p_norm: f64,
        scale: Scale,
    ) {
        let Scale { alpha, eps, lam } = scale;
        let g = &self.gains;
        let gamma = g
            .schedule
            .weight(g.position_gamma, g.position_switch, p_norm);
        let pa = normal_inverse3(&gram(&ws.a), [true; 3], eps, lam);
        add_tr_mul(&mut ws.dq, alpha, &ws.a, &(pa * e_p));
        self.add_null_terms(ws, q, alpha * gamma, (&pa, [true; 3]), None, (eps, lam));
    }

    /// eq. (13), task 2 (orientation, masked angular Jacobian) over task 3 and the
    /// obstacles.
    pub(super) fn orientation_task(
        &self,
        ws: &mut Workspace,
        q: &[f64],
        e_w: &Vec3,
        w_norm: f64,
        scale: Scale,
    ) {
        let Scale { alpha, eps, lam } = scale;
        let g = &self.gains;
        let gamma = g
            .schedule
            .weight(g.orientation_gamma, g.orientation_switch, w_norm);
        let pb = normal_inverse3(&gram(&ws.b), g.axis_mask, eps, lam);
        add_tr_mul(&mut ws.dq, alpha, &ws.b, &(pb * e_w));
        // The null-space terms project with `ws.a`: the orientation task's columns.
        std::mem::swap(&mut ws.a, &mut ws.b);
        self.add_null_terms(ws, q, alpha * gamma, (&pb, g.axis_mask), None, (eps, lam));
        std::mem::swap(&mut ws.a, &mut ws.b);
    }

    /// eq. (20): position first, orientation in its null space (eq. 17), then the joint
    /// limits and the obstacles in the null space of both.
    pub(super) fn hybrid_task(
        &self,
        ws: &mut Workspace,
        q: &[f64],
        e_p: &Vec3,
        e_w: &Vec3,
        p_norm: f64,
        scale: Scale,
    ) {
        let Scale { alpha, eps, lam } = scale;
        let g = &self.gains;
        let pa = normal_inverse3(&gram(&ws.a), [true; 3], eps, lam);
        // x1 = J_v⁺ e_p
        let ya = pa * e_p;
        for (x, v) in ws.x1.iter_mut().zip(&ws.a) {
            *x = v.dot(&ya);
        }
        // eq. (17): J̃_v = J_ω (I − J_v⁺ J_v) = J_ω − (J_ω J_vᵀ P_a) J_v.
        let m =
            ws.b.iter()
                .zip(&ws.a)
                .fold(Mat3::zeros(), |s, (b, a)| s + b * a.transpose())
                * pa;
        for ((t, b), a) in ws.t.iter_mut().zip(&ws.b).zip(&ws.a) {
            *t = b - m * a;
        }
        let pt = normal_inverse3(&gram(&ws.t), g.axis_mask, eps, lam);
        // J̃_v⁺ (e_ζ − J_ω J_v⁺ e_p)
        let r = e_w - mul(&ws.b, &ws.x1);
        let yt = pt * r;
        for ((d, x), t) in ws.dq.iter_mut().zip(&ws.x1).zip(&ws.t) {
            *d = alpha * (g.hybrid_position * x + g.hybrid_orientation * t.dot(&yt));
        }
        let gamma = g.schedule.weight(g.hybrid_gamma, g.hybrid_switch, p_norm);
        self.add_null_terms(
            ws,
            q,
            alpha * gamma,
            (&pa, [true; 3]),
            Some(&pt),
            (eps, lam),
        );
    }

    /// eq. (7): the conventional resolved rate, with the position Jacobian for a point
    /// target and the full one (orientation rows masked) for a pose. The latter goes
    /// through the SVD of the 6-row Jacobian: the one step that allocates.
    pub(super) fn conventional_task(
        &self,
        ws: &mut Workspace,
        e_p: &Vec3,
        e_w: &Vec3,
        pose_target: bool,
        scale: Scale,
    ) {
        let Scale { alpha, eps, lam } = scale;
        let g = &self.gains;
        if !pose_target {
            let pa = normal_inverse3(&gram(&ws.a), [true; 3], eps, lam);
            add_tr_mul(&mut ws.dq, alpha, &ws.a, &(pa * e_p));
            return;
        }
        let mask = g.axis_mask;
        let n = ws.dq.len();
        let rows: Vec<usize> = (0..3)
            .chain((0..3).filter(|&i| mask[i]).map(|i| i + 3))
            .collect();
        let j = DMatrix::from_fn(rows.len(), n, |r, c| ws.jac[(rows[r], c)]);
        let e = nalgebra::DVector::from_iterator(
            rows.len(),
            rows.iter()
                .map(|&r| if r < 3 { e_p[r] } else { e_w[r - 3] }),
        );
        let dq = pinv_general(&j, eps, lam) * e * alpha;
        ws.dq.copy_from_slice(dq.as_slice());
    }

    /// The projector of the null-space terms when they may move fewer coordinates than the
    /// tasks (`ws.null_free`, saturation rounds): the tasks' columns of those coordinates
    /// only, into `ws.na` (and `ws.nb`, `ws.nt` for the second task of eq. 17), with their
    /// normal inverses. A vector that is zero on the other coordinates stays zero there
    /// through it, and lies in the null space of the tasks' whole Jacobians.
    fn reduced_projector(
        &self,
        ws: &mut Workspace,
        rows: [bool; 3],
        second: bool,
        (eps, lam): Dls,
    ) -> (Mat3, Option<Mat3>) {
        for k in 0..ws.na.len() {
            let f = if ws.null_free[k] { 1.0 } else { 0.0 };
            ws.na[k] = ws.a[k] * f;
            ws.nb[k] = ws.b[k] * f;
        }
        let pa = normal_inverse3(&gram(&ws.na), rows, eps, lam);
        if !second {
            return (pa, None);
        }
        let m = ws
            .nb
            .iter()
            .zip(&ws.na)
            .fold(Mat3::zeros(), |s, (b, a)| s + b * a.transpose())
            * pa;
        for ((t, b), a) in ws.nt.iter_mut().zip(&ws.nb).zip(&ws.na) {
            *t = b - m * a;
        }
        let pt = normal_inverse3(&gram(&ws.nt), self.gains.axis_mask, eps, lam);
        (pa, Some(pt))
    }

    /// The null-space terms of eq. (13) / (20), each projected by
    /// `I − A⁺A − T⁺T` (`A⁺ = Aᵀ pa` with A = `ws.a`, whose active rows are `pa`'s second
    /// element; `T⁺ = Tᵀ pt` with T = `ws.t`, if given): `ws.null = s (I − A⁺A − T⁺T) ∇H`
    /// (skipped when the schedule gives `s = 0`) and `ws.avoid = Σ_j c_j f_j / ‖c_j‖²`
    /// with `c_j = (I − A⁺A − T⁺T) ∇g_j` (eq. 9 as a one-row task on each gap, see
    /// [`avoid`]; never scheduled). Both move only the coordinates of `ws.null_free`: where
    /// those are fewer than the tasks' free ones, the projector is the tasks' on them
    /// ([`Self::reduced_projector`]).
    fn add_null_terms(
        &self,
        ws: &mut Workspace,
        q: &[f64],
        s: f64,
        (pa, rows): (&Mat3, [bool; 3]),
        pt: Option<&Mat3>,
        dls: Dls,
    ) {
        if s == 0.0 && ws.repulsions.is_empty() {
            return;
        }
        let reduced = ws.null_free != ws.free;
        let (pa, pt) = if reduced {
            self.reduced_projector(ws, rows, pt.is_some(), dls)
        } else {
            (*pa, pt.copied())
        };
        let (a, t) = if reduced {
            (&ws.na, &ws.nt)
        } else {
            (&ws.a, &ws.t)
        };
        if s != 0.0 {
            joint_limits::gradient_into(
                q,
                self.arm.lower(),
                self.arm.upper(),
                self.gains.limit_margin,
                &mut ws.eta,
            );
            for ((e, d), free) in ws.eta.iter().zip(ws.null.iter_mut()).zip(&ws.null_free) {
                *d = if *free { s * e } else { 0.0 };
            }
            project(&mut ws.null, a, &pa, pt.as_ref().map(|p| (&t[..], p)));
        }
        // Planning paper eq. (9) as a one-row task on each gap, solved in the null space
        // of the tasks (eq. 20): c = P ∇g, Δq = c f / ‖c‖². Projecting the gap's row
        // first, not the three-row push J_s⁺ F after, makes each obstacle's step an
        // ascent of its own gap that vanishes where the gap is stationary (avoid.rs).
        // The nearly tied pieces of one obstacle are ONE task of several rows
        // (avoid::add_rows_step), each row weighted by how nearly its piece ties.
        let n = ws.avoid.len();
        let mut start = 0;
        while start < ws.repulsions.len() {
            let ob = ws.repulsions[start].obstacle;
            let m = ws.repulsions[start..]
                .iter()
                .take_while(|r| r.obstacle == ob)
                .count();
            ws.rows.resize(m * n, 0.0);
            ws.asks.clear();
            for (k, r) in ws.repulsions[start..start + m].iter().enumerate() {
                let row = &mut ws.rows[k * n..(k + 1) * n];
                avoid::gap_row_into(r, &ws.null_free, row);
                project(row, a, &pa, pt.as_ref().map(|p| (&t[..], p)));
                let s = r.weight.sqrt();
                row.iter_mut().for_each(|x| *x *= s);
                ws.asks.push(s * r.ask);
            }
            avoid::add_rows_step(&ws.rows, &ws.asks, dls.0, &mut ws.avoid);
            start += m;
        }
    }
}
