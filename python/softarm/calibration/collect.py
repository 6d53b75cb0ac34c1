"""Drive an arm through an excitation set and measure its end-effector poses.

The same driver runs the simulated plant and the hardware: it needs only ``send(q)``
(elongation command, m), ``sleep(dt)`` (let time pass: the simulated clock or the wall
clock) and ``measure()`` (the tracker's ``T_base_ee``, or None when the markers are not
seen). For every pose it

1. ramps from the previous command at no more than ``rate`` (m/s of elongation; the
   safety layer's 100 psi/s is 0.048 m/s, we stay at half of it by default),
2. first to ``command - approach`` and then up to ``command``: every actuator reaches
   its command from below, so the play hysteresis (``softarm.sim.hysteresis``, the braid's
   friction on the real muscle) leaves the same offset on every pose instead of a
   direction-dependent one, and a constant offset is absorbed by the fitted rest lengths,
3. waits ``settle`` seconds (:func:`settle_time`: five time constants of the chain's
   lag, at least 1 s),
4. averages the poses measured over ``average`` seconds (the mean rotation on SO(3)).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TypedDict

import numpy as np
from scipy.spatial.transform import Rotation

from softarm.checks import FloatArray as F64
from softarm.errors import ParameterError, VisionError

__all__ = ["collect", "paced_for", "settle_time"]


#: How far below each command every actuator first goes (m), at the least.
DEFAULT_APPROACH_M = 0.002
#: The shortest hold (s): five time constants of the quick rig (80 ms regulators and the
#: tracker's 0.1 s low-pass) with room to spare.
MIN_SETTLE_S = 1.0


def settle_time(lag_s: float) -> float:
    """How long to hold each pose on a chain lagging ``lag_s`` (s, regulators plus the
    measurement's filter): five time constants, at least :data:`MIN_SETTLE_S`. A fixed
    1 s left a 0.8 s plant 30 % short of its pose, and the fit absorbed that as
    geometry (33 mm median residual on seed 504)."""
    if not (math.isfinite(lag_s) and lag_s >= 0):
        raise ParameterError(f"lag_s = {lag_s!r}: must be finite and >= 0")
    return max(MIN_SETTLE_S, 5.0 * lag_s)


class Pacing(TypedDict, total=False):
    """:func:`collect`'s pacing keywords, as :func:`paced_for` sizes them."""

    settle: float
    approach: float
    approach_hold: float


def paced_for(lag_s: float, play_m: float = 0.0) -> Pacing:
    """:func:`collect`'s ``settle``, ``approach`` and ``approach_hold`` for a plant
    lagging ``lag_s`` (s) with ``play_m`` (m of elongation) of play hysteresis: hold
    :func:`settle_time`; dip at least twice the play below each command (so every
    actuator comes up through the whole band) and wait three time constants there (so a
    lagging regulator really gets down). Seed 504 at tau = 0.8 s / 5 psi: 20 mm median
    residual with the quick rig's pacing, 0.13 mm with this one."""
    if not (math.isfinite(play_m) and play_m >= 0):
        raise ParameterError(f"play_m = {play_m!r}: must be finite and >= 0")
    return {
        "settle": settle_time(lag_s),
        "approach": max(DEFAULT_APPROACH_M, 2.0 * play_m),
        "approach_hold": 3.0 * lag_s,
    }


def _mean_pose(poses: list[F64]) -> F64:
    out = np.eye(4)
    out[:3, 3] = np.mean([p[:3, 3] for p in poses], axis=0)
    out[:3, :3] = Rotation.from_matrix(np.stack([p[:3, :3] for p in poses])).mean().as_matrix()
    return out


def collect(
    commands: F64,
    send: Callable[[F64], object],
    sleep: Callable[[float], None],
    measure: Callable[[], F64 | None],
    *,
    dt: float = 0.05,
    rate: float = 0.024,
    approach: float = DEFAULT_APPROACH_M,
    settle: float = 1.0,
    average: float = 0.5,
    on_pose: Callable[[int, F64], None] | None = None,
    approach_hold: float = 0.0,
) -> tuple[F64, F64]:
    """Drive through ``commands`` (N, n) and return the commands that were measured and
    their mean measured poses (M, 4, 4), M <= N (a pose never seen is left out).

    Raises:
        ParameterError: a non-positive ``dt``, ``rate``, ``settle`` or ``average``.
        VisionError: fewer than half of the poses were seen.
    """
    for name, v in (("dt", dt), ("rate", rate), ("settle", settle), ("average", average)):
        if not (math.isfinite(v) and v > 0.0):
            raise ParameterError(f"{name} = {v!r}: must be positive and finite")
    c = np.asarray(commands, dtype=np.float64)
    here = np.zeros(c.shape[1])
    kept_c, kept_p = [], []

    def ramp_to(goal: F64) -> None:
        nonlocal here
        steps = max(1, math.ceil(float(np.abs(goal - here).max()) / (rate * dt)))
        for t in np.linspace(0.0, 1.0, steps + 1)[1:]:
            send(here + t * (goal - here))
            sleep(dt)
        here = goal.copy()

    for k, cmd in enumerate(c):
        ramp_to(np.maximum(cmd - approach, 0.0))
        for _ in range(math.ceil(approach_hold / dt)):  # a lagging plant gets there too
            send(here)
            sleep(dt)
        ramp_to(cmd)
        for _ in range(math.ceil(settle / dt)):
            send(cmd)
            sleep(dt)
        seen = []
        for _ in range(max(1, math.ceil(average / dt))):
            send(cmd)
            sleep(dt)
            pose = measure()
            if pose is not None:
                seen.append(pose)
        if seen:
            kept_c.append(cmd)
            kept_p.append(_mean_pose(seen))
            if on_pose is not None:
                on_pose(k, kept_p[-1])
    if 2 * len(kept_c) < len(c):
        raise VisionError(
            f"the end effector was seen at only {len(kept_c)} of {len(c)} calibration poses"
        )
    return np.array(kept_c), np.array(kept_p)
