"""softarm.Resolver / softarm.Gains through the bindings: types, every error path,
null-space properties, limits, saturation, and agreement with a numpy oracle of eq. (20)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import softarm
from softarm import Gains, Resolver

MID = np.full(9, 0.0166)
Q = np.array([0.010, 0.002, 0.025, 0.030, 0.012, 0.001, 0.005, 0.020, 0.015])
GOAL = np.array([0.020, 0.010, 0.005, 0.002, 0.022, 0.011, 0.015, 0.003, 0.030])


def exact(**kw: object) -> Gains:
    """Exact pseudo-inverses, no caps, joint-limit term always on."""
    base = {
        "singular_threshold": 0.0,
        "loop_singular_threshold": 0.0,
        "max_step": math.inf,
        "schedule": "step",
        "position_switch": 0.0,
        "orientation_switch": 0.0,
        "hybrid_switch": 0.0,
    }
    base.update(kw)
    return Gains(**base)


def pinv(j: np.ndarray) -> np.ndarray:
    return np.linalg.pinv(j, rcond=1e-12)


def rotvec(r: np.ndarray) -> np.ndarray:
    c = np.clip((np.trace(r) - 1) / 2, -1, 1)
    th = math.acos(c)
    v = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    return 0.5 * v if th < 1e-9 else th / (2 * math.sin(th)) * v


def numpy_eq20(arm: softarm.SoftArm, g: Gains, q: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Literal eq. (17) and (20) in numpy (axis mask x, z; exact pinv)."""
    pose, j = arm.forward_jacobian(q)
    jv, jw = j[:3], j[[3, 5]]
    ep = target[:3, 3] - pose[:3, 3]
    ew = rotvec(target[:3, :3] @ pose[:3, :3].T)[[0, 2]]
    lo, hi = arm.lower, arm.upper
    r = hi - lo
    d = g.limit_margin * r
    x = np.clip(q, lo + d, hi - d)
    eta = 0.25 * r**2 * (2 * x - hi - lo) / ((hi - x) * (x - lo)) ** 2  # grad of eq. (14)
    jvp = pinv(jv)
    n1 = np.eye(9) - jvp @ jv
    jt = jw @ n1  # eq. (17)
    jtp = pinv(jt)
    return g.hybrid_alpha * (
        g.hybrid_position * jvp @ ep
        + g.hybrid_orientation * jtp @ (ew - jw @ jvp @ ep)
        + g.hybrid_gamma * (n1 - jtp @ jt) @ eta
    )


def test_defaults_presets_and_replace(arm: softarm.SoftArm) -> None:
    res = Resolver(arm)
    assert res.mode == "hybrid"
    assert res.gains == Gains()
    p = Gains.paper()
    assert (p.position_alpha, p.position_gamma, p.position_switch) == (0.074, -0.01, 0.030)
    assert (p.hybrid_alpha, p.hybrid_position, p.hybrid_orientation) == (0.05, 1.0, 0.1)
    assert (p.hybrid_gamma, p.hybrid_switch, p.schedule) == (-5e-5, 0.05, "step")
    assert p.orientation_switch == pytest.approx(math.radians(30))
    assert p.axis_mask == (True, False, True)
    g = Gains(schedule="step").replace(hybrid_alpha=0.2, axis_mask=[True, True, True])
    assert (g.hybrid_alpha, g.schedule, g.axis_mask) == (0.2, "step", (True, True, True))
    assert g.as_dict()["hybrid_alpha"] == 0.2
    assert "Gains(" in repr(g) and "Resolver" in repr(res)


@pytest.mark.parametrize(
    ("kwargs", "error", "name"),
    [
        ({"hybrid_alpha": 0.0}, softarm.ParameterError, "hybrid_alpha"),
        ({"hybrid_gamma": 1e-3}, softarm.ParameterError, "hybrid_gamma"),
        ({"position_gamma": math.nan}, softarm.ParameterError, "position_gamma"),
        ({"limit_margin": 0.0}, softarm.ParameterError, "limit_margin"),
        ({"max_step": -1.0}, softarm.ParameterError, "max_step"),
        ({"schedule": "linear"}, softarm.ParameterError, "schedule"),
        ({"axis_mask": [True, False]}, softarm.ShapeError, "axis_mask"),
        ({"alpha": 0.3}, softarm.ParameterError, "alpha"),
        ({"damping": "big"}, softarm.ParameterError, "damping"),
    ],
)
def test_bad_gains_are_typed_and_named(kwargs: dict, error: type, name: str) -> None:
    with pytest.raises(error, match=name):
        Gains(**kwargs)


