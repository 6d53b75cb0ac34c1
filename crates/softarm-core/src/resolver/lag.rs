//! A first-order lag model of the actuators: the predictor of the lag-aware closed loop.
//!
//! The regulators and the sensor filter delay what a command does. An integrator
//! `q ← q + α J⁺ e` that reads the measured error keeps integrating the error the plant
//! has not yet had time to remove, overshoots, and through play hysteresis limit-cycles
//! (docs/control.md). Given the elongations the plant has reached by now, `ŷ`, the step
//! removes from the measured error the motion still in flight, `J (q − ŷ)` (a Smith
//! predictor on the model): the loop then behaves like the lag-free iteration on the
//! model, and its gain no longer needs the lag bound of [`super::gains::lag_alpha`].
//! `ŷ` follows the command through the lag discretised exactly for commands held over a
//! period: `ŷ ← ŷ + (1 − e^(−T/τ)) (u − ŷ)`.

use crate::error::{check_finite, check_len, Error, Result};

/// `ŷ`: each actuator's elongation behind a first-order lag of the commands.
#[derive(Debug, Clone, PartialEq)]
pub struct LagModel {
    tau_s: f64,
    period_s: f64,
    gain: f64,
    state: Vec<f64>,
}

impl LagModel {
    /// A lag of time constant `tau_s` (s) sampled every `period_s` (s), settled at `q0`.
    ///
    /// # Errors
    /// [`Error::Parameter`] for `tau_s` not in [0, 100] or `period_s` not in (0, 10];
    /// [`Error::NonFinite`] for a non-finite `q0`.
    pub fn new(tau_s: f64, period_s: f64, q0: &[f64]) -> Result<Self> {
        check_lag(tau_s, period_s)?;
        check_finite("q0", q0)?;
        let gain = if tau_s == 0.0 {
            1.0
        } else {
            -(-period_s / tau_s).exp_m1()
        };
        Ok(LagModel {
            tau_s,
            period_s,
            gain,
            state: q0.to_vec(),
        })
    }

    /// The predicted elongations now.
    pub fn state(&self) -> &[f64] {
        &self.state
    }

    /// Time constant (s).
    pub fn tau_s(&self) -> f64 {
        self.tau_s
    }

    /// Period (s).
    pub fn period_s(&self) -> f64 {
        self.period_s
    }

    /// One period with `command` held: returns the predicted elongations at its end.
    ///
    /// # Errors
    /// [`Error::Shape`] / [`Error::NonFinite`] for a bad `command`.
    pub fn advance(&mut self, command: &[f64]) -> Result<&[f64]> {
        check_len("command", command, self.state.len())?;
        check_finite("command", command)?;
        for (y, u) in self.state.iter_mut().zip(command) {
            *y += self.gain * (u - *y);
        }
        Ok(&self.state)
    }

    /// Settles the model at `q` (after a reset of the plant).
    ///
    /// # Errors
    /// As [`LagModel::advance`].
    pub fn reset(&mut self, q: &[f64]) -> Result<()> {
        check_len("q", q, self.state.len())?;
        check_finite("q", q)?;
        self.state.copy_from_slice(q);
        Ok(())
    }
}

/// The play (backlash) operator, one channel: the output follows the input only once the
/// input has moved more than half the band `width` away from it,
/// `y = clip(y_prev, x − w/2, x + w/2)`. It depends on the path of the input, not on its
/// speed (a pneumatic muscle's braid friction). The one law of play of the project: the
/// simulated plant's hysteresis (`softarm.sim.hysteresis`) and the controller's model of
/// it (`softarm.harvest.plant_model`) both apply it. `width` ≥ 0 (checked by
/// [`play_into`]); for finite values it is numpy's `clip`, bit for bit.
#[inline]
pub fn play(output: f64, input: f64, width: f64) -> f64 {
    let half = 0.5 * width;
    output.max(input - half).min(input + half)
}

/// [`play`] on every channel: `output[k] ← play(output[k], input[k], width[k])`.
///
/// # Errors
/// [`Error::Shape`] for lengths that differ; [`Error::NonFinite`] for a non-finite
/// `output` or `input`; [`Error::Parameter`] for a width that is negative or not finite.
pub fn play_into(output: &mut [f64], input: &[f64], width: &[f64]) -> Result<()> {
    check_len("input", input, output.len())?;
    check_len("width", width, output.len())?;
    check_finite("output", output)?;
    check_finite("input", input)?;
    for &w in width {
        if !(w.is_finite() && w >= 0.0) {
            return Err(Error::parameter("width", w, "must be finite and >= 0"));
        }
    }
    for ((y, &x), &w) in output.iter_mut().zip(input).zip(width) {
        *y = play(*y, x, w);
    }
    Ok(())
}

