//! One resolver step (eq. 7, 13, 20) with no heap allocation on the hot path: its
//! inputs, checks, task errors and command. The tasks themselves are in
//! [`super::tasks`], the saturation rounds and step caps in [`super::saturation`].
//!
//! Below the tasks of each mode (position, orientation, both) lie two null-space terms,
//! each projected onto the null space of every task above it and capped separately: the
//! joint-limit gradient of eq. (14), scheduled by the task error, and the repulsion from
//! obstacles (planning paper eq. 9, see [`super::avoid`]), never scheduled off.

use nalgebra::DMatrix;

use super::avoid::{self, Repulsion};
use super::orientation::{check_pose, orientation_error};
use super::{Mode, Resolver, Step, Target};
use crate::chain::{check_q, forward_jacobian_into};
use crate::distance::bodies::{BodyClosest, Piece};
use crate::distance::Obstacle;
use crate::error::{check_finite, check_len, Error, Result};
use crate::kinematics::Kinematics;
use crate::math::{Frame, Mat3, Mat4, Vec3};

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
    pub(super) jac: DMatrix<f64>,
    pub(super) a: Vec<Vec3>,
    pub(super) b: Vec<Vec3>,
    pub(super) t: Vec<Vec3>,
    pub(super) x1: Vec<f64>,
    pub(super) eta: Vec<f64>,
    pub(super) dq: Vec<f64>,
    pub(super) null: Vec<f64>,
    pub(super) unclamped: Vec<f64>,
    pub(super) free: Vec<bool>,
    /// The coordinates the null-space terms may move: the tasks' free ones less those a
    /// null-space term alone would take out of the limits (saturation rounds).
    pub(super) null_free: Vec<bool>,
    pub(super) fixed: Vec<f64>,
    /// The task part of the last round's increment, as capped.
    pub(super) task: Vec<f64>,
    /// The tasks' columns of the coordinates in `null_free` (`na`: the first task's,
    /// `nb`: the second's, `nt`: J̃ of eq. 17 from them), when those are fewer than the
    /// tasks' own.
    pub(super) na: Vec<Vec3>,
    pub(super) nb: Vec<Vec3>,
    pub(super) nt: Vec<Vec3>,
    pub(super) avoid: Vec<f64>,
    /// One obstacle's projected gap rows (row-major) and their asks.
    pub(super) rows: Vec<f64>,
    pub(super) asks: Vec<f64>,
    pub(super) hits: Vec<BodyClosest>,
    pub(super) trial: Vec<f64>,
    pub(super) pieces: Vec<Piece>,
    pub(super) repulsions: Vec<Repulsion>,
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
            null_free: vec![true; n],
            fixed: vec![0.0; n],
            task: vec![0.0; n],
            na: vec![Vec3::zeros(); n],
            nb: vec![Vec3::zeros(); n],
            nt: vec![Vec3::zeros(); n],
            avoid: vec![0.0; n],
            rows: Vec::new(),
            asks: Vec::new(),
            hits: Vec::new(),
            trial: vec![0.0; n],
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

/// The errors a step's tasks correct.
#[derive(Debug, Clone, Copy)]
pub(super) struct TaskErrors {
    /// e_p (m), corrected by the lag prediction when there is one.
    pub(super) p: Vec3,
    /// e_ζ (rad), masked, corrected alike.
    pub(super) w: Vec3,
    /// ‖e_p‖ at the input state, before the correction (reported, and the schedules').
    pub(super) p_norm: f64,
    /// ‖e_ζ‖ at the input state, before the correction.
    pub(super) w_norm: f64,
    /// Whether a lag prediction corrected the errors (a measurement and `plant_q`).
    pub(super) predicted: bool,
}

