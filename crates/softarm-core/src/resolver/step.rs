//! One resolver step (eq. 7, 13, 20) with no heap allocation on the hot path.
//!
//! Three-row task Jacobians are kept as lists of 3-vector columns, so that every
//! product is a loop of fixed-size 3-vector operations and every pseudo-inverse goes
//! through a 3×3 normal matrix ([`super::pinv::normal_inverse3`]). The projectors
//! `I − J⁺J` are never formed: `(I − J⁺J) η = η − Jᵀ P (J η)`.

use nalgebra::DMatrix;

use super::joint_limits;
use super::orientation::{check_pose, orientation_error};
use super::pinv::{normal_inverse3, pinv_general};
use super::{Mode, Resolver, Step, Target};
use crate::chain::{check_q, forward_jacobian_into};
use crate::error::{check_finite, Result};
use crate::kinematics::Kinematics;
use crate::math::{Mat3, Mat4, Vec3};

/// Preallocated buffers for [`Resolver::step_into`], sized for one arm.
#[derive(Debug, Clone)]
pub struct Workspace {
    jac: DMatrix<f64>,
    a: Vec<Vec3>,
    b: Vec<Vec3>,
    t: Vec<Vec3>,
    x1: Vec<f64>,
    eta: Vec<f64>,
    dq: Vec<f64>,
    null: Vec<f64>,
    unclamped: Vec<f64>,
    free: Vec<bool>,
    fixed: Vec<f64>,
}

impl Workspace {
    /// Buffers for an arm of `n` coordinates.
    pub fn new(n: usize) -> Self {
        Workspace {
            jac: DMatrix::zeros(6, n),
            a: vec![Vec3::zeros(); n],
            b: vec![Vec3::zeros(); n],
            t: vec![Vec3::zeros(); n],
            x1: vec![0.0; n],
            eta: vec![0.0; n],
            dq: vec![0.0; n],
            null: vec![0.0; n],
            unclamped: vec![0.0; n],
            free: vec![true; n],
            fixed: vec![0.0; n],
        }
    }

    /// The command of the last step before clamping (`q + Δq`).
    pub fn unclamped(&self) -> &[f64] {
        &self.unclamped
    }

    /// The model Jacobian (6×n) at the last step's input state.
    pub fn jacobian(&self) -> &DMatrix<f64> {
        &self.jac
    }
}

/// Errors at a step's input state and whether its command was clamped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepInfo {
    /// True when the command `q + Δq` left `[lower, upper]` and was clamped.
    pub saturated: bool,
    /// ‖e_p‖ (m) at the input state (measured pose if given, else the model's).
    pub position_error: f64,
    /// ‖e_ζ‖ (rad), masked, at the input state; 0 for a point target.
    pub orientation_error: f64,
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

impl<K: Kinematics> Resolver<K> {
    /// One step, allocating its result. See [`Resolver::step_into`].
    ///
    /// # Errors
    /// As [`Resolver::step_into`].
    pub fn step(&self, q: &[f64], target: &Target, current: Option<&Mat4>) -> Result<Step> {
        let mut ws = self.workspace();
        let mut out = vec![0.0; q.len()];
        let info = self.step_into(&mut ws, q, target, current, &mut out)?;
        Ok(Step {
            q: out,
            unclamped: ws.unclamped.clone(),
            info,
        })
    }

