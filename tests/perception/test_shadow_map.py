"""The small shadow map of a small render (softarm.sim.render.shadow_map): its texels are
the full map's, it holds what the render sees, and a C2 frame or a C1 window drawn
with it is the one drawn with the full map but for single pixels on shadow edges."""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np
import pytest

import softarm
from softarm.sim.bush import Bush
from softarm.sim.render.shadow_map import (
    LOCAL_SIZE,
    RIM_TEXELS,
    LightFrame,
    local_clip,
    local_light_position,
)

SUN = np.array([-0.3, 0.5, -0.8])
FULL_CLIP, FULL_SIZE = 1.92, 2048


def _frame(direction: np.ndarray = SUN) -> LightFrame:
    return LightFrame.of(direction, FULL_CLIP, FULL_SIZE)


@pytest.mark.parametrize("direction", [SUN, np.array([-1.0, 0.0, -0.01])])
def test_the_light_frame_is_mujocos(direction: np.ndarray) -> None:
    # mjr_lookAt: side = f x up0, up = side x f, up0 = f x (-1, 0, 0) unless that is
    # short (a light along x), then f x (0, 1, 0).
    f = direction / np.linalg.norm(direction)
    frame = _frame(direction)
    basis = np.vstack([frame.side, frame.up, f])
    np.testing.assert_allclose(basis @ basis.T, np.eye(3), atol=1e-12)
    assert np.dot(np.cross(frame.side, frame.up), -f) == pytest.approx(1.0)  # right-handed
    assert frame.pitch == pytest.approx(2 * FULL_CLIP / (FULL_SIZE - 2))
    assert local_clip(frame) == pytest.approx(frame.pitch * (LOCAL_SIZE - 2) / 2)


def test_the_light_moves_across_the_sunlight_by_whole_texels() -> None:
    frame = _frame()
    light = np.array([1.0, -2.0, 5.0])
    rng = np.random.default_rng(3)
    centres = light + 6.0 * SUN / np.linalg.norm(SUN) + rng.uniform(-0.3, 0.3, (20, 3))
    moved = local_light_position(frame, light, centres, np.full(20, 0.02))
    assert moved is not None
    shift = moved - light
    f = SUN / np.linalg.norm(SUN)
    assert abs(shift @ f) < 1e-12  # the depths from the light stay as they were
    for axis in (frame.side, frame.up):
        steps = (shift @ axis) / frame.pitch
        assert steps == pytest.approx(round(steps), abs=1e-9)
    # Every sphere is inside the small map, RIM_TEXELS to spare.
    offset = (centres - moved) @ np.vstack([frame.side, frame.up]).T
    half = local_clip(frame) - RIM_TEXELS * frame.pitch
    assert (np.abs(offset) + 0.02 <= half + frame.pitch).all()


def test_spheres_too_far_apart_take_the_full_map_and_those_outside_it_do_not_count() -> None:
    frame = _frame()
    light = np.zeros(3)
    across = frame.side
    apart = np.vstack([-0.7 * across, 0.7 * across])  # 1.4 m apart plus the radii
    assert local_light_position(frame, light, apart, np.full(2, 0.3)) is None
    outside = np.vstack([0.1 * across, 5.0 * across])  # beyond the full map's 1.92 m
    moved = local_light_position(frame, light, outside, np.full(2, 0.05))
    assert moved is not None
    assert np.linalg.norm(moved - light) < 0.2
    nothing = local_light_position(frame, light, np.zeros((0, 3)), np.zeros(0))
    assert nothing is not None and np.array_equal(nothing, light)


def _row_world() -> Any:
    from softarm.harvest.rigs.sim.rig import default_cameras
    from softarm.sim.render import RenderUnavailableError
    from softarm.sim.render.row_look import RowLook
    from softarm.sim.render.world import RenderedBush
    from softarm.sim.rig_cameras import BASE_TAG_ID

    pytest.importorskip("mujoco")
    cams = default_cameras(scale=0.25)
    bush = Bush.generate(
        softarm.SoftArm.blackberry(), 6, 4, view_point=cams.T_base_c1[:3, 3],
        unripe_fraction=0.4,
    )  # fmt: skip
    try:
        return RenderedBush(
            bush, cams.T_base_c1, cams.model(1), cams.model(2), cams.T_ee_c2, cams.T_ee_cube,
            cams.T_base_tag, BASE_TAG_ID, cams.base_tag, cams.cube_marker,
            RowLook.named("sun", 4),
        )  # fmt: skip
    except RenderUnavailableError as exc:
        pytest.skip(str(exc))


def _edges_only(small: np.ndarray, full: np.ndarray) -> None:
    """The two renders are the same but for scattered pixels on shadows' edges (the
    maps' float arithmetic differs in the last bits: a texel on an edge may flip): no
    3 x 3 patch differs anywhere, no region is shaded otherwise."""
    differs = (np.abs(small.astype(int) - full.astype(int)).max(axis=2) > 8).astype(np.uint8)
    assert differs.mean() < 0.025, differs.mean()
    assert not cv2.erode(differs, np.ones((3, 3), np.uint8)).any()


def test_small_renders_with_the_small_map_are_those_with_the_full_one() -> None:
    from softarm.sim.render.world import arm_sections

    world = _row_world()
    renderer = world.renderer
    try:
        arm = softarm.SoftArm.blackberry()
        q = np.asarray(world.bush.berries[0].q) * 0.9
        world.set_arm(arm_sections(arm, q), arm.forward(q))
        used = []
        place = renderer._sun.place
        renderer._sun.place = lambda *a: used.append(place(*a)) or used[-1]
        small_c2 = renderer.render("c2").colour
        small_windows = [
            renderer.render_window("c1_left", origin, 64)
            for origin in ((20, 30), (150, 100), (250, 10))
        ]
        assert all(used), used  # each took the small map
        # The sun is put back where it is (a worldbody light: at its model position).
        np.testing.assert_allclose(renderer.data.light_xpos, renderer.model.light_pos)
        renderer._sun.place = lambda *a: False  # the full map
        _edges_only(small_c2, renderer.render("c2").colour)
        for origin, small in zip(((20, 30), (150, 100), (250, 10)), small_windows, strict=True):
            _edges_only(small, renderer.render_window("c1_left", origin, 64))
    finally:
        world.close()
