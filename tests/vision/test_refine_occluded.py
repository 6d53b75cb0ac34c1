"""A marker whose corner a dark fruit covers: the contour's corner lands 4-5 px off (the
fruit joins the black border), too far for the refinement's one pass, which used to
refuse it and keep the contour's corner (a single-tag pose 10 cm off on rendered bushes).
The sides' lines, fitted on the profiles clear of the fruit, find the corner; a second
pass from there, its lines fitted without the points the fruit bends, keeps it."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

import softarm.vision.refine as refine
from clipped_marker import CELLS, SIZE, SS, marker_truth, render_marker
from softarm.vision import CameraModel
from softarm.vision.detector import MarkerDetector


@pytest.fixture(scope="module")
def pinhole() -> CameraModel:
    return CameraModel.ideal(900.0, SIZE, SIZE, [0.0, 0.0, 0.0, 0.0, 0.0])


def _covered(radius: float, dx: float, dy: float) -> np.ndarray:
    """The marker with a dark disc (a ripe fruit) of ``radius`` px centred (dx, dy) px
    from its top-left corner."""
    image = render_marker(20.0, 200.0)
    x, y = marker_truth()[0] + (dx, dy)
    centre = (round(x * SS), round(y * SS))
    cv2.circle(image, centre, round(radius * SS), 18, -1, cv2.LINE_AA, 4)
    return image


COVERS = [(2.5, -1.0, -1.0), (3.0, 0.0, 0.0), (3.0, -1.0, -1.0), (3.5, 0.0, 0.0)]


@pytest.mark.parametrize(("radius", "dx", "dy"), COVERS)
def test_a_covered_corner_is_found_by_the_sides(
    pinhole: CameraModel, radius: float, dx: float, dy: float
) -> None:
    image = _covered(radius, dx, dy)
    (detected,) = MarkerDetector("DICT_4X4_50", refine_edges=False).detect(image)
    truth = marker_truth()
    assert np.linalg.norm(detected.corners[0] - truth[0]) > 3.0  # the contour's corner
    corners = refine.refine_marker_corners(image, detected.corners, pinhole, CELLS)
    assert np.max(np.linalg.norm(corners - truth, axis=1)) < 0.25


@pytest.mark.parametrize(("radius", "dx", "dy"), COVERS)
def test_the_detector_reads_enough_pixels_for_the_second_pass(
    pinhole: CameraModel, radius: float, dx: float, dy: float
) -> None:
    # The detector refines later, on a copy of the marker's neighbourhood: it must hold
    # the second pass's profiles too.
    (found,) = MarkerDetector("DICT_4X4_50").detect(_covered(radius, dx, dy), pinhole)
    assert np.max(np.linalg.norm(found.corners - marker_truth(), axis=1)) < 0.25


def test_the_margin_grows_with_the_marker() -> None:
    small = marker_truth()
    large = 3.0 * small
    assert refine.read_margin(small) >= refine.READ_MARGIN + 0.25 * 42
    assert refine.read_margin(large) > refine.read_margin(small)