    /// One step from state `q` towards `target`, writing the next command (clamped into
    /// the limits) into `out` and the unclamped one into `ws`. `current` is the measured
    /// end-effector pose (closed loop); `None` uses the model's forward kinematics. The
    /// Jacobian is always the model's, at `q`. A state outside the limits is accepted
    /// and pulled back. No heap allocation except in `Conventional` mode with a pose
    /// target (SVD of the 6-row Jacobian).
    ///
    /// # Errors
    /// [`crate::Error::Shape`] / [`crate::Error::NonFinite`] for `q`, `out` or a
    /// point target of the wrong size or with NaN; [`crate::Error::Pose`] for a
    /// malformed `target` or `current` pose; [`crate::Error::Shape`] for a point target
    /// in `Orientation` or `Hybrid` mode, which need a pose; `ws` of the wrong size.
    pub fn step_into(
        &self,
        ws: &mut Workspace,
        q: &[f64],
        target: &Target,
        current: Option<&Mat4>,
        out: &mut [f64],
    ) -> Result<StepInfo> {
        let n = self.arm.n_dofs();
        check_q(&self.arm, q)?;
        crate::error::check_len("out", out, n)?;
        if ws.dq.len() != n {
            return Err(crate::Error::shape(
                "workspace",
                format!("sized for {n} coordinates"),
                format!("{} coordinates", ws.dq.len()),
            ));
        }
        let (p_target, r_target) = match target {
            Target::Pose(m) => {
                check_pose("target", m)?;
                (
                    m.fixed_view::<3, 1>(0, 3).into_owned(),
                    Some(m.fixed_view::<3, 3>(0, 0).into_owned()),
                )
            }
            Target::Position(p) => {
                check_finite("target", p.as_slice())?;
                (*p, None)
            }
        };
        if r_target.is_none() && matches!(self.mode, Mode::Orientation | Mode::Hybrid) {
            return Err(crate::Error::shape(
                "target",
                format!("a 4×4 pose in {} mode", self.mode.name()),
                "a 3-vector",
            ));
        }
        if let Some(c) = current {
            check_pose("current", c)?;
        }

        // eq. (4)–(6): the model's pose and Jacobian at q.
        let model = forward_jacobian_into(&self.arm, q, &mut ws.jac);
        let (p_cur, r_cur) = match current {
            Some(c) => (
                c.fixed_view::<3, 1>(0, 3).into_owned(),
                c.fixed_view::<3, 3>(0, 0).into_owned(),
            ),
            None => (model.pos, model.rot),
        };
        let g = &self.gains;
        let mask = g.axis_mask;
        let e_p = p_target - p_cur;
        let e_w = match r_target {
            Some(rt) => orientation_error(&rt, &r_cur, mask),
            None => Vec3::zeros(),
        };
        let (ep_norm, ew_norm) = (e_p.norm(), e_w.norm());

        let (eps, lam) = (g.singular_threshold, g.damping);
        let lower = self.arm.lower();
        let upper = self.arm.upper();
        // Saturation in the null space (Flacco et al. 2012), simplified: a coordinate
        // whose command would leave the limits is fixed at the limit, its column removed
        // from every task, what it still delivers subtracted from the task errors, and
        // the step recomputed with the other coordinates. The conventional controller is
        // only clamped (it is unconstrained by definition).
        ws.free.iter_mut().for_each(|f| *f = true);
        ws.fixed.iter_mut().for_each(|v| *v = 0.0);
        let alpha = match self.mode {
            Mode::Conventional => g.conventional_alpha,
            Mode::Position => g.position_alpha,
            Mode::Orientation => g.orientation_alpha,
            Mode::Hybrid => g.hybrid_alpha,
        };
        let rounds = if self.mode == Mode::Conventional {
            1
        } else {
            n + 1
        };
        let mut saturated = false;
        for round in 0..rounds {
            let (mut e_p, mut e_w) = (e_p, e_w);
            if round > 0 {
                let (jp, jw) = self.fixed_motion(ws);
                e_p -= jp / alpha;
                for i in 0..3 {
                    if mask[i] {
                        e_w[i] -= jw[i] / alpha;
                    }
                }
            }
            for k in 0..n {
                let c = ws.jac.column(k);
                let f = if ws.free[k] { 1.0 } else { 0.0 };
                ws.a[k] = Vec3::new(c[0], c[1], c[2]) * f;
                ws.b[k] = Vec3::new(
                    if mask[0] { c[3] * f } else { 0.0 },
                    if mask[1] { c[4] * f } else { 0.0 },
                    if mask[2] { c[5] * f } else { 0.0 },
                );
            }
            ws.dq.iter_mut().for_each(|v| *v = 0.0);
            ws.null.iter_mut().for_each(|v| *v = 0.0);
            match self.mode {
                Mode::Position => {
                    // eq. (13), task 1 over task 3.
                    let gamma = g
                        .schedule
                        .weight(g.position_gamma, g.position_switch, ep_norm);
                    let pa = normal_inverse3(&gram(&ws.a), [true; 3], eps, lam);
                    add_tr_mul(&mut ws.dq, g.position_alpha, &ws.a, &(pa * e_p));
                    if gamma != 0.0 {
                        self.add_projected_gradient(ws, q, g.position_alpha * gamma, &pa, None);
                    }
                }
                Mode::Orientation => {
                    // eq. (13), task 2 over task 3, with the masked angular Jacobian.
                    let gamma =
                        g.schedule
                            .weight(g.orientation_gamma, g.orientation_switch, ew_norm);
                    let pb = normal_inverse3(&gram(&ws.b), mask, eps, lam);
                    add_tr_mul(&mut ws.dq, g.orientation_alpha, &ws.b, &(pb * e_w));
                    if gamma != 0.0 {
                        std::mem::swap(&mut ws.a, &mut ws.b);
                        self.add_projected_gradient(ws, q, g.orientation_alpha * gamma, &pb, None);
                        std::mem::swap(&mut ws.a, &mut ws.b);
                    }
                }
                Mode::Hybrid => {
                    // eq. (20).
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
                    let pt = normal_inverse3(&gram(&ws.t), mask, eps, lam);
                    // J̃_v⁺ (e_ζ − J_ω J_v⁺ e_p)
                    let r = e_w - mul(&ws.b, &ws.x1);
                    let yt = pt * r;
                    let a4 = g.hybrid_alpha;
                    for ((d, x), t) in ws.dq.iter_mut().zip(&ws.x1).zip(&ws.t) {
                        *d = a4 * (g.hybrid_position * x + g.hybrid_orientation * t.dot(&yt));
                    }
                    let gamma = g.schedule.weight(g.hybrid_gamma, g.hybrid_switch, ep_norm);
                    if gamma != 0.0 {
                        self.add_projected_gradient(ws, q, a4 * gamma, &pa, Some(&pt));
                    }
                }
                Mode::Conventional => match r_target {
                    None => {
                        // eq. (7) with the position Jacobian.
                        let pa = normal_inverse3(&gram(&ws.a), [true; 3], eps, lam);
                        add_tr_mul(&mut ws.dq, g.conventional_alpha, &ws.a, &(pa * e_p));
                    }
                    Some(_) => {
                        // eq. (7) with the full Jacobian (orientation rows masked).
                        let rows: Vec<usize> = (0..3)
                            .chain((0..3).filter(|&i| mask[i]).map(|i| i + 3))
                            .collect();
                        let j = DMatrix::from_fn(rows.len(), n, |r, c| ws.jac[(rows[r], c)]);
                        let e = nalgebra::DVector::from_iterator(
                            rows.len(),
                            rows.iter()
                                .map(|&r| if r < 3 { e_p[r] } else { e_w[r - 3] }),
                        );
                        let dq = pinv_general(&j, eps, lam) * e * g.conventional_alpha;
                        ws.dq.copy_from_slice(dq.as_slice());
                    }
                },
            }

            // Step-length caps: the task part at `max_step`, the joint-limit part at half of
            // it, so that ∇H, large next to a limit, can never starve the tasks.
            let cap = |v: &[f64], max: f64| {
                let len = v.iter().map(|x| x * x).sum::<f64>().sqrt();
                if len > max {
                    max / len
                } else {
                    1.0
                }
            };
            let s_task = cap(&ws.dq, g.max_step);
            let s_null = cap(&ws.null, 0.5 * g.max_step);
            for (d, v) in ws.dq.iter_mut().zip(&ws.null) {
                *d = s_task * *d + s_null * v;
            }
            let mut newly_fixed = false;
            for k in 0..n {
                if !ws.free[k] {
                    ws.dq[k] = ws.fixed[k];
                    continue;
                }
                let raw = q[k] + ws.dq[k];
                if round == 0 {
                    ws.unclamped[k] = raw;
                }
                let c = raw.clamp(lower[k], upper[k]);
                if c != raw {
                    saturated = true;
                    if round + 1 < rounds {
                        ws.free[k] = false;
                        ws.fixed[k] = c - q[k];
                        newly_fixed = true;
                    }
                }
            }
            if round == 0 && self.mode == Mode::Conventional {
                ws.unclamped
                    .iter_mut()
                    .zip(q)
                    .zip(&ws.dq)
                    .for_each(|((u, x), d)| *u = x + d);
            }
            if !newly_fixed {
                break;
            }
        }
        for k in 0..n {
            out[k] = (q[k] + ws.dq[k]).clamp(lower[k], upper[k]);
        }
        Ok(StepInfo {
            saturated,
            position_error: ep_norm,
            orientation_error: ew_norm,
        })
    }

