"""Issue 12 (items 4, 5, 7, 8, 9, 14): each defect found by fault injection, as a test.

Every test here failed before its fix: absurd sizes aborted the interpreter or raised
``PanicException``, non-finite points passed silently, curves that overflow were accepted,
``closest`` ignored a q that is not an arc, batch calls read the caller's array without
the GIL, and complex or string inputs were coerced.
"""

from __future__ import annotations

import math
import threading

import numpy as np
import pytest

import softarm
from softarm import _core, errors

ARM = softarm.SoftArm.blackberry()
Q = np.full(9, 0.01)
CHAIN = _core.ArcChain([1.0, 1.0, 1.0])
QC = CHAIN.straight()
CURVE = _core.PolynomialCurve([[0.5, 0, 0], [0, 1, 0], [0, 0, 5]], (-2.0, 2.0))


# --- item 4: absurd sizes are typed errors naming the argument ---------------------------

HUGE = [10**12, 2**62, 2**63, 2**64, 10**30]


@pytest.mark.parametrize("n", HUGE)
def test_backbone_huge_sample_count_is_out_of_range(n: int) -> None:
    with pytest.raises(errors.OutOfRangeError, match=rf"samples = {n} "):
        ARM.backbone(Q, n)


def test_backbone_negative_count_names_the_real_value() -> None:
    with pytest.raises(errors.OutOfRangeError, match=r"samples = -5 "):
        ARM.backbone(Q, -5)
    with pytest.raises(errors.InputError, match="samples"):
        ARM.backbone(Q, 2.5)  # type: ignore[arg-type]


@pytest.mark.parametrize("n", [*HUGE, -1])
def test_curve_sample_huge_count_is_out_of_range(n: int) -> None:
    with pytest.raises(errors.OutOfRangeError, match=r"\bn = "):
        CURVE.sample(n)


def test_section_index_of_any_size_is_out_of_range() -> None:
    for section in (2**63, -(2**63) - 1, 10**30):
        with pytest.raises(errors.OutOfRangeError, match="section"):
            ARM.point(Q, section, 0.5)


@pytest.mark.parametrize(
    ("option", "value"),
    [
        ("arm_samples", 10**9),
        ("arm_samples", 2**64),
        ("max_iterations", 2**63),
        ("max_iterations", -1),
        ("stall_window", 10**12),
        ("repulsion_gain", 1e308),
        ("attraction_gain", 1e300),
        ("max_step_fraction", 2.0),
    ],
)
def test_planner_options_are_bounded(option: str, value: float) -> None:
    with pytest.raises(errors.InputError, match=option):
        _core.PotentialFieldPlanner(CHAIN, **{option: value})


@pytest.mark.parametrize("substeps", [10**9, 2**63, 0, -3])
def test_path_clearance_substeps_are_bounded(substeps: int) -> None:
    with pytest.raises(errors.OutOfRangeError, match="substeps"):
        _core.path_clearance(CHAIN, np.stack([QC, QC]), [CURVE], substeps)


# --- item 5: every obstacle form validated in one place ----------------------------------

BAD_POINTS = [
    ([0.1, math.nan, 0.3], errors.NonFiniteError),
    ([0.1, math.inf, 0.3], errors.NonFiniteError),
    ([1e200, 0.0, 0.0], errors.OutOfRangeError),
]


@pytest.mark.parametrize(("point", "error"), BAD_POINTS)
def test_bad_point_obstacle_is_rejected_by_every_query(
    point: list[float], error: type[Exception]
) -> None:
    p = np.array(point)
    with pytest.raises(error, match="obstacle"):
        _core.closest(CHAIN, QC, p)
    with pytest.raises(error, match=r"obstacles\[1\]"):
        _core.path_clearance(CHAIN, QC[None, :], [CURVE, p])
    planner = _core.PotentialFieldPlanner(CHAIN)
    with pytest.raises(error, match=r"obstacles\[0\]"):
        planner.plan(QC, [0.5, 0.5, 2.0], [p])