def test_bad_mode(arm: softarm.SoftArm) -> None:
    with pytest.raises(softarm.ParameterError, match="mode"):
        Resolver(arm, "fast")


def test_step_types_and_array_likes(arm: softarm.SoftArm) -> None:
    # No lag bound: the model's own pose as `current` then gives the open-loop step.
    res = Resolver(arm, gains=Gains(lag_periods=0.0))
    target = arm.forward(GOAL)
    r = res.step(list(Q), target.tolist())
    assert isinstance(r, softarm.StepResult)
    assert r.q.dtype == np.float64 and r.q.shape == (9,)
    assert r.unclamped.dtype == np.float64
    assert isinstance(r.saturated, bool)
    assert r.position_error == pytest.approx(np.linalg.norm(target[:3, 3] - arm.forward(Q)[:3, 3]))
    r2 = res.step(np.asfortranarray(Q), np.asfortranarray(target), current=arm.forward(Q))
    np.testing.assert_allclose(r2.q, r.q, atol=1e-15)
    with pytest.raises(AttributeError):
        r.q = Q  # type: ignore[misc]


def test_hybrid_step_matches_numpy_eq20(arm: softarm.SoftArm, rng: np.random.Generator) -> None:
    g = exact(hybrid_gamma=-3e-6, hybrid_orientation=0.4)
    res = Resolver(arm, "hybrid", g)
    for _ in range(20):
        q = rng.uniform(0.005, 0.028, 9)
        target = arm.forward(rng.uniform(0.002, 0.03, 9))
        dq = res.step(q, target).unclamped - q
        np.testing.assert_allclose(dq, numpy_eq20(arm, g, q, target), atol=1e-10)


@pytest.mark.parametrize(("mode", "rows"), [("position", [0, 1, 2]), ("hybrid", [0, 1, 2, 3, 5])])
def test_limit_term_does_not_disturb_higher_tasks(
    arm: softarm.SoftArm, rng: np.random.Generator, mode: str, rows: list[int]
) -> None:
    on = Resolver(arm, mode, exact())
    off = Resolver(arm, mode, exact(position_gamma=0.0, hybrid_gamma=0.0))
    for _ in range(20):
        q = rng.uniform(0.005, 0.028, 9)
        target = arm.forward(rng.uniform(0.002, 0.03, 9))
        d = on.step(q, target).unclamped - off.step(q, target).unclamped
        assert np.linalg.norm(d) > 1e-9
        j = arm.jacobian(q)[rows]
        assert np.linalg.norm(j @ d) < 1e-9 * np.linalg.norm(j) * np.linalg.norm(d)


def test_commands_stay_in_limits_and_saturation_is_reported(
    arm: softarm.SoftArm, rng: np.random.Generator
) -> None:
    lo, hi = arm.lower, arm.upper
    for mode in ("conventional", "position", "orientation", "hybrid"):
        res = Resolver(arm, mode, Gains.paper())
        seen = False
        for _ in range(100):
            q = rng.uniform(-0.02, 0.05, 9)
            t = arm.forward(rng.uniform(lo, hi))
            t[1, 3] += rng.uniform(-0.3, 0.3)
            r = res.step(q, t)
            assert np.all(r.q >= lo) and np.all(r.q <= hi)
            if np.any(r.unclamped < lo) or np.any(r.unclamped > hi):
                assert r.saturated
            seen |= r.saturated
        assert seen


