//! Saturation in the null space (Flacco et al. 2012), simplified, and the step-length
//! caps: the rounds of one resolver step.

use super::step::{subtract_masked, TaskErrors, Workspace};
use super::tasks::{Dls, Scale};
use super::{Mode, Resolver};
use crate::kinematics::Kinematics;
use crate::math::Vec3;

/// The factor that shortens `v` to Euclidean length `max` when it is longer (else 1).
#[inline]
fn cap_scale(v: &[f64], max: f64) -> f64 {
    let len = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if len > max {
        max / len
    } else {
        1.0
    }
}

/// How far towards a limit (a fraction of the room left) one step of the joint-limit
/// term may take a free coordinate ([`boundary_scale`]).
const BOUNDARY_FRACTION: f64 = 0.5;

/// The factor that keeps the joint-limit term `v` from taking any free coordinate more
/// than `fraction` of the way from `q` to the limit it moves towards (the fraction-to-
/// the-boundary rule of interior-point methods; 1 when it already does). ∇H of eq. (14)
/// is a barrier: next to a limit it is so steep that a step along it, even capped in
/// length, overshoots into the far limits of other coordinates through the null-space
/// projection, which then saturate in turn. Under a lag-bounded gain the tasks move
/// little against it, and the arm ended with every coordinate on a limit, 18 cm from a
/// target it reaches without the term (docs/control.md, section 3).
fn boundary_scale(
    v: &[f64],
    q: &[f64],
    lower: &[f64],
    upper: &[f64],
    free: &[bool],
    fraction: f64,
) -> f64 {
    let mut scale = 1.0_f64;
    for k in 0..v.len() {
        if !free[k] || v[k] == 0.0 {
            continue;
        }
        let room = if v[k] > 0.0 {
            upper[k] - q[k]
        } else {
            q[k] - lower[k]
        };
        scale = scale.min((fraction * room.max(0.0) / v[k].abs()).max(0.0));
    }
    scale
}

/// Clamps saturation round `round` (of `rounds`): a fixed coordinate keeps its fixed
/// increment; a free one whose command `q + Δq` leaves `[lower, upper]` is taken, for the
/// next round (none after the last), from the null-space terms only when the task part
/// alone keeps it inside (the terms below the tasks pushed it out: the tasks keep it), else
/// fixed at the limit for everything. The first round records the unclamped command.
/// Returns (whether a command left the limits, whether a coordinate was newly taken).
fn fix_saturated(
    ws: &mut Workspace,
    q: &[f64],
    lower: &[f64],
    upper: &[f64],
    round: usize,
    rounds: usize,
) -> (bool, bool) {
    let mut saturated = false;
    let mut newly_fixed = false;
    for k in 0..q.len() {
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
                let task = q[k] + ws.task[k];
                if ws.null_free[k] && task.clamp(lower[k], upper[k]) == task {
                    // Priority: a term below the tasks never takes a coordinate from them.
                    ws.null_free[k] = false;
                } else {
                    ws.free[k] = false;
                    ws.null_free[k] = false;
                    ws.fixed[k] = c - q[k];
                }
                newly_fixed = true;
            }
        }
    }
    (saturated, newly_fixed)
}

