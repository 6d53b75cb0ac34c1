"""The simulated pneumatic arm: a plant that is *not* the controller's model.

Commands (actuator elongations, m) go through the pressure map of IV-A (2100 psi per m),
are saturated at 0 and the maximum pressure, follow first-order regulator dynamics, pass
a rate-independent hysteresis, and are scaled by per-actuator gains that differ from the
nominal map by a few percent. The resulting elongations drive the *true* arm: a
:class:`softarm.SoftArm` whose sections (radii, rest lengths, offsets, twists) are
perturbed from the nominal ones. Its end-effector pose is measured by a simulated
tracker (noise + the paper's 10 rad/s low-pass filter). Everything is deterministic for
a given seed and runs in simulated time.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
import numpy.typing as npt

from softarm._core import Section, SoftArm
from softarm.checks import FloatArray as F64
from softarm.errors import ParameterError, ShapeError
from softarm.sim.hysteresis import PlayHysteresis
from softarm.sim.plant_file import plant_from_mapping, validate_plant_value
from softarm.sim.pressure import PressureDynamics, to_psi
from softarm.sim.tracker import PoseTracker
from softarm.units import MAX_PSI, METRES_PER_PSI


@dataclass(frozen=True)
class PlantConfig:
    """Parameters of the simulated plant (SI units unless the name says psi).

    Every field is checked against its range in
    :data:`softarm.sim.plant_file.PLANT_KEYS` (a bad one raises
    :class:`~softarm.errors.ParameterError` naming it); :meth:`from_mapping` builds one
    from a ``[plant]`` table and :func:`softarm.sim.plant_file.load_plant_file` from a
    TOML file (``--plant FILE``).
    """

    #: Relative spread (uniform, +-) of radii, rest lengths and plate offsets.
    geometry_spread: float = 0.03
    #: Spread (uniform, +-, rad) of the twists between sections.
    twist_spread: float = 0.03
    #: Relative spread of each actuator's elongation per psi around 1/2100 m/psi.
    gain_spread: float = 0.03
    #: Time constant of the pressure regulators (s).
    pressure_tau: float = 0.08
    #: Width of the hysteresis band (psi).
    hysteresis_psi: float = 1.5
    #: Largest regulator pressure (psi).
    max_psi: float = MAX_PSI
    #: Tracker noise, per axis: position (m) and rotation (rad).
    position_noise: float = 1e-4
    angle_noise: float = math.radians(0.1)
    #: Tracker low-pass cut-off (rad/s), the paper's 10 rad/s.
    cutoff: float = 10.0
    #: Which physics simulates the arm: "pcc" (constant-curvature arcs) or "cosserat".
    model: str = "pcc"
    #: Gravity in the base frame (m/s^2); the constant-curvature plant ignores it.
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)

    def __post_init__(self) -> None:
        for f in fields(self):
            value = validate_plant_value(f.name, getattr(self, f.name), where="PlantConfig")
            object.__setattr__(self, f.name, value)

    @classmethod
    def from_mapping(cls, mapping: Mapping[str, Any], *, where: str = "plant") -> PlantConfig:
        """A plant from a ``[plant]`` table (see :mod:`softarm.sim.plant_file`); keys left
        out keep their defaults. Unknown keys, wrong types and out-of-range values raise
        :class:`~softarm.errors.ParameterError` naming ``where.key``."""
        return plant_from_mapping(mapping, where=where)

    @property
    def play_m(self) -> float:
        """The declared play band width in elongation (m): ``hysteresis_psi`` at the
        nominal :data:`~softarm.units.METRES_PER_PSI` (what a lag model's play needs)."""
        return self.hysteresis_psi * METRES_PER_PSI


def perturbed_arm(nominal: SoftArm, rng: np.random.Generator, config: PlantConfig) -> SoftArm:
    """A copy of ``nominal`` with every section's geometry perturbed (see PlantConfig)."""
    sections = []
    for s in nominal.sections:
        u = rng.uniform(-config.geometry_spread, config.geometry_spread, 3)
        sections.append(
            Section(
                radius=s.radius * (1.0 + u[0]),
                rest_length=s.rest_length * (1.0 + u[1]),
                lower=s.lower,
                # The true arm is never asked to check limits; leave room for gain spread.
                upper=s.upper * (1.0 + 2.0 * config.gain_spread) + 1e-9,
                offset=s.offset * (1.0 + u[2]),
                twist=s.twist + rng.uniform(-config.twist_spread, config.twist_spread),
            )
        )
    return SoftArm(sections)


class SimulatedArm:
    """The plant. ``apply(command, dt)`` holds a command for ``dt`` seconds and returns
    the tracker's measurement of the end-effector pose.

    Args:
        model: the controller's nominal arm (default ``SoftArm.blackberry()``).
        config: plant parameters.
        seed: seed of every random choice (geometry, gains, noise).
    """

    def __init__(
        self, model: SoftArm | None = None, config: PlantConfig | None = None, seed: int = 0
    ) -> None:
        self.model = model if model is not None else SoftArm.blackberry()
        self.config = config if config is not None else PlantConfig()
        rng = np.random.default_rng(seed)
        self.true_arm = perturbed_arm(self.model, rng, self.config)
        n = self.model.n_dofs
        self.n = n
        self.metres_per_psi = METRES_PER_PSI * (
            1.0 + rng.uniform(-self.config.gain_spread, self.config.gain_spread, n)
        )
        self.dynamics = PressureDynamics(n, self.config.pressure_tau, self.config.max_psi)
        self.hysteresis = PlayHysteresis(np.full(n, self.config.hysteresis_psi))
        self.tracker = PoseTracker(
            np.random.default_rng(rng.integers(2**62)),
            self.config.position_noise,
            self.config.angle_noise,
            self.config.cutoff,
        )
        self.time = 0.0

    def _check(self, q: npt.ArrayLike, arg: str) -> F64:
        a = np.asarray(q, dtype=np.float64)
        if a.shape != (self.n,):
            raise ShapeError(f"{arg}: expected shape ({self.n},), got {a.shape}")
        return a

    def reset(self, q: npt.ArrayLike) -> F64:
        """Settles the plant at command ``q`` (m) with time 0; returns the measurement."""
        p = self.dynamics.saturate(to_psi(self._check(q, "q")))
        self.dynamics.pressure = p.copy()
        self.hysteresis.output = p.copy()
        self.tracker.reset()
        self.time = 0.0
        return self.tracker.measure(self.true_pose(), 0.0)

    @property
    def pressure(self) -> F64:
        """Regulator pressures (psi)."""
        return self.dynamics.pressure.copy()

    @property
    def elongation(self) -> F64:
        """True actuator elongations (m)."""
        return self.hysteresis.output * self.metres_per_psi

    def true_pose(self) -> F64:
        """The true end-effector pose (4, 4) now."""
        return self.true_arm.forward(self.elongation)

    def pose_at_pressure(self, psi: npt.ArrayLike) -> F64:
        """The true arm's steady-state pose at pressures ``psi`` (no hysteresis)."""
        p = self.dynamics.saturate(self._check(psi, "psi"))
        return self.true_arm.forward(p * self.metres_per_psi)

    def step(self, q: npt.ArrayLike, dt: float) -> None:
        """Holds command ``q`` (m, may be infeasible: the regulators saturate it) for
        ``dt`` seconds, without a tracker measurement (for plants measured otherwise)."""
        if not (math.isfinite(dt) and dt > 0.0):
            raise ParameterError(f"dt = {dt}: must be positive and finite")
        p = self.dynamics.advance(to_psi(self._check(q, "q")), dt)
        self.hysteresis(p)
        self.time += dt

    def apply(self, q: npt.ArrayLike, dt: float) -> F64:
        """:meth:`step`, then the tracker's measured pose (4, 4)."""
        self.step(q, dt)
        return self.tracker.measure(self.true_pose(), dt)
