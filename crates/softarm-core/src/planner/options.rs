//! Planner options and termination reasons.

use crate::error::{Error, Result, MAX_ITERATIONS};

/// Why [`super::PotentialFieldPlanner::plan`] stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Termination {
    /// The tip is within the goal tolerance.
    Reached,
    /// The tip moved less than `stall_tolerance` over `stall_window` iterations.
    Stalled,
    /// `max_iterations` were taken.
    IterationLimit,
    /// The step of eq. (9) was not finite (an undamped pseudo-inverse at a singularity).
    NonFiniteStep,
}

impl Termination {
    /// Lower-case name: "reached", "stalled", "iteration_limit", "non_finite_step".
    pub fn name(&self) -> &'static str {
        match self {
            Termination::Reached => "reached",
            Termination::Stalled => "stalled",
            Termination::IterationLimit => "iteration_limit",
            Termination::NonFiniteStep => "non_finite_step",
        }
    }
}

/// Gains and limits of the potential-field planner (eq. 9). Lengths in m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlannerOptions {
    /// `k_a` in `F_e = k_a V_e` (per iteration).
    pub attraction_gain: f64,
    /// Largest commanded tip displacement per iteration (m).
    pub max_tip_step: f64,
    /// `k_r` in `F_s = k_r (1/d − 1/ρ0) V̂ / d²` (m⁴).
    pub repulsion_gain: f64,
    /// Influence distance `ρ0`: obstacles farther than this exert no force (m).
    pub influence_distance: f64,
    /// Largest change of a coordinate per iteration, as a fraction of its range.
    pub max_step_fraction: f64,
    /// Damping `λ` of the pseudo-inverses.
    pub damping: f64,
    /// Distance of the tip to the goal that counts as reached (m).
    pub goal_tolerance: f64,
    /// Iteration limit.
    pub max_iterations: usize,
    /// Window (iterations) of the stall test.
    pub stall_window: usize,
    /// Tip progress over the window below which the plan has stalled (m).
    pub stall_tolerance: f64,
    /// `None`: exact closest points on the arcs (the proposed method). `Some(m)`: the
    /// paper's baseline, `m` points per section and brute-force distances.
    pub arm_samples: Option<usize>,
}

impl Default for PlannerOptions {
    /// Tuned for the planning paper's arm (three segments of length 1).
    fn default() -> Self {
        PlannerOptions {
            attraction_gain: 1.0,
            max_tip_step: 0.15,
            repulsion_gain: 3e-5,
            influence_distance: 0.1,
            max_step_fraction: 0.04,
            damping: 0.05,
            goal_tolerance: 0.01,
            max_iterations: 500,
            stall_window: 20,
            stall_tolerance: 1e-3,
            arm_samples: None,
        }
    }
}

/// Largest gain, tolerance or distance option (in its own unit): far beyond any arm, and
/// small enough that a step (gains times distances, divided by squared distances of at
/// least 1 µm) stays finite.
pub const MAX_OPTION: f64 = 1e3;

/// Most arm points per section of the sampled baseline (brute force, per obstacle point
/// and per iteration).
pub const MAX_ARM_SAMPLES: usize = 10_000;

impl PlannerOptions {
    /// Checks every option.
    ///
    /// # Errors
    /// [`Error::Parameter`] naming the first option out of its range: the gains,
    /// distances and tolerances finite, positive and at most [`MAX_OPTION`] (the repulsion
    /// gain, the damping and the stall tolerance may be 0), `max_step_fraction` in (0, 1],
    /// `max_iterations` and `stall_window` at most [`MAX_ITERATIONS`] (the window at least
    /// 1), `arm_samples` in [2, [`MAX_ARM_SAMPLES`]] when set.
    pub fn validate(&self) -> Result<()> {
        for (name, v, allow_zero, max) in [
            ("attraction_gain", self.attraction_gain, false, MAX_OPTION),
            ("max_tip_step", self.max_tip_step, false, MAX_OPTION),
            ("repulsion_gain", self.repulsion_gain, true, MAX_OPTION),
            (
                "influence_distance",
                self.influence_distance,
                false,
                MAX_OPTION,
            ),
            ("max_step_fraction", self.max_step_fraction, false, 1.0),
            ("damping", self.damping, true, MAX_OPTION),
            ("goal_tolerance", self.goal_tolerance, false, MAX_OPTION),
            ("stall_tolerance", self.stall_tolerance, true, MAX_OPTION),
        ] {
            let ok = v.is_finite() && (v > 0.0 || (allow_zero && v == 0.0)) && v <= max;
            if !ok {
                let low = if allow_zero { "[0" } else { "(0" };
                return Err(Error::parameter(
                    name,
                    v,
                    format!("must be finite and in {low}, {max}]"),
                ));
            }
        }
        for (name, v, min, max) in [
            ("max_iterations", self.max_iterations, 0, MAX_ITERATIONS),
            ("stall_window", self.stall_window, 1, MAX_ITERATIONS),
            (
                "arm_samples",
                self.arm_samples.unwrap_or(2),
                2,
                MAX_ARM_SAMPLES,
            ),
        ] {
            if v < min || v > max {
                return Err(Error::parameter(
                    name,
                    v as f64,
                    format!("must be an integer in [{min}, {max}]"),
                ));
            }
        }
        Ok(())
    }
}
