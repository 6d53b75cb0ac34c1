"""C1's stereo may match beyond the depths it keeps (CaneSettings.match_far): a row of
canes farther than the range is matched at its own depth and dropped, where a search
that stops at the range matches it to the neighbouring cane, nearer: phantoms."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from softarm.errors import ParameterError
from softarm.perception.canes import CaneSettings, mask_points
from softarm.vision.stereo_camera import StereoCamera

#: The far canes' depth (m), beyond CaneSettings' range (0.6-1.5 m), and their spacing (px).
FAR, SPACING = 2.5, 40


def _far_row(stereo: StereoCamera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A rectified pair of textured canes 5 px wide every SPACING px at FAR, and their
    mask: the next row seen through a gap."""
    rect = stereo.rectification
    d_far = round(rect.focal * rect.baseline / FAR)
    rng = np.random.default_rng(3)
    noise = cv2.GaussianBlur(rng.integers(0, 255, (480, 640 + d_far)).astype(np.uint8), (0, 0), 1)
    grey = np.full((480, 640 + d_far), 30, np.uint8)
    for x0 in range(0, 640 + d_far, SPACING):
        grey[:, x0 : x0 + 5] = 100 + noise[:, x0 : x0 + 5] // 2
    image = np.repeat(grey[:, :, None], 3, axis=2)
    left, right = image[:, :640].copy(), image[:, d_far:].copy()  # right[x - d] = left[x]
    mask = np.zeros((480, 640), bool)
    mask[100:400, 200:440] = True
    return left, right, mask & (grey[:, :640] > 60)


def test_far_canes_give_no_points_when_matched_beyond_the_range(stereo: StereoCamera) -> None:
    left, right, mask = _far_row(stereo)
    aliased = mask_points(left, right, stereo, mask, CaneSettings(reach=None))
    assert len(aliased) > 1000  # matched to the neighbouring cane, inside the range
    assert np.all(aliased[:, 2] < 1.55)
    farther = CaneSettings(reach=None, match_far=3.5)
    assert len(mask_points(left, right, stereo, mask, farther)) == 0


@pytest.mark.parametrize("bad", [1.0, float("nan"), True, "3"])
def test_a_bad_match_far_is_one_error_naming_it(bad: object) -> None:
    with pytest.raises(ParameterError, match=r"settings\.match_far"):
        CaneSettings(match_far=bad)  # type: ignore[arg-type]
