"""The learned berry detector's cost on one core (issue 41's speed goal: C1's perception
<= 50 ms per stereo frame, C2's <= 10 ms): the network and its post-processing on C1's
1280 x 720 eye (shrunk to 640 x 360 for the network) and on C2's 320 x 240 frame, beside
the colour-and-shape detector on the same frames."""

from __future__ import annotations

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
