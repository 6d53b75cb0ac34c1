//! One resolver step (eq. 7, 13, 20) with no heap allocation on the hot path.
//!
//! Three-row task Jacobians are kept as lists of 3-vector columns, so that every
//! product is a loop of fixed-size 3-vector operations and every pseudo-inverse goes
//! through a 3×3 normal matrix ([`super::pinv::normal_inverse3`]). The projectors
//! `I − J⁺J` are never formed: `(I − J⁺J) η = η − Jᵀ P (J η)`.
//!
//! Below the tasks of each mode (position, orientation, both) lie two null-space terms,
//! each projected onto the null space of every task above it and capped separately: the
//! joint-limit gradient of eq. (14), scheduled by the task error, and the repulsion from
//! obstacles (planning paper eq. 9, see [`super::avoid`]), never scheduled off.

use nalgebra::DMatrix;

use super::avoid::{self, Repulsion};
use super::joint_limits;
use super::orientation::{check_pose, orientation_error};
use super::pinv::{normal_inverse3, pinv_general};
use super::{Mode, Resolver, Step, Target};
use crate::chain::{check_q, forward_jacobian_into};
use crate::distance::bodies::Piece;
use crate::distance::Obstacle;
use crate::error::{check_finite, check_len, Error, Result};
use crate::kinematics::Kinematics;
use crate::math::{Mat3, Mat4, Vec3};

/// Largest |coordinate| (m) of a target or measured position: far beyond any arm, small
/// enough that squared errors stay finite.
pub const MAX_POSITION: f64 = 1e3;

/// What a step reads besides the state and the target.
#[derive(Debug, Clone, Copy, Default)]
pub struct StepInput<'a> {
    /// The measured end-effector pose (closed loop); `None` uses the model at `q`.
    pub current: Option<&'a Mat4>,
    /// The elongations the plant has reached (a [`super::LagModel`]'s prediction): the
    /// measured error is corrected by the motion still in flight, `J (q − plant_q)`, and
    /// the closed-loop α is not capped by the lag bound. Ignored without `current`.
    pub plant_q: Option<&'a [f64]>,
    /// Obstacles that repel the arm's body (eq. 9), in the null space of the tasks.
    pub obstacles: &'a [Obstacle],
}

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
    avoid: Vec<f64>,
    pieces: Vec<Piece>,
    repulsions: Vec<Repulsion>,
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
            avoid: vec![0.0; n],
            pieces: Vec::new(),
            repulsions: Vec::new(),
        }
    }

    /// The obstacle repulsions of the last step: (clearance m, closest arm point).
    pub fn repulsions(&self) -> impl Iterator<Item = (f64, Vec3)> + '_ {
        self.repulsions.iter().map(|r| (r.gap, r.arm_point))
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
    /// Smallest surface gap (m) of the model arm at `q` to the obstacles within the
    /// influence distance; `+∞` when none is that close (or there are none).
    pub clearance: f64,
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

/// Fails unless every coordinate of a position lies within ±[`MAX_POSITION`].
fn check_position(arg: &str, p: &Vec3) -> Result<()> {
    for v in p.iter() {
        if v.abs() > MAX_POSITION {
            return Err(Error::OutOfRange {
                arg: arg.to_owned(),
                value: *v,
                min: -MAX_POSITION,
                max: MAX_POSITION,
            });
        }
    }
    Ok(())
}

/// How many actuator ranges beyond its limits a state may lie: generous, because the
/// unconstrained controller of eq. (7) integrates unclamped commands on purpose.
pub const MAX_RANGES_OUTSIDE: f64 = 1e3;

/// Fails unless every coordinate lies within [`MAX_RANGES_OUTSIDE`] actuator ranges of
/// its limits: far beyond, the model's squares overflow (|q| ~ 1e153 gave NaN).
fn check_state(arg: &str, q: &[f64], lower: &[f64], upper: &[f64]) -> Result<()> {
    for (k, ((&x, &l), &u)) in q.iter().zip(lower).zip(upper).enumerate() {
        let r = MAX_RANGES_OUTSIDE * (u - l);
        if !(x >= l - r && x <= u + r) {
            return Err(Error::OutOfRange {
                arg: format!("{arg}[{k}]"),
                value: x,
                min: l - r,
                max: u + r,
            });
        }
    }
    Ok(())
}

