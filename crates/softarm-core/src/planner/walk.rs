//! One plan's walk (planning paper eq. 9): its state and the parts of each iteration,
//! from the repulsions to the observation of the new configuration.

use nalgebra::{DMatrix, Matrix3, Matrix3xX};

use super::{closest_sampled, PotentialFieldPlanner};
use crate::chain::{forward_jacobian_into, point_unchecked};
use crate::distance::{
    closest_to_arcs, closest_to_arcs_within, placed_arcs, Closest, Obstacle, PlacedArc,
};
use crate::kinematics::Kinematics;
use crate::math::Vec3;

/// The state of one plan: the path so far and the buffers of a step.
pub(super) struct Walk {
    /// Largest move of each coordinate per step (`max_step_fraction` of its range).
    pub(super) step_limit: Vec<f64>,
    /// The current configuration.
    pub(super) q: Vec<f64>,
    /// The 6×n Jacobian at `q`.
    pub(super) jac: DMatrix<f64>,
    /// The arcs at `q`.
    pub(super) arcs: Vec<PlacedArc>,
    /// Each obstacle's exact closest pair at `q`, `None` when provably irrelevant.
    pub(super) hits: Vec<Option<Closest>>,
    /// Smallest exact clearance so far.
    pub(super) min_clearance: f64,
    /// The tip at `q`.
    pub(super) tip: Vec3,
    /// Configurations so far, `q0` first.
    pub(super) path: Vec<Vec<f64>>,
    /// Tips so far.
    pub(super) tip_path: Vec<Vec3>,
    /// The step being computed.
    pub(super) dq: Vec<f64>,
    /// Coordinates not frozen at a limit.
    pub(super) free: Vec<bool>,
    /// The first (unprojected) pass's step.
    pub(super) first: Vec<f64>,
    /// Each repelling obstacle's point Jacobian and push.
    pub(super) repulsions: Vec<(Matrix3xX<f64>, Vec3)>,
}

impl<K: Kinematics> PotentialFieldPlanner<K> {
    /// The walk at `q0`: its exact closest pairs, clearance and tip.
    pub(super) fn start(&self, q0: &[f64], obstacles: &[Obstacle]) -> Walk {
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
    pub(super) fn repulsions(&self, walk: &mut Walk, obstacles: &[Obstacle]) {
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
    pub(super) fn attraction(&self, err: &Vec3) -> Vec3 {
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
    pub(super) fn projected_step(&self, walk: &mut Walk, dx: &Vec3) {
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
    pub(super) fn take_step(&self, walk: &mut Walk) {
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
    pub(super) fn observe(&self, walk: &mut Walk, obstacles: &[Obstacle]) {
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
    pub(super) fn stalled(&self, walk: &Walk, iterations: usize) -> bool {
        let o = &self.options;
        if iterations < o.stall_window {
            return false;
        }
        let back = walk.tip_path[walk.tip_path.len() - 1 - o.stall_window];
        (walk.tip - back).norm() < o.stall_tolerance
    }
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