    /// Position and angular motion (base frame) of the fixed coordinates' increments.
    fn fixed_motion(&self, ws: &Workspace) -> (Vec3, Vec3) {
        let mut v = Vec3::zeros();
        let mut w = Vec3::zeros();
        for (k, (&d, &free)) in ws.fixed.iter().zip(&ws.free).enumerate() {
            if !free {
                let c = ws.jac.column(k);
                v += Vec3::new(c[0], c[1], c[2]) * d;
                w += Vec3::new(c[3], c[4], c[5]) * d;
            }
        }
        (v, w)
    }

    /// null = s · (I − A⁺A − T⁺T) ∇H with `A⁺ = Aᵀ pa` (A = `ws.a`) and, if given,
    /// `T⁺ = Tᵀ pt` (T = `ws.t`): the null-space term of eq. (13) / (20).
    fn add_projected_gradient(
        &self,
        ws: &mut Workspace,
        q: &[f64],
        s: f64,
        pa: &Mat3,
        pt: Option<&Mat3>,
    ) {
        joint_limits::gradient_into(
            q,
            self.arm.lower(),
            self.arm.upper(),
            self.gains.limit_margin,
            &mut ws.eta,
        );
        for ((e, d), free) in ws.eta.iter_mut().zip(ws.null.iter_mut()).zip(&ws.free) {
            if !free {
                *e = 0.0;
            }
            *d = s * *e;
        }
        let u = pa * mul(&ws.a, &ws.eta);
        add_tr_mul(&mut ws.null, -s, &ws.a, &u);
        if let Some(pt) = pt {
            let v = pt * mul(&ws.t, &ws.eta);
            add_tr_mul(&mut ws.null, -s, &ws.t, &v);
        }
    }
}