def test_solve_converges_and_unreachable_does_not(arm: softarm.SoftArm) -> None:
    res = Resolver(arm)
    sol = res.solve(MID, arm.forward(GOAL))
    assert isinstance(sol, softarm.Solution)
    assert sol.converged and sol.position_error < 1e-4
    assert sol.orientation_error < math.radians(0.1) and 0 < sol.steps < 1000
    far = np.eye(4)
    far[1, 3] = 2.0
    bad = res.solve(MID, far, max_steps=100)
    assert not bad.converged and math.isfinite(bad.position_error)
    assert np.all(bad.q >= arm.lower) and np.all(bad.q <= arm.upper)
    with pytest.raises(AttributeError):
        sol.converged = False  # type: ignore[misc]
    point = Resolver(arm, "position").solve(MID, arm.forward(GOAL)[:3, 3])
    assert point.converged and point.orientation_error == 0.0


def test_straight_configuration_gives_finite_steps(arm: softarm.SoftArm) -> None:
    target = arm.forward(GOAL)
    for mode in ("conventional", "position", "orientation", "hybrid"):
        for base in (0.0, 0.0166):
            r = Resolver(arm, mode).step(np.full(9, base), target)
            assert np.all(np.isfinite(r.unclamped))


def test_every_input_error_is_typed_and_named(arm: softarm.SoftArm) -> None:
    res = Resolver(arm)
    t = arm.forward(Q)
    with pytest.raises(softarm.ShapeError, match="q"):
        res.step(np.zeros(8), t)
    with pytest.raises(softarm.NonFiniteError, match="q"):
        res.step(np.r_[np.nan, np.zeros(8)], t)
    with pytest.raises(softarm.ShapeError, match="target"):
        res.step(Q, np.eye(3))
    with pytest.raises(softarm.ShapeError, match="target"):
        res.step(Q, t[:3, 3])  # a point in hybrid mode
    nan = t.copy()
    nan[0, 3] = np.nan
    with pytest.raises(softarm.PoseError, match="target"):
        res.step(Q, nan)
    skew = t.copy()
    skew[0, 0] += 0.1
    with pytest.raises(softarm.PoseError, match="orthonormal"):
        res.step(Q, skew)
    with pytest.raises(softarm.PoseError, match="current"):
        res.step(Q, t, current=skew)
    with pytest.raises(softarm.ShapeError, match="current"):
        res.step(Q, t, current=np.eye(3))
    with pytest.raises(softarm.InputError, match="target"):
        res.step(Q, "pose")
    with pytest.raises(softarm.OutOfRangeError, match="max_steps"):
        res.solve(Q, t, max_steps=-1)
    with pytest.raises(softarm.ParameterError, match="position_tolerance"):
        res.solve(Q, t, position_tolerance=0.0)
    with pytest.raises(softarm.NonFiniteError, match="target"):
        Resolver(arm, "position").step(Q, [0.0, np.inf, 0.4])
    with pytest.raises(ValueError):
        res.step(Q, skew)


def test_solve_help_shows_its_defaults() -> None:
    import inspect

    params = inspect.signature(Resolver.solve).parameters
    assert params["max_steps"].default == 1000
    assert params["position_tolerance"].default == 1e-4
    assert params["orientation_tolerance"].default == pytest.approx(math.radians(0.1))
    assert params["obstacles"].kind is inspect.Parameter.KEYWORD_ONLY
    assert "max_steps=1000" in (Resolver.solve.__text_signature__ or "")


def test_solution_steps_counts_the_steps_run(arm: softarm.SoftArm) -> None:
    far = np.eye(4)
    far[1, 3] = 2.0
    for max_steps in (0, 1, 7, 60):
        sol = Resolver(arm).solve(MID, far, max_steps=max_steps)
        assert sol.termination == "step_limit" and sol.steps == max_steps, sol
        assert 0 <= sol.best_step <= sol.steps
    sol = Resolver(arm).solve(MID, arm.forward(GOAL))
    assert sol.converged and sol.steps == sol.best_step > 0
    assert f"best_step={sol.best_step}" in repr(sol)
    # The default max_steps is the one help() shows: a step limit of 1000 steps run.
    long = Resolver(arm).solve(MID, far)
    assert long.termination in ("step_limit", "stuck") and long.steps <= 1000
