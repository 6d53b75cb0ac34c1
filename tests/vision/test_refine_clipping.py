"""The corner refinement on a marker rendered analytically, its corners known to a
sixteenth of a pixel: a camera that crushes the ink's foot (black level, then clipped
at 0) or saturates the paper biases the gradient centroid; the border's width measures
that bias and the corners come back (softarm.vision.border_bias). A marker that clips
nothing keeps the centroid's corners."""

from __future__ import annotations

import numpy as np
import pytest

import softarm.vision.refine as refine
from clipped_marker import CELLS, SIZE, marker_truth, render_marker
from softarm.vision import CameraModel
from softarm.vision.border_bias import border_bias


@pytest.fixture(scope="module")
def pinhole() -> CameraModel:
    return CameraModel.ideal(900.0, SIZE, SIZE, [0.0, 0.0, 0.0, 0.0, 0.0])


def _error(image: np.ndarray, camera: CameraModel) -> float:
    """The largest corner error (px) after refining from a detection 0.3 px off."""
    detected = marker_truth() + np.array([[0.3, -0.2], [-0.25, 0.3], [0.2, 0.25], [-0.3, -0.3]])
    corners = refine.refine_marker_corners(image, detected, camera, CELLS)
    return float(np.max(np.linalg.norm(corners - marker_truth(), axis=1)))


@pytest.mark.parametrize(
    ("ink", "paper", "black_level"),
    [
        (2.0, 60.0, 8.0),  # a shaded tag: the black level crushes the ramp's foot
        (0.0, 200.0, 6.0),  # a lit one, the same black level
        (30.0, 330.0, 0.0),  # sunlit paper saturating at 255
    ],
)
def test_clipped_edges_are_located(
    pinhole: CameraModel, ink: float, paper: float, black_level: float
) -> None:
    # The gradient centroid alone is 0.21, 0.075 and 0.44 px off on these, every corner
    # outwards or inwards alike (the marker's scale, hence a body's distance, suffers);
    # refined, 0.01 px or less.
    assert _error(render_marker(ink, paper, black_level), pinhole) < 0.02


def test_clipped_edges_with_noise(pinhole: CameraModel) -> None:
    # 1.5 DN of read noise on a 60 DN step: the centroid alone 0.26 px off, refined 0.06.
    errors = [_error(render_marker(2.0, 60.0, 8.0, noise=1.5, seed=s), pinhole) for s in range(5)]
    assert np.median(errors) < 0.1


def test_unclipped_marker_keeps_the_centroid(
    pinhole: CameraModel, monkeypatch: pytest.MonkeyPatch
) -> None:
    def refused(*_: object) -> float:
        raise AssertionError("border_bias called on a marker that clips nothing")

    monkeypatch.setattr(refine, "border_bias", refused)
    assert _error(render_marker(20.0, 200.0), pinhole) < 0.02


def test_oblique_quad_measures_nothing() -> None:
    # A quad whose sides differ by more than MIN_ASPECT: one bias for all four sides
    # would not hold, so none is given.
    quad = np.array([[10.0, 10.0], [50.0, 10.0], [50.0, 30.0], [10.0, 30.0]])
    offsets = 0.25 * np.arange(-4, 5, dtype=np.float64)
    outward = np.array([[0.0, -1.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])
    crop = np.zeros((40, 60), np.float32)
    assert border_bias(crop, np.array([0, 0]), quad, CELLS, offsets, outward) == 0.0


def test_no_white_cell_measures_nothing() -> None:
    # An all-black inside has no inner edge to measure the border against.
    quad = np.array([[10.0, 10.0], [52.0, 10.0], [52.0, 52.0], [10.0, 52.0]])
    offsets = 0.25 * np.arange(-4, 5, dtype=np.float64)
    outward = np.array([[0.0, -1.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])
    crop = np.full((64, 64), 200.0, np.float32)
    crop[10:52, 10:52] = 0.0
    assert border_bias(crop, np.array([0, 0]), quad, CELLS, offsets, outward) == 0.0
