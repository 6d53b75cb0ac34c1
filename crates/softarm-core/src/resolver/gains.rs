//! Gains of the resolver and their scheduling by error norm (redundancy paper
//! eq. (12), (13), (20) and (23)–(25)).
//!
//! Units. Every step is a discrete increment `Δq = α·(…)` (eq. 7 with the `Δt` cancelled),
//! so each `α` is a dimensionless fraction of the task error removed per step and each task
//! weight `γ₄, γ₆` is dimensionless. The joint-limit weights `γ₂, γ₃, γ₅` multiply
//! `∇H` (eq. 14), which has units of 1/m because `H` is dimensionless and `q` is in
//! metres; so they are in m² (the increment `γ ∇H` is in m). A negative weight descends
//! `H`, i.e. pushes every actuator towards the middle of its range.

use crate::error::{Error, Result};

/// How a joint-limit weight is switched on and off with the task error `e`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Schedule {
    /// The paper's switch (eq. 23–25): `γ` when `‖e‖ > d`, 0 otherwise.
    Step,
    /// A smooth, continuous schedule `γ · e² / (e² + d²)`: 0 at `e = 0`, `γ/2` at the
    /// switch distance `d`, → `γ` far from the target. No jump in the command.
    Smooth,
}

impl Schedule {
    /// The scheduled weight for gain `gamma`, switch distance `switch` and error norm `e`.
    #[inline]
    pub fn weight(self, gamma: f64, switch: f64, e: f64) -> f64 {
        match self {
            Schedule::Step => {
                if e > switch {
                    gamma
                } else {
                    0.0
                }
            }
            Schedule::Smooth => {
                let e2 = e * e;
                let d2 = switch * switch;
                if e2 + d2 > 0.0 {
                    gamma * e2 / (e2 + d2)
                } else {
                    0.0
                }
            }
        }
    }

    /// Parses `"step"` or `"smooth"`.
    ///
    /// # Errors
    /// [`Error::Parameter`] for any other name.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "step" => Ok(Schedule::Step),
            "smooth" => Ok(Schedule::Smooth),
            _ => Err(Error::parameter(
                "schedule",
                f64::NAN,
                format!("unknown schedule {name:?}; expected \"step\" or \"smooth\""),
            )),
        }
    }

    /// The name accepted by [`Schedule::parse`].
    pub fn name(self) -> &'static str {
        match self {
            Schedule::Step => "step",
            Schedule::Smooth => "smooth",
        }
    }
}

/// All tuning parameters. Field names follow the paper's symbols.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gains {
    /// α of eq. (7), conventional resolved rate (dimensionless, per step).
    pub conventional_alpha: f64,
    /// α₂ of eq. (13), position over joint limits.
    pub position_alpha: f64,
    /// γ₂ of eq. (13)/(23), joint-limit weight in position mode (m², ≤ 0).
    pub position_gamma: f64,
    /// Switch distance of γ₂ on ‖e_p‖ (m); eq. (23): 30 mm.
    pub position_switch: f64,
    /// α₃ of eq. (13), orientation over joint limits.
    pub orientation_alpha: f64,
    /// γ₃ of eq. (13)/(24), joint-limit weight in orientation mode (m², ≤ 0).
    pub orientation_gamma: f64,
    /// Switch distance of γ₃ on ‖e_ζ‖ (rad); eq. (24): 30°.
    pub orientation_switch: f64,
    /// α₄ of eq. (20).
    pub hybrid_alpha: f64,
    /// γ₆ of eq. (20), weight of the position task.
    pub hybrid_position: f64,
    /// γ₄ of eq. (20), weight of the orientation task (in the null space of position).
    pub hybrid_orientation: f64,
    /// γ₅ of eq. (20)/(25), joint-limit weight in hybrid mode (m², ≤ 0).
    pub hybrid_gamma: f64,
    /// Switch distance of γ₅ on ‖e_p‖ (m); eq. (25): 50 mm.
    pub hybrid_switch: f64,
    /// Step or smooth scheduling of every joint-limit weight.
    pub schedule: Schedule,
    /// Which components (x, y, z, base frame) of the orientation error are controlled;
    /// the paper controls x and z (IV-D).
    pub axis_mask: [bool; 3],
    /// Largest damping λ of the damped least-squares pseudo-inverses (m for position,
    /// rad for orientation rows; applied only near a singularity).
    pub damping: f64,
    /// Smallest singular value below which damping starts (same units as J).
    pub singular_threshold: f64,
    /// Fraction of each actuator range next to a limit where ∇H is frozen at its value
    /// at the band's edge, so that it stays finite at and beyond the limits.
    pub limit_margin: f64,
    /// Largest Euclidean norm of the task part of one increment Δq (m); a longer one is
    /// shortened along its direction. The joint-limit part is capped at half of it.
    /// `f64::INFINITY` disables both caps.
    pub max_step: f64,
}

