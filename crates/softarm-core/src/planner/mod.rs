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

pub use options::{PlannerOptions, Termination, MAX_ARM_SAMPLES, MAX_OPTION};

use nalgebra::{DMatrix, Matrix3, Matrix3xX};

use crate::chain::{check_q, check_q_arcs, forward_jacobian_into, point_unchecked};
use crate::distance::{
    check_obstacles, closest_to_arcs, closest_to_arcs_within, placed_arcs, Closest, Obstacle,
    PlacedArc,
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

    /// The walk at `q0`: its exact closest pairs, clearance and tip.
    fn start(&self, q0: &[f64], obstacles: &[Obstacle]) -> Walk {
        let model = &self.model;
        let (lo, hi) = (model.lower(), model.upper());
        let n = model.n_dofs();
        let q = q0.to_vec();
        let mut jac = DMatrix::zeros(6, n);
        let arcs = placed_arcs(model, &q);
        // Exact closest pairs at the current configuration: they give the clearance of the
        // whole backbone and, for the proposed method, the repulsion points of the next step.
        let hits: Vec<Option<Closest>> = obstacles
            .iter()
            .map(|ob| Some(closest_to_arcs(&arcs, ob)))
            .collect();
        let min_clearance = min_distance(&hits);
        let tip = forward_jacobian_into(model, &q, &mut jac).pos;
        Walk {
            step_limit: (0..n)
                .map(|i| self.options.max_step_fraction * (hi[i] - lo[i]))
                .collect(),
            path: vec![q.clone()],
            q,
            jac,
            arcs,
            hits,
            min_clearance,
            tip,
            tip_path: vec![tip],
            dq: vec![0.0; n],
            free: vec![true; n],
            first: vec![0.0; n],
            repulsions: Vec::with_capacity(obstacles.len()),
        }
    }

    /// eq. (9), repulsive terms: for each obstacle whose closest arm point lies within the
    /// influence distance, that point's Jacobian and `F_sj = k_r (1/d − 1/ρ0) V̂_sj / d²`.
    fn repulsions(&self, walk: &mut Walk, obstacles: &[Obstacle]) {
        let o = &self.options;
        walk.repulsions.clear();
        for (ob, hit) in obstacles.iter().zip(&walk.hits) {
            let c = match (o.arm_samples, hit) {
                (None, Some(h)) => *h,
                (None, None) => continue,
                (Some(m), _) => closest_sampled(&walk.arcs, m, ob),
            };
            if c.distance >= o.influence_distance {
                continue;
            }
            let v = c.obstacle_point - c.arm_point;
            let d = v.norm();
            if d == 0.0 {
                continue;
            }
            let dd = d.max(1e-6);
            let mag = o.repulsion_gain * (1.0 / dd - 1.0 / o.influence_distance) / (dd * dd);
            let (_, js) = point_unchecked(&self.model, &walk.q, c.section, c.s);
            walk.repulsions.push((js, v * (mag / d)));
        }
    }

    /// eq. (9), attractive term: `F_e = k_a V_e`, saturated at `max_tip_step`.
    fn attraction(&self, err: &Vec3) -> Vec3 {
        let o = &self.options;
        let mut dx = err * o.attraction_gain;
        let len = dx.norm();
        if len > o.max_tip_step {
            dx *= o.max_tip_step / len;
        }
        dx
    }

    /// eq. (9): `Δq = J_e⁺ F_e − Σ_j J_sj⁺ F_sj` into `walk.dq`. Coordinates at a limit
    /// that the step pushes further are frozen and the step is recomputed without them
    /// (projection onto the feasible set, at most four passes); should every coordinate
    /// freeze, the unprojected step is kept (and clamped later).
    fn projected_step(&self, walk: &mut Walk, dx: &Vec3) {
        let damping = self.options.damping;
        let (lo, hi) = (self.model.lower(), self.model.upper());
        let je = walk.jac.fixed_rows::<3>(0).into_owned();
        walk.free.iter_mut().for_each(|f| *f = true);
        for pass in 0..4 {
            walk.dq.iter_mut().for_each(|v| *v = 0.0);
            // Attraction: J_e⁺ F_e(V_e).
            add_pinv(&je, &walk.free, dx, damping, 1.0, &mut walk.dq);
            // Repulsion: − Σ_j J_sj⁺ F_sj(V_sj).
            for (js, f) in &walk.repulsions {
                add_pinv(js, &walk.free, f, damping, -1.0, &mut walk.dq);
            }
            if pass == 0 {
                walk.first.copy_from_slice(&walk.dq);
            }
            let mut changed = false;
            for i in 0..walk.q.len() {
                let (q, dq) = (walk.q[i], walk.dq[i]);
                let blocked = (q <= lo[i] && dq < 0.0) || (q >= hi[i] && dq > 0.0);
                if walk.free[i] && blocked {
                    walk.free[i] = false;
                    changed = true;
                }
            }
            if !walk.free.iter().any(|&f| f) {
                // Everything would freeze: fall back to the unprojected step, clamped.
                walk.dq.copy_from_slice(&walk.first);
                break;
            }
            if !changed {
                break;
            }
        }
    }

    /// Applies `walk.dq`: scaled so that no coordinate moves by more than its step limit,
    /// then clamped to the model's limits.
    fn take_step(&self, walk: &mut Walk) {
        let (lo, hi) = (self.model.lower(), self.model.upper());
        let mut scale: f64 = 1.0;
        for (d, limit) in walk.dq.iter().zip(&walk.step_limit) {
            if d.abs() * scale > *limit {
                scale = limit / d.abs();
            }
        }
        for i in 0..walk.q.len() {
            walk.q[i] = (walk.q[i] + scale * walk.dq[i]).clamp(lo[i], hi[i]);
        }
    }

    /// The walk's new configuration: its arcs, exact closest pairs, clearance and tip,
    /// recorded in the path. Pairs farther than both the influence distance and the
    /// clearance so far can change neither, so they are skipped by exact lower bounds
    /// (`None`).
    fn observe(&self, walk: &mut Walk, obstacles: &[Obstacle]) {
        walk.arcs = placed_arcs(&self.model, &walk.q);
        let cutoff = self.options.influence_distance.max(walk.min_clearance);
        for (hit, ob) in walk.hits.iter_mut().zip(obstacles) {
            *hit = closest_to_arcs_within(&walk.arcs, ob, cutoff);
        }
        walk.min_clearance = walk.min_clearance.min(min_distance(&walk.hits));
        walk.tip = forward_jacobian_into(&self.model, &walk.q, &mut walk.jac).pos;
        walk.path.push(walk.q.clone());
        walk.tip_path.push(walk.tip);
    }

    /// Whether the tip has moved less than `stall_tolerance` over the last `stall_window`
    /// iterations (`iterations` taken so far).
    fn stalled(&self, walk: &Walk, iterations: usize) -> bool {
        let o = &self.options;
        if iterations < o.stall_window {
            return false;
        }
        let back = walk.tip_path[walk.tip_path.len() - 1 - o.stall_window];
        (walk.tip - back).norm() < o.stall_tolerance
    }
}

