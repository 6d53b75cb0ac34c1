"""The fine-positioning bias trace (softarm.experiments.fine_bias): its ray crossing is
the harvest's (RayCrossing.fix) written in C1's frame, and a grasp's decomposition
and the pooled figures are what their definitions say."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from softarm.experiments.fine_bias import (
    SOURCES,
    Fix,
    cross_rays,
    decompose,
    pooled,
    summarise,
)
from softarm.perception.approach import RayCrossing
from softarm.perception.berries import BerryDetection
from softarm.sim.rig_cameras import look_at
from softarm.vision.camera_model import CameraModel


def _look_at(eye: np.ndarray, target: np.ndarray) -> np.ndarray:
    """A camera pose at ``eye`` looking at ``target``, image y along +z."""
    return look_at(eye, target, up=(0.0, 0.0, -1.0))


def test_two_rays_through_a_point_cross_at_it() -> None:
    berry = np.array([0.05, -0.02, 0.9])
    T_c1_c2 = _look_at(np.array([0.3, 0.1, 0.7]), berry)
    local = np.linalg.inv(T_c1_c2) @ np.append(berry, 1.0)
    p = cross_rays(berry / np.linalg.norm(berry), local[:3] / np.linalg.norm(local[:3]), T_c1_c2)
    assert p is not None
    np.testing.assert_allclose(p, local[:3], atol=1e-12)


def test_the_crossing_is_the_harvests_in_c1s_frame() -> None:
    camera = CameraModel.ideal(150.0, 320, 240)
    T_base_c1 = _look_at(np.array([0.7, -0.45, 0.55]), np.array([0.0, 0.25, 0.3]))
    mapped = np.array([0.02, 0.3, 0.32])  # C1's berry, a little off the true one
    T_base_c2 = _look_at(np.array([0.05, 0.22, 0.3]), np.array([0.021, 0.301, 0.318]))
    det = BerryDetection((163.2, 117.9), 20.0, (0, 0, 1, 1), np.ones((1, 1), bool), 1.0,
                         "ripe", 1.0)  # fmt: skip
    harvest = RayCrossing(T_base_c1[:3, 3], mapped, 0.01).fix(det, T_base_c2, camera)
    T_c1_base = np.linalg.inv(T_base_c1)
    c1_dir = T_c1_base[:3, :3] @ mapped + T_c1_base[:3, 3]
    x, y = camera.normalize(np.array([det.center]))[0]
    ray = np.array([x, y, 1.0]) / np.linalg.norm([x, y, 1.0])
    mine = cross_rays(c1_dir / np.linalg.norm(c1_dir), ray, T_c1_base @ T_base_c2)
    assert harvest is not None and mine is not None
    np.testing.assert_allclose(mine, harvest, atol=1e-12)


def test_the_crossing_from_the_baseline_middle_is_the_harvests() -> None:
    # The harvest's C1 ray starts at the stereo baseline's middle, 6 cm along C1's x.
    camera = CameraModel.ideal(150.0, 320, 240)
    T_base_c1 = _look_at(np.array([0.7, -0.45, 0.55]), np.array([0.0, 0.25, 0.3]))
    origin = (T_base_c1 @ np.array([0.06, 0.0, 0.0, 1.0]))[:3]
    mapped = np.array([0.02, 0.3, 0.32])
    T_base_c2 = _look_at(np.array([0.05, 0.22, 0.3]), np.array([0.021, 0.301, 0.318]))
    det = BerryDetection((163.2, 117.9), 20.0, (0, 0, 1, 1), np.ones((1, 1), bool), 1.0,
                         "ripe", 1.0)  # fmt: skip
    harvest = RayCrossing(origin, mapped, 0.01).fix(det, T_base_c2, camera)
    T_c1_base = np.linalg.inv(T_base_c1)
    o1 = np.array([0.06, 0.0, 0.0])
    c1_dir = T_c1_base[:3, :3] @ mapped + T_c1_base[:3, 3] - o1
    x, y = camera.normalize(np.array([det.center]))[0]
    ray = np.array([x, y, 1.0]) / np.linalg.norm([x, y, 1.0])
    mine = cross_rays(c1_dir / np.linalg.norm(c1_dir), ray, T_c1_base @ T_base_c2, o1)
    assert harvest is not None and mine is not None
    np.testing.assert_allclose(mine, harvest, atol=1e-12)
    # ...and not the crossing from C1's optical centre.
    left = cross_rays(c1_dir / np.linalg.norm(c1_dir), ray, T_c1_base @ T_base_c2)
    assert left is not None and np.linalg.norm(left - harvest) > 1e-4


def test_the_weighed_crossing_is_the_harvests() -> None:
    # With the rays' spreads the harvest's fix lies between them (RayCrossing.spreads).
    camera = CameraModel.ideal(150.0, 320, 240)
    T_base_c1 = _look_at(np.array([0.7, -0.45, 0.55]), np.array([0.0, 0.25, 0.3]))
    origin = (T_base_c1 @ np.array([0.06, 0.0, 0.0, 1.0]))[:3]
    mapped = np.array([0.02, 0.3, 0.32])
    T_base_c2 = _look_at(np.array([0.05, 0.22, 0.3]), np.array([0.021, 0.301, 0.318]))
    det = BerryDetection((163.2, 117.9), 20.0, (0, 0, 1, 1), np.ones((1, 1), bool), 1.0,
                         "ripe", 1.0)  # fmt: skip
    spreads = (1.5e-4, 0.35)
    harvest = RayCrossing(origin, mapped, 0.01, spreads=spreads).fix(det, T_base_c2, camera)
    T_c1_base = np.linalg.inv(T_base_c1)
    o1 = np.array([0.06, 0.0, 0.0])
    c1_dir = T_c1_base[:3, :3] @ mapped + T_c1_base[:3, 3] - o1
    x, y = camera.normalize(np.array([det.center]))[0]
    ray = np.array([x, y, 1.0]) / np.linalg.norm([x, y, 1.0])
    T_c1_c2 = T_c1_base @ T_base_c2
    rad = (spreads[0], spreads[1] / camera.focal)
    mine = cross_rays(c1_dir / np.linalg.norm(c1_dir), ray, T_c1_c2, o1, rad)
    plain = cross_rays(c1_dir / np.linalg.norm(c1_dir), ray, T_c1_c2, o1)
    assert harvest is not None and mine is not None and plain is not None
    np.testing.assert_allclose(mine, harvest, atol=1e-12)
    assert np.linalg.norm(mine - plain) > 1e-5  # off C2's ray


def test_parallel_rays_give_no_crossing() -> None:
    assert cross_rays(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]), np.eye(4)) is None


def _grasp(measured: list[float], truth: list[float], by: dict[str, list[float]]) -> Any:
    subsets = {"": measured, **by}
    fix = Fix(0.0, 1, np.array(measured), np.array(truth),
              {k: np.array(v) for k, v in subsets.items()}, 0.1)  # fmt: skip
    grasp = np.array([0.0, 0.0, 0.03])
    return {"berry": 1, "fixes_to": 1, "true_error": np.array(truth) - grasp + 1e-4,
            "recent": [fix], "grasp_point": grasp}  # fmt: skip


def test_a_grasp_is_split_by_source() -> None:
    truth = [0.0, 0.0, 0.0305]
    measured = [0.0, 0.0, 0.0300]  # 0.5 mm short along the approach
    by = {s: measured for s in SOURCES}
    by["c1_ray"] = truth  # C1's ray alone carries the bias
    by["c2_centre+cube"] = measured
    by["c1_ray+cube"] = by["c1_ray+c2_centre"] = truth
    by["cube_rotation"] = by["cube_position"] = measured
    d = decompose(_grasp(measured, truth, by))
    assert d is not None
    assert d["bias"]["axial"] == pytest.approx(0.5) and d["bias"]["lateral"] == 0.0
    assert d["left_when_true"]["c1_ray"]["norm"] == 0.0
    assert d["left_when_true"]["cube"]["norm"] == pytest.approx(0.5)
    assert d["carried_alone"]["c1_ray"]["norm"] == pytest.approx(0.5)
    assert d["carried_alone"]["c2_centre"]["norm"] == 0.0


def test_a_grasp_without_fixes_is_left_out() -> None:
    assert decompose({"recent": [], "true_error": np.zeros(3)}) is None


def test_the_pooled_figures() -> None:
    row = {"label": "after", "rule": "steps", "body": "cube", "seed": 1, "ripe": 3,
           "harvested": 2, "unripe_picked": 0, "contact_steps": 0, "total_s": 10.0,
           "survey_s": 2.0, "berry_s": [3.0, 4.0], "true_mm": [0.2, 0.7],
           "over_budget": 0, "grasps": []}  # fmt: skip
    f = pooled([row])
    assert f["s_per_berry"] == 5.0 and f["true_over_05"] == 1 and f["true_n"] == 2
    assert f["harvested"] == 2 and f["ripe"] == 3
    assert summarise([row]) == {"grasps": 0}


def test_the_residual_and_the_bias_are_split() -> None:
    # Two grasps, 0.6 mm true along the approach: one from a bias of 0.45 mm and a
    # residual of 0.15 mm (within 0.5 mm had it ended on the measured berry), one from
    # a bias of 0.6 mm (not: the bias alone is over 0.5 mm).
    def grasp(bias_mm: float) -> dict[str, Any]:
        return {"true_vec_mm": [0.0, 0.0, 0.6], "bias": {"vec": [0.0, 0.0, bias_mm]},
                "left_when_true": {s: {"vec": [0.0, 0.0, 0.0]} for s in SOURCES},
                "carried_alone": {s: {"vec": [0.0, 0.0, bias_mm]} for s in SOURCES},
                "c1_ray_px": 0.2}  # fmt: skip

    out = summarise([{"seed": 1, "grasps": [grasp(0.45), grasp(0.6)]}])
    assert out["true_within_0.5mm"] == 0
    assert out["without_residual"] == 1 and out["without_bias"] == 2
    assert out["residual_norm_median_mm"] == pytest.approx(0.075)
    assert out["c1_ray"]["within_0.5mm_when_true_without_residual"] == 2
