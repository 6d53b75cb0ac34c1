"""Issue 13 item 5: the resolver's results (``StepResult``, ``Solution``) and the stateful
``LagModel`` pickle and deep-copy like the other core classes; a copied lag model carries
its predicted state and predicts the same elongations as the original."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import softarm
from softarm import _core

ARM = softarm.SoftArm.blackberry()
Q = np.array([0.010, 0.002, 0.025, 0.030, 0.012, 0.001, 0.005, 0.020, 0.015])
GOAL = ARM.forward(np.array([0.020, 0.010, 0.005, 0.002, 0.022, 0.011, 0.015, 0.003, 0.030]))
CANE = _core.PolynomialCurve([[0.06, 0.0, 0.03], [0.0, 0.0, 0.01], [0.0, 1.0, 0.0]], (0.0, 0.6))


def round_trips(obj: object) -> list[object]:
    return [pickle.loads(pickle.dumps(obj, protocol=p)) for p in (2, pickle.HIGHEST_PROTOCOL)] + [
        copy.deepcopy(obj),
        copy.copy(obj),
    ]


def step_fields(s: _core.StepResult) -> tuple[object, ...]:
    return (
        s.q.tolist(),
        s.unclamped.tolist(),
        s.saturated,
        s.position_error,
        s.orientation_error,
        s.clearance,
    )


@pytest.mark.parametrize("obstacles", [None, [CANE]], ids=["free", "cane"])
def test_step_result_round_trips(obstacles: object) -> None:
    step = softarm.Resolver(ARM).step(Q, GOAL, obstacles=obstacles)
    for copied in round_trips(step):
        assert type(copied) is _core.StepResult
        assert step_fields(copied) == step_fields(step)
        assert copied.q.dtype == np.float64


def test_saturated_step_keeps_its_flag_and_infinite_clearance() -> None:
    # At an upper limit with a far target the command saturates; no obstacle: clearance inf.
    q = np.array([0.0, 0.009, 0.0014, 0.0006, 0.0271, 0.0304, 0.0202, 0.0243, 0.0181])
    q[0] = ARM.upper[0]
    step = softarm.Resolver(ARM, "position").step(q, np.array([-0.3598, -0.1283, 0.3555]))
    assert step.saturated and step.clearance == float("inf")
    for copied in round_trips(step):
        assert step_fields(copied) == step_fields(step)


@pytest.mark.parametrize("max_steps", [3, 1000], ids=["step_limit", "converged"])
def test_solution_round_trips(max_steps: int) -> None:
    sol = softarm.Resolver(ARM).solve(Q, GOAL, max_steps=max_steps)
    for copied in round_trips(sol):
        assert type(copied) is _core.Solution
        assert np.array_equal(copied.q, sol.q)
        assert (copied.converged, copied.steps, copied.best_step, copied.termination) == (
            sol.converged,
            sol.steps,
            sol.best_step,
            sol.termination,
        )
        assert (copied.position_error, copied.orientation_error) == (
            sol.position_error,
            sol.orientation_error,
        )


def test_lag_model_round_trips_with_its_state() -> None:
    lag = _core.LagModel(0.4, 0.05, Q)
    lag.advance(Q + 0.004)
    lag.advance(Q - 0.002)
    for copied in round_trips(lag):
        assert type(copied) is _core.LagModel
        assert repr(copied) == repr(lag)
        assert np.array_equal(copied.q, lag.q)
    # The copies are independent and predict exactly what the original does.
    a, b = lag, pickle.loads(pickle.dumps(lag))
    for command in (Q + 0.01, Q, Q - 0.003):
        assert np.array_equal(a.advance(command), b.advance(command))
    b.reset(Q)
    assert not np.array_equal(a.q, b.q)


def test_rebuilders_reject_bad_fields() -> None:
    with pytest.raises(softarm.errors.SoftarmError, match="termination"):
        _core._rebuild_solution(Q, True, 1, 0.0, 0.0, "finished")
    with pytest.raises(softarm.errors.SoftarmError, match="unclamped"):
        _core._rebuild_step_result(Q, Q[:3], False, 0.0, 0.0, 1.0)
