"""C2's gate for a mapped berry slides along C1's ray (issue 41): the stereo places a
berry well across C1's line of sight and poorly along it, so a berry C1 placed 22 mm
short along its ray is still the berry C2 sees, and one as far off across the ray is
not. The rig's geometry: C1 about 1.1 m from the berry, C2 12 cm from it at about 45
degrees to C1's ray (the fine positioning's last centimetres)."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.errors import ParameterError
from softarm.perception.approach import (
    DISPARITY_SPREAD_PX,
    RayCrossing,
    along_spread,
)
from softarm.perception.berries import BerryDetection
from softarm.sim.rig_cameras import look_at
from softarm.vision.camera_model import CameraModel

C2 = CameraModel.ideal(300.0, 640, 480)
C1_CENTRE = np.array([0.0, -0.8, 0.6])
BERRY = np.array([0.05, 0.25, 0.35])  # the true berry
RADIUS = 0.011
# The depth 2 px of disparity spans at 1.1 m (f 900 px, baseline 12 cm): 22 mm, what
# the stereo missed by for the mapped berries the harvest skipped.
MISS = 0.022


def _look_at(eye: np.ndarray, target: np.ndarray) -> np.ndarray:
    """A camera pose at ``eye`` looking at ``target``, image y along +z."""
    return look_at(eye, target, up=(0.0, 0.0, -1.0))


def _c2_pose() -> np.ndarray:
    """C2 12 cm from the berry, its axis at 45 degrees to C1's ray."""
    u = (BERRY - C1_CENTRE) / np.linalg.norm(BERRY - C1_CENTRE)
    side = np.cross(u, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    back = (-u + side) / np.linalg.norm(-u + side)
    return _look_at(BERRY + 0.12 * back, BERRY)


def _seen(point: np.ndarray, T_base_c2: np.ndarray) -> BerryDetection:
    """C2's detection of a berry of RADIUS at ``point`` (its outline's size there)."""
    p = (np.linalg.inv(T_base_c2) @ np.append(point, 1.0))[:3]
    u, v = C2.project(p[None, :])[0]
    r = C2.focal * np.tan(np.arcsin(RADIUS / np.linalg.norm(p)))
    return BerryDetection((float(u), float(v)), float(r), (0, 0, 1, 1), np.ones((1, 1), bool),
                          1.0, "ripe", 1.0)  # fmt: skip


def _mapped_along(distance: float) -> np.ndarray:
    u = (BERRY - C1_CENTRE) / np.linalg.norm(BERRY - C1_CENTRE)
    out: np.ndarray = BERRY + distance * u
    return out


def _mapped_across(distance: float) -> np.ndarray:
    """Off across C1's ray and out of the plane of the two rays (within that plane C2
    cannot tell an offset across C1's ray from one along it)."""
    u = (BERRY - C1_CENTRE) / np.linalg.norm(BERRY - C1_CENTRE)
    side = np.cross(u, [0.0, 0.0, 1.0])
    across = np.cross(u, side)
    out: np.ndarray = BERRY + distance * across / np.linalg.norm(across)
    return out


@pytest.mark.parametrize("miss", [-MISS, MISS])
def test_a_berry_placed_off_along_c1s_ray_passes_the_gate(miss: float) -> None:
    T = _c2_pose()
    det = _seen(BERRY, T)
    spread = along_spread(1.1, 900.0, 0.12)
    assert not RayCrossing(C1_CENTRE, _mapped_along(miss), RADIUS).consistent(det, T, C2)
    assert RayCrossing(C1_CENTRE, _mapped_along(miss), RADIUS, spread).consistent(det, T, C2)


def test_the_fix_of_the_widened_gate_is_the_true_berry() -> None:
    T = _c2_pose()
    track = RayCrossing(C1_CENTRE, _mapped_along(MISS), RADIUS, along_spread(1.1, 900.0, 0.12))
    fix = track.fix(_seen(BERRY, T), T, C2)
    assert fix is not None
    np.testing.assert_allclose((T @ np.append(fix, 1.0))[:3], BERRY, atol=1e-6)


def test_a_berry_as_far_across_c1s_ray_is_still_refused() -> None:
    T = _c2_pose()
    track = RayCrossing(C1_CENTRE, _mapped_across(MISS), RADIUS, along_spread(1.1, 900.0, 0.12))
    assert not track.consistent(_seen(BERRY, T), T, C2)


def test_past_the_spread_along_the_ray_is_refused() -> None:
    T = _c2_pose()
    spread = 0.010
    track = RayCrossing(C1_CENTRE, _mapped_along(spread + 0.03), RADIUS, spread)
    assert not track.consistent(_seen(BERRY, T), T, C2)


def test_the_spread_is_the_depth_of_the_disparity_spread() -> None:
    z, f, b = 1.1, 900.0, 0.12
    near = f * b / (f * b / z + DISPARITY_SPREAD_PX)  # a disparity SPREAD px larger
    assert along_spread(z, f, b) == pytest.approx(z - near, rel=0.1)


@pytest.mark.parametrize("bad", [-0.01, float("nan"), "far"])
def test_a_bad_spread_is_refused(bad: object) -> None:
    with pytest.raises(ParameterError, match="along"):
        RayCrossing(C1_CENTRE, BERRY, RADIUS, bad)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("arg", "values"), [("depth", (0.0, 900.0, 0.12)), ("baseline", (1.0, 900.0, float("inf")))]
)
def test_along_spread_refuses_bad_numbers(arg: str, values: tuple[float, float, float]) -> None:
    with pytest.raises(ParameterError, match=arg):
        along_spread(*values)