impl<K: Kinematics> Resolver<K> {
    /// One step, allocating its result. See [`Resolver::step_into`].
    ///
    /// # Errors
    /// As [`Resolver::step_into`].
    pub fn step(&self, q: &[f64], target: &Target, current: Option<&Mat4>) -> Result<Step> {
        self.step_with(
            q,
            target,
            &StepInput {
                current,
                ..StepInput::default()
            },
        )
    }

    /// One step with every input ([`StepInput`]: measurement, lag prediction,
    /// obstacles), allocating its result.
    ///
    /// # Errors
    /// As [`Resolver::step_input_into`].
    pub fn step_with(&self, q: &[f64], target: &Target, input: &StepInput<'_>) -> Result<Step> {
        let mut ws = self.workspace();
        let mut out = vec![0.0; q.len()];
        let info = self.step_input_into(&mut ws, q, target, input, &mut out)?;
        Ok(Step {
            q: out,
            unclamped: ws.unclamped.clone(),
            info,
        })
    }

    /// One step from state `q` towards `target`, writing the next command (clamped into
    /// the limits) into `out` and the unclamped one into `ws`. `current` is the measured
    /// end-effector pose (closed loop); `None` uses the model's forward kinematics. The
    /// Jacobian is always the model's, at `q`. A state outside the limits (by at most
    /// [`MAX_RANGES_OUTSIDE`] ranges) is accepted and pulled back. No heap allocation except in
    /// `Conventional` mode with a pose target (SVD of the 6-row Jacobian).
    ///
    /// # Errors
    /// As [`Resolver::step_input_into`].
    pub fn step_into(
        &self,
        ws: &mut Workspace,
        q: &[f64],
        target: &Target,
        current: Option<&Mat4>,
        out: &mut [f64],
    ) -> Result<StepInfo> {
        let input = StepInput {
            current,
            ..StepInput::default()
        };
        self.step_input_into(ws, q, target, &input, out)
    }