/// `v[i] −= d[i]` on the controlled axes of `mask` only.
#[inline]
pub(super) fn subtract_masked(v: &mut Vec3, d: &Vec3, mask: [bool; 3]) {
    for i in 0..3 {
        if mask[i] {
            v[i] -= d[i];
        }
    }
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
        let goal = self.check_step(ws, q, target, input, out)?;
        // eq. (4)–(6): the model's pose and Jacobian at q.
        let model = forward_jacobian_into(&self.arm, q, &mut ws.jac);
        let errors = self.task_errors(ws, q, &model, &goal, input);
        // Planning paper eq. (9): the obstacles' repulsions at q, on the model.
        let clearance = avoid::repulsions_into(
            (&self.arm, &self.body),
            q,
            input.obstacles,
            &self.gains,
            &ws.jac,
            (&mut ws.pieces, &mut ws.hits),
            &mut ws.repulsions,
        );
        // The lag bound applies to a step that closes the loop through the plant without
        // a predictor accounting for the lag.
        let alpha = self.task_alpha(input.current.is_some() && !errors.predicted);
        // A step closed through the plant damps its pseudo-inverses more: the plant is not
        // the model along their ill-conditioned directions (Gains::loop_damping).
        let dls = self.gains.dls(input.current.is_some());
        let saturated = self.saturation_rounds(ws, q, &errors, goal.1.is_some(), alpha, dls);
        self.hold_repulsion(ws, q, &model.pos);
        self.write_command(ws, q, out)?;
        Ok(StepInfo {
            saturated,
            position_error: errors.p_norm,
            orientation_error: errors.w_norm,
            clearance,
        })
    }

    /// Checks every input of a step; returns the target's position and, for a pose, its
    /// rotation.
    fn check_step(
        &self,
        ws: &Workspace,
        q: &[f64],
        target: &Target,
        input: &StepInput<'_>,
        out: &[f64],
    ) -> Result<(Vec3, Option<Mat3>)> {
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
        if let Some(c) = input.current {
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
        Ok((p_target, r_target))
    }

    /// The position and (masked) orientation errors at the input state: measured when
    /// `input.current` is given, else the model's (`model`, at `q`).
    fn task_errors(
        &self,
        ws: &Workspace,
        q: &[f64],
        model: &Frame,
        (p_target, r_target): &(Vec3, Option<Mat3>),
        input: &StepInput<'_>,
    ) -> TaskErrors {
        let (p_cur, r_cur) = match input.current {
            Some(c) => (
                c.fixed_view::<3, 1>(0, 3).into_owned(),
                c.fixed_view::<3, 3>(0, 0).into_owned(),
            ),
            None => (model.pos, model.rot),
        };
        let mask = self.gains.axis_mask;
        let mut p = p_target - p_cur;
        let mut w = match r_target {
            Some(rt) => orientation_error(rt, &r_cur, mask),
            None => Vec3::zeros(),
        };
        let (p_norm, w_norm) = (p.norm(), w.norm());
        // The errors the tasks correct: with a lag prediction, the measured error less
        // the motion the plant will still make towards the command, J (q − ŷ) (Smith
        // predictor; docs/control.md).
        let predicted = input.current.is_some() && input.plant_q.is_some();
        if let (true, Some(y)) = (predicted, input.plant_q) {
            let mut v = Vec3::zeros();
            let mut u = Vec3::zeros();
            for (k, (&x, &yk)) in q.iter().zip(y).enumerate() {
                let c = ws.jac.column(k);
                let d = x - yk;
                v += Vec3::new(c[0], c[1], c[2]) * d;
                u += Vec3::new(c[3], c[4], c[5]) * d;
            }
            p -= v;
            subtract_masked(&mut w, &u, mask);
        }
        TaskErrors {
            p,
            w,
            p_norm,
            w_norm,
            predicted,
        }
    }

    /// The mode's task gain α. The lag bound (docs/control.md) caps the largest task gain
    /// when the step is `lagged`; in hybrid mode α₄ max(γ₆, γ₄), so that the balance
    /// between the tasks is kept. The joint-limit term is scaled alike: its motion lies in
    /// the MODEL's null space, which the true arm does not share, and faster than the
    /// tasks it would drift the pose.
    fn task_alpha(&self, lagged: bool) -> f64 {
        let g = &self.gains;
        match self.mode {
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
        }
    }

    /// Cuts the repulsion's part of the increment (`ws.avoid`, as the last saturation
    /// round applied it) to the fraction [`avoid::step_fraction`] finds on the model
    /// (`tip`: the gripper at `q`): a long null-space step moves the gripper by its
    /// second-order terms, the position task takes that back, and its correction undid
    /// the clearance the step had earned, so that the pair cycled instead of settling.
    fn hold_repulsion(&self, ws: &mut Workspace, q: &[f64], tip: &Vec3) {
        if ws.repulsions.is_empty() {
            return;
        }
        let held = matches!(self.mode, Mode::Position | Mode::Hybrid).then_some(tip);
        let t = avoid::step_fraction(
            &self.arm,
            q,
            &ws.avoid,
            (&ws.repulsions, held),
            &mut ws.trial,
        );
        if t < 1.0 {
            for (d, a) in ws.dq.iter_mut().zip(&ws.avoid) {
                *d -= (1.0 - t) * a;
            }
        }
    }

    /// The command `q + Δq`, clamped into the limits, into `out`.
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a non-finite increment. The inputs are bounded (validated
    /// gains, states and positions), so the increment is finite; should it ever not be,
    /// the command would be NaN, which the step promises never to return.
    fn write_command(&self, ws: &Workspace, q: &[f64], out: &mut [f64]) -> Result<()> {
        if let Some(k) = ws.dq.iter().position(|d| !d.is_finite()) {
            return Err(Error::NonFinite {
                arg: "step increment".to_owned(),
                index: k,
                value: ws.dq[k],
            });
        }
        let (lower, upper) = (self.arm.lower(), self.arm.upper());
        for k in 0..q.len() {
            out[k] = (q[k] + ws.dq[k]).clamp(lower[k], upper[k]);
        }
        Ok(())
    }
}