/// The largest pre-compensation ("lead") gain [`lead_gain`] gives by default.
pub const LEAD_GAIN_CAP: f64 = 1.5;

/// The pre-compensation gain `k` for regulators of time constant `tau_s` driven every
/// `period_s`: they are told `q + k (q − ŷ)`, which a first-order regulator approaches
/// `1 + k` times faster. Half the overshoot-free bound `a/(1 − a)`, `a = e^(−T/τ)`
/// (docs/control.md, section 6), at most `cap` ([`LEAD_GAIN_CAP`] by default). The cap
/// (tuned on seeds 0–3) keeps the boosted commands near the planned path: a larger boost
/// saturates some channels at 0 or 70 psi and not others, and the arm leaves the straight
/// line in q between two plan waypoints that the canes were checked against. 0 for no lag.
///
/// # Errors
/// [`Error::Parameter`] for a `tau_s` that is negative or not finite, or a `period_s`
/// that is not finite and positive.
pub fn lead_gain(tau_s: f64, period_s: f64, cap: f64) -> Result<f64> {
    if !(tau_s.is_finite() && tau_s >= 0.0) {
        return Err(Error::parameter("tau_s", tau_s, "must be finite and >= 0"));
    }
    if !(period_s.is_finite() && period_s > 0.0) {
        return Err(Error::parameter(
            "period_s",
            period_s,
            "must be finite and > 0",
        ));
    }
    if tau_s == 0.0 {
        return Ok(0.0);
    }
    let a = (-period_s / tau_s).exp();
    Ok(cap.min(0.5 * a / (1.0 - a)))
}

/// The predicted loop's gain on a quick plant ([`predicted_loop_alpha`]). 0.9 keeps
/// `α (1 + δ) < 1` for a plant's gain up to 11 % above the model's, the range where the
/// lag-free iteration converges without overshoot.
pub const PREDICTED_ALPHA_MAX: f64 = 0.9;

/// The lag-time product (s) the predicted loop's gain keeps below on a slow plant
/// ([`predicted_loop_alpha`]): 0.21 s keeps τ = 0.3 s at the 0.6 it was tuned at.
pub const PREDICTED_ALPHA_LAG_S: f64 = 0.21;

/// The predicted loop's smallest gain, the floor on any plant: the hybrid mode's own gain
/// of the default gains ([`super::Gains::blackberry`]`.hybrid_alpha`, 0.3), read rather
/// than copied.
pub fn predicted_alpha_min() -> f64 {
    super::Gains::blackberry().hybrid_alpha
}

/// The resolver's gain for the loop closed through the lag model, for a measurement chain
/// lagging `lag_s` in all (regulators + measurement lag, s).
///
/// With an exact model the predicted loop is the lag-free iteration `u ← u + α J⁺ e(u)`
/// and any `0 < α < 1` converges without overshoot whatever the lag (docs/control.md,
/// section 2). What the model leaves out (the play, the measurement's true lag, an error
/// in τ) acts for a time that grows with the lag, so the gain is cut as the lag grows:
/// `α = PREDICTED_ALPHA_LAG_S / lag_s` between [`predicted_alpha_min`] (0.3) and
/// [`PREDICTED_ALPHA_MAX`] (0.9); 0.9 for no lag. Measured on seeds 0–3 at 5 psi of
/// play: 0.6 shortens fine positioning by a third at τ = 0.08 and 0.3 s against 0.3; at
/// τ = 0.08 s 0.9 is quicker again (3.2 → 2.8 s per berry), at τ = 0.3 s 0.69 was less
/// accurate than 0.6; at τ = 1 s both 0.45 and 0.6 were slower and less accurate than 0.3.
///
/// # Errors
/// [`Error::Parameter`] for a `lag_s` that is negative or not finite.
pub fn predicted_loop_alpha(lag_s: f64) -> Result<f64> {
    if !(lag_s.is_finite() && lag_s >= 0.0) {
        return Err(Error::parameter("lag_s", lag_s, "must be finite and >= 0"));
    }
    if lag_s == 0.0 {
        return Ok(PREDICTED_ALPHA_MAX);
    }
    Ok((PREDICTED_ALPHA_LAG_S / lag_s)
        .max(predicted_alpha_min())
        .min(PREDICTED_ALPHA_MAX))
}