    /// [`Resolver::step_into`] with every input of [`StepInput`]. With a measured pose
    /// and no `plant_q`, α is capped by the lag bound of the gains
    /// ([`super::gains::lag_alpha`]). Obstacles add the repulsion of eq. (9) below every
    /// task (see [`super::avoid`]).
    ///
    /// # Errors
    /// [`crate::Error::Shape`] / [`crate::Error::NonFinite`] for `q`, `plant_q`, `out`
    /// or a point target of the wrong size or with NaN; [`crate::Error::OutOfRange`] for
    /// a coordinate of `q` or `plant_q` more than [`MAX_RANGES_OUTSIDE`] actuator ranges
    /// outside its limits,
    /// or a target or measured position beyond ±[`MAX_POSITION`]; [`crate::Error::Pose`]
    /// for a malformed `target` or `current` pose; [`crate::Error::Shape`] for a point
    /// target in `Orientation` or `Hybrid` mode, which need a pose, and for `ws` of the
    /// wrong size; [`crate::Error::Parameter`] for obstacles in `Conventional` mode
    /// (which has no null space to put them in).
    pub fn step_input_into(
        &self,
        ws: &mut Workspace,
        q: &[f64],
        target: &Target,
        input: &StepInput<'_>,
        out: &mut [f64],
    ) -> Result<StepInfo> {
        let n = self.arm.n_dofs();
        let lower = self.arm.lower();
        let upper = self.arm.upper();
        check_q(&self.arm, q)?;
        check_state("q", q, lower, upper)?;
        check_len("out", out, n)?;
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
        check_position("target", &p_target)?;
        if r_target.is_none() && matches!(self.mode, Mode::Orientation | Mode::Hybrid) {
            return Err(crate::Error::shape(
                "target",
                format!("a 4×4 pose in {} mode", self.mode.name()),
                "a 3-vector",
            ));
        }
        let current = input.current;
        if let Some(c) = current {
            check_pose("current", c)?;
            check_position("current", &c.fixed_view::<3, 1>(0, 3).into_owned())?;
        }
        if let Some(y) = input.plant_q {
            check_len("plant_q", y, n)?;
            check_finite("plant_q", y)?;
            check_state("plant_q", y, lower, upper)?;
        }
        for ob in input.obstacles {
            // The other forms are checked when they are built; a point is a bare vector.
            if let Obstacle::Point(p) = ob {
                check_finite("obstacles (point)", p.as_slice())?;
                check_position("obstacles (point)", p)?;
            }
        }
        if !input.obstacles.is_empty() && self.mode == Mode::Conventional {
            return Err(Error::parameter(
                "obstacles",
                input.obstacles.len() as f64,
                "the conventional controller (eq. 7) has no null space for obstacle \
                 avoidance; use the position, orientation or hybrid mode",
            ));
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
        // The errors the tasks correct: with a lag prediction, the measured error less
        // the motion the plant will still make towards the command, J (q − ŷ) (Smith
        // predictor; docs/control.md).
        let (mut e_p, mut e_w) = (e_p, e_w);
        let predicted = current.is_some() && input.plant_q.is_some();
        if let (true, Some(y)) = (predicted, input.plant_q) {
            let mut v = Vec3::zeros();
            let mut w = Vec3::zeros();
            for (k, (&x, &yk)) in q.iter().zip(y).enumerate() {
                let c = ws.jac.column(k);
                let d = x - yk;
                v += Vec3::new(c[0], c[1], c[2]) * d;
                w += Vec3::new(c[3], c[4], c[5]) * d;
            }
            e_p -= v;
            for i in 0..3 {
                if mask[i] {
                    e_w[i] -= w[i];
                }
            }
        }

        // Planning paper eq. (9): the obstacles' repulsions at q, on the model.
        let clearance = avoid::repulsions_into(
            &self.arm,
            q,
            input.obstacles,
            g,
            &ws.jac,
            &mut ws.pieces,
            &mut ws.repulsions,
        );

        let (eps, lam) = (g.singular_threshold, g.damping);
        // Saturation in the null space (Flacco et al. 2012), simplified: a coordinate
        // whose command would leave the limits is fixed at the limit, its column removed
        // from every task, what it still delivers subtracted from the task errors, and
        // the step recomputed with the other coordinates. The conventional controller is
        // only clamped (it is unconstrained by definition).
        ws.free.iter_mut().for_each(|f| *f = true);
        ws.fixed.iter_mut().for_each(|v| *v = 0.0);
        // The lag bound (docs/control.md) caps the largest task gain; in hybrid mode
        // α₄ max(γ₆, γ₄), so that the balance between the tasks is kept. The joint-limit
        // term is scaled alike: its motion lies in the MODEL's null space, which the true
        // arm does not share, and faster than the tasks it would drift the pose.
        let lagged = current.is_some() && !predicted;
        let alpha = match self.mode {
            Mode::Conventional => g.effective_alpha(g.conventional_alpha, lagged),
            Mode::Position => g.effective_alpha(g.position_alpha, lagged),
            Mode::Orientation => g.effective_alpha(g.orientation_alpha, lagged),
            Mode::Hybrid => {
                let w = g.hybrid_position.max(g.hybrid_orientation);
                if w > 0.0 {
                    g.effective_alpha(g.hybrid_alpha * w, lagged) / w
                } else {
                    g.hybrid_alpha
                }
            }
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
            ws.avoid.iter_mut().for_each(|v| *v = 0.0);
            match self.mode {
                Mode::Position => {
                    // eq. (13), task 1 over task 3.
                    let gamma = g
                        .schedule
                        .weight(g.position_gamma, g.position_switch, ep_norm);
                    let pa = normal_inverse3(&gram(&ws.a), [true; 3], eps, lam);
                    add_tr_mul(&mut ws.dq, alpha, &ws.a, &(pa * e_p));
                    self.add_null_terms(ws, q, alpha * gamma, &pa, None);
                }
                Mode::Orientation => {
                    // eq. (13), task 2 over task 3, with the masked angular Jacobian.
                    let gamma =
                        g.schedule
                            .weight(g.orientation_gamma, g.orientation_switch, ew_norm);
                    let pb = normal_inverse3(&gram(&ws.b), mask, eps, lam);
                    add_tr_mul(&mut ws.dq, alpha, &ws.b, &(pb * e_w));
                    std::mem::swap(&mut ws.a, &mut ws.b);
                    self.add_null_terms(ws, q, alpha * gamma, &pb, None);
                    std::mem::swap(&mut ws.a, &mut ws.b);
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
                    for ((d, x), t) in ws.dq.iter_mut().zip(&ws.x1).zip(&ws.t) {
                        *d = alpha * (g.hybrid_position * x + g.hybrid_orientation * t.dot(&yt));
                    }
                    let gamma = g.schedule.weight(g.hybrid_gamma, g.hybrid_switch, ep_norm);
                    self.add_null_terms(ws, q, alpha * gamma, &pa, Some(&pt));
                }
                Mode::Conventional => match r_target {
                    None => {
                        // eq. (7) with the position Jacobian.
                        let pa = normal_inverse3(&gram(&ws.a), [true; 3], eps, lam);
                        add_tr_mul(&mut ws.dq, alpha, &ws.a, &(pa * e_p));
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
                        let dq = pinv_general(&j, eps, lam) * e * alpha;
                        ws.dq.copy_from_slice(dq.as_slice());
                    }
                },
            }

            // Step-length caps: the task part at `max_step`, each null-space part (joint
            // limits, obstacles) at half of it, so that ∇H, large next to a limit, can
            // never starve the tasks nor the repulsion.
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
            let s_avoid = cap(&ws.avoid, 0.5 * g.max_step);
            for ((d, v), a) in ws.dq.iter_mut().zip(&ws.null).zip(&ws.avoid) {
                *d = s_task * *d + s_null * v + s_avoid * a;
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
        // The inputs are bounded (validated gains, states and positions), so the
        // increment is finite; should it ever not be, the command would be NaN, which the
        // step promises never to return.
        if let Some(k) = ws.dq.iter().position(|d| !d.is_finite()) {
            return Err(Error::NonFinite {
                arg: "step increment".to_owned(),
                index: k,
                value: ws.dq[k],
            });
        }
        for k in 0..n {
            out[k] = (q[k] + ws.dq[k]).clamp(lower[k], upper[k]);
        }
        Ok(StepInfo {
            saturated,
            position_error: ep_norm,
            orientation_error: ew_norm,
            clearance,
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

    /// The null-space terms of eq. (13) / (20), each projected by
    /// `I − A⁺A − T⁺T` (`A⁺ = Aᵀ pa` with A = `ws.a`; `T⁺ = Tᵀ pt` with T = `ws.t`, if
    /// given): `ws.null = s (I − A⁺A − T⁺T) ∇H` (skipped when the schedule gives `s = 0`)
    /// and `ws.avoid = (I − A⁺A − T⁺T) Σ_j J_sj⁺ F_j` (eq. 9; never scheduled).
    fn add_null_terms(&self, ws: &mut Workspace, q: &[f64], s: f64, pa: &Mat3, pt: Option<&Mat3>) {
        if s != 0.0 {
            joint_limits::gradient_into(
                q,
                self.arm.lower(),
                self.arm.upper(),
                self.gains.limit_margin,
                &mut ws.eta,
            );
            for ((e, d), free) in ws.eta.iter().zip(ws.null.iter_mut()).zip(&ws.free) {
                *d = if *free { s * e } else { 0.0 };
            }
            project(&mut ws.null, &ws.a, pa, pt.map(|p| (&ws.t[..], p)));
        }
        if !ws.repulsions.is_empty() {
            avoid::add_pseudo_inverse_pushes(
                &ws.repulsions,
                &ws.free,
                self.gains.singular_threshold,
                self.gains.damping,
                &mut ws.avoid,
            );
            project(&mut ws.avoid, &ws.a, pa, pt.map(|p| (&ws.t[..], p)));
        }
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
