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
    /// [`Error::Choice`] for any other name.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "step" => Ok(Schedule::Step),
            "smooth" => Ok(Schedule::Smooth),
            _ => Err(Error::Choice {
                arg: "schedule".to_owned(),
                value: name.to_owned(),
                reason: "unknown schedule; expected \"step\" or \"smooth\"".to_owned(),
            }),
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

/// Which ends of a [`FloatField`]'s range are accepted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ends {
    /// `[min, max]`.
    Closed,
    /// `(min, max]`: a gain of 0 would never move.
    OpenMin,
    /// `(min, max]` or `+∞` (no cap).
    OpenMinOrInfinite,
}

/// One floating-point field of [`Gains`] with its bounds. [`Gains::FLOAT_FIELDS`] is the
/// one list that the validation, the Python binding's properties, keywords, `as_dict`
/// and pickling iterate.
#[derive(Debug, Clone, Copy)]
pub struct FloatField {
    /// The field's name.
    pub name: &'static str,
    /// The field's documentation (its doc comment, one line per line).
    pub doc: &'static str,
    /// Reads the field.
    pub get: fn(&Gains) -> f64,
    /// Writes the field.
    pub set: fn(&mut Gains, f64),
    /// Lower bound.
    pub min: f64,
    /// Upper bound.
    pub max: f64,
    /// Which ends are accepted.
    pub ends: Ends,
    /// The range as error messages state it.
    pub range: &'static str,
}

impl FloatField {
    /// Whether `v` lies in the field's range (NaN never does).
    pub fn accepts(&self, v: f64) -> bool {
        match self.ends {
            Ends::Closed => v >= self.min && v <= self.max,
            Ends::OpenMin => v > self.min && v <= self.max,
            Ends::OpenMinOrInfinite => v == f64::INFINITY || (v > self.min && v <= self.max),
        }
    }
}

