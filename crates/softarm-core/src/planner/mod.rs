//! The potential-field planner of the planning paper, eq. (9):
//!
//! ```text
//! q̇ = J_e(q)⁺ F_e(V_e) − Σ_j J_sj(q)⁺ F_sj(V_sj)
//! ```
//!
//! The tip is attracted to the goal, `F_e(V_e) = k_a V_e` saturated at `max_tip_step`; the
//! arm point closest to obstacle `j` is repelled, `F_sj = k_r (1/d − 1/ρ0) V̂_sj / d²` for
//! `d < ρ0` (the gradient of Khatib's potential; the minus sign in eq. 9 pushes the point
//! away from the obstacle), through the damped pseudo-inverse `Jᵀ (J Jᵀ + λ² I)⁻¹` of the
//! 3×n point Jacobian (eq. 8). Coordinates at a limit that the step would push further are
//! frozen and the step recomputed without them; the step is then scaled so that no
//! coordinate moves by more than `max_step_fraction` of its range, and clamped to the
//! model's limits. The loop ends when
//! the tip is within `goal_tolerance` of the goal, when it has moved less than
//! `stall_tolerance` over `stall_window` iterations, or after `max_iterations`.
//!
//! The closest arm point of each obstacle is exact ([`crate::distance`]), or, for the
//! paper's baseline, the nearest of `arm_samples` points per section found by brute force.
//! Either way the clearance recorded in [`Plan::min_clearance`] is the exact distance of
//! the whole backbone (every arc) to every obstacle, at every configuration of the path.

mod options;
pub mod scenarios;
mod walk;

pub use options::{PlannerOptions, Termination, MAX_ARM_SAMPLES, MAX_OPTION};

use crate::chain::{check_q, check_q_arcs};
use crate::distance::{
    check_obstacles, closest_to_arcs, placed_arcs, Closest, Obstacle, PlacedArc,
};
use crate::error::{check_bounded, check_count, Error, Result, MAX_POSITION};

/// Most configurations `path_clearance` interpolates between two path entries.
pub const MAX_SUBSTEPS: usize = 10_000;
use crate::kinematics::Kinematics;
use crate::math::Vec3;

/// A planned path.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Configurations, `q0` first, one per iteration.
    pub path: Vec<Vec<f64>>,
    /// Tip (end-effector) positions along the path.
    pub tip_path: Vec<Vec3>,
    /// Whether the tip ended within the goal tolerance.
    pub reached: bool,
    /// Number of iterations (steps of eq. 9) taken.
    pub iterations: usize,
    /// Smallest exact distance between any arc and any obstacle over the whole path
    /// (infinity without obstacles).
    pub min_clearance: f64,
    /// Why the loop ended.
    pub termination: Termination,
}

/// Potential-field planner (eq. 9) on any arm model: [`crate::ArcChain`] or
/// [`crate::SoftArm`].
#[derive(Debug, Clone)]
pub struct PotentialFieldPlanner<K> {
    model: K,
    options: PlannerOptions,
}

impl<K: Kinematics> PotentialFieldPlanner<K> {
    /// A planner for `model`.
    ///
    /// # Errors
    /// [`Error::Parameter`] for an invalid option (see [`PlannerOptions::validate`]).
    pub fn new(model: K, options: PlannerOptions) -> Result<Self> {
        options.validate()?;
        Ok(PotentialFieldPlanner { model, options })
    }

    /// The model.
    pub fn model(&self) -> &K {
        &self.model
    }

    /// The options.
    pub fn options(&self) -> &PlannerOptions {
        &self.options
    }

    /// Plans from `q0` to the tip position `goal` among `obstacles` (any mix).
    ///
    /// # Errors
    /// [`Error::Shape`] / [`Error::NonFinite`] for a bad `q0` or `goal`,
    /// [`Error::OutOfRange`] for a `q0` outside the model's limits or a goal beyond
    /// [`MAX_POSITION`], as [`check_obstacles`] for a bad obstacle, [`Error::Parameter`]
    /// for a curve or mesh obstacle with `arm_samples` set (the sampled baseline supports
    /// points, clouds and segments).
    pub fn plan(&self, q0: &[f64], goal: &Vec3, obstacles: &[Obstacle]) -> Result<Plan> {
        self.check_plan(q0, goal, obstacles)?;
        let o = &self.options;
        let mut walk = self.start(q0, obstacles);
        let mut termination = Termination::IterationLimit;
        let mut iterations = 0;
        while iterations < o.max_iterations {
            let err = goal - walk.tip;
            if err.norm() <= o.goal_tolerance {
                termination = Termination::Reached;
                break;
            }
            // Repulsion directions first: the closest arm point of each obstacle.
            self.repulsions(&mut walk, obstacles);
            self.projected_step(&mut walk, &self.attraction(&err));
            if walk.dq.iter().any(|v| !v.is_finite()) {
                // A damping of 0 at a singular Jacobian: no step can be taken (eq. 8 has
                // no finite solution); stop rather than write NaN into the path.
                termination = Termination::NonFiniteStep;
                break;
            }
            self.take_step(&mut walk);
            iterations += 1;
            self.observe(&mut walk, obstacles);
            if self.stalled(&walk, iterations) {
                termination = Termination::Stalled;
                break;
            }
        }
        if termination == Termination::IterationLimit
            && (goal - walk.tip).norm() <= o.goal_tolerance
        {
            termination = Termination::Reached;
        }
        Ok(Plan {
            path: walk.path,
            tip_path: walk.tip_path,
            reached: termination == Termination::Reached,
            iterations,
            min_clearance: walk.min_clearance,
            termination,
        })
    }

