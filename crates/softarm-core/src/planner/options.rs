//! Planner options and termination reasons.

use crate::error::{Error, Result};

/// Why [`super::PotentialFieldPlanner::plan`] stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Termination {
    /// The tip is within the goal tolerance.
    Reached,
    /// The tip moved less than `stall_tolerance` over `stall_window` iterations.
    Stalled,
    /// `max_iterations` were taken.
    IterationLimit,
}

impl Termination {
    /// Lower-case name: "reached", "stalled", "iteration_limit".
    pub fn name(&self) -> &'static str {
        match self {
            Termination::Reached => "reached",
            Termination::Stalled => "stalled",
            Termination::IterationLimit => "iteration_limit",
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
            attraction_gain: 0.5,
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

impl PlannerOptions {
    /// Checks every option.
    ///
    /// # Errors
    /// [`Error::Parameter`] naming the first option that is not finite and positive (the
    /// damping may be 0; `arm_samples` must be at least 2 when set).
    pub fn validate(&self) -> Result<()> {
        for (name, v, allow_zero) in [
            ("attraction_gain", self.attraction_gain, false),
            ("max_tip_step", self.max_tip_step, false),
            ("repulsion_gain", self.repulsion_gain, true),
            ("influence_distance", self.influence_distance, false),
            ("max_step_fraction", self.max_step_fraction, false),
            ("damping", self.damping, true),
            ("goal_tolerance", self.goal_tolerance, false),
            ("stall_tolerance", self.stall_tolerance, true),
        ] {
            let ok = v.is_finite() && (v > 0.0 || (allow_zero && v == 0.0));
            if !ok {
                return Err(Error::parameter(
                    name,
                    v,
                    if allow_zero {
                        "must be finite and not negative"
                    } else {
                        "must be finite and positive"
                    },
                ));
            }
        }
        if self.stall_window == 0 {
            return Err(Error::parameter("stall_window", 0.0, "must be at least 1"));
        }
        if let Some(m) = self.arm_samples {
            if m < 2 {
                return Err(Error::parameter(
                    "arm_samples",
                    m as f64,
                    "must be at least 2",
                ));
            }
        }
        Ok(())
    }
}