impl<K: Kinematics> Resolver<K> {
    /// Saturation in the null space (Flacco et al. 2012), simplified, by priority: a
    /// coordinate whose command would leave the limits is taken from the null-space terms
    /// (joint limits, obstacles) alone when the tasks' part keeps it inside, else fixed at
    /// the limit, its column removed from every task and what it still delivers subtracted
    /// from the task errors; the step is recomputed with the other coordinates (at most
    /// 2n + 1 rounds: each takes a coordinate from the null-space terms or from all).
    /// Fixing a coordinate that only the lowest terms pushed out would take it from the
    /// tasks above them: next to a cane the repulsion pinned four coordinates on their
    /// limits, and the tasks, left with five for five rows, ill-conditioned, cycled by up
    /// to `max_step` about the pose (issue 27). The conventional
    /// controller is only clamped (it is unconstrained by definition): one round. Leaves
    /// the increment in `ws.dq`; returns whether any command left the limits.
    pub(super) fn saturation_rounds(
        &self,
        ws: &mut Workspace,
        q: &[f64],
        errors: &TaskErrors,
        pose_target: bool,
        alpha: f64,
        (eps, lam): Dls,
    ) -> bool {
        let scale = Scale { alpha, eps, lam };
        let n = q.len();
        ws.free.iter_mut().for_each(|f| *f = true);
        ws.null_free.iter_mut().for_each(|f| *f = true);
        ws.fixed.iter_mut().for_each(|v| *v = 0.0);
        let conventional = self.mode == Mode::Conventional;
        let rounds = if conventional { 1 } else { 2 * n + 1 };
        let mut saturated = false;
        for round in 0..rounds {
            let (e_p, e_w) = self.round_errors(ws, errors, round, alpha);
            self.load_task_columns(ws);
            ws.dq.iter_mut().for_each(|v| *v = 0.0);
            ws.null.iter_mut().for_each(|v| *v = 0.0);
            ws.avoid.iter_mut().for_each(|v| *v = 0.0);
            match self.mode {
                Mode::Position => self.position_task(ws, q, &e_p, errors.p_norm, scale),
                Mode::Orientation => self.orientation_task(ws, q, &e_w, errors.w_norm, scale),
                Mode::Hybrid => self.hybrid_task(ws, q, &e_p, &e_w, errors.p_norm, scale),
                Mode::Conventional => self.conventional_task(ws, &e_p, &e_w, pose_target, scale),
            }
            self.cap_and_combine(ws, q);
            let (lower, upper) = (self.arm.lower(), self.arm.upper());
            let (clamped, newly_fixed) = fix_saturated(ws, q, lower, upper, round, rounds);
            saturated |= clamped;
            if round == 0 && conventional {
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
        saturated
    }

    /// The task errors of saturation round `round`: after the first, less what the fixed
    /// coordinates still deliver (per unit α).
    fn round_errors(
        &self,
        ws: &Workspace,
        errors: &TaskErrors,
        round: usize,
        alpha: f64,
    ) -> (Vec3, Vec3) {
        let (mut e_p, mut e_w) = (errors.p, errors.w);
        if round > 0 {
            let (jp, jw) = self.fixed_motion(ws);
            e_p -= jp / alpha;
            subtract_masked(&mut e_w, &(jw / alpha), self.gains.axis_mask);
        }
        (e_p, e_w)
    }

    /// Step-length caps: the task part at `max_step`, each null-space part (joint limits,
    /// obstacles) at half of it, so that ∇H, large next to a limit, can never starve the
    /// tasks nor the repulsion; the joint-limit part also takes no free coordinate more
    /// than half way to a limit ([`boundary_scale`]). Leaves the sum of the three capped
    /// parts in `ws.dq`.
    fn cap_and_combine(&self, ws: &mut Workspace, q: &[f64]) {
        let max = self.gains.max_step;
        let s_task = cap_scale(&ws.dq, max);
        let (lower, upper) = (self.arm.lower(), self.arm.upper());
        let s_null = cap_scale(&ws.null, 0.5 * max).min(boundary_scale(
            &ws.null,
            q,
            lower,
            upper,
            &ws.null_free,
            BOUNDARY_FRACTION,
        ));
        for (t, d) in ws.task.iter_mut().zip(&ws.dq) {
            *t = s_task * d;
        }
        let s_avoid = cap_scale(&ws.avoid, 0.5 * max);
        // The repulsion's part is kept as applied: the step may still cut it
        // (Resolver::hold_repulsion).
        ws.avoid.iter_mut().for_each(|a| *a *= s_avoid);
        for ((d, v), a) in ws.dq.iter_mut().zip(&ws.null).zip(&ws.avoid) {
            *d = s_task * *d + s_null * v + a;
        }
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
}

#[cfg(test)]
mod tests {
    use super::boundary_scale;

    const LOWER: [f64; 3] = [0.0, 0.0, 0.0];
    const UPPER: [f64; 3] = [0.03, 0.03, 0.03];

    #[test]
    fn a_step_towards_a_limit_is_cut_to_half_the_room_left() {
        let q = [0.001, 0.015, 0.015];
        let v = [-0.004, 0.001, -0.001]; // 1 mm of room, 4 mm towards the lower limit
        let s = boundary_scale(&v, &q, &LOWER, &UPPER, &[true; 3], 0.5);
        assert!((s - 0.125).abs() < 1e-12, "{s}");
        for k in 0..3 {
            let x = q[k] + s * v[k];
            let room = (q[k] - LOWER[k]).min(UPPER[k] - q[k]);
            assert!(x - LOWER[k] >= 0.5 * room - 1e-15 || UPPER[k] - x >= 0.5 * room - 1e-15);
            assert!(x > LOWER[k] && x < UPPER[k]);
        }
    }

    #[test]
    fn a_step_that_keeps_its_room_is_left_whole() {
        let q = [0.001, 0.015, 0.029];
        let v = [0.002, 0.001, -0.003]; // away from the near limits, far from the others
        assert_eq!(boundary_scale(&v, &q, &LOWER, &UPPER, &[true; 3], 0.5), 1.0);
    }

    #[test]
    fn fixed_coordinates_are_the_saturation_rounds_business() {
        let q = [0.0, 0.015, 0.015];
        let v = [-0.002, 0.001, 0.001]; // on the lower limit, pushed further out
        assert_eq!(
            boundary_scale(&v, &q, &LOWER, &UPPER, &[false, true, true], 0.5),
            1.0
        );
        assert_eq!(boundary_scale(&v, &q, &LOWER, &UPPER, &[true; 3], 0.5), 0.0);
    }
}