/// Checks a lag `tau_s` in [0, 100] s and a control period `period_s` in (0, 10] s: the
/// one validation of the lag that [`LagModel::new`] and `Gains::for_lag` share.
///
/// # Errors
/// [`Error::Parameter`] naming the argument that is out of its range.
pub(crate) fn check_lag(tau_s: f64, period_s: f64) -> Result<()> {
    if !(0.0..=100.0).contains(&tau_s) {
        return Err(Error::parameter("tau_s", tau_s, "must lie in [0, 100] s"));
    }
    if !(period_s > 0.0 && period_s <= 10.0) {
        return Err(Error::parameter(
            "period_s",
            period_s,
            "must lie in (0, 10] s",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn follows_a_step_as_a_first_order_lag() {
        let mut m = LagModel::new(1.0, 0.05, &[0.0]).unwrap();
        for _ in 0..20 {
            m.advance(&[1.0]).unwrap();
        }
        // One time constant: 1 − 1/e.
        assert!((m.state()[0] - (1.0 - (-1.0f64).exp())).abs() < 1e-12);
        let mut z = LagModel::new(0.0, 0.05, &[0.0]).unwrap();
        assert_eq!(z.advance(&[2.0]).unwrap(), &[2.0]);
        assert!(LagModel::new(-1.0, 0.05, &[0.0]).is_err());
        assert!(LagModel::new(1.0, 0.0, &[0.0]).is_err());
        assert!(m.advance(&[1.0, 2.0]).is_err());
    }

    #[test]
    fn play_moves_only_outside_its_band() {
        // Band 2: the output stays until the input is more than 1 away.
        let mut y = 0.0;
        for (x, want) in [
            (0.5, 0.0),
            (1.0, 0.0),
            (1.5, 0.5),
            (0.0, 0.5),
            (-1.0, 0.0),
            (-2.0, -1.0),
        ] {
            y = play(y, x, 2.0);
            assert_eq!(y, want, "x = {x}");
        }
        assert_eq!(play(3.0, 1.0, 0.0), 1.0);
        let mut out = [0.0, 1.0];
        play_into(&mut out, &[2.0, 1.0], &[1.0, 4.0]).unwrap();
        assert_eq!(out, [1.5, 1.0]);
        assert!(play_into(&mut out, &[2.0], &[1.0, 1.0]).is_err());
        assert!(play_into(&mut out, &[2.0, 1.0], &[-1.0, 1.0]).is_err());
        assert!(play_into(&mut out, &[f64::NAN, 1.0], &[1.0, 1.0]).is_err());
    }

    #[test]
    fn loop_gain_laws() {
        // lead: half of a/(1 − a), capped; none without a lag.
        let a = (-0.05f64 / 0.08).exp();
        assert_eq!(
            lead_gain(0.08, 0.05, LEAD_GAIN_CAP).unwrap(),
            0.5 * a / (1.0 - a)
        );
        assert_eq!(lead_gain(1.0, 0.05, LEAD_GAIN_CAP).unwrap(), LEAD_GAIN_CAP);
        assert_eq!(lead_gain(0.0, 0.05, LEAD_GAIN_CAP).unwrap(), 0.0);
        assert!(lead_gain(-1.0, 0.05, LEAD_GAIN_CAP).is_err());
        assert!(lead_gain(0.1, 0.0, LEAD_GAIN_CAP).is_err());
        // predicted α: 0.21 s / lag between the hybrid gain and 0.9.
        assert_eq!(predicted_loop_alpha(0.0).unwrap(), PREDICTED_ALPHA_MAX);
        assert_eq!(predicted_loop_alpha(0.1).unwrap(), PREDICTED_ALPHA_MAX);
        assert!((predicted_loop_alpha(0.6).unwrap() * 0.6 - PREDICTED_ALPHA_LAG_S).abs() < 1e-15);
        assert_eq!(predicted_loop_alpha(5.0).unwrap(), predicted_alpha_min());
        assert_eq!(predicted_alpha_min(), 0.3);
        assert!(predicted_loop_alpha(f64::NAN).is_err());
        assert!(predicted_loop_alpha(-0.1).is_err());
    }
}
