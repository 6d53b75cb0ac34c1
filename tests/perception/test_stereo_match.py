"""The stereo match of one berry along the rows (``softarm.perception.stereo``): the
disparity of a textured fruit, no unique match on a flat one, and the shading's veto
when it contradicts the outline's and another fruit lies beside the berry."""

from __future__ import annotations

import numpy as np

from softarm.perception.berries import BerryDetection
from softarm.perception.stereo import UNIQUENESS, _cost_allows, _Cues, match_disparity

RANGE = (5.0, 80.0)


def _berry(x: int = 120, y: int = 40, side: int = 14) -> BerryDetection:
    mask = np.zeros((100, 240), bool)
    mask[y : y + side, x : x + side] = True
    return BerryDetection(
        (x + side / 2, y + side / 2), side / 2, (x, y, side, side), mask, 1.0, "ripe", 1.0
    )


def _shifted(left: np.ndarray, disparity: int) -> np.ndarray:
    right = np.zeros_like(left)
    right[:, : left.shape[1] - disparity] = left[:, disparity:]
    return right


def test_a_textured_fruit_matches_at_its_disparity() -> None:
    rng = np.random.default_rng(0)
    left = rng.uniform(0, 255, (100, 240)).astype(np.float32)
    d = match_disparity(left, _shifted(left, 31), _berry(), RANGE)
    assert d is not None and abs(d - 31.0) < 0.2


def test_a_flat_fruit_on_a_flat_ground_has_no_unique_match() -> None:
    left = np.full((100, 240), 20.0, np.float32)
    assert match_disparity(left, _shifted(left, 31), _berry(), RANGE) is None


def test_the_shading_vetoes_an_outline_it_contradicts() -> None:
    # Dark everywhere but one bright patch in the right eye, 50 px of disparity away:
    # the shading matches the dark fruit almost anywhere (no unique match), but not there.
    left = np.full((100, 240), 20.0, np.float32)
    right = left.copy()
    right[35:60, 62:82] = 200.0
    berry = _berry()
    assert match_disparity(left, right, berry, RANGE) is None
    assert _cost_allows(left, right, berry, RANGE, 31.0)
    assert not _cost_allows(left, right, berry, RANGE, 50.0)
    assert 0.0 < UNIQUENESS < 1.0


def test_the_cues_together() -> None:
    rng = np.random.default_rng(1)
    textured = rng.uniform(0, 255, (100, 240)).astype(np.float32)
    flat = np.full((100, 240), 20.0, np.float32)
    berry = _berry()
    both = _Cues(
        (textured, _shifted(textured, 31)), (textured, _shifted(textured, 31)), berry, RANGE
    )
    assert both.disparity() is not None and abs(both.disparity() - 31.0) < 0.2  # type: ignore[operator]
    # The outline flat (no unique match) and not contradicting: the shading's stands.
    shading_only = _Cues(
        (flat, _shifted(flat, 31)), (textured, _shifted(textured, 31)), berry, RANGE
    )
    assert shading_only.by_outline is None and shading_only.disparity() is not None
    # Both unique, 1.5 px apart: the shading's; 3 px apart: neither where another fruit
    # lies beside the berry (the outline may be on it), the outline's where none does.
    beside = [berry, _berry(x=140)]
    near = _Cues(
        (textured, _shifted(textured, 33)), (textured, _shifted(textured, 31)), berry, RANGE,
        beside,
    )  # fmt: skip
    near.by_outline = 32.5
    assert near.disparity() == near.by_shading
    near.by_outline = 34.5
    assert near.disparity() is None
    near.neighbours = []
    assert near.disparity() == 34.5
