"""The corner refinement on a marker rendered analytically, its corners known to a
sixteenth of a pixel: a camera that crushes the ink's foot (black level, then clipped
at 0) or saturates the paper biases the gradient centroid; the border's width measures
that bias and the corners come back (softarm.vision.border_bias). A marker that clips
nothing keeps the centroid's corners."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

import softarm.vision.refine as refine
from softarm.vision import CameraModel
from softarm.vision.border_bias import border_bias
from softarm.vision.dictionaries import get_dictionary

SS = 16  # supersampling: the marker's corners sit on this grid of a pixel
CELL_PX = 7  # px per cell (a 6-cell marker, 42 px: the cube's tags near C1)
CELLS = 6
SIZE = 80  # px: the image
ORIGIN = (17 + 5 / SS, 19 + 11 / SS)  # the marker's top-left corner (px, pixel edges)


def _render(
    ink: float,
    paper: float,
    black_level: float = 0.0,
    blur_px: float = 0.7,
    noise: float = 0.0,
    seed: int = 0,
) -> np.ndarray:
    """A 4x4 marker (id 3) with its quiet zone, blurred by a Gaussian PSF of ``blur_px``,
    area-sampled, then as a camera delivers it: ``black_level`` DN subtracted, read
    ``noise`` (DN) added, clipped to 0-255 and rounded."""
    bits = cv2.aruco.generateImageMarker(get_dictionary("DICT_4X4_50"), 3, CELLS)
    level = np.where(bits > 0, paper, ink).astype(np.float32)
    big = np.repeat(np.repeat(level, CELL_PX * SS, 0), CELL_PX * SS, 1)
    canvas = np.full((SIZE * SS, SIZE * SS), paper, np.float32)
    x0, y0 = round(ORIGIN[0] * SS), round(ORIGIN[1] * SS)
    canvas[y0 : y0 + big.shape[0], x0 : x0 + big.shape[1]] = big
    blurred = np.asarray(cv2.GaussianBlur(canvas, (0, 0), blur_px * SS), np.float64)
    light = blurred.reshape(SIZE, SS, SIZE, SS).mean(axis=(1, 3))
    rng = np.random.default_rng(seed)
    signal = light - black_level + noise * rng.standard_normal(light.shape)
    image: np.ndarray = np.clip(np.round(signal), 0, 255).astype(np.uint8)
    return image


def _truth() -> np.ndarray:
    """The marker's corners in OpenCV's pixel coordinates (a pixel's centre is integer)."""
    side = CELLS * CELL_PX
    x, y = ORIGIN[0] - 0.5, ORIGIN[1] - 0.5
    return np.array([[x, y], [x + side, y], [x + side, y + side], [x, y + side]])


@pytest.fixture(scope="module")
def pinhole() -> CameraModel:
    return CameraModel.ideal(900.0, SIZE, SIZE, [0.0, 0.0, 0.0, 0.0, 0.0])


def _error(image: np.ndarray, camera: CameraModel) -> float:
    """The largest corner error (px) after refining from a detection 0.3 px off."""
    detected = _truth() + np.array([[0.3, -0.2], [-0.25, 0.3], [0.2, 0.25], [-0.3, -0.3]])
    corners = refine.refine_marker_corners(image, detected, camera, CELLS)
    return float(np.max(np.linalg.norm(corners - _truth(), axis=1)))


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
    assert _error(_render(ink, paper, black_level), pinhole) < 0.02


def test_clipped_edges_with_noise(pinhole: CameraModel) -> None:
    # 1.5 DN of read noise on a 60 DN step: the centroid alone 0.26 px off, refined 0.06.
    errors = [_error(_render(2.0, 60.0, 8.0, noise=1.5, seed=s), pinhole) for s in range(5)]
    assert np.median(errors) < 0.1


def test_unclipped_marker_keeps_the_centroid(
    pinhole: CameraModel, monkeypatch: pytest.MonkeyPatch
) -> None:
    def refused(*_: object) -> float:
        raise AssertionError("border_bias called on a marker that clips nothing")

    monkeypatch.setattr(refine, "border_bias", refused)
    assert _error(_render(20.0, 200.0), pinhole) < 0.02


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
