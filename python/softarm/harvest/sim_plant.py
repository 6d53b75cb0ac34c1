"""The simulated pneumatic arm the harvest rig drives: a TRUE arm that differs from the
controller's model, behind first-order pressure dynamics.

Model mismatch (seeded): section rest lengths ±1 %, actuator radii ±2 %, and each
actuator's elongation per psi ±3 % around the paper's 1/2100 m (section IV-A), so the
loop must close through the cameras. The regulators and 3 m hoses (section II-D) are a
first-order lag of ``tau`` seconds.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm._core import Section, SoftArm
from softarm.hardware.pressure_map import METRES_PER_PSI

__all__ = ["LagArmPlant", "perturbed_arm"]

FloatArray = npt.NDArray[np.float64]


def perturbed_arm(model: SoftArm, rng: np.random.Generator) -> SoftArm:
    """A copy of ``model`` with rest lengths ±1 % and radii ±2 % (1 sigma)."""
    sections = []
    for s in model.sections:
        sections.append(
            Section(
                radius=s.radius * (1 + 0.02 * rng.standard_normal()),
                rest_length=s.rest_length * (1 + 0.01 * rng.standard_normal()),
                lower=s.lower,
                upper=s.upper * 1.1,  # the true actuator is not stopped at the model's limit
                offset=s.offset,
                twist=s.twist,
            )
        )
    return SoftArm(sections)


class LagArmPlant:
    """Implements :class:`~softarm.hardware.simulated.PressurePlant` plus ``advance``,
    ``q`` and ``pose`` for the simulator.

    Args:
        arm: the TRUE arm.
        metres_per_psi: (n,) true elongation per psi of each actuator.
        tau: time constant (s) of the pressure response.
    """

    def __init__(self, arm: SoftArm, metres_per_psi: FloatArray, tau: float = 0.1) -> None:
        self.arm = arm
        self.gain = np.asarray(metres_per_psi, dtype=np.float64)
        self.tau = float(tau)
        self._target = np.zeros(arm.n_actuators)
        self._p = np.zeros(arm.n_actuators)

    @classmethod
    def around(cls, model: SoftArm, seed: int, tau: float = 0.1) -> LagArmPlant:
        """A seeded plant that differs from ``model`` as the module docstring says."""
        rng = np.random.default_rng(seed)
        gain = METRES_PER_PSI * (1 + 0.03 * rng.standard_normal(model.n_actuators))
        return cls(perturbed_arm(model, rng), gain, tau)

    def command_pressures(self, psi: FloatArray) -> None:
        """Regulator set-points (psi)."""
        self._target = np.array(psi, dtype=np.float64)

    def pressures(self) -> FloatArray:
        """Actuator pressures now (psi)."""
        return self._p.copy()

    def advance(self, dt: float) -> None:
        """Let ``dt`` seconds pass (exact first-order step)."""
        self._p += (self._target - self._p) * (1.0 - np.exp(-dt / self.tau))

    def q(self) -> FloatArray:
        """True elongations (m)."""
        return np.clip(self._p * self.gain, self.arm.lower, self.arm.upper)

    def pose(self) -> FloatArray:
        """True ``T_base_ee``."""
        return self.arm.forward(self.q())
