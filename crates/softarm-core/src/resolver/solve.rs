//! Iterating steps to tolerance with the model alone.

use super::step::StepInput;
use super::{Mode, Resolver, Target};
use crate::distance::Obstacle;
use crate::error::{Error, Result};
use crate::kinematics::Kinematics;

/// Stopping rule of [`Resolver::solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveOptions {
    /// Largest number of steps.
    pub max_steps: usize,
    /// Position tolerance on ‖e_p‖ (m).
    pub position_tolerance: f64,
    /// Orientation tolerance on the masked ‖e_ζ‖ (rad).
    pub orientation_tolerance: f64,
}

impl Default for SolveOptions {
    /// 1000 steps, 0.1 mm, 0.1°.
    fn default() -> Self {
        SolveOptions {
            max_steps: 1000,
            position_tolerance: 1e-4,
            orientation_tolerance: 0.1f64.to_radians(),
        }
    }
}

/// Why [`Resolver::solve`] stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SolveTermination {
    /// Every controlled error is within its tolerance.
    Converged,
    /// A step left the configuration unchanged: the resolver cannot leave it (a singular
    /// configuration, such as the straight rest pose in position mode, where the
    /// position Jacobian loses the rank the error needs, or every coordinate that would
    /// help held at a limit). More steps would change nothing.
    Stuck,
    /// `max_steps` steps were taken without reaching the tolerances.
    StepLimit,
}

impl SolveTermination {
    /// Lower-case name: "converged", "stuck", "step_limit".
    pub fn name(&self) -> &'static str {
        match self {
            SolveTermination::Converged => "converged",
            SolveTermination::Stuck => "stuck",
            SolveTermination::StepLimit => "step_limit",
        }
    }
}

/// The result of [`Resolver::solve`].
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// The best configuration found (inside the limits).
    pub q: Vec<f64>,
    /// Whether every controlled error is within its tolerance at `q`.
    pub converged: bool,
    /// Steps run: the last configuration evaluated is `q0` after `steps` steps (at most
    /// `max_steps`).
    pub steps: usize,
    /// The step at which `q` was reached (`q0` after `best_step` steps; at most `steps`).
    pub best_step: usize,
    /// ‖e_p‖ at `q` (m).
    pub position_error: f64,
    /// Masked ‖e_ζ‖ at `q` (rad); 0 for a point target.
    pub orientation_error: f64,
    /// Why the iteration stopped.
    pub termination: SolveTermination,
}

impl<K: Kinematics> Resolver<K> {
    /// Iterates [`Resolver::step_into`] on the model from `q0` (first clamped into the
    /// limits) until the errors the mode controls are within tolerance, or `max_steps`.
    /// An unreachable target is not an error: it ends with `converged = false` and the
    /// best configuration seen (smallest error relative to the tolerances).
    ///
    /// # Errors
    /// As [`Resolver::step_into`]; [`Error::Parameter`] for a tolerance that is not
    /// positive and finite.
    pub fn solve(&self, q0: &[f64], target: &Target, opts: &SolveOptions) -> Result<Solution> {
        self.solve_with(q0, target, opts, &[])
    }

    /// [`Resolver::solve`] with `obstacles` repelling the model arm at every step
    /// (planning paper eq. 9, below every task; see [`super::avoid`]).
    ///
    /// # Errors
    /// As [`Resolver::solve`].
    pub fn solve_with(
        &self,
        q0: &[f64],
        target: &Target,
        opts: &SolveOptions,
        obstacles: &[Obstacle],
    ) -> Result<Solution> {
        for (name, v) in [
            ("position_tolerance", opts.position_tolerance),
            ("orientation_tolerance", opts.orientation_tolerance),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::parameter(name, v, "must be positive and finite"));
            }
        }
        let (use_p, use_o) = match (self.mode, target) {
            (Mode::Position, _) | (Mode::Conventional, Target::Position(_)) => (true, false),
            (Mode::Orientation, _) => (false, true),
            (Mode::Hybrid | Mode::Conventional, _) => (true, true),
        };
        let score = |ep: f64, eo: f64| {
            let a = if use_p {
                ep / opts.position_tolerance
            } else {
                0.0
            };
            let b = if use_o {
                eo / opts.orientation_tolerance
            } else {
                0.0
            };
            a.max(b)
        };
        let mut ws = self.workspace();
        let mut q = q0.to_vec();
        crate::chain::check_q(&self.arm, &q)?;
        self.arm_clamp(&mut q);
        let mut next = vec![0.0; q.len()];
        let mut best: Option<Solution> = None;
        let mut best_score = f64::INFINITY;
        let input = StepInput {
            obstacles,
            ..StepInput::default()
        };
        let mut termination = SolveTermination::StepLimit;
        let mut steps = 0;
        for k in 0..=opts.max_steps {
            steps = k;
            let info = self.step_input_into(&mut ws, &q, target, &input, &mut next)?;
            let s = score(info.position_error, info.orientation_error);
            if s < best_score || best.is_none() {
                best_score = s;
                best = Some(Solution {
                    q: q.clone(),
                    converged: s <= 1.0,
                    steps: k,
                    best_step: k,
                    position_error: info.position_error,
                    orientation_error: info.orientation_error,
                    termination,
                });
            }
            if s <= 1.0 {
                termination = SolveTermination::Converged;
                break;
            }
            if next == q {
                termination = SolveTermination::Stuck;
                break;
            }
            if k == opts.max_steps {
                break;
            }
            std::mem::swap(&mut q, &mut next);
        }
        let mut sol =
            best.ok_or_else(|| Error::parameter("max_steps", 0.0, "no step was taken"))?;
        sol.steps = steps;
        sol.termination = if sol.converged {
            SolveTermination::Converged
        } else {
            termination
        };
        Ok(sol)
    }

    fn arm_clamp(&self, q: &mut [f64]) {
        for ((v, lo), hi) in q.iter_mut().zip(self.arm.lower()).zip(self.arm.upper()) {
            *v = v.clamp(*lo, *hi);
        }
    }
}
