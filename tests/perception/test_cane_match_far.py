"""C1's stereo may match beyond the depths it keeps (CaneSettings.match_far): a row of
canes farther than the range is matched at its own depth and dropped, where a search
that stops at the range matches it to the neighbouring cane, nearer: phantoms."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from softarm.errors import ParameterError
from softarm.perception.cane_pixels import matched_disparity, stereo_disparity
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
    aliased = mask_points(left, right, stereo, mask, CaneSettings(reach=None, match_far=None))
    assert len(aliased) > 1000  # matched to the neighbouring cane, inside the range
    assert np.all(aliased[:, 2] < 1.55)
    farther = CaneSettings(reach=None, match_far=3.5)
    assert len(mask_points(left, right, stereo, mask, farther)) == 0


@pytest.mark.parametrize("bad", [1.0, float("nan"), True, "3"])
def test_a_bad_match_far_is_one_error_naming_it(bad: object) -> None:
    with pytest.raises(ParameterError, match=r"settings\.match_far"):
        CaneSettings(match_far=bad)  # type: ignore[arg-type]


def _near_cane_with_a_far_twin(
    stereo: StereoCamera,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """A rectified pair: a textured tube 5 px wide at NEAR before a textured backdrop at
    1.4 m, and in the right image the same tube again where a cane at FAR would be seen
    (a neighbouring cane of the same look beyond the range): the near cane's match within
    the range is as good as one beyond it. Its mask and its true disparity."""
    rect = stereo.rectification
    fb = rect.focal * rect.baseline
    d_near, d_far, d_back = round(fb / NEAR), round(fb / FAR), round(fb / 1.4)
    rng = np.random.default_rng(8)
    noise = rng.integers(0, 255, (480, 900)).astype(np.uint8)
    backdrop = np.repeat(cv2.GaussianBlur(noise, (0, 0), 1.0)[:, :, None], 3, axis=2)
    left = backdrop[:, 100:740].copy()
    right = backdrop[:, 100 + d_back : 740 + d_back].copy()
    bark = cv2.GaussianBlur(rng.integers(0, 255, (480, 5)).astype(np.uint8), (0, 0), 1.0)
    tube = np.repeat((60 + bark // 2)[:, :, None], 3, axis=2)
    x = 320
    left[100:400, x : x + 5] = tube[100:400]
    for d in (d_near, d_far):
        right[100:400, x - d : x - d + 5] = tube[100:400]
    mask = np.zeros((480, 640), bool)
    mask[100:400, x : x + 5] = True
    return left, right, mask, float(d_near)


#: The near cane's depth (m), within CaneSettings' range.
NEAR = 1.0


def test_a_near_cane_with_an_equally_good_far_match_keeps_its_near_match(
    stereo: StereoCamera,
) -> None:
    # Searched out to 3 m alone, SGBM finds two equally good disparities for most of the
    # tube (its uniqueness check fails) and leaves them unmatched; with the ties going to
    # the range, the tube is matched as well as by a search within the range alone.
    left, right, mask, d_near = _near_cane_with_a_far_twin(stereo)
    rect = stereo.rectification

    def right_share(disparity: np.ndarray) -> float:
        return float(np.mean(np.abs(disparity[mask] - d_near) <= 1.0))

    in_range = right_share(stereo_disparity(left, right, rect, mask, (0.6, 1.5)))
    wide = matched_disparity(left, right, rect, mask, (0.6, 1.5), 3.0, ties_in_range=False)
    tied = matched_disparity(left, right, rect, mask, (0.6, 1.5), 3.0)
    assert in_range > 0.6
    assert right_share(wide) < 0.3 * in_range
    assert right_share(tied) >= in_range - 0.01
    points = mask_points(left, right, stereo, mask, CaneSettings(reach=None, match_far=3.0))
    assert len(points) > 0.6 * mask.sum()
    assert abs(float(np.median(points[:, 2])) - NEAR) < 0.02


def test_far_canes_are_still_dropped_with_ties_to_the_range(stereo: StereoCamera) -> None:
    # A far cane's own match beats its aliased neighbour's: nothing of it is kept.
    left, right, mask = _far_row(stereo)
    settings = CaneSettings(reach=None, match_far=3.5, ties_in_range=True)
    assert len(mask_points(left, right, stereo, mask, settings)) < 0.01 * mask.sum()


@pytest.mark.parametrize("bad", [1, None, "yes"])
def test_a_bad_ties_in_range_is_one_error_naming_it(bad: object) -> None:
    with pytest.raises(ParameterError, match=r"settings\.ties_in_range"):
        CaneSettings(ties_in_range=bad)  # type: ignore[arg-type]
