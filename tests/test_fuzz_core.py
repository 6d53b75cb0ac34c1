"""Property-based fuzzing of every public entry point of ``softarm._core`` (issue 12).

Every call gets hostile input (NaN, infinities, subnormals, huge and negative integers,
complex numbers, strings, wrong shapes, ...) mixed with valid input, and must either
raise a typed ``softarm.errors.SoftarmError`` or return a finite result inside its limits:
never another exception type, never a crash (a crash ends the pytest process).

The default is bounded for CI (5 to 20 s). Longer runs, and the figures in
docs/reliability.md::

    SOFTARM_FUZZ_EXAMPLES=2000 SOFTARM_FUZZ_RANDOM=1 SOFTARM_FUZZ_REPORT=fuzz.json \\
        .venv/bin/python -m pytest -q tests/test_fuzz_core.py

``SOFTARM_FUZZ_EXAMPLES`` is the number of examples per test, ``SOFTARM_FUZZ_RANDOM=1``
draws new examples (the default replays the same derandomized ones, so CI is
reproducible), and ``SOFTARM_FUZZ_REPORT`` writes the counts (calls, typed errors, other
exceptions) as JSON.
"""

from __future__ import annotations

import json
import math
import os
import warnings
from collections import Counter
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import softarm
from softarm import _core, errors

EXAMPLES = int(os.environ.get("SOFTARM_FUZZ_EXAMPLES", "50"))
SETTINGS = settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize=os.environ.get("SOFTARM_FUZZ_RANDOM") != "1",
    database=None,
    suppress_health_check=list(HealthCheck),
)
STATS: Counter[str] = Counter()


@pytest.fixture(scope="module", autouse=True)
def _report() -> Iterator[None]:
    yield
    path = os.environ.get("SOFTARM_FUZZ_REPORT")
    if path:
        with open(path, "w", encoding="utf-8") as f:
            json.dump({"examples_per_test": EXAMPLES, **STATS}, f, indent=2)


# --- hostile values ------------------------------------------------------------------------

SPECIAL = [
    math.nan,
    math.inf,
    -math.inf,
    0.0,
    -0.0,
    5e-324,
    1e-300,
    -1e-9,
    1e-9,
    1e6,
    -1e6,
    1e155,
    1e300,
    -1e300,
]
floats = st.one_of(
    st.sampled_from(SPECIAL),
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(-2.0, 2.0),
)
ints = st.one_of(
    st.sampled_from([0, 1, 2, 3, -1, -5, 2**31, 2**62, 2**63, 2**64, 10**12, 10**30]),
    st.integers(-(2**70), 2**70),
    st.integers(-3, 40),
)
junk = st.one_of(
    st.complex_numbers(),
    st.text(max_size=4),
    st.none(),
    st.booleans(),
    st.just([1.0, 2.0]),
    st.just({"a": 1}),
    st.just(np.complex128(0.5 + 0.5j)),
    st.just(np.array([np.nan])),
)
scalars = st.one_of(st.floats(-2.0, 2.0), floats, floats, ints, junk)
counts = st.one_of(st.integers(0, 40), ints, ints, junk, floats)


def vectors(n: int, elements: st.SearchStrategy[Any] = floats) -> st.SearchStrategy[Any]:
    """Arrays meant to be of length n: mostly right, sometimes wrong length, dtype or kind."""
    right = st.lists(elements, min_size=n, max_size=n).map(np.array)
    return st.one_of(
        right,
        right,
        right,
        st.lists(elements, min_size=0, max_size=n + 2).map(np.array),
        st.lists(st.complex_numbers(), min_size=n, max_size=n).map(np.array),
        st.lists(st.text(max_size=3), min_size=n, max_size=n),
        st.lists(floats, min_size=n, max_size=n).map(lambda v: np.array(v).reshape(1, -1)),
        junk,
    )


