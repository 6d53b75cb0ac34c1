"""One control stack for both worlds (issue 24, item 1): the simulated rig and the
hardware rig built from one configuration (the hardware's devices faked) get the same
controller, actuator lag model and lead, and planner. Only the devices differ."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
import pytest

from softarm import SoftArm
from softarm.calibration.metrics import PoseErrorStats
from softarm.calibration.result import Calibration, GainMap
from softarm.config import GainsConfig
from softarm.hardware.pressure_map import METRES_PER_PSI
from softarm.harvest.control import stack as rig
from softarm.harvest.rigs.hardware import rig as hw_rig
from softarm.harvest.rigs.sim import rig as sim_rig
from softarm.harvest.rigs.sim.options import SimRigOptions
from softarm.identified_plant import IdentifiedPlant

from .test_hw_rig_config import _config, no_devices  # noqa: F401  (the fixture)

N = 9
#: The simulated plant's lag, as `softarm identify` would measure it.
IDENTIFIED = IdentifiedPlant(
    tau_s=(0.08,) * N,
    metres_per_psi=(METRES_PER_PSI,) * N,
    hysteresis_psi=(0.5,) * N,
    dead_time_s=(0.0,) * N,
)
GAINS = {"damping": 0.02, "max_step": 0.004}


@pytest.fixture
def stacks(monkeypatch: pytest.MonkeyPatch) -> list[rig.ControlStack]:
    """Every control stack built, in order."""
    built: list[rig.ControlStack] = []

    def record(*args: Any, **kwargs: Any) -> rig.ControlStack:
        built.append(rig.build_control_stack(*args, **kwargs))
        return built[-1]

    monkeypatch.setattr(sim_rig, "build_control_stack", record)
    monkeypatch.setattr(hw_rig, "build_control_stack", record)
    return built


def _settings(stack: rig.ControlStack) -> dict[str, Any]:
    """What configures a control stack (the devices and the canes left out)."""
    c, a, p = stack.controller, stack.actuator, stack.planner
    lag = a._model
    return {
        "mode": c.resolver.mode,
        "gains": c.resolver.gains.as_dict(),
        "transport": None if c.transport is None else c.transport.gains.as_dict(),
        "predicts": c.plant_q is not None,
        "way_check": c.clearance is not None,
        "limits": [x.tolist() for x in c.limits()],
        "lead": a._lead,
        "lag_period": None if lag is None else lag.period,
        "play": None if lag is None else lag._play.tolist(),
        "regulators": None if lag is None else _lag(lag._regulators),
        "sensor": None if lag is None else _lag(lag._filter),
        "planner_gains": p.resolver.gains.as_dict(),
        "planner_config": p.cfg,
        "planner_checks": p.clearance is not None,
        "near_standoff": p.near_standoff,
        "grasp_offset": stack.clearance.offset,
    }


def _lag(model: Any) -> tuple[float, float] | None:
    """(tau, period) of a first-order ``LagModel`` (as it pickles), None without one."""
    return None if model is None else tuple(model.__reduce__()[1][:2])


@pytest.mark.usefixtures("no_devices")
def test_both_rigs_get_the_same_controller_from_one_config(
    stacks: list[rig.ControlStack],
) -> None:
    config = replace(_config(), gains=GainsConfig(dict(GAINS)))
    options = SimRigOptions(
        n_berries=1, seed=0, config=config.harvest, identified=IDENTIFIED, gains=GAINS
    )
    sim_rig.build_sim_rig(options)
    hardware = hw_rig.build_hardware_rig(config, identified=IDENTIFIED)
    try:
        sim, hw = (_settings(s) for s in stacks)
    finally:
        hardware.close()
    assert sim == hw
    assert sim["regulators"] == (0.08, 0.1) and sim["sensor"] is not None
    assert sim["lead"] > 0 and sim["predicts"] and sim["transport"] is not None
    assert sim["gains"]["damping"] == sim["transport"]["damping"] == 0.02  # every resolver
    assert np.all(np.asarray(sim["play"]) > 0)


@pytest.mark.usefixtures("no_devices")
def test_without_an_identified_plant_the_hardware_gain_is_bounded_for_the_slowest(
    stacks: list[rig.ControlStack],
) -> None:
    hardware = hw_rig.build_hardware_rig(_config())
    try:
        (hw,) = (_settings(s) for s in stacks)
    finally:
        hardware.close()
    assert not hw["predicts"] and hw["transport"] is None and hw["lead"] == 0.0
    assert hw["gains"]["lag_periods"] == rig.Gains().lag_periods
    assert hw["way_check"] and hw["planner_checks"]  # no canes known: checked all the same


def test_a_fitted_model_replaces_the_configured_arm_and_channel_gains() -> None:
    config = _config()
    arm = SoftArm.blackberry()
    poses = np.tile(np.eye(4), (2, 1, 1))
    fit = Calibration(arm, np.full(N, 1.1), PoseErrorStats.of(poses, poses))
    inputs = hw_rig.hardware_inputs(config, calibration=fit)
    assert inputs.model is arm
    assert isinstance(inputs.pressure_map, GainMap)
    assert inputs.pressure_map.max_psi == config.channels.p_max
