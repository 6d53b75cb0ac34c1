"""Simulated clock, gripper (with ripeness sensor and ground truth) and a watcher of the
arm's clearance to the canes, for the simulated harvest rig."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from softarm.checks import FloatArray
from softarm.harvest.control.clearance import Clearance
from softarm.harvest.machine.interfaces import BerryTarget
from softarm.sim.bush import Berry
from softarm.sim.plant import ArmPlant

__all__ = ["ArmWatch", "SimClock", "SimGripper"]


class SimClock:
    """Simulated time; every ``sleep(dt)`` runs each of ``on_advance`` with ``dt``."""

    def __init__(self, on_advance: Sequence[Callable[[float], None]] = ()) -> None:
        self.t = 0.0
        self.on_advance = list(on_advance)

    def now(self) -> float:
        """Simulated seconds."""
        return self.t

    def sleep(self, dt: float) -> None:
        """Advance the simulation by ``dt``."""
        self.t += dt
        for f in self.on_advance:
            f(dt)


class SimGripper:
    """The gripper, its ripeness sensor and the simulation's ground truth in one.

    ``close`` grasps the selected berry if the true grasp point is within ``workspace``
    of it; ``read`` returns that berry's ripeness (0 with nothing in the fingers);
    ``open`` away from the bush delivers the berry: it leaves ``on_bush``.
    """

    def __init__(
        self,
        plant: ArmPlant,
        vision: object,
        on_bush: list[Berry],
        offset: float,
        workspace: float,
    ) -> None:
        self.plant, self.vision, self.on_bush = plant, vision, on_bush
        self.offset, self.workspace = offset, workspace
        self.holding: Berry | None = None
        self._closed = False
        self.delivered: list[int] = []
        #: True elongations at each grasp, for plots of the arm.
        self.grasp_shapes: list[FloatArray] = []

    def _grasp_point(self) -> FloatArray:
        pose = self.plant.pose()
        return pose[:3, 3] + self.offset * pose[:3, 2]

    def _berry(self, tag_id: int) -> Berry | None:
        return next((b for b in self.on_bush if b.tag_id == tag_id), None)

    def close(self) -> None:
        """Close the fingers; catch the selected berry if it is between them."""
        self._closed = True
        berry = self._berry(self.vision.selected.tag_id)  # type: ignore[attr-defined]
        near = berry is not None and np.linalg.norm(self._grasp_point() - berry.position)
        self.holding = berry if berry is not None and near <= self.workspace else None

    def open(self) -> None:
        """Open; a berry carried away from the bush is delivered (removed from it)."""
        self._closed = False
        b = self.holding
        if b is not None and np.linalg.norm(self._grasp_point() - b.position) > self.workspace:
            self.on_bush.remove(b)
            self.delivered.append(b.tag_id)
        self.holding = None

    @property
    def position(self) -> float:
        """Closure fraction (:class:`softarm.hardware.protocols.Gripper`): 0 open, 1 closed."""
        return 1.0 if self._closed else 0.0

    def read(self) -> float:
        """Ripeness of the berry in the fingers; 0.0 (unripe) when there is none."""
        return 0.0 if self.holding is None else self.holding.ripeness

    def grasp_errors(self, berry: BerryTarget, axis: FloatArray) -> tuple[float, float]:
        """True (distance grasp point → berry, angle gripper axis → ``axis``) now."""
        b = self._berry(berry.tag_id)
        self.grasp_shapes.append(self.plant.q())
        if b is None:
            return float("nan"), float("nan")
        z = self.plant.pose()[:3, 2]
        ang = float(np.arccos(np.clip(z @ axis, -1.0, 1.0)))
        return float(np.linalg.norm(self._grasp_point() - b.position)), ang


class ArmWatch:
    """Samples the TRUE arm's gap to the canes after every time step (ground truth of
    "no contact with a branch"); a gap below zero is a contact."""

    def __init__(self, plant: ArmPlant, clearance: Clearance) -> None:
        self.plant, self.clearance = plant, clearance
        self.min_gap = float("inf")
        self.contacts = 0
        #: True gripper positions (3,) after every step, for plots.
        self.trajectory: list[FloatArray] = []

    def sample(self, dt: float = 0.0) -> None:
        """Record the gap of the arm (and the gripper position) as it is now."""
        q = self.plant.q()
        self.trajectory.append(self.plant.arm.forward(q)[:3, 3])
        gap = self.clearance.gap(q)
        self.min_gap = min(self.min_gap, gap)
        self.contacts += gap < 0.0