def near(base: np.ndarray, scale: float) -> st.SearchStrategy[np.ndarray]:
    """Valid-looking arrays: `base` plus noise, with a hostile value now and then."""
    hit = st.tuples(st.integers(0, base.size - 1), floats)
    return st.tuples(
        st.lists(st.floats(-scale, scale), min_size=base.size, max_size=base.size),
        st.one_of(st.none(), st.none(), st.none(), hit),
    ).map(lambda t: _perturb(base, t[0], t[1]))


def _perturb(base: np.ndarray, noise: list[float], hit: tuple[int, float] | None) -> np.ndarray:
    v = base.astype(float).ravel() + np.array(noise)
    if hit is not None:
        v[hit[0]] = hit[1]
    return v.reshape(base.shape)


# --- the contract --------------------------------------------------------------------------


def finite(value: object) -> bool:
    if isinstance(value, np.ndarray):
        return value.dtype.kind in "iu" or bool(np.isfinite(value).all())
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, (tuple, list)):
        return all(finite(v) for v in value)
    return True


def call(fn: Callable[[], Any], infinite_ok: bool = False) -> Any:
    """Runs one fuzzed call: a typed error (returns None) or a finite result (a float may be
    infinite where `infinite_ok`: the clearance with no obstacle)."""
    STATS["calls"] += 1
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a ComplexWarning is a silent coercion
            out = fn()
    except errors.SoftarmError:
        STATS["typed_errors"] += 1
        return None
    except Exception as e:  # the point of the test: any other type fails
        STATS["other_exceptions"] += 1
        raise AssertionError(f"untyped {type(e).__name__}: {e}") from e
    STATS["results"] += 1
    assert finite(out) or (infinite_ok and out == math.inf), out
    return out


def check_closest(c: _core.Closest, model: object) -> None:
    assert c.distance >= 0.0 and math.isfinite(c.distance)
    assert 0 <= c.section < model.n_sections  # type: ignore[attr-defined]
    assert 0.0 <= c.s <= 1.0 and math.isfinite(c.u)
    assert finite(c.arm_point) and finite(c.obstacle_point)


ARM = softarm.SoftArm.blackberry()
CHAIN = _core.ArcChain([1.0, 1.0, 1.0])
MODELS = {"arm": ARM, "chain": CHAIN}
Q = {"arm": np.full(9, 0.015), "chain": CHAIN.straight()}
SCALE = {"arm": 0.02, "chain": 0.5}
CURVE = _core.PolynomialCurve([[0.5, 0, 0], [0, 1, 0], [0, 0, 5]], (-2.0, 2.0))
OBSTACLES = [
    CURVE,
    _core.Segment([0.1, -1.0, 0.3], [0.1, 1.0, 0.3]),
    _core.PointCloud(np.random.default_rng(3).uniform(-1, 2, (50, 3))),
    _core.TriangleMesh([[-1, -1, 0.6], [1, -1, 0.6], [0, 1, 0.6]], [[0, 1, 2]]),
]
model_names = st.sampled_from(sorted(MODELS))


def configurations(name: str) -> st.SearchStrategy[Any]:
    """Mostly valid-looking configurations (3 in 4), else hostile ones."""
    valid = near(Q[name], SCALE[name])
    return st.one_of(valid, valid, valid, vectors(MODELS[name].n_dofs))


obstacles = st.one_of(
    st.sampled_from(OBSTACLES),
    st.sampled_from(OBSTACLES),
    near(np.array([0.1, 0.1, 0.3]), 1.0),
    vectors(3),
    junk,
)


# --- kinematics ----------------------------------------------------------------------------


@SETTINGS
@given(st.lists(scalars, min_size=6, max_size=6), st.lists(floats, min_size=3, max_size=3))
def test_section_and_soft_arm(args: list[Any], q: list[float]) -> None:
    section = call(lambda: softarm.Section(*args))
    if section is not None:
        arm = call(lambda: softarm.SoftArm([section]))
        call(lambda: arm.forward(q))
        call(lambda: arm.jacobian(np.array(q) * 1e-2))
    call(lambda: softarm.SoftArm(args))  # type: ignore[arg-type]


