"""Shared machinery of the benchtop experiments (redundancy paper IV): target
generation on the true arm, the closed loop, and error metrics."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from softarm._core import Gains, Resolver
from softarm.checks import FloatArray as F64
from softarm.sim.arm import SimulatedArm
from softarm.sim.pressure import to_psi
from softarm.units import METRES_PER_PSI

#: Control period (s): one resolver step per tracker sample.
CONTROL_PERIOD = 0.05
#: The paper's start: every actuator at this pressure (psi), give or take
#: ``START_SPREAD_PSI``.
START_PSI = 35.0
START_SPREAD_PSI = 0.5
#: Samples at the end of a run whose errors are averaged as its final error (1 s).
FINAL_WINDOW = 20


def declared_gains(plant: SimulatedArm, period: float = CONTROL_PERIOD) -> Gains:
    """The resolver's default gains with the plant's lag declared (regulators + the
    tracker's low-pass filter): the closed-loop gain cap of ``Gains.for_lag``
    (docs/control.md) at that lag rather than the defaults' 20 periods."""
    cfg = plant.config
    return Gains.for_lag(cfg.pressure_tau + 1.0 / cfg.cutoff, period)


def orientation_error(judge: Resolver, q: F64, target: F64, pose: F64) -> float:
    """The core's masked orientation error (rad) of ``pose`` against ``target``: the
    norm of the rotation vector of R_target R_currentᵀ over the paper's X/Z axes
    (``judge``'s ``axis_mask``), as ``StepResult.orientation_error`` returns it with
    ``pose`` as the measured pose. The step's command is discarded: only the error is
    read, so Python never recomputes e_ζ."""
    return judge.step(q, target, pose).orientation_error


def start_configuration(rng: np.random.Generator, n: int, psi: float = START_PSI) -> F64:
    """The paper's start: a small feasible pressure with a small perturbation (m)."""
    return (psi + rng.uniform(-START_SPREAD_PSI, START_SPREAD_PSI, n)) * METRES_PER_PSI


def bush_pressures(
    plant: SimulatedArm, rng: np.random.Generator, count: int, min_y: float = 0.05
) -> list[F64]:
    """``count`` random feasible pressure vectors whose true end-effector positions lie on
    the +Y side (like berries in a bush along +Y, Fig. 5), spread evenly in y."""
    candidates: list[tuple[float, F64]] = []
    hi = plant.config.max_psi
    while len(candidates) < 20 * count:
        p = rng.uniform(0.1 * hi, 0.9 * hi, plant.n)
        y = plant.pose_at_pressure(p)[1, 3]
        if y >= min_y:
            candidates.append((float(y), p))
    candidates.sort(key=lambda c: c[0])
    idx = np.linspace(0, len(candidates) - 1, count).round().astype(int)
    return [candidates[i][1] for i in idx]


@dataclass
class Trace:
    """One closed-loop run, sampled every control period."""

    time: list[float] = field(default_factory=list)
    position_error: list[float] = field(default_factory=list)  # true, m
    orientation_error: list[float] = field(default_factory=list)  # true, masked, rad
    command_psi: list[F64] = field(default_factory=list)  # as computed, before the plant
    infeasible: int = 0  # commands with a pressure below 0 or above the maximum
    saturated: int = 0  # steps whose command the resolver clamped

    def final(self, window: int = FINAL_WINDOW) -> tuple[float, float]:
        """Mean true errors over the last ``window`` samples."""
        return (
            float(np.mean(self.position_error[-window:])),
            float(np.mean(self.orientation_error[-window:])),
        )

    def settle_time(self, tolerance: float) -> float:
        """First time after which the position error stays below ``tolerance``."""
        e = np.asarray(self.position_error)
        above = np.nonzero(e > tolerance)[0]
        if len(above) == 0:
            return 0.0
        if above[-1] == len(e) - 1:
            return math.inf
        result: float = self.time[above[-1] + 1]
        return result


def closed_loop(
    resolver: Resolver,
    plant: SimulatedArm,
    target: F64,
    q0: F64,
    duration: float,
    *,
    constrained: bool = True,
    period: float = CONTROL_PERIOD,
) -> Trace:
    """Runs ``resolver`` against ``plant`` for ``duration`` seconds.

    The controller's state is its last command (eq. 7: q(t + Δt) = q̇ Δt + q(t)); the
    error comes from the tracker (``current=``). ``constrained=False`` is the
    conventional controller: it sends and integrates the *unclamped* command, which the
    plant's regulators then saturate at 0 and the maximum pressure.
    """
    lower, upper = plant.model.lower, plant.model.upper
    pose_target = np.asarray(target, dtype=np.float64)
    full_pose = pose_target.shape == (4, 4)
    p_target = pose_target[:3, 3] if full_pose else pose_target
    q = np.asarray(q0, dtype=np.float64).copy()
    # Scores the true pose with the default X/Z mask, whatever the controller's gains.
    judge = Resolver(plant.model, "hybrid")
    measured = plant.reset(q)
    trace = Trace()
    for k in range(round(duration / period)):
        r = resolver.step(q, pose_target, measured)
        command = r.q if constrained else r.unclamped
        trace.saturated += int(r.saturated)
        if np.any(command < lower - 1e-15) or np.any(command > upper + 1e-15):
            trace.infeasible += 1
        q = command
        measured = plant.apply(q, period)
        true = plant.true_pose()
        trace.time.append((k + 1) * period)
        trace.command_psi.append(to_psi(q))
        trace.position_error.append(float(np.linalg.norm(p_target - true[:3, 3])))
        trace.orientation_error.append(
            orientation_error(judge, q, pose_target, true) if full_pose else 0.0
        )
    return trace
