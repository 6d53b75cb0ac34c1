//! Gain-scheduled task-priority redundancy resolution (redundancy paper III-B, III-C).
//!
//! Four controllers, all discrete resolved-rate steps `q ← clamp(q + Δq)`:
//!
//! | [`Mode`] | Δq |
//! | --- | --- |
//! | `Conventional` | `α J⁺ e` (eq. 7), with the full Jacobian for a pose target (masked orientation rows) or the position Jacobian for a point target |
//! | `Position` | `α₂ (J_v⁺ e_p + γ₂ (I − J_v⁺ J_v) ∇H)` (eq. 13, task 1 over 3) |
//! | `Orientation` | `α₃ (J_ω⁺ e_ζ + γ₃ (I − J_ω⁺ J_ω) ∇H)` (eq. 13, task 2 over 3) |
//! | `Hybrid` | `α₄ [γ₆ J_v⁺ e_p + γ₄ J̃_v⁺ (e_ζ − J_ω J_v⁺ e_p) + γ₅ (I − J_v⁺ J_v − J̃_v⁺ J̃_v) ∇H]` (eq. 20, J̃_v of eq. 17) |
//!
//! The joint-limit weights γ₂, γ₃, γ₅ are scheduled by the task error norm
//! ([`Schedule`]); ∇H is the gradient of the joint-limit cost of eq. (14)
//! ([`joint_limits`]); pseudo-inverses are damped near singularities ([`pinv`]). The
//! command never leaves `[lower, upper]`: it is clamped, and the step reports it.
//!
//! # Example
//! ```
//! use softarm_core::resolver::{Gains, Mode, Resolver, SolveOptions, Target};
//! use softarm_core::{Kinematics, SoftArm};
//! let arm = SoftArm::blackberry();
//! let goal = arm.forward(&[0.01, 0.02, 0.005, 0.015, 0.0, 0.02, 0.01, 0.01, 0.03]).unwrap();
//! let res = Resolver::new(arm, Mode::Hybrid, Gains::blackberry()).unwrap();
//! let sol = res.solve(&[0.0166; 9], &Target::Pose(goal), &SolveOptions::default()).unwrap();
//! assert!(sol.converged && sol.position_error < 1e-4);
//! ```

pub mod avoid;
pub mod gains;
pub mod joint_limits;
pub mod lag;
pub mod orientation;
pub mod pinv;
mod saturation;
mod solve;
mod step;
mod tasks;

pub use gains::{lag_alpha, Gains, Schedule};
pub use lag::{
    lead_gain, play, play_into, predicted_alpha_min, predicted_loop_alpha, LagModel, LEAD_GAIN_CAP,
    PREDICTED_ALPHA_LAG_S, PREDICTED_ALPHA_MAX,
};
pub use solve::{Solution, SolveOptions, SolveTermination};
pub use step::{StepInfo, StepInput, Workspace};

use crate::body::Body;
use crate::error::{Error, Result};
use crate::kinematics::Kinematics;
use crate::math::{Mat4, Vec3};

/// Which controller a [`Resolver`] runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Eq. (7): `α J⁺ e`, no redundancy resolution, no joint-limit avoidance.
    Conventional,
    /// Eq. (13), first line: position over joint-limit avoidance.
    Position,
    /// Eq. (13), second line: orientation over joint-limit avoidance.
    Orientation,
    /// Eq. (20): position, then orientation, then joint-limit avoidance.
    Hybrid,
}

impl Mode {
    /// Parses `"conventional" | "position" | "orientation" | "hybrid"`.
    ///
    /// # Errors
    /// [`Error::Choice`] naming `mode` and the string for any other one.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "conventional" => Ok(Mode::Conventional),
            "position" => Ok(Mode::Position),
            "orientation" => Ok(Mode::Orientation),
            "hybrid" => Ok(Mode::Hybrid),
            _ => Err(Error::Choice {
                arg: "mode".to_owned(),
                value: name.to_owned(),
                reason: "unknown mode; expected \"conventional\", \"position\", \
                         \"orientation\" or \"hybrid\""
                    .to_owned(),
            }),
        }
    }

    /// The name accepted by [`Mode::parse`].
    pub fn name(self) -> &'static str {
        match self {
            Mode::Conventional => "conventional",
            Mode::Position => "position",
            Mode::Orientation => "orientation",
            Mode::Hybrid => "hybrid",
        }
    }
}

/// What the end effector should reach.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// A full pose (4×4, base frame). Accepted by every mode; `Position` mode uses
    /// only its translation.
    Pose(Mat4),
    /// A point (base frame). Accepted by `Position` and `Conventional` modes.
    Position(Vec3),
}

/// A resolver for one arm, mode, set of gains and body (the surfaces its obstacle task
/// keeps off the obstacles, [`avoid`]). Immutable: steps take a [`Workspace`] (or
/// allocate one), so one resolver can serve several threads.
#[derive(Debug, Clone)]
pub struct Resolver<K: Kinematics> {
    arm: K,
    mode: Mode,
    gains: Gains,
    body: Body,
}

impl<K: Kinematics> Resolver<K> {
    /// A resolver for `arm`, measuring the arm's default body
    /// ([`Kinematics::default_body`]: for a [`crate::SoftArm`], [`Body::for_arm`] with the
    /// gripper ending at the end-effector frame).
    ///
    /// # Errors
    /// [`Error::Parameter`] for invalid gains (see [`Gains::validate`]).
    pub fn new(arm: K, mode: Mode, gains: Gains) -> Result<Self> {
        gains.validate()?;
        let body = arm.default_body();
        Ok(Resolver {
            arm,
            mode,
            gains,
            body,
        })
    }

    /// This resolver with the obstacle task measuring `body` (e.g. the harvest's, whose
    /// gripper reaches the grasp point).
    ///
    /// # Errors
    /// [`Error::Shape`] naming `body` when it has another number of sections than the arm.
    pub fn with_body(self, body: Body) -> Result<Self> {
        let n = self.arm.n_sections();
        if body.section_radii().len() != n {
            return Err(Error::shape(
                "body",
                format!("{n} section radii, one per section of the arm"),
                body.section_radii().len().to_string(),
            ));
        }
        Ok(Resolver { body, ..self })
    }

    /// The arm model.
    pub fn arm(&self) -> &K {
        &self.arm
    }
    /// The mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }
    /// The gains.
    pub fn gains(&self) -> &Gains {
        &self.gains
    }
    /// The body the obstacle task measures.
    pub fn body(&self) -> &Body {
        &self.body
    }

    /// A workspace sized for this resolver's arm.
    pub fn workspace(&self) -> Workspace {
        Workspace::new(self.arm.n_dofs())
    }
}

/// One step's result, allocating form of [`Resolver::step_into`].
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// The next command, inside `[lower, upper]`.
    pub q: Vec<f64>,
    /// The command before clamping (`q + Δq`); what an unconstrained controller sends.
    pub unclamped: Vec<f64>,
    /// Errors at the input state and whether the command was clamped.
    pub info: StepInfo,
}