@SETTINGS
@given(
    vectors(3, st.one_of(floats, st.floats(0.1, 2.0))),
    st.one_of(st.none(), vectors(9)),
    st.one_of(st.none(), vectors(9)),
)
def test_arc_chain_constructor(lengths: Any, lower: Any, upper: Any) -> None:
    chain = call(lambda: _core.ArcChain(lengths, lower, upper))
    if chain is not None:
        assert (chain.lower < chain.upper).all()
        call(lambda: chain.forward(chain.straight()))


@SETTINGS
@given(st.data(), model_names, scalars, counts, counts)
def test_kinematic_methods(data: st.DataObject, name: str, s: Any, section: Any, n: Any) -> None:
    model = MODELS[name]
    q = data.draw(configurations(name))
    call(lambda: model.forward(q))
    call(lambda: model.jacobian(q))
    call(lambda: model.forward_jacobian(q))
    call(lambda: model.frames(q))
    call(lambda: model.point(q, section, s))
    out = call(lambda: model.backbone(q, n if isinstance(n, int) and n < 5000 else 20))
    if out is not None:
        assert out.shape[1] == 3
    call(lambda: model.backbone(q, n))
    qs = data.draw(st.one_of(st.lists(configurations(name), max_size=4), vectors(4), junk))
    call(lambda: model.forward_batch(qs))
    call(lambda: model.jacobian_batch(qs))
    if name == "arm":
        call(lambda: ARM.configuration(q))


# --- obstacles and distances ---------------------------------------------------------------


@SETTINGS
@given(
    st.one_of(
        st.lists(st.lists(floats, min_size=4, max_size=4), min_size=3, max_size=3).map(np.array),
        st.lists(st.lists(st.floats(-3, 3), min_size=3, max_size=3), min_size=3, max_size=3),
        vectors(6),
        junk,
    ),
    st.one_of(st.tuples(floats, floats), st.tuples(st.floats(-3, 0), st.floats(0.1, 3)), junk),
    counts,
    scalars,
    st.data(),
)
def test_polynomial_curve(coeffs: Any, u_range: Any, n: Any, u: Any, data: st.DataObject) -> None:
    curve = call(lambda: _core.PolynomialCurve(coeffs, u_range))
    if curve is None:
        return
    call(lambda: curve(u))
    call(lambda: curve(np.linspace(*curve.u_range, 5)))
    call(lambda: curve.sample(n if isinstance(n, int) and n < 5000 else 7))
    call(lambda: curve.sample(n))
    name = data.draw(model_names)
    c = call(lambda: _core.closest(MODELS[name], Q[name], curve))
    if c is not None:
        check_closest(c, MODELS[name])


@SETTINGS
@given(vectors(3), vectors(3), st.lists(vectors(3), max_size=5), scalars, st.data())
def test_point_obstacle_classes(a: Any, b: Any, pts: Any, tol: Any, data: st.DataObject) -> None:
    call(lambda: _core.Segment(a, b))
    call(lambda: _core.PointCloud(pts))
    tris = data.draw(st.one_of(st.just([[0, 1, 2]]), vectors(3), junk))
    mesh = call(lambda: _core.TriangleMesh(pts, tris, tol))
    if mesh is not None:
        c = call(lambda: _core.closest(CHAIN, CHAIN.straight(), mesh))
        if c is not None:
            check_closest(c, CHAIN)


@SETTINGS
@given(st.data(), model_names, obstacles)
def test_closest(data: st.DataObject, name: str, obstacle: Any) -> None:
    model = MODELS[name]
    q = data.draw(configurations(name))
    c = call(lambda: _core.closest(model, q, obstacle))
    if c is not None:
        check_closest(c, model)
    not_an_arm = data.draw(junk)
    call(lambda: _core.closest(not_an_arm, Q[name], OBSTACLES[0]))


# --- planning ------------------------------------------------------------------------------

PLANNER_OPTIONS = [
    "attraction_gain",
    "max_tip_step",
    "repulsion_gain",
    "influence_distance",
    "max_step_fraction",
    "damping",
    "goal_tolerance",
    "max_iterations",
    "stall_window",
    "stall_tolerance",
    "arm_samples",
]


