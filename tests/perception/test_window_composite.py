"""C1's marker window as the arm drawn over the row kept from an earlier render
(softarm.sim.render.window_composite): the same pixels as the window drawn whole where
the arm casts no shadow, the arm's own pixels the same in the sun, and the kept row drawn
again whenever the harvest changes it (a leaf pushed, a berry picked)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import softarm
from softarm.sim.bush import Bush
from softarm.sim.render.labels import KINDS
from softarm.sim.render.row_look import RowLook
from softarm.sim.render.window_composite import (
    SHARE_STEPS,
    arm_casters,
    composite,
    quantised_share,
)

SEED = 4
SCALE = 0.5


def _world(look: str, shadows: bool = True) -> Any:
    """Row SEED at half scale (640 x 360), the arm reaching for its first berry."""
    from softarm.harvest.rigs.sim.options import default_cameras
    from softarm.sim.render import RenderUnavailableError
    from softarm.sim.render.world import RenderedBush, arm_sections
    from softarm.sim.rig_cameras import BASE_TAG_ID

    pytest.importorskip("mujoco")
    cams = default_cameras(scale=SCALE)
    arm = softarm.SoftArm.blackberry()
    bush = Bush.generate(arm, 6, SEED, view_point=cams.T_base_c1[:3, 3], unripe_fraction=0.4)
    try:
        world = RenderedBush(
            bush, cams.T_base_c1, cams.model(1), cams.model(2), cams.T_ee_c2, cams.T_ee_cube,
            cams.T_base_tag, BASE_TAG_ID, cams.base_tag, cams.cube_marker,
            RowLook.named(look, SEED), shadows=shadows, marker_body="frustum",
            composited_windows=True,
        )  # fmt: skip
    except RenderUnavailableError as exc:
        pytest.skip(str(exc))
    q = np.asarray(bush.berries[0].q) * 0.9
    world.set_arm(arm_sections(arm, q), arm.forward(q))
    return world


def _origin(world: Any, side: int) -> tuple[int, int]:
    """The top-left pixel of a ``side`` window centred on the marker body."""
    r = world.renderer
    cube = r.data.mocap_pos[r._mocap["arm_cube"]]
    c1 = r.cameras["c1_left"]
    x, y, z = (np.linalg.inv(c1.T_parent_camera) @ np.append(cube, 1.0))[:3]
    u, v = c1.focal * x / z + c1.principal[0], c1.focal * y / z + c1.principal[1]
    return int(u - side / 2), int(v - side / 2)


def _arm_pixels(world: Any, origin: tuple[int, int], side: int) -> np.ndarray:
    """The window's pixels of the arm, from the whole frame's geom ids."""
    geoms = world.renderer.render("c1_left", geoms=True).geoms
    x0, y0 = origin
    kinds = world.labels.kinds(geoms[y0 : y0 + side, x0 : x0 + side])
    result: np.ndarray = kinds == KINDS.index("arm")
    return result


def test_a_caster_is_a_sphere_on_the_arms_way_to_the_sun() -> None:
    travel = np.array([0.0, 0.0, -1.0])  # the sun overhead
    arm, arm_r = np.array([[0.0, 0.0, 0.0]]), np.array([0.05])
    centres = np.array([[0.0, 0.0, 0.5], [0.08, 0.0, 0.3], [0.2, 0.0, 0.3], [0.0, 0.0, -0.3]])
    radii = np.array([0.01, 0.04, 0.04, 0.1])
    # Above it, above and within the radii's sum, beside it, below it (no shadow up).
    np.testing.assert_array_equal(
        arm_casters(centres, radii, arm, arm_r, travel), [True, True, False, False]
    )


def test_the_arm_is_taken_where_it_lies_nearer() -> None:
    scene = (np.zeros((2, 2, 3), np.uint8), np.array([[1.0, 1.0], [0.5, 40.0]], np.float32))
    arm = (np.full((2, 2, 3), 200, np.uint8), np.array([[0.8, 0.9995], [0.6, 40.0]], np.float32))
    out = composite(scene, arm)
    # Nearer (taken), within the tolerance (the same surface), behind, both at the far plane.
    np.testing.assert_array_equal(out[..., 0], [[200, 0], [0, 0]])


def test_the_share_steps_down() -> None:
    assert quantised_share(1.0) == 1.0
    assert quantised_share(0.9999) == 1.0 - 1.0 / SHARE_STEPS
    assert quantised_share(0.5) == 0.5
    assert 0.82 - 1.0 / SHARE_STEPS < quantised_share(0.82) <= 0.82


def _same(a: np.ndarray, b: np.ndarray) -> None:
    """The same pixels but for a few on the edges of thin things (a pixel whose centre
    lies on a triangle's edge is rounded one way through the whole frame's projection,
    the other through the window's): at most 0.1 %."""
    assert a.shape == b.shape
    assert (np.abs(a.astype(int) - b.astype(int)).max(axis=2) > 0).mean() <= 0.001


def test_without_shadows_a_composited_window_is_the_whole_window() -> None:
    """Where the arm casts no shadow the two ways draw the same pixels, and a leaf pushed
    aside or a berry picked draws the kept row again."""
    world = _world("overcast", shadows=False)
    try:
        r, windows = world.renderer, world.windows
        assert windows is not None
        for side in (96, 160):
            origin = _origin(world, side)
            _same(windows.render(origin, side), r.render_window("c1_left", origin, side))
        assert windows.scene.drawn == 1  # one kept row for both
        world.remove_berry(world.bush.berries[0].tag_id)
        origin = _origin(world, 160)
        _same(windows.render(origin, 160), r.render_window("c1_left", origin, 160))
        assert windows.scene.drawn == 2
        leaf = r._leaves[0]
        r.push_leaves(r._leaf_home[:1], np.array([0.01]))  # the first leaf pushed
        assert np.allclose(r.model.geom_pos[leaf], (0.0, -50.0, 0.0))
        windows.render(origin, 160)
        assert windows.scene.drawn == 3
        assert windows.render((-10, 0), 96) is None  # past the frame: drawn whole instead
    finally:
        world.close()


@pytest.mark.parametrize("look", ["sun", "overcast"])
def test_in_the_sun_the_arm_is_drawn_as_before(look: str) -> None:
    """With the sun's shadows the arm's pixels (its shading, its own shadows and the
    row's on it) are the window's own; off the arm only the arm's shadow on the row and
    single pixels on the edges of the row's shadows (the kept frame's full shadow map
    against the window's small one) differ: under 1 % of the window (row seed 4, sun: 83
    pixels of 16,384, 40 of them darker in the window drawn whole)."""
    world = _world(look)
    try:
        r, windows = world.renderer, world.windows
        side = 128
        origin = _origin(world, side)
        whole = r.render_window("c1_left", origin, side).astype(int)
        mixed = windows.render(origin, side).astype(int)
        on_arm = _arm_pixels(world, origin, side)
        assert on_arm.mean() > 0.2  # the marker body fills much of it
        differ = np.abs(whole - mixed).max(axis=2) > 8
        assert (differ & on_arm).mean() < 0.002
        assert (differ & ~on_arm).mean() < 0.01
    finally:
        world.close()
