"""Issue 27 items 2, 3 and 4: one body model and one home for each law.

- The arm's body (per-section radii, plates, the gripper as a capsule) is declared once in
  the core (``softarm._core.Body``); the harvest's ``Clearance``, the Cosserat rod's
  ``RodClearance`` and the resolver's default body radius all use it, and
  ``softarm.geometry``'s radii are the core's.
- The play operator and the loop-gain laws (``lead_gain``, ``predicted_loop_alpha``) are
  the core's; checked here against the Python they replace, on random inputs.
"""

from __future__ import annotations

import numpy as np
import pytest

from softarm import Gains, PolynomialCurve, Resolver, SoftArm, _core, geometry
from softarm._core import Body, lead_gain, play, predicted_loop_alpha
from softarm.errors import NonFiniteError, ParameterError, ShapeError
from softarm.harvest.control.clearance import Clearance

ARM = SoftArm.blackberry()


def test_one_declaration_of_the_radii() -> None:
    assert geometry.ACTUATOR_RADIUS is _core.ACTUATOR_RADIUS
    assert geometry.CANE_RADIUS is _core.CANE_RADIUS
    assert geometry.GRIPPER_RADIUS is _core.GRIPPER_RADIUS
    body = Body.for_arm(ARM, 0.03)
    want = [s.radius + _core.ACTUATOR_RADIUS for s in ARM.sections]
    np.testing.assert_array_equal(body.section_radii, want)
    assert body.gripper_radius == _core.GRIPPER_RADIUS
    assert body.gripper_back == ARM.sections[-1].offset and body.grasp_offset == 0.03
    # The resolver's default body is the arm's, the gripper ending at the end effector.
    assert Resolver(ARM).body == Body.for_arm(ARM, 0.0)
    assert Clearance(ARM, [], 0.03).body == body


def _pieces(q: np.ndarray, n: int) -> list[tuple[np.ndarray, float]]:
    """Points (n per piece) of the body at q with their radii, from the kinematics alone:
    each arc (``arm.point``), each inner plate (the straight part between a section's tip
    and the next one's base), the gripper (distal tip to the grasp point)."""
    body = Body.for_arm(ARM, 0.03)
    out = []
    s = np.linspace(0.0, 1.0, n)
    for i, r in enumerate(body.section_radii):
        out.append((np.array([ARM.point(q, i, t)[0] for t in s]), r))
        tip = ARM.point(q, i, 1.0)[0]
        if i + 1 < ARM.n_sections:
            nxt = ARM.point(q, i + 1, 0.0)[0]
            out.append((tip + np.outer(s, nxt - tip), r))
        else:
            ee = ARM.forward(q)
            end = ee[:3, 3] + 0.03 * ee[:3, 2]
            out.append((tip + np.outer(s, end - tip), body.gripper_radius))
    return out


def test_clearance_gap_agrees_with_brute_force_sampling() -> None:
    rng = np.random.default_rng(27)
    for _ in range(25):
        q = rng.uniform(0.0, 70 / 2100, 9)
        pieces = _pieces(q, 300)
        anchor = pieces[rng.integers(len(pieces))][0][rng.integers(300)]
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        side = np.cross(d, rng.normal(size=3))
        side /= np.linalg.norm(side)
        a = anchor + side * rng.uniform(0.0, 0.06) - 0.15 * d
        bend = side * rng.uniform(-0.2, 0.2)
        cane = PolynomialCurve(np.column_stack([a, 0.3 * d, bend]), (0.0, 1.0))
        exact = Clearance(ARM, [cane], 0.03).gap(q)
        pts = cane(np.linspace(0.0, 1.0, 3000))
        brute = min(
            float((np.linalg.norm(x[:, None] - pts[None], axis=2).min(axis=1) - r).min())
            for x, r in pieces
        )
        brute -= _core.CANE_RADIUS
        assert exact <= brute + 1e-9
        assert brute - exact < 3e-4


def test_rod_clearance_measures_the_same_body() -> None:
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig
    from softarm.sim.arm import PlantConfig
    from softarm.sim.cosserat.clearance import RodClearance

    rig = build_sim_rig(SimRigOptions(n_berries=1, seed=3, plant=PlantConfig(model="cosserat")))
    rod = rig.watch.clearance
    assert isinstance(rod, RodClearance)
    assert rod.body == Body.for_arm(rig.plant.arm, rod.offset)
    np.testing.assert_array_equal(rod.radii, rod.body.section_radii + _core.CANE_RADIUS)


def test_body_checks_its_inputs() -> None:
    with pytest.raises(ShapeError):
        Body([], 0.025, 0.06, 0.03)
    with pytest.raises(ParameterError):
        Body([0.03, -0.01], 0.025, 0.06, 0.03)
    with pytest.raises(ParameterError):
        Body.for_arm(ARM, float("nan"))
    body = Body.for_arm(ARM, 0.03)
    assert body.gap(ARM, np.zeros(9), []) == np.inf
    with pytest.raises(ShapeError):
        Body([0.03, 0.03], 0.025, 0.06, 0.03).gap(ARM, np.zeros(9), [np.zeros(3)])
    import pickle

    assert pickle.loads(pickle.dumps(body)) == body


def _old_play(y: np.ndarray, x: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The operator as sim/hysteresis.py and harvest/control/plant_model.py each wrote it."""
    half = 0.5 * w
    return np.clip(y, x - half, x + half)


def test_play_is_the_previous_operator_bit_for_bit() -> None:
    rng = np.random.default_rng(3)
    for _ in range(2000):
        n = int(rng.integers(1, 12))
        y, x = rng.normal(0, 3, n), rng.normal(0, 3, n)
        w = np.abs(rng.normal(0, 2, n)) * (rng.random(n) < 0.8)
        np.testing.assert_array_equal(play(y, x, w), _old_play(y, x, w))
    with pytest.raises(ShapeError):
        play(np.zeros(2), np.zeros(3), np.zeros(2))
    with pytest.raises(ParameterError):
        play(np.zeros(2), np.zeros(2), [1.0, -1.0])
    with pytest.raises(NonFiniteError):
        play(np.zeros(2), [np.nan, 0.0], np.zeros(2))


def _old_lead(tau_s: float, period_s: float, cap: float = 1.5) -> float:
    if tau_s == 0:
        return 0.0
    a = float(np.exp(-period_s / tau_s))
    return min(cap, 0.5 * a / (1.0 - a))


def _old_alpha(lag_s: float) -> float:
    if lag_s == 0:
        return 0.9
    return float(np.clip(0.21 / lag_s, Gains().hybrid_alpha, 0.9))


def test_loop_gain_laws_are_the_previous_python_ones() -> None:
    rng = np.random.default_rng(4)
    for _ in range(5000):
        tau = float(rng.choice([0.0, rng.uniform(0, 0.05), rng.uniform(0, 3)]))
        period = float(rng.choice([0.05, rng.uniform(1e-3, 1.0)]))
        # exp may differ from numpy's in the last bit
        assert lead_gain(tau, period) == pytest.approx(_old_lead(tau, period), rel=1e-15)
        lag = float(rng.choice([0.0, rng.uniform(0, 2)]))
        assert predicted_loop_alpha(lag) == _old_alpha(lag)
    assert lead_gain(0.08, 0.05) == _old_lead(0.08, 0.05)  # the simulated plant's lag
    assert _core.PREDICTED_ALPHA_MIN == Gains().hybrid_alpha
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(ParameterError):
            predicted_loop_alpha(bad)
        with pytest.raises(ParameterError):
            lead_gain(bad, 0.05)
    with pytest.raises(ParameterError):
        lead_gain(0.1, 0.0)
