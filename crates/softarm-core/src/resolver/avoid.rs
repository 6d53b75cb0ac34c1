//! Obstacle avoidance as the lowest-priority task of the resolver (planning paper eq. 9).
//!
//! For each obstacle the exact closest pair to the arm's whole body (arcs, end plates,
//! gripper: [`crate::distance::bodies`]) is found. Within the influence distance ρ₀ of
//! the surface gap `g = d − body_radius`, the closest arm point is pushed straight away
//! from the obstacle by `F = k_r (1/g − 1/ρ₀) / g²` (m per step; the gradient of
//! Khatib's potential, the repulsive term of eq. 9, with `g` clamped at 1 mm), through
//! the damped pseudo-inverse of its 3×n point Jacobian (eq. 8): `Δq_j = J_sj⁺ F_j`. The
//! step projects `Σ_j Δq_j` onto the null space of every task of its mode, as eq. (20)
//! does the joint-limit gradient, caps it on its own, and never schedules it off: it is
//! safety, and it must keep acting at the target.
//!
//! The pairs are evaluated on the MODEL at the commanded `q`, not on the measurement, so
//! the repulsion adds no loop through the plant's lag.

use nalgebra::DMatrix;

use super::pinv::normal_inverse3;
use super::Gains;
use crate::chain::point_unchecked;
use crate::distance::bodies::{closest_piece_within, placed_pieces_into, BodyBox, Piece};
use crate::distance::Obstacle;
use crate::kinematics::Kinematics;
use crate::math::{Mat3, Vec3};

/// Smallest surface gap (m) used in the law: below it the push no longer grows.
const MIN_GAP: f64 = 1e-3;

/// One obstacle's push on its closest arm point.
#[derive(Debug, Clone)]
pub struct Repulsion {
    /// Surface gap (m); negative when the surfaces overlap.
    pub gap: f64,
    /// Closest arm point (base frame).
    pub arm_point: Vec3,
    /// Columns of the point's 3×n Jacobian.
    pub jac: Vec<Vec3>,
    /// The displacement F asked of the point (m per step).
    pub push: Vec3,
}

fn columns(j: &nalgebra::Matrix3xX<f64>) -> Vec<Vec3> {
    j.column_iter().map(|c| c.into_owned()).collect()
}

/// Fills `out` with the repulsion of every obstacle within the influence distance of the
/// model arm at `q` (`jac`: the end-effector Jacobian at `q`). Returns the smallest
/// surface gap among them, `+∞` when none is that close.
pub fn repulsions_into<K: Kinematics + ?Sized>(
    arm: &K,
    q: &[f64],
    obstacles: &[Obstacle],
    gains: &Gains,
    jac: &DMatrix<f64>,
    pieces: &mut Vec<Piece>,
    out: &mut Vec<Repulsion>,
) -> f64 {
    out.clear();
    if obstacles.is_empty() || gains.influence_distance <= 0.0 {
        return f64::INFINITY;
    }
    placed_pieces_into(arm, q, pieces);
    // One box around the whole body per step; each obstacle is tested against it first.
    let bound = BodyBox::around(pieces);
    let cutoff = gains.body_radius + gains.influence_distance;
    let rho = gains.influence_distance;
    let mut clearance = f64::INFINITY;
    let n_sections = arm.n_sections();
    for ob in obstacles {
        let Some(hit) = closest_piece_within(pieces, &bound, ob, cutoff) else {
            continue;
        };
        let c = hit.closest;
        let gap = c.distance - gains.body_radius;
        clearance = clearance.min(gap);
        let away = c.arm_point - c.obstacle_point;
        let d = away.norm();
        if gap >= rho || d == 0.0 {
            // At d = 0 the backbone crosses the obstacle: no direction to push in.
            continue;
        }
        let g = gap.max(MIN_GAP);
        let push = away * (gains.repulsion_gain * (1.0 / g - 1.0 / rho) / (g * g) / d);
        let cols = if !hit.rigid {
            columns(&point_unchecked(arm, q, c.section, c.s).1)
        } else {
            // A point of a rigid part moves as the affine combination of the part's ends.
            let start = columns(&point_unchecked(arm, q, c.section, 1.0).1);
            let end: Vec<Vec3> = if c.section + 1 < n_sections {
                columns(&point_unchecked(arm, q, c.section + 1, 0.0).1)
            } else {
                (0..jac.ncols())
                    .map(|k| Vec3::new(jac[(0, k)], jac[(1, k)], jac[(2, k)]))
                    .collect()
            };
            start
                .iter()
                .zip(&end)
                .map(|(a, b)| a * (1.0 - c.s) + b * c.s)
                .collect()
        };
        out.push(Repulsion {
            gap,
            arm_point: c.arm_point,
            jac: cols,
            push,
        });
    }
    clearance
}

/// `out += Σ_j J_sj⁺ F_j` (eq. 8–9) with the columns of coordinates that are not `free`
/// removed, through the damped pseudo-inverse of [`normal_inverse3`].
pub fn add_pseudo_inverse_pushes(
    reps: &[Repulsion],
    free: &[bool],
    threshold: f64,
    damping: f64,
    out: &mut [f64],
) {
    for r in reps {
        let gram = r
            .jac
            .iter()
            .zip(free)
            .filter(|(_, f)| **f)
            .fold(Mat3::zeros(), |s, (c, _)| s + c * c.transpose());
        let y = normal_inverse3(&gram, [true; 3], threshold, damping) * r.push;
        for ((o, c), f) in out.iter_mut().zip(&r.jac).zip(free) {
            if *f {
                *o += c.dot(&y);
            }
        }
    }
}
