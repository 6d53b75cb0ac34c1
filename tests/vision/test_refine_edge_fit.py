"""The corner refinement with its edges fitted by a blurred step (refine.EDGE_FIT,
softarm.vision.edge_fit) on the analytic marker of tests/clipped_marker.py: a clean
marker's corners as the centroid finds them, a clipped one's unbiased by its border
(whose inner edges are then fitted too), and under the row camera's noise and JPEG the
corners nearer the truth than the centroid's on the same frames."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

import softarm.vision.refine as refine
from clipped_marker import CELLS, SIZE, marker_truth, render_marker
from softarm.vision import CameraModel

DETECTED = marker_truth() + np.array([[0.3, -0.2], [-0.25, 0.3], [0.2, 0.25], [-0.3, -0.3]])


@pytest.fixture(scope="module")
def pinhole() -> CameraModel:
    return CameraModel.ideal(900.0, SIZE, SIZE, [0.0, 0.0, 0.0, 0.0, 0.0])


def _errors(image: np.ndarray, camera: CameraModel) -> np.ndarray:
    corners = refine.refine_marker_corners(image, DETECTED, camera, CELLS)
    errors: np.ndarray = np.linalg.norm(corners - marker_truth(), axis=1)
    return errors


@pytest.mark.parametrize(
    ("ink", "paper", "black_level", "limit"),
    [
        (20.0, 200.0, 0.0, 0.02),  # nothing clipped
        (2.0, 60.0, 8.0, 0.02),  # a crushed ink: the border's bias, fitted
        (0.0, 200.0, 6.0, 0.02),
        (30.0, 330.0, 0.0, 0.03),  # a saturated paper
    ],
)
def test_fitted_corners_of_clean_and_clipped_markers(
    pinhole: CameraModel,
    monkeypatch: pytest.MonkeyPatch,
    ink: float,
    paper: float,
    black_level: float,
    limit: float,
) -> None:
    monkeypatch.setattr(refine, "EDGE_FIT", True)
    assert _errors(render_marker(ink, paper, black_level), pinhole).max() < limit


def test_border_bias_measured_with_the_fit(
    pinhole: CameraModel, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A saturated paper moves the fitted edges other than the centroids: the border's
    # inner edges must be located alike, or the bias it measures is the wrong one.
    monkeypatch.setattr(refine, "EDGE_FIT", True)
    image = render_marker(30.0, 330.0, 0.0)
    fitted = _errors(image, pinhole).max()
    monkeypatch.setattr(refine, "_fitted", None)  # the inner edges by the centroid
    assert _errors(image, pinhole).max() > fitted + 0.01  # 0.040 px against 0.026


@pytest.mark.parametrize(("ink", "paper", "black_level"), [(10.0, 120.0, 0.0), (5.0, 180.0, 6.0)])
def test_fitted_corners_under_noise_and_jpeg(
    pinhole: CameraModel,
    monkeypatch: pytest.MonkeyPatch,
    ink: float,
    paper: float,
    black_level: float,
) -> None:
    light = render_marker(ink, paper)
    rng = np.random.default_rng(11)
    centroid, fitted = [], []
    for _ in range(20):
        # The row camera's read-out (shot and read noise, black level, clipping) and JPEG.
        std = np.sqrt(0.25 * light + 2.0**2)
        raw = np.clip(
            np.round(light + std * rng.standard_normal(light.shape) - black_level), 0, 255
        )
        data = cv2.imencode(".jpg", raw.astype(np.uint8), [cv2.IMWRITE_JPEG_QUALITY, 75])[1]
        image = cv2.imdecode(data, cv2.IMREAD_GRAYSCALE)
        monkeypatch.setattr(refine, "EDGE_FIT", False)
        centroid.extend(_errors(image, pinhole))
        monkeypatch.setattr(refine, "EDGE_FIT", True)
        fitted.extend(_errors(image, pinhole))
    assert np.median(fitted) < 0.85 * np.median(centroid)