@pytest.mark.parametrize(("point", "error"), BAD_POINTS)
def test_bad_coordinates_are_rejected_by_every_obstacle_class(
    point: list[float], error: type[Exception]
) -> None:
    with pytest.raises(error, match="points"):
        _core.PointCloud([point, [0, 0, 0]])
    with pytest.raises(error, match="b"):
        _core.Segment([0, 0, 0], point)
    with pytest.raises(error, match="vertices"):
        _core.TriangleMesh([point, [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])


# --- item 7: curves whose evaluation overflows are refused --------------------------------


@pytest.mark.parametrize(
    ("coeffs", "u_range"),
    [
        ([[0, 0, 0, 1e300], [0, 0, 0, 0], [0, 0, 0, 0]], (-1e5, 1e5)),  # |F| overflows
        ([[0, 1, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0]], (-1e200, 1.0)),  # u beyond 1e150
        ([[0, 0, 1, 0], [0, 0, 0, 0], [0, 0, 0, 0]], (-1e60, 1.0)),  # reaches 1e120 m
    ],
)
def test_curve_that_overflows_is_rejected(coeffs: list[list[float]], u_range: tuple) -> None:
    with pytest.raises(errors.ParameterError, match=r"coeffs|u_range"):
        _core.PolynomialCurve(coeffs, u_range)


# --- item 8: closest and path_clearance check q against the model ------------------------


def test_closest_refuses_a_negative_arc_length() -> None:
    q = QC.copy()
    q[3] = -1.0  # section 1 with arc length -1
    with pytest.raises(errors.ParameterError, match=r"q\[3\.\.6\]"):
        _core.closest(CHAIN, q, CURVE)
    with pytest.raises(errors.ParameterError, match=r"q\[3\.\.6\]"):
        _core.path_clearance(CHAIN, np.stack([QC, q]), [CURVE])
    # A SoftArm elongation below -rest_length (0.15 m) shortens its arc below zero.
    with pytest.raises(errors.ParameterError, match=r"q\[0\.\.3\]"):
        _core.closest(ARM, np.r_[[-0.5] * 3, [0.0] * 6], [0.1, 0.0, 0.3])


def test_huge_coordinates_are_out_of_range_everywhere() -> None:
    q = Q.copy()
    q[4] = 1e200
    for call in (ARM.forward, ARM.jacobian, ARM.frames):
        with pytest.raises(errors.OutOfRangeError, match=r"q\[4\]"):
            call(q)
    with pytest.raises(errors.OutOfRangeError, match=r"qs\[4\]"):
        ARM.forward_batch(q[None, :])


# --- item 9: batch calls own what they read ------------------------------------------------


def test_batch_output_is_never_torn_by_a_concurrent_writer() -> None:
    """A writer flips the input between two valid batches while forward_batch runs. The
    output must be one of the two (the call copied its input under the GIL), never NaN."""
    rows = 20_000
    a = np.zeros((rows, 9))
    b = np.full((rows, 9), 0.02)
    qs = a.copy()
    stop = threading.Event()

    def writer() -> None:
        flip = False
        while not stop.is_set():
            qs[:] = math.nan if flip else 0.0
            qs[:] = b if flip else a
            flip = not flip

    pose_a, pose_b = ARM.forward(a[0]), ARM.forward(b[0])
    t = threading.Thread(target=writer)
    t.start()
    try:
        for _ in range(40):
            try:
                out = ARM.forward_batch(qs)
            except errors.NonFiniteError:
                continue  # the copy caught the writer mid-way: rejected, not computed
            assert np.isfinite(out).all()
            for pose in (out[0], out[-1]):
                assert np.allclose(pose, pose_a) or np.allclose(pose, pose_b)
    finally:
        stop.set()
        t.join()


# --- item 14 (core parts) --------------------------------------------------------------------


@pytest.mark.parametrize(
    "call",
    [
        lambda: ARM.forward(Q.astype(complex)),
        lambda: ARM.forward(["0.01"] * 9),
        lambda: ARM.forward_batch(np.zeros((2, 9), dtype=complex)),
        lambda: ARM.forward(np.zeros(9, dtype=bool)),
        lambda: ARM.point(Q, 0, np.complex128(0.5 + 1j)),
        lambda: ARM.point(Q, 0, "0.5"),
        lambda: softarm.Section(0.02 + 0j, 0.15, 0.0, 0.03),
        lambda: softarm.Section("0.02", 0.15, 0.0, 0.03),
        lambda: softarm.Section(np.complex128(0.02), 0.15, 0.0, 0.03),
        lambda: _core.PolynomialCurve(np.zeros((3, 2), dtype=complex), (0.0, 1.0)),
        lambda: _core.PolynomialCurve(np.zeros((3, 2)), ("0", "1")),
        lambda: CURVE(np.complex128(0.5)),
        lambda: _core.closest(CHAIN, QC, np.array([0.1, 0.2, 0.3 + 1j])),
        lambda: _core.TriangleMesh(np.eye(3), [[0, 1, 2]], tolerance="1e-4"),
        lambda: _core.PotentialFieldPlanner(CHAIN, damping=0.05j),
    ],
)
def test_complex_and_string_inputs_are_typed_errors(call) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(errors.InputError):
        call()


@pytest.mark.parametrize(
    ("kwargs", "arg"),
    [
        ({"radius": 5e-324}, "radius"),
        ({"radius": 1e-9}, "radius"),
        ({"radius": 1e9}, "radius"),
        ({"rest_length": 1e-300}, "rest_length"),
        ({"upper": 1e300}, "upper"),
        ({"offset": 1e300}, "offset"),
        ({"twist": 100.0}, "twist"),
    ],
)
def test_section_geometry_is_bounded(kwargs: dict, arg: str) -> None:
    args = {"radius": 0.02, "rest_length": 0.15, "lower": 0.0, "upper": 0.03} | kwargs
    with pytest.raises(errors.ParameterError, match=arg):
        softarm.Section(**args)


def test_tiny_section_radius_no_longer_gives_nan() -> None:
    arm = softarm.SoftArm([softarm.Section(1e-4, 0.15, 0.0, 0.03)])
    assert np.isfinite(arm.forward([0.03, 0.0, 0.01])).all()


def test_mesh_tolerance_below_a_micron_is_refused_and_above_is_met() -> None:
    verts = [[-1, -1, 0.7], [1, -1, 0.7], [0, 1, 0.7]]
    with pytest.raises(errors.ParameterError, match="tolerance"):
        _core.TriangleMesh(verts, [[0, 1, 2]], tolerance=1e-9)
    # The smallest allowed tolerance is met: an arc bent by 3 rad (its top, z = 1/3 m, in
    # its interior) under a plane at z = 0.5, against dense samples of the arc.
    chain = _core.ArcChain([1.0], lower=[0.5, -4, -7], upper=[1.5, 4, 7])
    mesh = _core.TriangleMesh([[-5, -5, 0.5], [5, -5, 0.5], [0, 5, 0.5]], [[0, 1, 2]], 1e-6)
    q = np.array([1.0, 3.0, 0.0])
    pts = chain.backbone(q, 200_001)
    exact = float(0.5 - np.max(pts[:, 2]))
    got = _core.closest(chain, q, mesh).distance
    assert exact - 1e-6 - 1e-12 <= got <= exact + 1e-12


def test_curve_evaluation_is_checked_against_its_range() -> None:
    """Found by the fuzz test: a NaN parameter evaluated to NaN points."""
    for u in (math.nan, 2.5, -1e300):
        with pytest.raises(errors.OutOfRangeError, match="u"):
            CURVE(u)
    with pytest.raises(errors.OutOfRangeError, match=r"u\[1\]"):
        CURVE(np.array([0.0, math.nan]))
    assert np.isfinite(CURVE(np.linspace(*CURVE.u_range, 9))).all()
