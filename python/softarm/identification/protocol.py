"""The excitation: what pressures the identification commands, and for how long.

Three phases, every command inside ``[lo, hi]`` psi (within the safety layer's limit) and
every change slower than its rate limit (the safety layer enforces both again):

1. **settle** — all channels from vented to the base pressure, held: one step per
   channel, seen by the pressure readings.
2. **per channel** — for each channel in turn, the others held at the base: a step up to
   ``base + amplitude``, a step down to ``base`` (approached from above), a ramp down to
   ``base - amplitude``, a step up to ``base`` (approached from below). The steps give
   the regulator's lag and dead time, the ramp the lag under a moving command, and the
   two holds at ``base`` the hysteresis (same pressure, two approach directions).
3. **random** — random pressure vectors in ``[lo, hi]`` until the time budget is spent:
   the poses spread over the workspace that the kinematic fit needs to tell the
   actuators' gains from the geometry (see :mod:`softarm.identification.kinematic`).

A hold ends once every pressure reading is within ``settle_psi`` of its command and the
minimum hold (the tracker's low-pass settling) is over, or at its maximum length.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from softarm.checks import FloatArray as F64
from softarm.errors import ParameterError

__all__ = ["Design", "Segment"]


@dataclass(frozen=True)
class Segment:
    """One piece of the excitation.

    Attributes:
        target: pressures (psi) at the end of the segment, shape ``(n,)``.
        kind: ``"hold"`` (step to ``target`` and wait) or ``"ramp"`` (linear from the
            previous target to ``target`` over ``duration``).
        duration: the ramp's length, or the hold's maximum length (s).
        min_duration: a hold's minimum length (s).
        phase: ``"settle"``, ``"channel"`` or ``"random"``.
        channel: the channel under test in the per-channel phase, else -1.
        fit: whether the end of this hold goes into the kinematic fit.
    """

    target: F64
    kind: str
    duration: float
    min_duration: float = 0.0
    phase: str = "random"
    channel: int = -1
    fit: bool = True


@dataclass(frozen=True)
class Design:
    """The excitation's parameters (psi, s). Defaults suit the blackberry arm (0-70 psi)
    at a 20 Hz control rate and fit 2 minutes of arm time for 9 channels."""

    n: int = 9
    lo: float = 8.0
    hi: float = 62.0
    base: float = 30.0
    amplitude: float = 22.0
    ramp_rate: float = 40.0  # psi/s, below the safety layer's 100 psi/s
    hold_min: float = 0.5  # five time constants of the paper's 10 rad/s tracker filter
    hold_max: float = 1.8
    settle_psi: float = 0.3
    budget_s: float = 120.0
    seed: int = 0

    def __post_init__(self) -> None:
        if not (0.0 <= self.lo < self.base - self.amplitude + 1e-9):
            raise ParameterError(
                f"base - amplitude = {self.base - self.amplitude}: must be >= lo = {self.lo}"
            )
        if self.base + self.amplitude > self.hi + 1e-9:
            raise ParameterError(
                f"base + amplitude = {self.base + self.amplitude}: must be <= hi = {self.hi}"
            )
        for name in ("ramp_rate", "hold_min", "hold_max", "settle_psi", "budget_s"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0.0):
                raise ParameterError(f"{name} = {v}: must be finite and > 0")

    def segments(self) -> Iterator[Segment]:
        """The schedule; the random phase never ends (the runner stops it on budget)."""
        base = np.full(self.n, self.base)
        yield Segment(base, "hold", 3.0, 1.0, phase="settle", fit=True)
        hold = ("hold", self.hold_max, self.hold_min)  # kind, duration, min_duration
        for i in range(self.n):
            up, down = base.copy(), base.copy()
            up[i] += self.amplitude
            down[i] -= self.amplitude
            yield Segment(up, *hold, phase="channel", channel=i)
            yield Segment(base, *hold, phase="channel", channel=i)
            yield Segment(
                down, "ramp", 2 * self.amplitude / self.ramp_rate, phase="channel",
                channel=i, fit=False,
            )  # fmt: skip
            yield Segment(down, *hold, phase="channel", channel=i)
            yield Segment(base, *hold, phase="channel", channel=i)
        rng = np.random.default_rng(self.seed)
        while True:
            yield Segment(rng.uniform(self.lo, self.hi, self.n), *hold)