    /// Checks the inputs of [`PotentialFieldPlanner::plan`] (its errors).
    fn check_plan(&self, q0: &[f64], goal: &Vec3, obstacles: &[Obstacle]) -> Result<()> {
        let model = &self.model;
        check_q(model, q0)?;
        check_bounded("goal", goal.as_slice(), MAX_POSITION)?;
        check_obstacles(obstacles)?;
        let (lo, hi) = (model.lower(), model.upper());
        for i in 0..q0.len() {
            crate::error::check_range(&format!("q0[{i}]"), q0[i], lo[i], hi[i])?;
        }
        if self.options.arm_samples.is_some() {
            if let Some(k) = obstacles
                .iter()
                .position(|ob| matches!(ob, Obstacle::Curve(_) | Obstacle::Mesh(_)))
            {
                return Err(Error::parameter(
                    &format!("obstacles[{k}]"),
                    k as f64,
                    "the sampled-arm baseline takes points, point clouds and segments",
                ));
            }
        }
        Ok(())
    }
}

/// Exact clearance of the whole backbone: the smallest distance of any arc to any obstacle.
pub fn clearance(arcs: &[PlacedArc], obstacles: &[Obstacle]) -> f64 {
    obstacles
        .iter()
        .map(|ob| closest_to_arcs(arcs, ob).distance)
        .fold(f64::INFINITY, f64::min)
}

/// The paper's baseline: the arm discretised into `m` points per section, and the closest
/// pair found by brute force between those points and the obstacle.
pub fn closest_sampled(arcs: &[PlacedArc], m: usize, obstacle: &Obstacle) -> Closest {
    let mut best = Closest::none();
    let denom = (m.max(2) - 1) as f64;
    for (i, arc) in arcs.iter().enumerate() {
        for k in 0..m.max(1) {
            let s = if m <= 1 { 1.0 } else { k as f64 / denom };
            let x = arc.point(s);
            let (d, u, p) = match obstacle {
                Obstacle::Point(p) => ((p - x).norm(), 0.0, *p),
                Obstacle::Cloud(c) => {
                    let (d, idx) = c.closest_to_point_brute_force(&x);
                    (d, idx as f64, c.points()[idx])
                }
                Obstacle::Segment(seg) => {
                    let (u, p) = seg.closest_to_point(&x);
                    ((p - x).norm(), u, p)
                }
                Obstacle::Mesh(mesh) => {
                    let (d, p) = mesh.closest_to_point(&x);
                    (d, 0.0, p)
                }
                Obstacle::Curve(_) => continue,
            };
            if d < best.distance {
                best = Closest::new(i, s, x, u, p, d);
            }
        }
    }
    best
}

/// Exact clearance along a path, checking `substeps` configurations linearly interpolated
/// between consecutive path entries as well (to catch an arm passing through a thin
/// obstacle between two steps).
///
/// # Errors
/// As [`crate::distance::closest`] for a bad configuration in `path` or a bad obstacle,
/// [`Error::OutOfRange`] for `substeps` outside [1, [`MAX_SUBSTEPS`]].
pub fn path_clearance<K: Kinematics + ?Sized>(
    model: &K,
    path: &[Vec<f64>],
    obstacles: &[Obstacle],
    substeps: usize,
) -> Result<f64> {
    let mut min = f64::INFINITY;
    check_count("substeps", substeps, 1, MAX_SUBSTEPS)?;
    check_obstacles(obstacles)?;
    // Interpolated configurations are convex combinations of checked ones: their
    // coordinates stay finite and bounded, and each section's arc length (affine in q for
    // both models) stays positive.
    for q in path {
        check_q_arcs(model, q)?;
    }
    for (k, q) in path.iter().enumerate() {
        min = min.min(clearance(&placed_arcs(model, q), obstacles));
        if let Some(next) = path.get(k + 1) {
            for j in 1..substeps {
                let t = j as f64 / substeps as f64;
                let qi: Vec<f64> = q.iter().zip(next).map(|(a, b)| a + t * (b - a)).collect();
                min = min.min(clearance(&placed_arcs(model, &qi), obstacles));
            }
        }
    }
    Ok(min)
}
