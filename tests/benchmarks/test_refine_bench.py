"""The corner refinement's cost per marker (softarm.vision.refine): a 42 px marker whose
ink a camera's black level crushed (the border's bias measured, the lines moved) against
the same marker clipping nothing (the gradient centroid alone, the code before's path).

    pytest tests/benchmarks/test_refine_bench.py --benchmark-only
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from clipped_marker import CELLS, SIZE, marker_truth, render_marker
from softarm.vision import CameraModel
from softarm.vision.refine import refine_marker_corners

cv2.setNumThreads(1)  # one core, as the harvest's C1 tracking runs


@pytest.fixture(scope="module")
def camera() -> CameraModel:
    return CameraModel.ideal(900.0, SIZE, SIZE, [0.0, 0.0, 0.0, 0.0, 0.0])


@pytest.mark.parametrize(
    ("ink", "paper", "black_level"),
    [(2.0, 60.0, 8.0), (20.0, 200.0, 0.0)],
    ids=["crushed", "clean"],
)
def test_refine_marker_corners(  # type: ignore[no-untyped-def]
    benchmark, camera: CameraModel, ink: float, paper: float, black_level: float
) -> None:
    image = render_marker(ink, paper, black_level, noise=1.0)
    detected = marker_truth() + 0.2
    corners = benchmark(refine_marker_corners, image, detected, camera, CELLS)
    assert np.max(np.linalg.norm(corners - marker_truth(), axis=1)) < 0.1