/// Declares [`Gains`] once: each float field with its doc comment and its bounds
/// (`floats`), then the other fields (`others`). It generates the struct (each float's
/// doc ends with its range), [`Gains::FLOAT_FIELDS`] and [`Gains::OTHER_FIELDS`].
macro_rules! declare_gains {
    (
        $(#[doc = $sdoc:literal])*
        pub struct Gains {
            floats {
                $(
                    $(#[doc = $doc:literal])*
                    pub $name:ident: f64 in ($min:expr, $max:expr, $ends:ident, $range:literal),
                )*
            }
            others {
                $(
                    $(#[doc = $odoc:literal])*
                    pub $oname:ident: $oty:ty,
                )*
            }
        }
    ) => {
        $(#[doc = $sdoc])*
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub struct Gains {
            $(
                $(#[doc = $doc])*
                #[doc = ""]
                #[doc = concat!("Accepted range: ", $range, ".")]
                pub $name: f64,
            )*
            $(
                $(#[doc = $odoc])*
                pub $oname: $oty,
            )*
        }

        impl Gains {
            /// Every float field with its bounds, in declaration order.
            pub const FLOAT_FIELDS: &'static [FloatField] = &[
                $(FloatField {
                    name: stringify!($name),
                    doc: concat!($($doc, "\n"),*),
                    get: |g: &Gains| g.$name,
                    set: |g: &mut Gains, v: f64| g.$name = v,
                    min: $min,
                    max: $max,
                    ends: Ends::$ends,
                    range: $range,
                }),*
            ];

            /// The fields that are not floats (`schedule`, `axis_mask`), in order.
            pub const OTHER_FIELDS: &'static [&'static str] = &[$(stringify!($oname)),*];
        }
    };
}

declare_gains! {
    /// All tuning parameters. Field names follow the paper's symbols.
    pub struct Gains {
        floats {
            /// α of eq. (7), conventional resolved rate (dimensionless, per step).
            pub conventional_alpha: f64 in (0.0, 2.0, OpenMin, "(0, 2]"),
            /// α₂ of eq. (13), position over joint limits.
            pub position_alpha: f64 in (0.0, 2.0, OpenMin, "(0, 2]"),
            /// γ₂ of eq. (13)/(23), joint-limit weight in position mode (m², ≤ 0).
            pub position_gamma: f64 in
                (-1.0, 0.0, Closed, "[-1, 0] m² (a negative weight descends H)"),
            /// Switch distance of γ₂ on ‖e_p‖ (m); eq. (23): 30 mm.
            pub position_switch: f64 in (0.0, 10.0, Closed, "[0, 10] m"),
            /// α₃ of eq. (13), orientation over joint limits.
            pub orientation_alpha: f64 in (0.0, 2.0, OpenMin, "(0, 2]"),
            /// γ₃ of eq. (13)/(24), joint-limit weight in orientation mode (m², ≤ 0).
            pub orientation_gamma: f64 in
                (-1.0, 0.0, Closed, "[-1, 0] m² (a negative weight descends H)"),
            /// Switch distance of γ₃ on ‖e_ζ‖ (rad); eq. (24): 30°.
            pub orientation_switch: f64 in (0.0, std::f64::consts::PI, Closed, "[0, π] rad"),
            /// α₄ of eq. (20).
            pub hybrid_alpha: f64 in (0.0, 2.0, OpenMin, "(0, 2]"),
            /// γ₆ of eq. (20), weight of the position task.
            pub hybrid_position: f64 in (0.0, 10.0, Closed, "[0, 10]"),
            /// γ₄ of eq. (20), weight of the orientation task (in the null space of position).
            pub hybrid_orientation: f64 in (0.0, 10.0, Closed, "[0, 10]"),
            /// γ₅ of eq. (20)/(25), joint-limit weight in hybrid mode (m², ≤ 0).
            pub hybrid_gamma: f64 in
                (-1.0, 0.0, Closed, "[-1, 0] m² (a negative weight descends H)"),
            /// Switch distance of γ₅ on ‖e_p‖ (m); eq. (25): 50 mm.
            pub hybrid_switch: f64 in (0.0, 10.0, Closed, "[0, 10] m"),
            /// Largest damping λ of the damped least-squares pseudo-inverses (m for position,
            /// rad for orientation rows; applied only near a singularity).
            pub damping: f64 in (0.0, 1.0, Closed, "[0, 1]"),
            /// Smallest singular value below which damping starts (same units as J).
            pub singular_threshold: f64 in (0.0, 1.0, Closed, "[0, 1]"),
            /// `damping` of a step that closes the loop through the plant (a measured pose is
            /// given, with or without a lag prediction). Larger than `damping` because the
            /// plant is not the model: along a direction where the model's (reduced) Jacobian
            /// has a small singular value σ, the plant's response differs from σ by the model
            /// error, so an undamped 1/σ turns it into a loop gain far above α; near the
            /// joint limits this is what limit-cycles through the play (docs/control.md §3).
            pub loop_damping: f64 in (0.0, 1.0, Closed, "[0, 1]"),
            /// `singular_threshold` of a closed-loop step (see `loop_damping`).
            pub loop_singular_threshold: f64 in (0.0, 1.0, Closed, "[0, 1]"),
            /// Fraction of each actuator range next to a limit where ∇H is frozen at its value
            /// at the band's edge, so that it stays finite at and beyond the limits. Below
            /// ~1e-6 of the range, ∇H at the band's edge (∝ 1/margin²) is no longer a
            /// meaningful number; 0 would make it infinite.
            pub limit_margin: f64 in (1e-6, 0.45, Closed, "[1e-6, 0.45]"),
            /// Largest Euclidean norm of the task part of one increment Δq (m); a longer one is
            /// shortened along its direction. The joint-limit part is capped at half of it.
            /// `f64::INFINITY` disables both caps.
            pub max_step: f64 in (0.0, 1.0, OpenMinOrInfinite, "(0, 1] m or inf"),
            /// First-order lag of the actuators, sensor filter included, in control periods
            /// (`τ / T`), that a closed-loop step (one given a measured pose and no lag
            /// prediction) must tolerate. The mode's largest task gain (α, or α₄ max(γ₆, γ₄) in
            /// hybrid mode) is then capped at [`lag_alpha`]`(lag_periods)`, the largest gain for
            /// which an integrator behind that lag does not overshoot (see `docs/control.md`);
            /// the other weights keep their ratios.
            /// 0 = no lag: no cap. Steps on the model (no measurement, and `solve`) are not capped.
            pub lag_periods: f64 in (0.0, 1e4, Closed, "[0, 10000] control periods"),
            /// `k_r` of the repulsion law (planning paper eq. 9): the closest arm point of an
            /// obstacle is pushed away by `k_r (1/g − 1/ρ₀) / g²` metres per step, with `g` the
            /// surface gap (clamped at 1 mm) and ρ₀ = `influence_distance` (m⁴ per step).
            pub repulsion_gain: f64 in (0.0, 1e-3, Closed, "[0, 1e-3] m⁴"),
            /// ρ₀ of eq. (9): surface gap (m) below which an obstacle repels.
            pub influence_distance: f64 in (0.0, 1.0, Closed, "[0, 1] m"),
            /// Radius (m) of every obstacle about its centre line (a cane's by default). The
            /// surface gap is, piece by piece of the resolver's body, the exact backbone
            /// distance less the piece's radius and this.
            pub obstacle_radius: f64 in (0.0, 1.0, Closed, "[0, 1] m"),
        }
        others {
            /// Step or smooth scheduling of every joint-limit weight.
            pub schedule: Schedule,
            /// Which components (x, y, z, base frame) of the orientation error are controlled;
            /// the paper controls x and z (IV-D).
            pub axis_mask: [bool; 3],
        }
    }
}

// The body's radii are declared once, in [`crate::body`].
pub use crate::body::{ACTUATOR_RADIUS, CANE_RADIUS};

/// Lag the default gains tolerate in closed loop (control periods): 20, i.e. 1 s at the
/// 50 ms period of the harvest, the slow end of pneumatic regulators behind long hoses.
pub const DEFAULT_LAG_PERIODS: f64 = 20.0;

/// The largest integrator gain α that keeps the loop `u ← u + α e` around a first-order
/// lag of `lag_periods` control periods free of overshoot: `tanh(1 / (4 N))`.
///
/// Derivation (docs/control.md): with `a = exp(−1/N)` the closed loop has the
/// characteristic polynomial `z² − (1 + a − α(1 − a)) z + a`; it is stable for
/// `α < 2(1 + a)/(1 − a)`, but its poles are real (no overshoot, hence no limit cycle
/// through play hysteresis) only for `α ≤ (1 − √a)/(1 + √a) = tanh(1/(4N))`, where both
/// poles sit at `√a`, the fastest decay the lag allows. `N = 0` gives 1.
#[inline]
pub fn lag_alpha(lag_periods: f64) -> f64 {
    if lag_periods <= 0.0 {
        1.0
    } else {
        (0.25 / lag_periods).tanh()
    }
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
            // The paper has no closed-loop damping of its own: the same values.
            loop_damping: 0.02,
            loop_singular_threshold: 0.05,
            limit_margin: 0.01,
            max_step: 0.005,
            lag_periods: 0.0,
            repulsion_gain: 1.5e-9,
            influence_distance: 0.03,
            obstacle_radius: CANE_RADIUS,
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
            // Twice the threshold and 2.5 times the damping in closed loop: the largest
            // gain σ/(σ² + λ²) of a damped direction drops from 27 to 11.5
            // (docs/control.md §3).
            loop_damping: 0.05,
            loop_singular_threshold: 0.1,
            limit_margin: 0.01,
            max_step: 0.004,
            lag_periods: DEFAULT_LAG_PERIODS,
            // 1 mm per step at a 1 cm gap, 0 at 3 cm (ρ₀).
            repulsion_gain: 1.5e-9,
            influence_distance: 0.03,
            obstacle_radius: CANE_RADIUS,
        }
    }

    /// [`Gains::blackberry`] for a plant whose actuators (sensor filter included) lag
    /// with time constant `tau_s` behind commands sent every `period_s` seconds: the
    /// closed-loop α cap of [`lag_alpha`] at `tau_s / period_s` periods instead of the
    /// default's 20.
    ///
    /// # Errors
    /// [`Error::Parameter`] for a `tau_s` not in [0, 100] s or a `period_s` not in
    /// (0, 10] s.
    pub fn for_lag(tau_s: f64, period_s: f64) -> Result<Self> {
        super::lag::check_lag(tau_s, period_s)?;
        let g = Gains {
            lag_periods: tau_s / period_s,
            ..Gains::blackberry()
        };
        g.validate()?;
        Ok(g)
    }

    /// The (singular threshold, damping) of the damped pseudo-inverses: the `loop_*` pair
    /// when the step closes the loop through the plant (`closed_loop`, with or without a
    /// lag prediction), else the model's pair.
    pub fn dls(&self, closed_loop: bool) -> (f64, f64) {
        if closed_loop {
            (self.loop_singular_threshold, self.loop_damping)
        } else {
            (self.singular_threshold, self.damping)
        }
    }

    /// The α of `mode`'s step, capped at [`lag_alpha`] when the step closes the loop
    /// through the plant (`closed_loop`) and no predictor accounts for the lag.
    pub fn effective_alpha(&self, alpha: f64, closed_loop: bool) -> f64 {
        if closed_loop {
            alpha.min(lag_alpha(self.lag_periods))
        } else {
            alpha
        }
    }

    /// Checks every float field against its range in [`Gains::FLOAT_FIELDS`] (physically
    /// meaningful ranges, so that no step can overflow into a non-finite command).
    ///
    /// # Errors
    /// [`Error::Parameter`] naming the first field (in declaration order) outside its
    /// range: an α not in (0, 2]; a task weight (γ₄, γ₆) not in [0, 10]; a joint-limit
    /// weight (γ₂, γ₃, γ₅) not in [−1, 0] m²; a position switch distance not in [0, 10] m or
    /// the orientation one not in [0, π]; damping or threshold not in [0, 1];
    /// `limit_margin` not in [1e-6, 0.45]; `max_step` not in (0, 1] m or infinite;
    /// `lag_periods` not in [0, 10 000]; `repulsion_gain` not in [0, 1e-3];
    /// `influence_distance` or `obstacle_radius` not in [0, 1] m.
    pub fn validate(&self) -> Result<()> {
        for f in Self::FLOAT_FIELDS {
            let v = (f.get)(self);
            if !f.accepts(v) {
                return Err(Error::parameter(
                    f.name,
                    v,
                    format!("must lie in {}", f.range),
                ));
            }
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
