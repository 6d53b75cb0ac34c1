"""The planner's move of a solution towards mid-range in its task's null space
(softarm.harvest.control.mid_band): the projector's identities, the band cost's
gradient, and a solution near a limit brought into the band on the same pose."""

from __future__ import annotations

import numpy as np
import pytest

from softarm._core import SoftArm
from softarm.errors import ParameterError
from softarm.harvest.control.clearance import Clearance
from softarm.harvest.control.ik import ModelIK, planning_resolver
from softarm.harvest.control.mid_band import (
    band_gradient,
    null_projector,
    task_error,
    toward_mid,
)
from softarm.harvest.machine.targets import approach_pose
from softarm.harvest_config import HarvestConfig
from softarm.sim.bush import Bush

MASK = (True, False, True)  # the blackberry gains' orientation rows


@pytest.fixture(scope="module")
def arm() -> SoftArm:
    return SoftArm.blackberry()


def _near_limits(arm: SoftArm, seed: int) -> np.ndarray:
    """A configuration with two channels within 2 % of a limit, the rest anywhere."""
    rng = np.random.default_rng(seed)
    lo, hi = np.asarray(arm.lower), np.asarray(arm.upper)
    q = rng.uniform(lo + 0.3 * (hi - lo), hi - 0.3 * (hi - lo))
    q[rng.integers(0, 3)] = hi[0] - 0.01 * (hi[0] - lo[0])
    q[3 + rng.integers(0, 3)] = lo[3] + 0.01 * (hi[3] - lo[3])
    return np.asarray(q, dtype=np.float64)


@pytest.mark.parametrize("seed", range(5))
def test_projector_identities(arm: SoftArm, seed: int) -> None:
    q = _near_limits(arm, seed)
    _, jac = task_error(arm, q, arm.forward(q), MASK)
    n = null_projector(jac)
    assert jac.shape == (5, arm.n_actuators)
    np.testing.assert_allclose(n, n.T, atol=1e-12)
    np.testing.assert_allclose(n @ n, n, atol=1e-12)
    assert np.max(np.abs(jac @ n)) <= 1e-9 * np.max(np.abs(jac))
    # Rank: the nine elongations less the five task rows.
    assert np.trace(n) == pytest.approx(arm.n_actuators - 5, abs=1e-9)


def test_projector_of_a_rank_deficient_jacobian_keeps_the_lost_direction() -> None:
    jac = np.array([[1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])  # rank 1
    n = null_projector(jac)
    np.testing.assert_allclose(n, np.diag([0.0, 1.0, 1.0]), atol=1e-12)


def test_band_gradient_is_zero_inside_and_points_out_beyond() -> None:
    lo, hi = np.zeros(3), np.ones(3)
    g = band_gradient(np.array([0.05, 0.5, 0.97]), lo, hi, 0.1)
    np.testing.assert_allclose(g, [-0.05, 0.0, 0.07], atol=1e-12)


def test_task_error_is_zero_at_the_pose_of_q(arm: SoftArm) -> None:
    q = _near_limits(arm, 0)
    err, _ = task_error(arm, q, arm.forward(q), MASK)
    assert np.max(np.abs(err)) <= 1e-12


@pytest.mark.parametrize("seed", range(5))
def test_toward_mid_keeps_the_pose_and_leaves_the_limits(arm: SoftArm, seed: int) -> None:
    q = _near_limits(arm, seed)
    target = arm.forward(q)
    lo, hi = np.asarray(arm.lower), np.asarray(arm.upper)
    x = toward_mid(arm, q, target, MASK, 0.15)
    assert x is not q
    err, _ = task_error(arm, x, target, MASK)
    assert np.linalg.norm(err[:3]) <= 1e-3 and np.linalg.norm(err[3:]) <= 0.02
    room = lambda v: float(np.min(np.minimum(v - lo, hi - v)) / (hi[0] - lo[0]))  # noqa: E731
    assert room(q) < 0.02
    assert room(x) > 0.05  # well off both limits
    cost = lambda v: float(np.sum(band_gradient(v, lo, hi, 0.15) ** 2))  # noqa: E731
    assert cost(x) < 0.25 * cost(q)


def test_toward_mid_leaves_a_solution_in_the_band_as_it_is(arm: SoftArm) -> None:
    q = 0.5 * (np.asarray(arm.lower) + np.asarray(arm.upper))
    assert toward_mid(arm, q, arm.forward(q), MASK, 0.15) is q


def _room(arm: SoftArm, q: np.ndarray) -> float:
    lo, hi = np.asarray(arm.lower), np.asarray(arm.upper)
    return float(np.min(np.minimum(q - lo, hi - q)))


@pytest.mark.parametrize("seed", [3, 7])
def test_the_planner_with_a_band_ends_farther_from_the_limits_on_the_same_pose(
    arm: SoftArm, seed: int
) -> None:
    bush = Bush.generate(arm, 3, seed)
    clearance = Clearance(arm, [b.curve() for b in bush.branches], 0.03)
    q = np.full(arm.n_actuators, 0.0167)  # the harvest's home elongation
    current = arm.forward(q)
    plans = []
    for band in (0.0, 0.5):
        planner = ModelIK(
            planning_resolver(arm), HarvestConfig(), seed=0, clearance=clearance, band=band
        )
        plan = planner.plan(q, bush.berries[0].position, current)
        assert plan is not None
        plans.append(plan)
    (plain, axis0), (banded, axis1) = plans
    np.testing.assert_allclose(axis0, axis1)  # the same approach, the same pose
    assert _room(arm, banded[-1]) > _room(arm, plain[-1])
    pre = approach_pose(current, bush.berries[0].position, axis1, 0.03 + 0.05)
    err, _ = task_error(arm, banded[-1], pre, MASK)
    assert np.linalg.norm(err[:3]) <= 1e-3


@pytest.mark.parametrize("band", [-0.1, 0.6, float("nan")])
def test_the_plan_band_is_checked(band: float) -> None:
    with pytest.raises(ParameterError, match="plan_band"):
        HarvestConfig(plan_band=band)
