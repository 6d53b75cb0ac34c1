"""The cane fit's loss chain (softarm.experiments.cane_losses) on a synthetic scene whose
every stage is known: one straight cane 0.8 m in front of C1, cut a little more at each
stage (hidden in one eye, out of the mask, unmatched, placed, fitted)."""

from __future__ import annotations

import numpy as np
import pytest

from softarm._core import PolynomialCurve
from softarm.experiments.cane_losses import STAGES, LossViews, loss_chain, summarise
from softarm.perception.cane_metrics import cane_map_error
from softarm.perception.canes import CaneFit
from softarm.vision.stereo_camera import StereoCamera

DEPTH = 0.8  # m: the cane's distance from C1 (whose left eye is the base here)


class _Cane:
    """A straight cane x = 0, z = DEPTH from y = ``y0`` to ``y1`` (m)."""

    def __init__(self, y0: float, y1: float, z: float = DEPTH) -> None:
        self.coeffs = np.array([[0.0, 0, 0, 0], [y0, y1 - y0, 0, 0], [z, 0, 0, 0]])


def _row(y: float) -> int:
    """The image row of height ``y`` (m) on the cane (f = 900 px, centre row 240)."""
    return round(240 + 900 * y / DEPTH)


def _views(stereo: StereoCamera) -> LossViews:
    shape = (480, 640)
    left_ids = np.full(shape, -1, np.int32)
    left_ids[: _row(0.08), 318:323] = 0
    left_ids[_row(0.08) :, 318:323] = 1  # past y = 8 cm another cane (id 1) is in front
    right_ids = np.full(shape, -1, np.int32)
    d = 900 * 0.12 / DEPTH  # the disparity, 135 px
    right_ids[: _row(0.0), int(320 - d) - 2 : int(320 - d) + 3] = 0
    mask = np.zeros(shape, bool)
    mask[: _row(-0.04), 318:323] = True
    disparity = np.full(shape, np.nan, np.float32)
    disparity[: _row(-0.06), 318:323] = d
    y = np.arange(-0.1, -0.0705, 0.001)  # placed right up to y = -0.07: covers to -0.06
    right = np.column_stack([np.zeros_like(y), y, np.full_like(y, DEPTH), np.full_like(y, 0.003)])
    wrong = right.copy()
    wrong[:, 2] += 0.1  # placed 10 cm too far: covers nothing
    placed = np.vstack([right, wrong])
    line = _Cane(-0.1, -0.095).coeffs
    fit = CaneFit(PolynomialCurve(line, (0.0, 1.0)), line, 0.003, right[:10, :3], 10)
    return LossViews(stereo, left_ids, right_ids, mask, disparity, placed, right[::10], [fit])


def test_each_stage_keeps_what_the_one_before_kept_and_its_own_share(
    stereo: StereoCamera,
) -> None:
    chain = loss_chain([_Cane(-0.1, 0.1)], _views(stereo), workspace=1.0)
    expected = {
        "workspace": 0.2, "in_view": 0.2, "left": 0.18, "both": 0.1, "mask": 0.06,
        "matched": 0.04, "placed": 0.04, "budget": 0.03, "fitted": 0.015,
    }  # fmt: skip
    assert list(chain)[: len(STAGES)] == list(STAGES)
    for stage, metres in expected.items():
        assert chain[stage] == pytest.approx(metres, abs=0.0025), stage


def test_the_unchained_coverage_is_the_cane_maps(stereo: StereoCamera) -> None:
    views = _views(stereo)
    canes = [_Cane(-0.1, 0.1)]
    chain = loss_chain(canes, views, workspace=1.0)
    assert chain["coverage_all"] == pytest.approx(
        cane_map_error(views.fits, canes, workspace=1.0)["coverage"], abs=0.01
    )


def test_a_cane_out_of_the_frames_or_the_depth_range_is_not_in_view(
    stereo: StereoCamera,
) -> None:
    near = _Cane(-0.1, 0.1, z=0.3)  # nearer than the stereo's 0.6 m
    aside = np.array([[2.0, 0, 0, 0], [-0.1, 0.2, 0, 0], [DEPTH, 0, 0, 0]])
    canes = [near, type("C", (), {"coeffs": aside})()]
    chain = loss_chain(canes, _views(stereo), workspace=3.0)
    assert chain["workspace"] == pytest.approx(0.4, abs=0.003) and chain["in_view"] == 0.0


def test_the_summary_pools_metres_and_shares_over_scenes() -> None:
    rows = [
        {"condition": "sun", "source": "net", "settings": "default", "seed": s,
         **{k: m * v for k, v in zip(STAGES, np.linspace(1.0, 0.2, len(STAGES)), strict=True)},
         "coverage_all": 0.3}
        for s, m in ((1, 1.0), (2, 3.0))
    ]  # fmt: skip
    (row,) = summarise(rows)
    assert row["metres"]["workspace"] == 4.0 and row["share"]["fitted"] == 0.2
    assert row["coverage_all"] == 0.3 and row["seeds"] == [1, 2] and row["scenes"] == 2
