"""The cost of splitting touching fruit (softarm.perception.detector.touching) on C1's
1280 x 720 eye, one core: the colour rule with and without its ripe blobs split, on a
frame of 40 clusters of two or three touching fruit (the split's work grows with the
blobs that could hold two fruit; the network's share is on its half-size map)."""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np
import pytest

from softarm.perception.berries import DetectorSettings
from softarm.perception.detector.choice import detector
from softarm.vision.camera_model import CameraModel

cv2.setNumThreads(1)  # one core, as the targets are stated


def _clusters(width: int, height: int) -> np.ndarray:
    rng = np.random.default_rng(0)
    image = np.full((height, width, 3), (60, 110, 70), np.uint8)
    for _ in range(40):
        x, y = int(rng.integers(30, width - 60)), int(rng.integers(30, height - 30))
        for k in range(int(rng.integers(2, 4))):
            cv2.circle(image, (x + 17 * k, y), 9, (40, 8, 25), -1)
    return image


@pytest.mark.parametrize("split", [False, True], ids=["whole", "split"])
@pytest.mark.parametrize("name", ["colour", "net"])
def test_touching_split_per_c1_frame(benchmark: Any, name: str, split: bool) -> None:
    image = _clusters(1280, 720)
    camera = CameraModel.ideal(900.0, 1280, 720)
    settings = DetectorSettings(split_touching=split, split_colour_blobs=split)
    dets = benchmark(detector(name).detect_berries, image, camera, None, settings)
    assert isinstance(dets, list)
