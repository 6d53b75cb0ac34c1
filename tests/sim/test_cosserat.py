"""The Cosserat-rod plant against closed forms (PyElastica, optional extra ``cosserat``).

* no gravity: the rod's equilibrium is the constant-curvature arm of eq. (1)-(3);
* one actuator elongated: the section bends away from it, in the plane eq. (1) gives;
* a straight uniform cantilever under its own weight: tip deflection q L^4 / (8 EI)
  (Euler-Bernoulli);
* the plant (pressure side + rod) runs a few control periods; a missing PyElastica is a
  clear error.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import softarm
from softarm.errors import MissingDependencyError
from softarm.sim.cosserat.params import RodParameters, cantilever_sag, design_stiffness

ARM = softarm.SoftArm.blackberry()


def test_stiffness_design_gives_the_sag() -> None:
    p = RodParameters(design_sag=0.02)
    ei = design_stiffness(ARM, p)
    assert cantilever_sag(ARM, p, ei) == pytest.approx(0.02)
    # proportional to n r^2 (ring of muscles), distal softest
    assert ei[0] > ei[1] > ei[2]


def test_missing_pyelastica_is_a_clear_error(monkeypatch) -> None:
    import builtins

    from softarm.sim import cosserat

    real = builtins.__import__

    def no_elastica(name, *args, **kwargs):
        if name == "elastica" or name.startswith("elastica."):
            raise ImportError("No module named 'elastica'")
        return real(name, *args, **kwargs)

    monkeypatch.delitem(__import__("sys").modules, "elastica", raising=False)
    monkeypatch.setattr(builtins, "__import__", no_elastica)
    with pytest.raises(MissingDependencyError, match=r"softarm\[cosserat\]") as info:
        cosserat.require_elastica()
    assert info.value.extra == "cosserat" and isinstance(info.value, softarm.SoftarmError)


elastica = pytest.importorskip("elastica")

from softarm.sim.cosserat.rod import RodArm  # noqa: E402


@pytest.fixture(scope="module")
def weightless() -> RodArm:
    return RodArm(ARM, RodParameters(settle_speed=1e-5), gravity=(0.0, 0.0, 0.0))


def test_without_gravity_the_rod_is_the_constant_curvature_arm(weightless: RodArm) -> None:
    q = np.array([0.0, 0.02, 0.03, 0.03, 0.0, 0.01, 0.0, 0.033, 0.0])
    weightless.set_elongations(q)
    weightless.relax(max_time=3.0)
    pose, expected = weightless.pose(), ARM.forward(q)
    assert np.linalg.norm(pose[:3, 3] - expected[:3, 3]) < 2e-5
    assert np.abs(pose[:3, :3] - expected[:3, :3]).max() < 1e-3


@pytest.mark.parametrize("actuator", [0, 4, 8])
def test_one_actuator_bends_its_section_away_from_it(weightless: RodArm, actuator: int) -> None:
    section, j = divmod(actuator, 3)
    q = np.zeros(9)
    q[actuator] = 0.02
    weightless.set_elongations(q)
    weightless.relax(max_time=3.0)
    line = weightless.centreline()
    # centre-line point m ends element m; the section's last element ends its arc
    last = int(np.flatnonzero(weightless.kinds == section)[-1])
    frames = ARM.frames(np.zeros(9))  # the section's base frame (straight arm)
    base = frames[section]
    end = line[last] - base[:3, 3]
    # eq. (1): theta = arctan(sqrt(3)(l3 - l2) / (l2 + l3 - 2 l1)); the arc's centre lies
    # towards theta, i.e. away from the elongated actuator at angle 2 pi j / 3.
    away = base[:3, :3] @ np.array(
        [-math.cos(2 * math.pi * j / 3), -math.sin(2 * math.pi * j / 3), 0]
    )
    lateral = end - (end @ base[:3, 2]) * base[:3, 2]
    assert lateral @ away > 0.9 * np.linalg.norm(lateral) > 0
    # in the bending plane: no component across it
    across = np.cross(base[:3, 2], away)
    assert abs(lateral @ across) < 1e-3 * np.linalg.norm(lateral)
    _, phi, _ = ARM.configuration(q)[section]
    arc = ARM.configuration(q)[section][0]
    # the chord of an arc of length arc and angle phi: lateral = arc (1 - cos phi) / phi
    assert np.linalg.norm(lateral) == pytest.approx(arc * (1 - math.cos(phi)) / phi, rel=2e-3)


def test_straight_cantilever_sags_as_euler_bernoulli() -> None:
    # One uniform section, no plates or gripper, stiff in shear: w = q L^4 / (8 EI).
    length, ei = 0.45, 4.0
    arm = softarm.SoftArm([softarm.Section(0.028, length, 0.0, 0.03, offset=0.0)])
    p = RodParameters(
        muscles=(6,), plate_masses=(0.0,), gripper_mass=0.0, cube_mass=0.0,
        bending_stiffness=(ei,), shear_stiffness=(1e6,), muscle_axial_stiffness=1e6,
        elements_per_section=20, settle_speed=1e-5,
    )  # fmt: skip
    g = 9.81
    rod = RodArm(arm, p, gravity=(-g, 0.0, 0.0))
    rod.set_elongations(np.zeros(3))
    rod.relax(max_time=5.0)
    q = p.line_masses(arm)[0] * g
    expected = q * length**4 / (8 * ei)
    assert 0.001 < expected < 0.02  # small deflection: the linear theory holds
    assert -rod.pose()[0, 3] == pytest.approx(expected, rel=0.02)
    assert cantilever_sag(arm, p, np.array([ei])) == pytest.approx(expected, rel=1e-3)


def test_plant_runs_control_periods_with_gravity() -> None:
    from softarm.sim.arm import PlantConfig
    from softarm.sim.cosserat.plant import CosseratPlant
    from softarm.sim.pressure import METRES_PER_PSI

    plant = CosseratPlant(ARM, PlantConfig(model="cosserat", gravity=(0.0, -9.81, 0.0)), seed=3)
    rest = plant.pose()
    assert 0.01 < -rest[1, 3] < 0.05  # the horizontal arm sags 1-5 cm
    plant.command_pressures(np.full(9, 0.02 / METRES_PER_PSI))
    for _ in range(6):
        plant.advance(0.05)
    # All actuators up equally: the arm extends ~2 cm (less the pressure lag).
    assert plant.pose()[2, 3] > rest[2, 3] + 0.01
    assert plant.pressures().min() > 20.0
    assert plant.centreline().shape[1] == 3


def test_sim_rig_runs_on_the_rod() -> None:
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig
    from softarm.sim.arm import PlantConfig
    from softarm.sim.cosserat.clearance import RodClearance
    from softarm.sim.cosserat.plant import CosseratPlant

    plant = PlantConfig(model="cosserat", gravity=(-9.81, 0.0, 0.0))
    rig = build_sim_rig(SimRigOptions(n_berries=1, seed=3, plant=plant))
    assert isinstance(rig.plant, CosseratPlant)
    assert isinstance(rig.watch.clearance, RodClearance)
    rig.machine.actuator.send(np.full(9, 0.01))
    for _ in range(4):
        rig.clock.sleep(0.05)
    assert np.isfinite(rig.watch.min_gap) and rig.watch.contacts == 0
    # the gripper the cameras see is the rod's, sagging along -x
    assert rig.plant.pose()[0, 3] < rig.plant.arm.forward(rig.plant.q())[0, 3] - 0.01
