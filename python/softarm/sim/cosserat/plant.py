"""The Cosserat-rod plant: the constant-curvature plant's pressure side driving a rod.

Everything between the command and the actuators' true elongations is the plant of
:mod:`softarm.sim.arm` (a :class:`~softarm.sim.arm.SimulatedArm`: the 1/2100 m/psi map,
saturation, first-order regulator lag, play hysteresis, per-actuator gains, perturbed
geometry from the seed); the elongations then set the intrinsic strains of a
:class:`~softarm.sim.cosserat.rod.RodArm` built on the same perturbed geometry, with
gravity ``config.gravity`` in the base frame. The rod starts at its static equilibrium
and then follows its damped dynamics in real time (``RodArm.advance``). Same interface as
:class:`softarm.sim.plant.ArmPlant`.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm._core import SoftArm
from softarm.checks import FloatArray as F64
from softarm.sim.arm import PlantConfig, SimulatedArm
from softarm.sim.cosserat.params import RodParameters
from softarm.sim.cosserat.rod import RodArm
from softarm.sim.plant import ArmPlant

__all__ = ["CosseratPlant"]


class CosseratPlant(ArmPlant):
    """A Cosserat-rod arm behind the simulated pressure bank.

    Args:
        model: the controller's nominal arm (the plant perturbs it from ``seed``).
        config: plant parameters (``config.gravity`` is used here; ``config.model`` is
            not checked, so a "pcc" config gives a rod under its gravity too).
        seed: seed of the geometry, the gains and the tracker noise.
        params: masses, stiffness and relaxation of the rod (its stiffness is designed
            on the *nominal* arm, so every seed's rod sags alike).
        start: initial command (m), default vented.
    """

    def __init__(
        self,
        model: SoftArm,
        config: PlantConfig | None = None,
        seed: int = 0,
        params: RodParameters | None = None,
        start: F64 | None = None,
    ) -> None:
        config = config if config is not None else PlantConfig()
        sim = SimulatedArm(model, config, seed=seed)
        p = (params or RodParameters()).with_stiffness(model)
        self.rod = RodArm(sim.true_arm, p, gravity=config.gravity)
        super().__init__(sim, start)  # resets the pressures: settle the rod there
        self.rod.set_elongations(self.sim.elongation)
        self.rod.relax(max_time=5.0)

    def advance(self, dt: float) -> None:
        """Let ``dt`` seconds pass with the current set-points: the pressures move (lag,
        saturation, hysteresis), then the rod's damped dynamics run for ``dt`` under the
        elongations they reached."""
        self.sim.step(self._command, dt)
        self.rod.set_elongations(self.sim.elongation)
        self.rod.advance(dt)

    def pose(self) -> F64:
        """True ``T_base_ee`` of the rod (gravity included)."""
        return self.rod.pose()

    def centreline(self) -> F64:
        """The rod's centre line (n, 3), base first."""
        return self.rod.centreline()

    def centreline_sections(self) -> npt.NDArray[np.int64]:
        """Section index of every centre-line point (for its body radius)."""
        return self.rod.node_sections()