/// The state of one plan: the path so far and the buffers of a step.
struct Walk {
    /// Largest move of each coordinate per step (`max_step_fraction` of its range).
    step_limit: Vec<f64>,
    /// The current configuration.
    q: Vec<f64>,
    /// The 6×n Jacobian at `q`.
    jac: DMatrix<f64>,
    /// The arcs at `q`.
    arcs: Vec<PlacedArc>,
    /// Each obstacle's exact closest pair at `q`, `None` when provably irrelevant.
    hits: Vec<Option<Closest>>,
    /// Smallest exact clearance so far.
    min_clearance: f64,
    /// The tip at `q`.
    tip: Vec3,
    /// Configurations so far, `q0` first.
    path: Vec<Vec<f64>>,
    /// Tips so far.
    tip_path: Vec<Vec3>,
    /// The step being computed.
    dq: Vec<f64>,
    /// Coordinates not frozen at a limit.
    free: Vec<bool>,
    /// The first (unprojected) pass's step.
    first: Vec<f64>,
    /// Each repelling obstacle's point Jacobian and push.
    repulsions: Vec<(Matrix3xX<f64>, Vec3)>,
}

/// `dq += sign · Jᵀ (J Jᵀ + λ² I)⁻¹ f` (eq. 8, damped), using only the `free` columns.
fn add_pinv(j: &Matrix3xX<f64>, free: &[bool], f: &Vec3, damping: f64, sign: f64, dq: &mut [f64]) {
    let mut j = j.clone();
    for (k, &ok) in free.iter().enumerate() {
        if !ok {
            j.column_mut(k).fill(0.0);
        }
    }
    let jjt: Matrix3<f64> = &j * j.transpose() + Matrix3::identity() * (damping * damping);
    let Some(chol) = jjt.cholesky() else {
        return;
    };
    let y = chol.solve(f);
    let step = j.transpose() * y;
    for (d, s) in dq.iter_mut().zip(step.iter()) {
        *d += sign * s;
    }
}

fn min_distance(hits: &[Option<Closest>]) -> f64 {
    hits.iter()
        .flatten()
        .map(|h| h.distance)
        .fold(f64::INFINITY, f64::min)
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
