"""Perception speed on one core: the stereo berry perception on one C1 frame pair
(rectify both eyes, detect, match, triangulate; target ≤ 50 ms) and detection alone on
a C2 frame (target ≤ 10 ms), on rendered bushes; the renderer's own stereo frame beside
them (not part of the perception budget)."""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import pytest

sys.path.insert(0, str(Path(__file__).parent.parent / "perception"))
from perception_world import rendered_world

from softarm.perception.berries import detect_berries
from softarm.perception.stereo import locate_berries

cv2.setNumThreads(1)  # one core, as the targets are stated


@pytest.fixture(scope="module")
def world():  # type: ignore[no-untyped-def]
    w = rendered_world(310)
    yield w
    w.close()


def test_stereo_berries_per_c1_frame(benchmark, world) -> None:  # type: ignore[no-untyped-def]
    left, right = world.c1()
    _ = world.stereo.rectification  # built once per camera, not per frame
    benchmark(locate_berries, left.colour, right.colour, world.stereo)


def test_berries_per_c2_frame(benchmark, world) -> None:  # type: ignore[no-untyped-def]
    berry = world.bush.berries[0]
    import softarm
    from softarm.sim.render.world import arm_sections

    arm = softarm.SoftArm.blackberry()
    q = berry.q * 0.97
    world.set_arm(arm_sections(arm, q), arm.forward(q))
    frame = world.c2_frame().colour
    benchmark(detect_berries, frame, world.c2)


def test_render_c1_stereo_pair(benchmark, world) -> None:  # type: ignore[no-untyped-def]
    world.hide_arm()
    benchmark.pedantic(world.c1, rounds=5, iterations=1)


def _arm_at_a_berry(world):  # type: ignore[no-untyped-def]
    """The arm 3 % short of the first berry's grasp, where fine positioning renders."""
    import softarm
    from softarm.sim.render.world import arm_sections

    arm = softarm.SoftArm.blackberry()
    q = world.bush.berries[0].q * 0.97
    T_base_ee = arm.forward(q)
    world.set_arm(arm_sections(arm, q), T_base_ee)
    return T_base_ee


def test_render_cube_window(benchmark, world) -> None:  # type: ignore[no-untyped-def]
    """The C1 window the cube is tracked in, once per control period."""
    T_base_cube = _arm_at_a_berry(world) @ world.T_ee_cube
    world.cube_window(T_base_cube)  # its renderer made
    benchmark(world.cube_window, T_base_cube)


def test_render_c2_frame(benchmark) -> None:  # type: ignore[no-untyped-def]
    """C2's frame at 320 x 240, as the harvest renders it, once per control period
    near the berry."""
    from softarm.harvest.rigs.sim.worlds import C2_SCALE

    world = rendered_world(310, c2_scale=C2_SCALE)
    _arm_at_a_berry(world)
    benchmark(world.c2_frame)
    world.close()
