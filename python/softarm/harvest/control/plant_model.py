"""The controller's model of the measurement chain behind the actuator: what the measured
pose will still do after the commands already sent (docs/control.md, section 6).

    command ──regulators (first-order lag τ)──► pressure ──play (band w)──► elongation
            ──measurement (lag τ_m)──► what the camera pipeline reports

Both lags are :class:`softarm.LagModel` (Rust). The loop needs the motion still *in
flight*, ``q − ŷ``: where the last target puts the arm once everything sent has arrived,
less what the measured pose reflects now. At rest ``ŷ = q``: nothing is in flight and
the loop closes on the measured error alone, whatever the model's errors (a Smith
predictor).

With the play's band width known (declared or identified), a play operator sits between
the regulators and the measurement, and the motion in flight is where the play's output
ends once the regulators reach the last target, less ŷ. A command that stays inside the
band then has nothing in flight: the loop goes on integrating at its full gain until the
command leaves the band, and no longer counts the creep across the band as motion to
come (docs/control.md, section 6).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm._core import (
    PREDICTED_ALPHA_LAG_S,
    PREDICTED_ALPHA_MAX,
    PREDICTED_ALPHA_MIN,
    LagModel,
    play,
    predicted_loop_alpha,
)
from softarm.checks import FloatArray
from softarm.errors import ParameterError

__all__ = [
    "MEASUREMENT_LAG_PERIODS",
    "PREDICTED_ALPHA_LAG_S",
    "PREDICTED_ALPHA_MAX",
    "PREDICTED_ALPHA_MIN",
    "MeasurementModel",
    "predicted_loop_alpha",
]


#: The measurement's own lag (control periods) the predictor puts behind the regulators:
#: one camera frame, taken at the start of the period. The simulated cameras have none,
#: so there it over-estimates the lag, on purpose: the predicted loop then approaches
#: the berry without overshoot, and on a plant with play each overshoot costs a reversal
#: through the band. Tuning seeds 0-3, tau = 0.08 s, median s per berry at 1.5 / 5 psi:
#: 2.95 / 4.0 with none, 2.8 / 3.35 with one period, 3.2 / 3.75 with two (the 0.1 s
#: tracker filter the rig used to assume; docs/control.md, section 6).
MEASUREMENT_LAG_PERIODS = 1.0

# The predicted loop's gain law and its constants are the core's (control math, beside
# LagModel: crates/softarm-core/src/resolver/lag.rs), re-exported here:
# ``predicted_loop_alpha(lag_s) = PREDICTED_ALPHA_LAG_S / lag_s`` within
# [PREDICTED_ALPHA_MIN (the default hybrid_alpha), PREDICTED_ALPHA_MAX].


def _widths(play_m: float | npt.ArrayLike, n: int) -> FloatArray:
    """``play_m`` as ``n`` band widths (m): one for every channel, or one per channel."""
    try:
        play = np.asarray(play_m, dtype=np.float64)
    except (TypeError, ValueError):
        play = np.full(1, np.nan)
    if play.ndim == 0:
        play = np.full(n, float(play))
    if play.shape != (n,) or not np.all(np.isfinite(play)) or np.any(play < 0):
        raise ParameterError(
            f"play_m = {play_m!r}: must be one width or {n} widths (m), finite and >= 0"
        )
    return play


class MeasurementModel:
    """Regulators' lag then the measurement's, per channel, in elongations (m).

    Args:
        n: channels.
        tau_s: the regulators' time constant (s, >= 0).
        period_s: the control period (s) each :meth:`advance` lasts.
        filter_s: the measurement's own lag (s, >= 0): a pose filter, a camera frame.
        play_m: the actuators' play band width (m of elongation; one, or one per
            channel; 0: none), between the regulators and the measurement, as the plant
            has it (a play operator: the output moves only once the input is more than
            half the band away).
    """

    def __init__(
        self,
        n: int,
        tau_s: float,
        period_s: float,
        filter_s: float = 0.0,
        play_m: float | npt.ArrayLike = 0.0,
    ) -> None:
        for name, value in (("tau_s", tau_s), ("filter_s", filter_s)):
            if not (np.isfinite(value) and value >= 0):
                raise ParameterError(f"{name} = {value!r}: must be finite and >= 0")
        widths = _widths(play_m, n)
        self.period = float(period_s)
        self._play = widths.copy()  # the band widths of softarm._core.play
        zeros = np.zeros(n)
        self._arm = zeros.copy()  # the play's output: where the actuators are
        self._regulators = LagModel(tau_s, period_s, zeros) if tau_s > 0 else None
        self._filter = LagModel(filter_s, period_s, zeros) if filter_s > 0 else None
        self._pressure = zeros.copy()  # the regulators' output, as an elongation
        self._target = zeros.copy()

    @property
    def regulators(self) -> FloatArray:
        """The regulators' output now (m): what a lead on them acts against."""
        return self._pressure.copy()

    @property
    def measured(self) -> FloatArray:
        """What the measured pose reflects now (m): ŷ."""
        return np.asarray(self._filter.q) if self._filter is not None else self._arm.copy()

    def play_band(self) -> tuple[FloatArray, FloatArray]:
        """The play's output now and its band widths (m): a command within half a width of
        the output moves nothing."""
        return self._arm.copy(), self._play.copy()

    def advance(self, drive: FloatArray) -> None:
        """One period with ``drive`` (m, the regulators' command, boost included) held."""
        if self._regulators is not None:
            self._pressure = np.asarray(self._regulators.advance(drive))
        else:
            self._pressure = np.asarray(drive, dtype=np.float64).copy()
        self._arm = play(self._arm, self._pressure, self._play)
        if self._filter is not None:
            self._filter.advance(self._arm)

    def command(self, target: FloatArray) -> None:
        """The q sent (m, without the boost): where the regulators are headed."""
        self._target = np.asarray(target, dtype=np.float64).copy()

    def in_flight(self) -> FloatArray:
        """The motion (m) the measured pose will still make once the regulators reach the
        last target: ``q − ŷ`` without play; with it, the play's output at the end of
        that monotone approach, ``clip(arm, q − w/2, q + w/2)``, less ŷ (a command
        inside the band moves nothing)."""
        return play(self._arm, self._target, self._play) - self.measured

    def arm_in_flight(self) -> FloatArray:
        """The motion (m) the actuators themselves will still make towards the last
        target: what the arm has left to move, whatever the measurement's own lag."""
        return self._target - self._pressure
