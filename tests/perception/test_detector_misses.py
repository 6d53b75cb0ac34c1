"""Which ripe fruit a detector misses (``perception/detector/misses.py``, the table of
``python -m softarm.experiments.detector_eval --misses``) on a hand-made labelled folder
whose answers are known: a lone fruit found, two touching fruit merged into one
detection, a fruit never proposed, and fruit the recall does not count."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from detector_scenes import disc, write_folder

from softarm.errors import InputError
from softarm.perception.berries import BerryDetection
from softarm.perception.detector.misses import fruit_cases, miss_table

LONE, LEFT, RIGHT = disc(30, 60, 10), disc(80, 60, 10), disc(99, 60, 10)
UNSEEN, HIDDEN, GREEN = disc(135, 25, 8), disc(135, 95, 8), disc(30, 20, 8)


class _Fixed:
    """A detector that finds the lone fruit and one blob over the touching pair."""

    def detect_berries(
        self, image: Any, camera: Any, depth: Any = None, settings: Any = None
    ) -> Any:
        return [_det(LONE), _det(LEFT | RIGHT)]

    def fruit_mask(self, image: Any, settings: Any = None) -> Any:
        return np.zeros(image.shape[:2], np.uint8)


def _det(mask: np.ndarray) -> BerryDetection:
    return BerryDetection((0.0, 0.0), 1.0, (0, 0, 1, 1), mask, 1.0, "ripe", 1.0)


def _folder(tmp_path: Path) -> Path:
    scene = [
        ("ripe", LONE, True), ("ripe", LEFT, True), ("ripe", RIGHT, True),
        ("ripe", UNSEEN, False), ("ripe", HIDDEN, True), ("unripe", GREEN, True),
    ]  # fmt: skip
    coco_path = write_folder(tmp_path, [scene])
    coco = json.loads(coco_path.read_text())
    for a, visible in zip(coco["annotations"], (1.0, 0.9, 0.8, 1.0, 0.3, 1.0), strict=True):
        a["attributes"] = {"visible_fraction": visible, "position_camera_m": [0.0, 0.0, 0.5]}
    coco["images"][0]["view"] = "c1_left"
    coco_path.write_text(json.dumps(coco))
    return tmp_path


def test_the_cases_say_which_fruit_was_found_and_why_not(tmp_path: Path) -> None:
    cases = fruit_cases(_Fixed(), _folder(tmp_path))
    # The hidden fruit (0.3 visible) and the unripe one are not counted; the blob over
    # the pair is the right fruit's (it has the larger IoU), the left one is missed.
    assert [c.found for c in cases] == [True, False, True, False]
    lone, left, right, unseen = cases
    assert lone.best_iou == 1.0 and not lone.touches
    assert left.touches and right.touches and 0.5 > left.best_iou > 0.3
    assert unseen.best_iou == 0.0 and not unseen.touches
    assert lone.radius_px == pytest.approx(10.0, abs=0.5)
    # its visible area (the labelled pixels; the pair overlap by a sliver) over its share
    assert left.radius_px == pytest.approx(np.sqrt(LEFT.sum() / 0.9 / np.pi), rel=0.01)
    assert lone.distance_m == pytest.approx(0.5) and lone.view == "c1_left"


def test_the_table_counts_the_misses_by_bin(tmp_path: Path) -> None:
    text = miss_table(fruit_cases(_Fixed(), _folder(tmp_path)))
    assert "| touches other fruit (0 no, 1 yes) | 1–2 | 2 | 1 | 0.50 |" in text
    assert "| touches other fruit (0 no, 1 yes) | 0–1 | 2 | 1 | 0.50 |" in text
    assert "2 of 4 missed: 1 overlapped by a detection not matched to it" in text
    assert "(a merge or a fragment; 1 of them touching another fruit), 1 with no" in text


def test_a_folder_without_its_images_is_an_input_error(tmp_path: Path) -> None:
    folder = _folder(tmp_path)
    for image in (folder / "images").iterdir():
        image.unlink()
    with pytest.raises(InputError, match="name no image"):
        fruit_cases(_Fixed(), folder)
