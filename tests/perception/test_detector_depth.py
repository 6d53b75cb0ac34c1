"""Depth as a check on berry detections (softarm.perception.detector.depth_check) on
synthetic scenes: a berry-sized sphere at a berry's depth is kept; a stone-sized one, a
far one, a flat picture of a berry and a blob across a depth edge are dropped; bad depth
is a typed error naming it. And the network's stage rule: ripe by majority."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from detector_scenes import H, W, disc, draw, sphere_depth

from softarm.errors import InputError, VisionError
from softarm.experiments.detector_eval import candidates
from softarm.perception.berries import DetectorSettings, detect_berries
from softarm.perception.detector.choice import DETECTORS
from softarm.perception.detector.depth_check import (
    FRUIT_RADIUS_M,
    DepthCheck,
    metric_radius,
    rejection,
)
from softarm.perception.detector.instances import RIPE_SHARE, instance_stage
from softarm.vision.camera_model import CameraModel

FOCAL = 300.0
CAMERA = CameraModel.ideal(FOCAL, W, H)
CENTRE = (80, 60)


def _one_ripe(r_px: int) -> np.ndarray:
    return draw([("ripe", disc(*CENTRE, r_px))])


def _check(r_px: int, depth: np.ndarray, focal: float = FOCAL) -> str | None:
    mask = disc(*CENTRE, r_px)
    return rejection(mask, float(np.sqrt(mask.sum() / np.pi)), depth, focal, DepthCheck())


def test_a_berry_sized_sphere_at_a_berry_depth_is_kept_and_placed() -> None:
    # 12 px at 0.3 m through f = 300 px: a 12 mm fruit.
    depth = sphere_depth(*CENTRE, 12, 0.3, FOCAL)
    [det] = detect_berries(_one_ripe(12), CAMERA, depth)
    assert det.ripeness == "ripe" and det.position is not None
    assert det.position[2] == pytest.approx(0.31, abs=0.01)


def test_a_stone_sized_sphere_is_dropped() -> None:
    # 30 px at 0.3 m: a 3 cm stone, twice the largest fruit.
    depth = sphere_depth(*CENTRE, 30, 0.3, FOCAL)
    assert _check(30, depth) == "size"
    assert detect_berries(_one_ripe(30), CAMERA, depth) == []


def test_a_speck_too_small_for_a_fruit_is_dropped() -> None:
    # 6 px at 0.2 m: a 4 mm speck, smaller than half of the smallest fruit.
    depth = sphere_depth(*CENTRE, 6, 0.2, FOCAL)
    assert _check(6, depth) == "size"


def test_a_berry_sized_sphere_beyond_the_working_range_is_dropped() -> None:
    # Through a long lens (f = 3000 px) 9 px at 4 m is a 12 mm fruit, but 4 m away.
    camera = CameraModel.ideal(3000.0, W, H)
    depth = sphere_depth(*CENTRE, 9, 4.0, 3000.0)
    assert _check(9, depth, 3000.0) == "range"
    assert detect_berries(_one_ripe(9), camera, depth) == []
    near = sphere_depth(*CENTRE, 9, 1.5, 3000.0)  # 4.5 mm at 1.5 m: in range, too small
    assert _check(9, near, 3000.0) == "size"


def test_a_flat_picture_of_a_berry_is_dropped() -> None:
    # A fruit-sized disc on a tilted flat board: the hedge's face, a berry's photo.
    yy, xx = np.mgrid[:H, :W]
    board = 0.3 + 0.001 * (xx - CENTRE[0]) + 0.0005 * (yy - CENTRE[1])
    assert _check(12, board) == "sphere"
    assert detect_berries(_one_ripe(12), CAMERA, board) == []
    relaxed = DetectorSettings(depth_check=DepthCheck(min_relief=0.0))
    assert len(detect_berries(_one_ripe(12), CAMERA, board, relaxed)) == 1


def test_a_blob_across_a_depth_edge_is_dropped() -> None:
    # A dark blob over three things at three depths (a leaf in front, a fruit-sized
    # bump, the ground behind), none of them half of it: no one surface is a fruit's.
    depth = sphere_depth(*CENTRE, 12, 0.3, FOCAL)
    depth[:, : CENTRE[0] - 4] = 0.25
    depth[:, CENTRE[0] + 4 :] = 0.5
    assert _check(12, depth) == "sphere"


def test_unknown_depth_keeps_the_detection_without_a_position() -> None:
    depth = np.full((H, W), np.nan)
    depth[0, :3] = (0.0, np.inf, -np.inf)  # ROS REP 118: unknown, too far, too near
    [det] = detect_berries(_one_ripe(12), CAMERA, depth)
    assert det.position is None


@pytest.mark.parametrize(
    "depth",
    [np.ones((H, W + 1)), np.ones((H, W, 1)), -np.ones((H, W)), np.ones((H, W), np.int64)],
    ids=["wider", "three axes", "negative", "integer"],
)
def test_bad_depth_is_a_vision_error_naming_depth(depth: np.ndarray) -> None:
    with pytest.raises(VisionError, match="depth"):
        detect_berries(_one_ripe(12), CAMERA, depth)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"fruit_radius_m": (0.02, 0.01)},
        {"range_m": (np.nan, 3.0)},
        {"outline_px": -1.0},
        {"sphere_share": 1.5},
        {"min_relief": -0.1},
    ],
)
def test_bad_depth_check_settings_are_an_input_error_naming_them(kwargs: dict[str, Any]) -> None:
    with pytest.raises(InputError, match=next(iter(kwargs))):
        DepthCheck(**kwargs)


def test_metric_radius_is_exact_for_a_sphere_on_the_axis() -> None:
    # A 12 mm sphere whose near surface is 6 cm away: its outline's half-angle.
    radius, surface = 0.012, 0.06
    r_px = FOCAL * np.tan(np.arcsin(radius / (surface + radius)))
    assert metric_radius(r_px, surface, FOCAL) == pytest.approx(radius, rel=1e-9)


def test_the_fruit_size_is_the_renderer_fruit_size() -> None:
    from softarm.sim.render.mjcf import BERRY_HALF
    from softarm.sim.render.row_mjcf import FRUIT_BINS

    # Drupelets: centres at 0.85-0.86 of the half-size, radius 0.32-0.34 of the
    # half-width (mjcf._berry, row_mjcf._drupelet_meshes); scales 0.8-1.15.
    smallest = FRUIT_BINS.min() * BERRY_HALF[0] * (0.86 + 0.32)
    largest = FRUIT_BINS.max() * (0.85 * BERRY_HALF[2] + 0.34 * BERRY_HALF[0])
    assert FRUIT_RADIUS_M == pytest.approx((smallest, largest), abs=1e-5)


def test_ripe_needs_the_majority_of_the_stage_mass() -> None:
    # The plurality would call this ripe: turning and unripe split the rest.
    stage, p_ripe = instance_stage(np.array([0.45, 0.35, 0.20]))
    assert stage == "turning" and p_ripe == pytest.approx(0.45)
    assert instance_stage(np.array([0.45, 0.15, 0.40]))[0] == "unripe"
    assert instance_stage(np.array([RIPE_SHARE, 0.2, 0.2]) / (RIPE_SHARE + 0.4))[0] == "ripe"


def test_the_candidates_are_each_detector_and_two_given_depth() -> None:
    names = list(candidates())
    assert names == [*DETECTORS, "colour+depth", "net+colour+depth"]
    assert [with_depth for _, with_depth in candidates().values()] == [False] * 3 + [True] * 2


def test_a_candidate_network_is_scored_beside_the_shipped_one() -> None:
    from softarm.perception.detector.learned import LearnedDetector
    from softarm.perception.detector.network import DEFAULT_WEIGHTS

    cands = candidates(DEFAULT_WEIGHTS, 1280)
    assert list(cands) == [
        *DETECTORS, "cand", "cand+colour", "colour+depth", "net+colour+depth",
        "cand+colour+depth",
    ]  # fmt: skip
    cand, with_depth = cands["cand"]
    assert isinstance(cand, LearnedDetector) and cand.network.max_side == 1280 and not with_depth
    assert cands["cand+colour+depth"] == (cands["cand+colour"][0], True)


@pytest.mark.parametrize("extra", [["--max-side", "4"], ["--max-side", "x"], []])
def test_bad_evaluation_arguments_are_one_usage_line(
    capsys: pytest.CaptureFixture[str], extra: list[str]
) -> None:
    from softarm.experiments.detector_eval import main

    args = ["sun"] if not extra else ["sun=somewhere", *extra]
    with pytest.raises(SystemExit) as exit_info:
        main(args)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert "error:" in err[-1] and "Traceback" not in "\n".join(err)