impl Gains {
    /// The gains printed in the paper, eq. (23)–(25) and IV-B/IV-C, taken as numbers in
    /// the units above (the paper gives none). α₃ is not printed for the proposed
    /// orientation controller; the conventional value 0.05 is used. `max_step` (5 mm)
    /// is not in the paper: with `q` in metres, γ₂ = −0.01 m² gives increments of
    /// metres next to a limit, and the cap keeps them physical.
    pub fn paper() -> Self {
        Gains {
            conventional_alpha: 0.074,
            position_alpha: 0.074,
            position_gamma: -0.01,
            position_switch: 0.030,
            orientation_alpha: 0.05,
            orientation_gamma: -0.005,
            orientation_switch: 30f64.to_radians(),
            hybrid_alpha: 0.05,
            hybrid_position: 1.0,
            hybrid_orientation: 0.1,
            hybrid_gamma: -5e-5,
            hybrid_switch: 0.050,
            schedule: Schedule::Step,
            axis_mask: [true, false, true],
            damping: 0.02,
            singular_threshold: 0.05,
            limit_margin: 0.01,
            max_step: 0.005,
        }
    }

    /// Gains tuned for [`crate::SoftArm::blackberry`] (and arms of similar size): they
    /// converge with the model alone and in closed loop on the simulated plant.
    pub fn blackberry() -> Self {
        Gains {
            conventional_alpha: 0.3,
            position_alpha: 0.3,
            position_gamma: -2e-6,
            position_switch: 0.030,
            orientation_alpha: 0.3,
            orientation_gamma: -2e-6,
            orientation_switch: 30f64.to_radians(),
            hybrid_alpha: 0.3,
            hybrid_position: 1.0,
            hybrid_orientation: 0.5,
            hybrid_gamma: -2e-6,
            hybrid_switch: 0.050,
            schedule: Schedule::Smooth,
            axis_mask: [true, false, true],
            damping: 0.02,
            singular_threshold: 0.05,
            limit_margin: 0.01,
            max_step: 0.004,
        }
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`Error::Parameter`] naming the first invalid field: α not in (0, 2], a γ task
    /// weight negative or non-finite, a joint-limit weight positive or non-finite, a
    /// switch distance negative, damping or threshold negative, margin not in [0, 0.5),
    /// `max_step` not positive.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("conventional_alpha", self.conventional_alpha),
            ("position_alpha", self.position_alpha),
            ("orientation_alpha", self.orientation_alpha),
            ("hybrid_alpha", self.hybrid_alpha),
        ] {
            if !(v > 0.0 && v <= 2.0) {
                return Err(Error::parameter(name, v, "must lie in (0, 2]"));
            }
        }
        for (name, v) in [
            ("hybrid_position", self.hybrid_position),
            ("hybrid_orientation", self.hybrid_orientation),
            ("position_switch", self.position_switch),
            ("orientation_switch", self.orientation_switch),
            ("hybrid_switch", self.hybrid_switch),
            ("damping", self.damping),
            ("singular_threshold", self.singular_threshold),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::parameter(name, v, "must be finite and >= 0"));
            }
        }
        for (name, v) in [
            ("position_gamma", self.position_gamma),
            ("orientation_gamma", self.orientation_gamma),
            ("hybrid_gamma", self.hybrid_gamma),
        ] {
            if !(v.is_finite() && v <= 0.0) {
                return Err(Error::parameter(
                    name,
                    v,
                    "must be finite and <= 0 (a negative weight descends H)",
                ));
            }
        }
        if !(self.limit_margin >= 0.0 && self.limit_margin < 0.5) {
            return Err(Error::parameter(
                "limit_margin",
                self.limit_margin,
                "must lie in [0, 0.5)",
            ));
        }
        if self.limit_margin == 0.0 {
            // ∇H is infinite at a limit; a zero margin would let it blow up.
            return Err(Error::parameter(
                "limit_margin",
                0.0,
                "must be > 0 (∇H is infinite at a limit)",
            ));
        }
        if self.max_step.is_nan() || self.max_step <= 0.0 {
            return Err(Error::parameter("max_step", self.max_step, "must be > 0"));
        }
        Ok(())
    }
}

impl Default for Gains {
    fn default() -> Self {
        Gains::blackberry()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valid() {
        assert!(Gains::paper().validate().is_ok());
        assert!(Gains::blackberry().validate().is_ok());
    }

    #[test]
    fn step_schedule_switches_at_the_distance() {
        assert_eq!(Schedule::Step.weight(-1.0, 0.03, 0.031), -1.0);
        assert_eq!(Schedule::Step.weight(-1.0, 0.03, 0.03), 0.0);
    }

    #[test]
    fn smooth_schedule_is_continuous_and_half_at_the_switch() {
        let s = Schedule::Smooth;
        assert!((s.weight(-1.0, 0.03, 0.03) + 0.5).abs() < 1e-15);
        assert_eq!(s.weight(-1.0, 0.03, 0.0), 0.0);
        assert_eq!(s.weight(-1.0, 0.0, 0.0), 0.0);
        let (a, b) = (s.weight(-1.0, 0.03, 0.03), s.weight(-1.0, 0.03, 0.030_001));
        assert!((a - b).abs() < 1e-4);
    }

    #[test]
    fn bad_fields_are_named() {
        let mut g = Gains::blackberry();
        g.hybrid_gamma = 1.0;
        match g.validate() {
            Err(Error::Parameter { arg, .. }) => assert_eq!(arg, "hybrid_gamma"),
            other => panic!("unexpected {other:?}"),
        }
        assert!(Schedule::parse("linear").is_err());
    }
}
