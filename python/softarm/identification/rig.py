"""What the identification runs on: a pressure bank behind the safety layer, a clock that
advances one control period, and the tracked end-effector pose.

:class:`SimIdentificationRig` is the simulated plant of ``softarm harvest --sim`` for the
same seed and ``[plant]`` table; :mod:`softarm.identification.hardware` opens the real
one. The identification sees only what the hardware gives: the safety layer's commands,
the regulators' pressure readings and the tracker's pose, never the true elongations.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from softarm._core import SoftArm
from softarm.checks import FloatArray as F64
from softarm.config import ChannelsConfig
from softarm.errors import ParameterError
from softarm.hardware.safety import SafePressureBank
from softarm.hardware.simulated import SimulatedPressureBank
from softarm.sim.arm import PlantConfig, SimulatedArm
from softarm.units import METRES_PER_PSI

__all__ = ["IdentificationRig", "SimIdentificationRig", "sim_plant_seed"]


#: Safety limits of the simulated rig: the channels' defaults, as ``build_sim_rig``'s
#: (70 psi, the arm's 0.0333 m upper limit; 100 psi/s; a 0.5 s watchdog).
SIM_P_MAX, SIM_RATE, SIM_WATCHDOG = (
    ChannelsConfig().p_max,
    ChannelsConfig().max_rate_psi_per_s,
    ChannelsConfig().watchdog_timeout_s,
)


def sim_plant_seed(seed: int) -> int:
    """The plant seed ``build_sim_rig`` uses for bush seed ``seed`` (so that
    ``identify --sim --seed S`` identifies the plant ``harvest --sim --seed S`` runs on)."""
    return seed + 1000


class IdentificationRig(Protocol):
    """The hardware boundary the identification experiment talks to."""

    bank: SafePressureBank
    #: Control period (s).
    period: float
    #: Cut-off (rad/s) of the first-order low-pass the pose tracker applies, or None.
    pose_cutoff: float | None
    #: Nominal actuator elongation per psi (m/psi) of the arm model.
    metres_per_psi: float

    def now(self) -> float:
        """Arm time (s)."""
        ...

    def advance(self) -> None:
        """Let one control period pass (simulated or real)."""
        ...

    def pose(self) -> F64 | None:
        """The tracked ``T_base_ee`` (4, 4), or None when the tracker lost it."""
        ...

    def close(self) -> None:
        """Vent and release the devices."""
        ...


class _SimPressures:
    """The :class:`~softarm.hardware.simulated.PressurePlant` face of a SimulatedArm that
    also keeps the tracker's last measurement."""

    def __init__(
        self, arm: SimulatedArm, noise_psi: float = 0.0, seed: int = 0, monitor: bool = True
    ) -> None:
        self.arm = arm
        self.monitor = monitor
        self.command = np.zeros(arm.n)
        self.measured = arm.reset(self.command)
        self.noise_psi = noise_psi
        self.rng = np.random.default_rng(seed)

    def command_pressures(self, psi: F64) -> None:
        self.command = np.asarray(psi, dtype=np.float64).copy()

    def pressures(self) -> F64:
        if not self.monitor:  # as NidaqPressureBank without a monitor: the command
            return self.command.copy()
        p = self.arm.pressure
        if self.noise_psi > 0.0:  # a pressure monitor's reading noise
            p = p + self.rng.normal(0.0, self.noise_psi, p.shape)
        return p

    def advance(self, dt: float) -> None:
        # The regulators receive psi; the plant converts through the nominal map and
        # applies its own true gains (softarm.sim.arm).
        self.measured = self.arm.apply(self.command * METRES_PER_PSI, dt)


class SimIdentificationRig:
    """The simulated plant behind a :class:`SafePressureBank` on a simulated clock.

    Args:
        plant: the plant's parameters (the ``[plant]`` table).
        seed: the harvest seed; the plant is drawn from :func:`sim_plant_seed`.
        model: the nominal arm (default ``SoftArm.blackberry()``).
        period: control period (s).
        reading_noise_psi: standard deviation of the pressure readings' noise (psi); the
            plant's regulators are exact, a real pressure monitor is not.
        pressure_monitor: False: the readings echo the commands, as on hardware with no
            pressure board (the lag is then identified from the poses).
    """

    def __init__(
        self,
        plant: PlantConfig | None = None,
        seed: int = 0,
        model: SoftArm | None = None,
        period: float = 0.05,
        reading_noise_psi: float = 0.0,
        pressure_monitor: bool = True,
    ) -> None:
        self.model = model if model is not None else SoftArm.blackberry()
        self.plant = plant if plant is not None else PlantConfig()
        if self.plant.model != "pcc":
            # The estimator's pose model is the constant-curvature one (eq. 3): a rod
            # sagging under gravity is not, and a 2-minute rod run costs many minutes.
            raise ParameterError(
                f"plant.model = {self.plant.model!r}: identify --sim runs on the 'pcc' "
                "plant only (use softarm calibrate for the Cosserat plant's geometry)"
            )
        self.arm = SimulatedArm(self.model, self.plant, seed=sim_plant_seed(seed))
        if not (np.isfinite(reading_noise_psi) and reading_noise_psi >= 0.0):
            raise ParameterError(f"reading_noise_psi = {reading_noise_psi}: must be >= 0")
        self._sim = _SimPressures(
            self.arm, reading_noise_psi, sim_plant_seed(seed) + 1, pressure_monitor
        )
        self.period = period
        self.pose_cutoff: float | None = self.plant.cutoff
        self.metres_per_psi = METRES_PER_PSI
        self._time = 0.0
        self.bank = SafePressureBank(
            SimulatedPressureBank(self._sim, self.arm.n), SIM_P_MAX, SIM_RATE, SIM_WATCHDOG,
            self.now, watchdog_thread=False, simulated=True,
        )  # fmt: skip

    def now(self) -> float:
        return self._time

    def advance(self) -> None:
        self._sim.advance(self.period)
        self._time += self.period

    def pose(self) -> F64 | None:
        return self._sim.measured.copy()

    def close(self) -> None:
        self.bank.close()

    def truth(self) -> dict[str, list[float]]:
        """The plant's true per-channel values (for tests and the docs' tables only)."""
        n = self.arm.n
        return {
            "tau_s": [self.plant.pressure_tau] * n,
            "metres_per_psi": self.arm.metres_per_psi.tolist(),
            "hysteresis_psi": [self.plant.hysteresis_psi] * n,
            "dead_time_s": [0.0] * n,
        }
