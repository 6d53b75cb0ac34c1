"""C2's fix weighed between C1's ray and C2's by their spreads
(softarm.perception.approach.RayCrossing with ``spreads``): the fix is the point nearest
both rays in the least squares weighted by each ray's inverse variance at the berry, so
that an error of C2's centre across both rays moves it by C1's share of the variance
only, where the fix on C2's ray took the whole error."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.errors import InputError
from softarm.perception.approach import RayCrossing
from softarm.perception.berries import BerryDetection
from softarm.sim.rig_cameras import look_at
from softarm.vision.camera_model import CameraModel

CAMERA = CameraModel.ideal(150.0, 320, 240)
T_BASE_C1 = look_at(np.array([0.7, -0.45, 0.55]), np.array([0.0, 0.25, 0.3]), up=(0, 0, -1.0))
BERRY = np.array([0.02, 0.3, 0.32])
T_BASE_C2 = look_at(np.array([0.05, 0.22, 0.3]), BERRY, up=(0.0, 0.0, -1.0))


def _detection(offset_px: tuple[float, float]) -> BerryDetection:
    """C2's detection of the berry, its centre ``offset_px`` from the true projection."""
    p = np.linalg.inv(T_BASE_C2) @ np.append(BERRY, 1.0)
    x, y = CAMERA.project(p[None, :3])[0] + np.asarray(offset_px)
    return BerryDetection((x, y), 20.0, (0, 0, 1, 1), np.ones((1, 1), bool), 1.0, "ripe", 1.0)


def _in_base(fix: np.ndarray) -> np.ndarray:
    out: np.ndarray = (T_BASE_C2 @ np.append(fix, 1.0))[:3]
    return out


def _cost(p: np.ndarray, lines: list[tuple[np.ndarray, np.ndarray, float]]) -> float:
    """Sum of squared distances of ``p`` from each (origin, unit direction, weight) line."""
    total = 0.0
    for o, u, w in lines:
        d = p - o
        total += w * float(d @ d - (d @ u) ** 2)
    return total


def test_the_weighed_fix_is_the_weighted_least_squares_point() -> None:
    spreads = (2e-4, 0.4)  # C1's rad, C2's px
    crossing = RayCrossing(T_BASE_C1[:3, 3], BERRY, 0.01, spreads=spreads)
    fix = crossing.fix(_detection((0.8, -0.5)), T_BASE_C2, CAMERA)
    assert fix is not None
    p = _in_base(fix)
    c1_range = float(np.linalg.norm(p - T_BASE_C1[:3, 3]))
    c2_range = float(np.linalg.norm(p - T_BASE_C2[:3, 3]))
    x, y = CAMERA.normalize(np.array([_detection((0.8, -0.5)).center]))[0]
    c2_ray = T_BASE_C2[:3, :3] @ (np.array([x, y, 1.0]) / np.linalg.norm([x, y, 1.0]))
    lines = [
        (T_BASE_C1[:3, 3], crossing.c1_ray, 1.0 / (spreads[0] * c1_range) ** 2),
        (T_BASE_C2[:3, 3], c2_ray, 1.0 / (spreads[1] / CAMERA.focal * c2_range) ** 2),
    ]
    best = _cost(p, lines)
    for step in np.eye(3) * 1e-6:  # no nearby point does better
        assert _cost(p + step, lines) >= best - 1e-12
        assert _cost(p - step, lines) >= best - 1e-12


def test_an_error_of_c2s_centre_moves_the_weighed_fix_less() -> None:
    # C1's ray exact; C2's centre 0.5 px off: the fix on C2's ray takes it all.
    det = _detection((0.5, 0.5))
    plain = RayCrossing(T_BASE_C1[:3, 3], BERRY, 0.01).fix(det, T_BASE_C2, CAMERA)
    weighed = RayCrossing(T_BASE_C1[:3, 3], BERRY, 0.01, spreads=(1.5e-4, 0.35)).fix(
        det, T_BASE_C2, CAMERA
    )
    assert plain is not None and weighed is not None
    before = float(np.linalg.norm(_in_base(plain) - BERRY))
    after = float(np.linalg.norm(_in_base(weighed) - BERRY))
    assert after < 0.8 * before


def test_rays_through_the_berry_fix_it_with_or_without_spreads() -> None:
    fix = RayCrossing(T_BASE_C1[:3, 3], BERRY, 0.01, spreads=(1.5e-4, 0.35)).fix(
        _detection((0.0, 0.0)), T_BASE_C2, CAMERA
    )
    assert fix is not None
    np.testing.assert_allclose(_in_base(fix), BERRY, atol=1e-9)


@pytest.mark.parametrize("spreads", [(0.0, 0.35), (1e-4, -1.0), (float("nan"), 0.3)])
def test_a_spread_that_is_no_positive_number_is_refused(spreads: tuple[float, float]) -> None:
    with pytest.raises(InputError, match="spreads"):
        RayCrossing(T_BASE_C1[:3, 3], BERRY, 0.01, spreads=spreads)
