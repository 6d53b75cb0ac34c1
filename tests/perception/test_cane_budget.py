"""The cane fit's point budget is spent within the arm's reach: a view full of far cane
pixels (the next row, the hedge) and one near cane keeps the near cane's points, from
C1's stereo, from a depth image and from the survey's view pairs alike."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from softarm.errors import ParameterError
from softarm.perception import canes
from softarm.perception.canes import CaneSettings, cane_points, centre_line_points, mask_points
from softarm.perception.self_filter import CANE_REACH
from softarm.vision.stereo_camera import StereoCamera

#: Depths (m) of the near cane and of the far wall of cane pixels, the camera at the base.
NEAR, FAR = 0.7, 1.4
#: The near cane's rows and columns in the left image: 300 x 5 = 1,500 pixels.
ROWS, COL = slice(100, 400), 400


def _scene(stereo: StereoCamera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A rectified pair: a textured wall at FAR whose every pixel in columns 0-379 is
    called cane (about 110,000 pixels), and a 5-pixel tube at NEAR; the mask of both."""
    rect = stereo.rectification
    fb = rect.focal * rect.baseline
    d_far, d_near = round(fb / FAR), round(fb / NEAR)
    noise = np.random.default_rng(7).integers(0, 255, (480, 640 + d_far)).astype(np.uint8)
    texture = np.repeat(cv2.GaussianBlur(noise, (0, 0), 1.0)[:, :, None], 3, axis=2)
    left, right = texture[:, :640].copy(), texture[:, d_far:].copy()  # right[x - d] = left[x]
    tube = (np.array([0.6, 0.9, 1.0, 0.8, 0.5])[:, None] * [40, 120, 110]).astype(np.uint8)
    left[ROWS, COL : COL + 5] = tube
    right[ROWS, COL - d_near : COL - d_near + 5] = tube
    mask = np.zeros((480, 640), bool)
    mask[:, 200:380] = True
    mask[ROWS, COL : COL + 5] = True
    return left, right, mask


def _near(points: np.ndarray) -> int:
    return int(np.sum(np.linalg.norm(points[:, :3], axis=1) <= CANE_REACH))


def test_the_near_cane_keeps_its_points_from_c1s_stereo(stereo: StereoCamera) -> None:
    left, right, mask = _scene(stereo)
    settings = CaneSettings(max_points=1000)
    points = mask_points(left, right, stereo, mask, settings)
    # Every point kept is within reach: the near cane's 1,500 pixels share the 1,000
    # (one in two, an even step), the wall's take none of them.
    assert len(points) > 600 and _near(points) == len(points)
    assert np.median(points[:, 2]) == pytest.approx(NEAR, abs=0.03)
    # The budget over the whole view (as before the reach) leaves the cane a few
    # points, far under the fit's support of 70.
    whole = mask_points(left, right, stereo, mask, CaneSettings(max_points=1000, reach=None))
    assert _near(whole) < 40 and len(whole) > 900


def test_the_near_cane_keeps_its_points_from_a_depth_image(
    stereo: StereoCamera, monkeypatch: pytest.MonkeyPatch
) -> None:
    left, _, mask = _scene(stereo)
    depth = np.full((480, 640), FAR, np.float32)
    depth[ROWS, COL : COL + 5] = NEAR
    monkeypatch.setattr(canes, "source_mask", lambda *_: mask)
    points = cane_points(left, None, stereo, depth, CaneSettings(max_points=1000))
    assert len(points) == 750 and _near(points) == 750  # 1,500 pixels, one in two
    whole = cane_points(left, None, stereo, depth, CaneSettings(max_points=1000, reach=None))
    assert _near(whole) < 40


def test_the_survey_views_points_are_dropped_beyond_reach_before_the_budget() -> None:
    # centre_line_points is the survey's (cane_views.view_pair_points) last step.
    rng = np.random.default_rng(8)
    wall = np.column_stack([rng.uniform(-0.5, 0.5, (40_000, 2)), np.full(40_000, FAR)])
    cane = np.column_stack([np.zeros(300), np.linspace(-0.1, 0.1, 300), np.full(300, 0.5)])
    surface, radius = np.vstack([wall, cane]), np.full(40_300, 0.004)
    kept = centre_line_points(surface, radius, np.eye(4), (0.1, 1.5), 1000, CANE_REACH)
    assert len(kept) == 300 and _near(kept) == 300
    whole = centre_line_points(surface, radius, np.eye(4), (0.1, 1.5), 1000)
    assert _near(whole) < 20


@pytest.mark.parametrize("reach", [0.0, -1.0, float("nan"), float("inf"), "far", True])
def test_a_bad_reach_is_a_parameter_error_naming_it(reach: object) -> None:
    with pytest.raises(ParameterError, match=r"settings\.reach"):
        CaneSettings(reach=reach)  # type: ignore[arg-type]
