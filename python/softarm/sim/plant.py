"""The plant interface of the simulated rig: the pressure bank's set-points (psi) in, the
true arm out. :class:`ArmPlant` drives a :class:`~softarm.sim.arm.SimulatedArm` (constant
curvature); :class:`~softarm.sim.cosserat.plant.CosseratPlant` subclasses it. A new plant
implements the same five methods (``command_pressures``, ``pressures``, ``advance``,
``q``, ``pose``) and the ``arm`` / ``sim`` attributes; see ``docs/architecture.md``."""

from __future__ import annotations

import numpy as np

from softarm._core import SoftArm
from softarm.checks import FloatArray
from softarm.sim.arm import SimulatedArm
from softarm.units import METRES_PER_PSI

__all__ = ["ArmPlant"]


class ArmPlant:
    """A :class:`~softarm.hardware.simulated.PressurePlant` on a
    :class:`~softarm.sim.arm.SimulatedArm` (true geometry, per-actuator gains, regulator
    lag and hysteresis, all differing from the controller's model), advanced by the
    simulated clock.

    The regulator set-points (psi) become the arm's elongation command through the
    nominal map (1/2100 m per psi, section IV-A); the arm applies its own true gains.
    """

    def __init__(self, arm: SimulatedArm, start: FloatArray | None = None) -> None:
        self.sim = arm
        self._command = np.zeros(arm.n) if start is None else np.asarray(start, dtype=float)
        arm.reset(self._command)

    @classmethod
    def seeded(cls, model: SoftArm, seed: int) -> ArmPlant:
        """A plant around ``model`` drawn from ``seed``, starting vented."""
        return cls(SimulatedArm(model, seed=seed))

    @property
    def arm(self) -> SoftArm:
        """The TRUE arm (for ground truth and clearance)."""
        return self.sim.true_arm

    def command_pressures(self, psi: FloatArray) -> None:
        """Regulator set-points (psi)."""
        self._command = np.asarray(psi, dtype=np.float64) * METRES_PER_PSI

    def pressures(self) -> FloatArray:
        """Regulator pressures (psi)."""
        return self.sim.pressure

    def advance(self, dt: float) -> None:
        """Let ``dt`` seconds pass with the current set-points.

        ``step``, not ``apply``: the rig measures the pose with its own cameras, so the
        plant's tracker measurement would be computed only to be thrown away."""
        self.sim.step(self._command, dt)

    def q(self) -> FloatArray:
        """True elongations (m)."""
        return self.sim.elongation

    def pose(self) -> FloatArray:
        """True ``T_base_ee``."""
        return self.sim.true_pose()
