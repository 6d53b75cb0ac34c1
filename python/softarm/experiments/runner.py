"""What the experiment runners share: the plant, random generator and gains each starts
from, the cases (a target and a start configuration) it draws, the proposed controller
run against the conventional one from the same start, and the run it plots.

IV-B (:mod:`~softarm.experiments.position`) and IV-C
(:mod:`~softarm.experiments.orientation`) compare a proposed controller with a
conventional one target by target; IV-D (:mod:`~softarm.experiments.hybrid`) and the
schedule comparison (:mod:`~softarm.experiments.schedule`) run several controllers over
the same pressures on the bush side. The order of the random draws, and of the runs on a
plant (whose tracker noise is one stream), is what the runners had on their own, so the
results are the same to the bit.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softarm._core import Gains, Resolver
from softarm.checks import FloatArray as F64
from softarm.experiments.common import (
    Trace,
    bush_pressures,
    closed_loop,
    declared_gains,
    start_configuration,
)
from softarm.experiments.output import plot_comparison
from softarm.sim.arm import SimulatedArm

__all__ = [
    "Controller",
    "Pair",
    "Start",
    "bush_cases",
    "most_infeasible",
    "plot_pair",
    "run_pairs",
    "start",
    "target_of",
]


@dataclass(frozen=True)
class Start:
    """Where a runner starts: the plant of the seed, the runner's own random generator and
    the gains its controllers use."""

    plant: SimulatedArm
    rng: np.random.Generator
    gains: Gains


def start(out: Path, seed: int, offset: int, gains: Gains | None) -> Start:
    """Creates ``out`` and draws the plant of ``seed``. The random generator is seeded
    ``seed + offset``, so that the experiments draw different targets on the same plant;
    the gains are the ones given, or the defaults declared for the plant's lag
    (:func:`~softarm.experiments.common.declared_gains`)."""
    out.mkdir(parents=True, exist_ok=True)
    plant = SimulatedArm(seed=seed)
    rng = np.random.default_rng(seed + offset)
    return Start(plant, rng, gains if gains is not None else declared_gains(plant))


def bush_cases(plant: SimulatedArm, rng: np.random.Generator, count: int) -> list[tuple[F64, F64]]:
    """``count`` (pressures, start configuration) pairs: the pressures on the bush side
    (:func:`~softarm.experiments.common.bush_pressures`) drawn first, then one start per
    pressure, in order."""
    return [(p, start_configuration(rng, plant.n)) for p in bush_pressures(plant, rng, count)]


def target_of(pose: F64, mode: str) -> F64:
    """What a controller in ``mode`` is given of a target ``pose`` (4, 4): its position
    in position mode, the whole pose otherwise."""
    result: F64 = pose[:3, 3] if mode == "position" else pose
    return result


@dataclass(frozen=True)
class Controller:
    """A resolver under a name, and whether the loop clamps its commands (the proposed
    controllers) or sends them as computed (the conventional one, eq. 7)."""

    name: str
    resolver: Resolver
    constrained: bool = True

    def run(self, plant: SimulatedArm, target: F64, q0: F64, duration: float) -> Trace:
        """One closed-loop run on ``plant`` from ``q0`` (:func:`closed_loop`)."""
        return closed_loop(self.resolver, plant, target, q0, duration, constrained=self.constrained)


@dataclass(frozen=True)
class Pair:
    """The proposed and the conventional controller on one target, from the same start."""

    proposed: Trace
    conventional: Trace


def run_pairs(
    plant: SimulatedArm,
    proposed: Resolver,
    conventional: Resolver,
    cases: list[tuple[F64, F64]],
    duration: float,
) -> list[Pair]:
    """Per (target, start) case, the proposed controller with its commands clamped, then
    the conventional one sending its commands unclamped (eq. 7), as the paper ran it."""
    return [
        Pair(
            closed_loop(proposed, plant, target, q0, duration),
            closed_loop(conventional, plant, target, q0, duration, constrained=False),
        )
        for target, q0 in cases
    ]


def most_infeasible(pairs: list[Pair]) -> int | None:
    """The case whose conventional run computed the most infeasible commands (the first
    of those tied): the one that shows the difference best. None without a case."""
    if not pairs:
        return None
    return max(range(len(pairs)), key=lambda i: pairs[i].conventional.infeasible)


def plot_pair(path: Path, title: str, pair: Pair, *, orientation: bool = False) -> None:
    """Both runs of ``pair`` over time, labelled by the paper's equations."""
    plot_comparison(
        path,
        title,
        {"proposed (eq. 13)": pair.proposed, "conventional (eq. 7)": pair.conventional},
        orientation=orientation,
    )
