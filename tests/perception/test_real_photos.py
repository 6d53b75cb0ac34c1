"""The real-photo false-call count (softarm.experiments.real_photos): counted on drawn
images whose answer is known, and a clear error where the photos' package is missing."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from softarm.errors import MissingDependencyError
from softarm.experiments.real_photos import Photo, false_ripe_calls, table


def _leaf_green(with_berry: bool) -> np.ndarray:
    image = np.full((240, 320, 3), (40, 120, 50), np.uint8)  # BGR: a plain green
    if with_berry:
        cv2.circle(image, (160, 120), 14, (60, 15, 45), -1)  # a dark purple disc
    return image


def test_a_plain_green_photo_has_no_ripe_call() -> None:
    ripe, calls, _ = false_ripe_calls(_leaf_green(False), "colour")
    assert (ripe, calls) == (0, 0)


def test_a_dark_purple_disc_is_one_ripe_call() -> None:
    ripe, _, dets = false_ripe_calls(_leaf_green(True), "colour")
    assert ripe == 1
    assert np.hypot(dets[0].center[0] - 160, dets[0].center[1] - 120) < 3


def test_the_table_gives_the_share_of_photos() -> None:
    results = {"colour": {"photos": 4, "photos_with_ripe_call": 1, "share_with_ripe_call": 0.25,
                          "ripe_calls": 2}}  # fmt: skip
    assert "| colour | 1 (25%) | 2 | 4 |" in table(results)


def test_a_missing_package_is_a_clear_error() -> None:
    with pytest.raises(MissingDependencyError, match="pip install"):
        Photo("softarm_no_such_package", "data", "x.png").read()
