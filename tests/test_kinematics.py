"""The kinematics through the bindings: the papers' formulas, rotation axioms, Jacobians
against finite differences, batches, and every error path."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import softarm
from oracle import fd_jacobian, soft_arm_forward

ARM = softarm.SoftArm.blackberry()
ELONGATION = st.floats(0.0, 70 / 2100, allow_nan=False)
Q9 = st.lists(ELONGATION, min_size=9, max_size=9).map(np.array)


def paper_sections(arm: softarm.SoftArm) -> list[tuple[float, float, float, float]]:
    return [(s.radius, s.rest_length, s.offset, s.twist) for s in arm.sections]


def test_straight_arm_is_a_line() -> None:
    t = ARM.forward(np.zeros(9))
    assert t.shape == (4, 4) and t.dtype == np.float64
    assert t[:3, 3] == pytest.approx([0, 0, 3 * 0.15 + 2 * 0.012 + 0.06], abs=1e-15)


def test_pure_elongation() -> None:
    t = ARM.forward(np.full(9, 0.01))
    assert t[:3, 3] == pytest.approx([0, 0, 0.534 + 0.03], abs=1e-14)


def test_one_actuator_bends_away_from_it() -> None:
    q = np.zeros(9)
    q[0] = 0.02  # actuator 1 of the proximal section, on +x
    tip = ARM.frames(q)[1][:3, 3]
    assert tip[0] < -1e-3 and abs(tip[1]) < 1e-15
    length, bend, direction = ARM.configuration(q)[0]
    assert bend == pytest.approx(2 * 0.02 / (3 * 0.028))
    assert direction == pytest.approx(math.pi)
    assert length == pytest.approx(0.15 + 0.02 / 3)


@settings(max_examples=150, deadline=None)
@given(Q9)
def test_matches_paper_equations(q: np.ndarray) -> None:
    sections = paper_sections(ARM)
    # Eq. (1) divides by s_i: the literal form is only defined off straight.
    for i in range(3):
        l1, l2, l3 = q[3 * i : 3 * i + 3]
        if l1 * l1 + l2 * l2 + l3 * l3 - l1 * l2 - l2 * l3 - l1 * l3 < 1e-14:
            return
    np.testing.assert_allclose(ARM.forward(q), soft_arm_forward(sections, q), atol=1e-12)


@settings(max_examples=150, deadline=None)
@given(Q9)
def test_rotations_are_orthonormal(q: np.ndarray) -> None:
    for f in ARM.frames(q):
        r = f[:3, :3]
        np.testing.assert_allclose(r.T @ r, np.eye(3), atol=1e-13)
        assert np.linalg.det(r) == pytest.approx(1.0, abs=1e-13)
        np.testing.assert_array_equal(f[3], [0, 0, 0, 1])


@settings(max_examples=80, deadline=None)
@given(Q9)
def test_jacobian_matches_finite_differences(q: np.ndarray) -> None:
    np.testing.assert_allclose(ARM.jacobian(q), fd_jacobian(ARM.forward, q), atol=3e-7)


@pytest.mark.parametrize("offset", [0.0, 1e-12, 1e-9, -1e-9])
def test_jacobian_smooth_through_straight(offset: float, rng: np.random.Generator) -> None:
    q = np.full(9, 0.01) + offset * rng.standard_normal(9)
    j = ARM.jacobian(q)
    assert np.isfinite(j).all()
    np.testing.assert_allclose(j, fd_jacobian(ARM.forward, q, 1e-6), atol=1e-6)
    np.testing.assert_allclose(j, ARM.jacobian(np.full(9, 0.01)), atol=1e-5)


@settings(max_examples=60, deadline=None)
@given(Q9, st.integers(0, 2), st.floats(0.0, 1.0))
def test_point_jacobian_matches_finite_differences(q: np.ndarray, section: int, s: float) -> None:
    p, jp = ARM.point(q, section, s)
    assert p.shape == (3,) and jp.shape == (3, 9)
    h = 1e-7
    fd = np.column_stack(
        [
            (ARM.point(q + h * e, section, s)[0] - ARM.point(q - h * e, section, s)[0]) / (2 * h)
            for e in np.eye(9)
        ]
    )
    np.testing.assert_allclose(jp, fd, atol=3e-7)
    # Later sections do not move this point.
    assert not jp[:, 3 * (section + 1) :].any()


def test_backbone_and_frames_agree() -> None:
    q = np.array([0.0, 0.02, 0.03, 0.03, 0.0, 0.01, 0.0, 0.033, 0.0])
    pts = ARM.backbone(q, 11)
    frames = ARM.frames(q)
    assert pts.shape == (33, 3) and frames.shape == (4, 4, 4)
    np.testing.assert_allclose(pts[0], frames[0][:3, 3], atol=1e-15)
    for i in range(3):
        np.testing.assert_allclose(pts[11 * i], frames[i][:3, 3], atol=1e-14)
        np.testing.assert_allclose(pts[11 * i + 5], ARM.point(q, i, 0.5)[0], atol=1e-14)


def test_batches_match_single_calls(rng: np.random.Generator) -> None:
    qs = rng.uniform(ARM.lower, ARM.upper, size=(50, 9))
    poses, jacs = ARM.forward_batch(qs), ARM.jacobian_batch(qs)
    assert poses.shape == (50, 4, 4) and jacs.shape == (50, 6, 9)
    for q, t, j in zip(qs, poses, jacs, strict=True):
        np.testing.assert_array_equal(t, ARM.forward(q))
        np.testing.assert_allclose(j, ARM.jacobian(q), atol=1e-14)
    assert ARM.forward_batch(np.zeros((0, 9))).shape == (0, 4, 4)


def test_accepts_array_likes() -> None:
    ref = ARM.forward(np.zeros(9))
    np.testing.assert_array_equal(ARM.forward([0] * 9), ref)
    np.testing.assert_array_equal(ARM.forward(tuple([0.0] * 9)), ref)
    np.testing.assert_array_equal(ARM.forward(np.zeros(18)[::2]), ref)  # strided
    np.testing.assert_array_equal(ARM.forward(np.zeros(9, dtype=np.float32)), ref)


def test_arc_chain_matches_planning_paper_eq_2_3() -> None:
    chain = softarm.ArcChain([1.0, 1.0, 1.0])
    q = np.array([1.0, 0.4, 0.3, 1.2, 0.8, -1.0, 0.9, 1.1, 2.0])
    t = np.eye(4)
    for length, th, ph in q.reshape(3, 3):
        cp, sp, ct, s_t = np.cos(ph), np.sin(ph), np.cos(th), np.sin(th)
        h = np.eye(4)
        h[:3, :3] = [[cp * ct, -sp, cp * s_t], [sp * ct, cp, sp * s_t], [-s_t, 0, ct]]
        h[:3, 3] = [(1 - ct) * length / th * cp, (1 - ct) * length / th * sp, s_t * length / th]
        t = t @ h
    np.testing.assert_allclose(chain.forward(q), t, atol=1e-12)
    np.testing.assert_allclose(chain.jacobian(q), fd_jacobian(chain.forward, q, 1e-6), atol=1e-6)
    np.testing.assert_allclose(chain.straight(), [1, 0, 0] * 3)


@pytest.mark.parametrize(
    ("call", "error", "words"),
    [
        (lambda: ARM.forward(np.zeros(8)), softarm.ShapeError, "q"),
        (lambda: ARM.forward(np.zeros((3, 3))), softarm.ShapeError, "q"),
        (lambda: ARM.jacobian([0.0] * 8 + [math.nan]), softarm.NonFiniteError, "q"),
        (lambda: ARM.forward([0.0] * 8 + [math.inf]), softarm.NonFiniteError, "q"),
        (lambda: ARM.forward(["a"] * 9), softarm.InputError, "q"),
        (lambda: ARM.point(np.zeros(9), 3, 0.5), softarm.OutOfRangeError, "section"),
        (lambda: ARM.point(np.zeros(9), -1, 0.5), softarm.OutOfRangeError, "section"),
        (lambda: ARM.point(np.zeros(9), 0, 1.5), softarm.OutOfRangeError, "s"),
        (lambda: ARM.point(np.zeros(9), 0, math.nan), softarm.OutOfRangeError, "s"),
        (lambda: ARM.backbone(np.zeros(9), 1), softarm.OutOfRangeError, "samples"),
        (lambda: ARM.forward_batch(np.zeros((4, 8))), softarm.ShapeError, "qs"),
        (lambda: ARM.jacobian_batch(np.full((2, 9), math.nan)), softarm.NonFiniteError, "qs"),
        (lambda: softarm.Section(-0.01, 0.15, 0, 0.03), softarm.ParameterError, "radius"),
        (lambda: softarm.Section(0.01, 0.0, 0, 0.03), softarm.ParameterError, "rest_length"),
        (lambda: softarm.Section(0.01, 0.15, 0.03, 0.03), softarm.ParameterError, "lower"),
        (lambda: softarm.Section(0.01, 0.15, 0, math.nan), softarm.ParameterError, "upper"),
        (lambda: softarm.SoftArm([]), softarm.ShapeError, "sections"),
        (lambda: softarm.ArcChain([1.0, -1.0]), softarm.ParameterError, "lengths[1]"),
        (lambda: softarm.ArcChain([]), softarm.ShapeError, "lengths"),
        (lambda: softarm.ArcChain([1.0], lower=[2, 0, 0]), softarm.ParameterError, "lower[0]"),
    ],
)
def test_errors_are_typed_and_named(call: object, error: type, words: str) -> None:
    with pytest.raises(error, match=words.replace("[", r"\[").replace("]", r"\]")):
        call()  # type: ignore[operator]
    assert issubclass(error, softarm.SoftarmError) and issubclass(error, ValueError)


def test_custom_arm_round_trips_sections() -> None:
    secs = [softarm.Section(0.02, 0.1, 0.0, 0.02, offset=0.01, twist=0.5) for _ in range(2)]
    arm = softarm.SoftArm(secs)
    assert arm.n_sections == 2 and arm.n_actuators == 6
    assert arm.sections == secs
    np.testing.assert_allclose(arm.upper, 0.02)


def test_elongations_without_geometry_are_rejected_by_name() -> None:
    from softarm.errors import InputError, ParameterError

    q = np.full(9, -0.2)  # every section's arc length 0.15 - 0.2 < 0
    calls = (
        ARM.forward,
        ARM.jacobian,
        ARM.forward_jacobian,
        ARM.frames,
        ARM.backbone,
        ARM.configuration,
        lambda q: ARM.point(q, 1, 0.5),
    )
    for call in calls:
        with pytest.raises(ParameterError) as info:
            call(q)
        e = info.value
        assert isinstance(e, InputError) and isinstance(e, ValueError)
        assert e.argument == "q[0..3]" and e.value < 0 and "arc length" in e.expected
    rows = np.stack([np.zeros(9), q])
    for batch in (ARM.forward_batch, ARM.jacobian_batch):
        with pytest.raises(ParameterError) as info:
            batch(rows)
        assert info.value.argument == "qs[1, 0..3]"
    # Only the third section without geometry: named by its elongations.
    last = np.r_[np.zeros(6), [-0.2] * 3]
    with pytest.raises(ParameterError, match=r"q\[6\.\.9\]"):
        ARM.forward(last)


def test_outside_the_limits_but_with_geometry_is_still_computed() -> None:
    below = ARM.lower - 0.01  # past the limits, arc lengths still positive
    above = ARM.upper + 0.01
    for q in (below, above):
        t = ARM.forward(q)
        assert np.all(np.isfinite(t)) and np.allclose(t[3], [0, 0, 0, 1])
        assert np.all(np.isfinite(ARM.jacobian(q)))
    assert "positive arc length" in (softarm.SoftArm.__doc__ or "")
