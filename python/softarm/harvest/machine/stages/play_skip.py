"""Fine positioning's command carried across the actuators' play once it is seen creeping
through it (``[harvest] play_skip``, off by default).

A channel that reversed on the way in holds its output while its command crosses the
play's band (``sim/hysteresis.py``: the output moves once the input is more than half a
width away). The lag model knows the band (docs/control.md §6), so it has nothing in
flight there, and the loop integrates the measured error at its gain: near the berry
the error is under a millimetre and the command creeps a few hundredths of a psi a
period through a band of several psi (4.2 s on the slow plant's diagnosis seed 1531,
docs/harvest-candidates.md "Pre-grasp poses off the limits"). Here, once a channel's command has
moved the same way for ``periods`` periods in a row while still inside the band, it is
put at the band's edge in that direction, plus this period's step: what the creep would
reach, at once. At the edge itself the output does not move, so the jump cannot
overshoot; only the loop's own step beyond it moves the arm. A channel whose command
turns back, or that leaves the band, starts its count again: a command that dithers
about the goal never jumps (a backlash inverse on every reversal made the regulators'
lag cost a τ each time, docs/control.md "Measured and rejected").
"""

from __future__ import annotations

import numpy as np

from softarm.harvest.machine.interfaces import FloatArray

__all__ = ["PlaySkip"]


class PlaySkip:
    """Counts, per channel, the periods its command has moved one way inside the play's
    band, and moves it to the band's edge after ``periods`` of them (>= 1)."""

    def __init__(self, periods: int) -> None:
        self.periods = int(periods)
        self._run: FloatArray | None = None  # signed periods in a row, per channel

    def step(
        self, q: FloatArray, q_next: FloatArray, band: tuple[FloatArray, FloatArray] | None
    ) -> tuple[FloatArray, list[int]]:
        """``q_next`` (the loop's next command after ``q``, m) with the channels that crept
        ``periods`` periods through ``band`` (the lag model's play output and widths, m;
        None: no play model, nothing changes) moved to the band's edge; and those
        channels."""
        if band is None:
            return q_next, []
        output, widths = band
        step = q_next - q
        way = np.sign(step)
        inside = np.abs(q_next - output) < widths / 2
        run = np.zeros_like(q_next) if self._run is None else self._run
        same = (way != 0) & (np.sign(run) == way)
        run = np.where(inside & (way != 0), np.where(same, run + way, way), 0.0)
        jump = np.abs(run) >= self.periods
        run[jump] = 0.0
        self._run = run
        moved = np.where(jump, output + way * widths / 2 + step, q_next)
        return moved, [int(k) for k in np.flatnonzero(jump)]
