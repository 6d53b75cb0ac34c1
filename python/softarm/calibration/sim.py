"""Calibration on the simulated rig's plant: the same plant ``softarm harvest --sim
--seed S`` runs on (seed S + 1000, the ``[plant]`` table of ``--plant FILE``), measured
by the simulated tracker (its noise and 10 rad/s low-pass, from the plant config)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from softarm._core import SoftArm
from softarm.calibration.collect import Pacing, collect, paced_for
from softarm.calibration.excitation import excitation_set
from softarm.calibration.fit import calibrate
from softarm.calibration.result import Calibration
from softarm.checks import FloatArray as F64
from softarm.sim.arm import PlantConfig
from softarm.sim.tracker import PoseTracker
from softarm.units import METRES_PER_PSI

if TYPE_CHECKING:
    from softarm.sim.plant import ArmPlant

__all__ = ["PlantDriver", "build_plant", "calibrate_plant", "true_poses"]


def build_plant(model: SoftArm, config: PlantConfig, seed: int) -> ArmPlant:
    """The simulated plant of ``config.model`` ("pcc" or "cosserat") drawn from ``seed``
    (the harvest rig uses ``seed + 1000``), starting vented."""
    if config.model == "cosserat":
        from softarm.sim.cosserat import CosseratPlant

        return CosseratPlant(model, config, seed=seed)
    from softarm.sim.arm import SimulatedArm
    from softarm.sim.plant import ArmPlant

    return ArmPlant(SimulatedArm(model, config, seed=seed))


@dataclass
class PlantDriver:
    """``send``/``sleep``/``measure`` of :func:`~softarm.calibration.collect.collect` on
    a simulated plant (anything with ``command_pressures``, ``advance`` and ``pose``)."""

    plant: ArmPlant
    tracker: PoseTracker | None

    def __post_init__(self) -> None:
        self.last: F64 | None = None
        self.sent: F64 | None = None

    def send(self, q: F64) -> None:
        self.sent = np.asarray(q, dtype=np.float64)
        self.plant.command_pressures(self.sent / METRES_PER_PSI)

    def vent(self) -> None:
        """Command 0 psi on every channel that was driven (the regulators' vent)."""
        if self.sent is not None:
            self.plant.command_pressures(np.zeros_like(self.sent))

    def sleep(self, dt: float) -> None:
        self.plant.advance(dt)
        pose = self.plant.pose()
        self.last = pose if self.tracker is None else self.tracker.measure(pose, dt)

    def measure(self) -> F64 | None:
        return self.last


def _pace(config: PlantConfig, lag_s: float, settle: float | None) -> Pacing:
    """:func:`~softarm.calibration.collect.paced_for` a chain lagging ``lag_s`` with
    ``config``'s play; ``settle`` (s), when given, replaces the paced hold."""
    pace = paced_for(lag_s, config.play_m)
    if settle is not None:
        pace["settle"] = settle
    return pace


def calibrate_plant(
    plant: ArmPlant,
    config: PlantConfig,
    nominal: SoftArm,
    *,
    n_poses: int = 80,
    seed: int = 0,
    on_pose: Callable[[int, F64], None] | None = None,
    average: float = 0.5,
    bias: bool = False,
    settle: float | None = None,
) -> tuple[Calibration, F64, F64]:
    """Drive ``plant`` through ``n_poses`` excitation poses measured by a tracker with
    ``config``'s noise, and fit; returns the calibration and the data (commands, poses).
    The holds are paced for the plant's declared lag (regulators plus the tracker's
    filter) and play (:func:`~softarm.calibration.collect.paced_for`); ``settle`` (s),
    when given, replaces the paced hold at each pose."""
    filter_s = 0.0 if config.cutoff is None else 1.0 / config.cutoff
    pace = _pace(config, config.pressure_tau + filter_s, settle)
    tracker = PoseTracker(
        np.random.default_rng(seed), config.position_noise, config.angle_noise, config.cutoff
    )
    drv = PlantDriver(plant, tracker)
    commands = excitation_set(nominal, n_poses, seed=seed)
    try:
        c, p = collect(
            commands, drv.send, drv.sleep, drv.measure, on_pose=on_pose, average=average, **pace
        )
    except BaseException:
        # Stopped (SIGTERM, Ctrl-C) or failed half way: leave the plant vented, as the
        # hardware rig's close() leaves the arm.
        drv.vent()
        raise
    return calibrate(nominal, c, p, bias=bias), c, p


def true_poses(
    plant: ArmPlant, commands: F64, config: PlantConfig, settle: float | None = None
) -> F64:
    """The plant's noise-free settled poses at ``commands``, driven as in the fit: paced
    for ``config``'s regulator lag and play (no tracker, so no filter lag); ``settle``
    (s), when given, replaces the paced hold. A fixed hold would leave a slow plant
    short of its poses, and the held-out reference with it."""
    pace = _pace(config, config.pressure_tau, settle)
    drv = PlantDriver(plant, None)
    return collect(commands, drv.send, drv.sleep, drv.measure, average=0.05, **pace)[1]
