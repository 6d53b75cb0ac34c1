"""The row's small renders (C2, C1's windows) draw the ground plane as a few large quads
(softarm.sim.render.renderer.SMALL_RENDER_GROUND_GRID), a whole C1 frame as MuJoCo's
finest grid (row_mjcf.GROUND_GRID): MuJoCo makes a plane's quads when it makes the
context, and draws them in each of a shadowed render's three passes. The row's lights
are directional, so the small renders are the same, pixel for pixel."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from row_world import sunlit_row_world

#: MuJoCo's most grid lines a side of a drawn plane (mjMAXPLANEGRID).
MAX_PLANE_GRID = 200


def _quads_a_side(half_size: float, pitch: float) -> int:
    """The quads along one side of a drawn plane of ``half_size`` (m) and grid ``pitch``,
    as MuJoCo counts them (makePlane in render_context.c)."""
    step = max(pitch, half_size / (MAX_PLANE_GRID - 2))
    n = int(np.floor(half_size / step))
    return n - n % 2 + 2


def test_small_renders_draw_a_few_quads_of_ground_and_whole_frames_the_finest() -> None:
    import mujoco

    from softarm.sim.render.shadow_map import LOCAL_SIZE

    world = sunlit_row_world()
    renderer = world.renderer
    m = renderer.model
    ground = m.geom("bg_ground").id
    half = float(m.geom_size[ground, 0])
    made = []  # (small shadow map, ground quads a side) of each context made

    def spy(model: Any, h: int, w: int) -> Any:
        small = int(model.vis.quality.shadowsize) == LOCAL_SIZE
        made.append((small, _quads_a_side(half, float(model.geom_size[ground, 2]))))
        return mujoco.Renderer(model, h, w)

    renderer._mj = _WithRenderer(mujoco, spy)
    try:
        renderer.render("c2")
        renderer.render("c1_left")
    finally:
        renderer._mj = mujoco
        world.close()
    assert sorted(made) == [(False, MAX_PLANE_GRID), (True, 12)], made
    assert _quads_a_side(half, float(m.geom_size[ground, 2])) == MAX_PLANE_GRID  # kept


class _WithRenderer:
    """The ``mujoco`` module with its ``Renderer`` replaced."""

    def __init__(self, module: Any, renderer: Any) -> None:
        self._module, self.Renderer = module, renderer

    def __getattr__(self, name: str) -> Any:
        return getattr(self._module, name)


def test_small_renders_are_those_of_the_finest_grid(monkeypatch: pytest.MonkeyPatch) -> None:
    from softarm.sim.render import renderer as module

    windows = ((560, 260), (900, 120))
    coarse = sunlit_row_world()
    try:
        c2 = coarse.renderer.render("c2").colour
        small = [coarse.renderer.render_window("c1_left", o, 96) for o in windows]
    finally:
        coarse.close()
    monkeypatch.setattr(module, "SMALL_RENDER_GROUND_GRID", 0.1)  # read as a context is made
    fine = sunlit_row_world()
    try:
        np.testing.assert_array_equal(c2, fine.renderer.render("c2").colour)
        for origin, window in zip(windows, small, strict=True):
            np.testing.assert_array_equal(
                window, fine.renderer.render_window("c1_left", origin, 96)
            )
    finally:
        fine.close()
