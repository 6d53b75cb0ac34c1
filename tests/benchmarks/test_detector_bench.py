"""The learned berry detector's cost on one core (issue 41's speed goal: C1's perception
<= 50 ms per stereo frame, C2's <= 10 ms): the network and its post-processing on C1's
1280 x 720 eye (shrunk to 640 x 360 for the network) and on C2's 320 x 240 frame, beside
the colour-and-shape detector on the same frames."""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np
import pytest

from softarm.perception.detector.choice import detector
from softarm.vision.camera_model import CameraModel

cv2.setNumThreads(1)  # one core, as the targets are stated


def _frame(width: int, height: int) -> np.ndarray:
    """Leaf green with dark fruit-sized discs (what the network does costs the same
    whatever it finds, bar the post-processing)."""
    rng = np.random.default_rng(0)
    image = np.full((height, width, 3), (60, 110, 70), np.uint8)
    for _ in range(40):
        x, y = int(rng.integers(width)), int(rng.integers(height))
        cv2.circle(image, (x, y), max(3, width // 120), (40, 8, 25), -1)
    return image


@pytest.mark.parametrize("name", ["colour", "net"])
@pytest.mark.parametrize("size", [(1280, 720), (320, 240)], ids=["c1", "c2"])
def test_detector_per_frame(benchmark, name: str, size: tuple[int, int]) -> None:  # type: ignore[no-untyped-def]
    image = _frame(*size)
    camera = CameraModel.ideal(900.0 * size[0] / 1280, *size)
    det = detector(name)
    dets = benchmark(det.detect_berries, image, camera)
    assert isinstance(dets, list)


def _with_depth(width: int, height: int, focal: float) -> tuple[np.ndarray, np.ndarray]:
    """Leaf green with 40 dark discs of a fruit's size 0.6 m away (10 px at C1, 8 at C2),
    and its depth image (m): each disc a fruit's cap before a wall at 0.8 m, so that
    every disc reaches the depth check's plane fit."""
    rng = np.random.default_rng(0)
    image = np.full((height, width, 3), (60, 110, 70), np.uint8)
    depth = np.full((height, width), 0.8, np.float32)
    r_px = max(8, width // 120)
    radius = r_px * 0.6 / focal
    yy, xx = np.mgrid[:height, :width]
    for _ in range(40):
        x, y = int(rng.integers(width)), int(rng.integers(height))
        cv2.circle(image, (x, y), r_px, (40, 8, 25), -1)
        rho = np.hypot(xx - x, yy - y) * 0.6 / focal
        cap = rho <= radius
        depth[cap] = 0.6 + radius - np.sqrt(radius**2 - rho[cap] ** 2)
    return image, depth


@pytest.mark.parametrize("with_depth", [False, True], ids=["image", "depth"])
@pytest.mark.parametrize("size", [(1280, 720), (320, 240)], ids=["c1", "c2"])
def test_colour_detector_with_the_depth_check(
    benchmark: Any, size: tuple[int, int], with_depth: bool
) -> None:
    focal = 900.0 * size[0] / 1280
    image, depth = _with_depth(*size, focal)
    camera = CameraModel.ideal(focal, *size)
    dets = benchmark(
        detector("colour").detect_berries, image, camera, depth if with_depth else None
    )
    assert len(dets) > 10
