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
}
