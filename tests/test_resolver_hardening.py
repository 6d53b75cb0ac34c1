"""Resolver defects found by fault injection (issue 12, items 6 and 14): never a NaN
command, every gain bounded, errors that name the real value, a termination reason, and
gains that pickle."""

from __future__ import annotations

import copy
import math
import pickle

import numpy as np
import pytest

import softarm
from softarm import Gains, Resolver
from softarm.errors import OutOfRangeError, ParameterError, SoftarmError

ARM = softarm.SoftArm.blackberry()
MID = np.full(9, 0.0166)
GOAL = ARM.forward(np.array([0.020, 0.010, 0.005, 0.002, 0.022, 0.011, 0.015, 0.003, 0.030]))


def finite_in_limits_or_typed(call) -> None:  # type: ignore[no-untyped-def]
    """The promise of ``Resolver.step``: a finite command inside the limits, or a typed
    softarm error; never NaN, never another exception type."""
    try:
        r = call()
    except SoftarmError:
        return
    q = np.asarray(r.q)
    assert np.all(np.isfinite(q)), q
    assert np.all(q >= ARM.lower) and np.all(q <= ARM.upper)


@pytest.mark.parametrize("mode", ["conventional", "position", "orientation", "hybrid"])
@pytest.mark.parametrize("big", [1e153, -1e153, 1e200, 1e300])
def test_huge_states_give_a_typed_error_not_nan(mode: str, big: float) -> None:
    q = MID.copy()
    q[4] = big
    with pytest.raises(OutOfRangeError, match=r"q\[4\]"):
        Resolver(ARM, mode).step(q, GOAL)


@pytest.mark.parametrize("big", [1e155, -1e155, 1e300])
def test_huge_targets_give_a_typed_error_not_nan(big: float) -> None:
    goal = GOAL.copy()
    goal[0, 3] = big
    with pytest.raises(OutOfRangeError, match="target"):
        Resolver(ARM, "hybrid").step(MID, goal)
    with pytest.raises(OutOfRangeError, match="target"):
        Resolver(ARM, "position").step(MID, np.array([0.0, big, 0.1]))
    with pytest.raises(OutOfRangeError, match="current"):
        Resolver(ARM, "hybrid").step(MID, GOAL, goal)


def test_far_but_sane_targets_still_step() -> None:
    goal = GOAL.copy()
    goal[:3, 3] = [500.0, -800.0, 999.0]  # unreachable, inside the bound
    r = Resolver(ARM, "hybrid", Gains(max_step=math.inf)).step(MID, goal)
    assert np.all(np.isfinite(r.q)) and r.saturated


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("limit_margin", 1e-300),
        ("limit_margin", 0.5),
        ("hybrid_gamma", -1e300),
        ("position_gamma", -2.0),
        ("hybrid_position", 1e300),
        ("hybrid_orientation", -0.1),
        ("damping", 1e300),
        ("singular_threshold", 5.0),
        ("position_switch", 1e300),
        ("orientation_switch", 4.0),
        ("max_step", 1e300),
        ("hybrid_alpha", 0.0),
        ("lag_periods", -1.0),
        ("lag_periods", 1e9),
        ("repulsion_gain", 1.0),
        ("influence_distance", math.nan),
        ("obstacle_radius", -0.1),
    ],
)
def test_every_gain_is_bounded(field: str, value: float) -> None:
    with pytest.raises(ParameterError, match=field):
        Gains(**{field: value})


def test_extreme_but_valid_gains_never_give_nan() -> None:
    rng = np.random.default_rng(0)
    extremes = [
        Gains(limit_margin=1e-6, hybrid_gamma=-1.0, position_gamma=-1.0, max_step=math.inf),
        Gains(damping=0.0, singular_threshold=0.0, hybrid_position=10.0, hybrid_alpha=2.0),
        Gains(hybrid_switch=0.0, position_switch=0.0, schedule="step", hybrid_gamma=-1.0),
    ]
    for g in extremes:
        for mode in ("position", "orientation", "hybrid", "conventional"):
            res = Resolver(ARM, mode, g)
            for _ in range(20):
                q = rng.uniform(ARM.lower - 0.03, ARM.upper + 0.03)
                finite_in_limits_or_typed(lambda: res.step(q, GOAL))  # noqa: B023
                finite_in_limits_or_typed(lambda: res.step(q, GOAL, GOAL))  # noqa: B023


def test_unknown_mode_and_schedule_name_the_string() -> None:
    with pytest.raises(ParameterError, match=r"mode = \"pose\""):
        Resolver(ARM, mode="pose")
    with pytest.raises(ParameterError, match=r"schedule = \"linear\""):
        Gains(schedule="linear")


def test_solve_says_why_it_stopped() -> None:
    res = Resolver(ARM, "position")
    straight = np.zeros(9)
    # Below the rest pose: every actuator would have to shorten past its lower limit.
    down = ARM.forward(straight)[:3, 3] + np.array([0.0, 0.0, -0.05])
    sol = res.solve(straight, down)
    assert not sol.converged and sol.termination == "stuck", sol
    assert sol.steps == 0
    ok = Resolver(ARM, "hybrid").solve(MID, GOAL)
    assert ok.converged and ok.termination == "converged"
    short = Resolver(ARM, "hybrid").solve(MID, GOAL, max_steps=2)
    assert not short.converged and short.termination == "step_limit"
    assert "termination" in repr(short)


def test_gains_pickle_and_deepcopy() -> None:
    g = Gains(hybrid_alpha=0.2, schedule="step", axis_mask=(True, True, False), lag_periods=3.0)
    for h in (pickle.loads(pickle.dumps(g)), copy.deepcopy(g), copy.copy(g)):
        assert h == g and h.as_dict() == g.as_dict()
    assert Gains.from_dict(g.as_dict()) == g


def test_for_lag_caps_alpha_by_the_lag_bound() -> None:
    g = Gains.for_lag(1.0, 0.05)
    assert g.lag_periods == pytest.approx(20.0)
    assert Gains().lag_periods == 20.0
    with pytest.raises(ParameterError, match="tau_s"):
        Gains.for_lag(-1.0, 0.05)
    with pytest.raises(ParameterError, match="period_s"):
        Gains.for_lag(1.0, 0.0)