@SETTINGS
@given(st.sampled_from(PLANNER_OPTIONS), st.one_of(scalars, counts), model_names)
def test_planner_options(option: str, value: Any, name: str) -> None:
    planner = call(lambda: _core.PotentialFieldPlanner(MODELS[name], **{option: value}))
    if planner is not None:
        # None stands for the default, as for every optional argument.
        assert planner.options[option] == value or value is None or option == "arm_samples"


@SETTINGS
@given(
    st.data(),
    model_names,
    st.one_of(near(np.array([0.3, 0.3, 1.5]), 1.0), vectors(3)),
    st.lists(obstacles, max_size=3),
    st.sampled_from([None, 5]),
    st.floats(0.0, 1e-2),
)
def test_plan(
    data: st.DataObject,
    name: str,
    goal: Any,
    obs: list[Any],
    arm_samples: int | None,
    damping: float,
) -> None:
    model = MODELS[name]
    planner = _core.PotentialFieldPlanner(
        model, max_iterations=30, damping=damping, arm_samples=arm_samples
    )
    q0 = data.draw(st.one_of(st.just(Q[name]), configurations(name)))
    plan = call(lambda: planner.plan(q0, goal, obs))
    if plan is not None:
        path = plan.path
        assert finite(path) and finite(plan.tip_path)
        assert (path >= model.lower).all() and (path <= model.upper).all()
        assert plan.min_clearance >= 0.0
        assert math.isfinite(plan.min_clearance) or not obs


@SETTINGS
@given(
    st.data(),
    model_names,
    st.lists(obstacles, max_size=3),
    st.one_of(st.integers(1, 20), counts),
)
def test_path_clearance(data: st.DataObject, name: str, obs: list[Any], substeps: Any) -> None:
    model = MODELS[name]
    path = data.draw(
        st.one_of(
            st.lists(configurations(name), min_size=1, max_size=3),
            vectors(model.n_dofs),
            junk,
        )
    )
    if isinstance(substeps, int) and substeps > 50:
        path = [Q[name]]  # one row: no interpolation, the count is only validated
    d = call(lambda: _core.path_clearance(model, path, obs, substeps), infinite_ok=not obs)
    if d is not None:
        assert d >= 0.0 and (math.isfinite(d) or not obs)


@SETTINGS
@given(st.one_of(st.sampled_from(["line", "curve", "tree", "forest", ""]), junk))
def test_paper_scenario(name: Any) -> None:
    call(lambda: _core.paper_scenario(name))


# --- the resolver ----------------------------------------------------------------------------


# Every field of Gains, read from the binding itself so that a new gain is fuzzed too.
GAIN_FIELDS = list(_core.Gains().as_dict())


@SETTINGS
@given(
    st.sampled_from(GAIN_FIELDS),
    scalars,
    st.one_of(st.sampled_from(["conventional", "position", "orientation", "hybrid"]), junk),
    st.data(),
)
def test_resolver(field: str, value: Any, mode: Any, data: st.DataObject) -> None:
    gains = call(lambda: _core.Gains(**{field: value}))
    resolver = call(lambda: _core.Resolver(ARM, mode, gains))
    if resolver is None:
        return
    q = data.draw(configurations("arm"))
    target = data.draw(
        st.one_of(
            st.just(ARM.forward(np.full(9, 0.02))),
            near(ARM.forward(np.full(9, 0.02)), 0.05),
            near(np.array([0.05, 0.05, 0.5]), 0.2),
            vectors(3),
            vectors(16),
        )
    )
    step = call(lambda: resolver.step(q, target))
    if step is not None:
        assert (step.q >= ARM.lower).all() and (step.q <= ARM.upper).all()
    steps = data.draw(st.one_of(st.integers(0, 30), counts))
    if isinstance(steps, int) and steps > 30:
        steps = -1 if steps < 0 else 2**64  # only the validation of a large count
    sol = call(lambda: resolver.solve(q, target, steps))
    if sol is not None:
        assert (sol.q >= ARM.lower).all() and (sol.q <= ARM.upper).all()
