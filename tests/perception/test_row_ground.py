"""The row's ground plane is drawn as a few large quads (softarm.sim.render.row_mjcf.
GROUND_GRID): MuJoCo draws a plane as a grid of quads in each of a shadowed render's
three passes, and the row's lights are directional, so the grid's pitch changes no lit
colour: the small renders the harvest draws are the same, pixel for pixel."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import softarm
from softarm.sim.bush import Bush

#: MuJoCo's most grid lines a side of a drawn plane (mjMAXPLANEGRID).
MAX_PLANE_GRID = 200


def _quads_a_side(half_size: float, pitch: float) -> int:
    """The quads along one side of a drawn plane of ``half_size`` (m) and grid ``pitch``,
    as MuJoCo counts them (makePlane in render_context.c)."""
    step = max(pitch, half_size / (MAX_PLANE_GRID - 2))
    n = int(np.floor(half_size / step))
    return n - n % 2 + 2


def _row_world(grid: float | None = None) -> Any:
    from softarm.harvest.rigs.sim.options import default_cameras
    from softarm.sim.render import RenderUnavailableError, row_mjcf
    from softarm.sim.render.row_look import RowLook
    from softarm.sim.render.world import arm_sections, world_for
    from softarm.sim.rig_cameras import BASE_TAG_ID

    pytest.importorskip("mujoco")
    cams = default_cameras()  # the harvest's: C2 at half scale, 320 x 240
    arm = softarm.SoftArm.blackberry()
    bush = Bush.generate(arm, 6, 4, view_point=cams.T_base_c1[:3, 3], unripe_fraction=0.4)
    kept = row_mjcf.GROUND_GRID
    row_mjcf.GROUND_GRID = kept if grid is None else grid
    try:
        world = world_for(bush, cams, BASE_TAG_ID, RowLook.named("sun", 4), 0.5)
    except RenderUnavailableError as exc:
        pytest.skip(str(exc))
    finally:
        row_mjcf.GROUND_GRID = kept
    q = np.asarray(bush.berries[0].q) * 0.9
    world.set_arm(arm_sections(arm, q), arm.forward(q))
    return world


def test_the_ground_is_a_few_quads_not_mujocos_finest_grid() -> None:
    world = _row_world()
    try:
        m = world.renderer.model
        ground = m.geom("bg_ground").id
        half = float(m.geom_size[ground, 0])
        assert _quads_a_side(half, float(m.geom_size[ground, 2])) <= 16
        assert _quads_a_side(half, 0.1) == MAX_PLANE_GRID  # the pitch it was drawn at
    finally:
        world.close()


def test_small_renders_are_those_of_the_fine_grid() -> None:
    coarse, fine = _row_world(), _row_world(grid=0.1)
    try:
        np.testing.assert_array_equal(
            coarse.renderer.render("c2").colour, fine.renderer.render("c2").colour
        )
        for origin in ((560, 260), (900, 120)):
            np.testing.assert_array_equal(
                coarse.renderer.render_window("c1_left", origin, 96),
                fine.renderer.render_window("c1_left", origin, 96),
            )
    finally:
        coarse.close()
        fine.close()
