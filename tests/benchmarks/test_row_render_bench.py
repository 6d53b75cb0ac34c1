"""What a small render of the daylight row costs (issue 37 item 6): C2's frame (at the
harvest's half scale) and a 184-pixel window of C1's left eye around the marker cube,
the arm reaching for a berry, drawn with the small shadow map (the harvest's way) and
with the full one, on the same world; with the small map on the same row whose
small renders draw the ground on MuJoCo's finest grid (200 x 200 quads, as before
renderer.SMALL_RENDER_GROUND_GRID); with the small map on the same world drawing
the bush's canes as their capsules (as before softarm.sim.render.cane_mesh); and with
the ground plane in the sun's depth pass (as before renderer.BushRenderer._draw); and
the window as the arm drawn over the row kept from one whole render
(softarm.sim.render.window_composite, off in the harvest)."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

import softarm
from softarm.sim.bush import Bush

SEED = 4
WINDOW = 184


def _row() -> Any:
    """The row of SEED with the arm reaching for its first berry."""
    pytest.importorskip("mujoco")
    from softarm.harvest.rigs.sim.options import default_cameras
    from softarm.sim.render import RenderUnavailableError
    from softarm.sim.render.row_look import RowLook
    from softarm.sim.render.world import arm_sections, world_for
    from softarm.sim.rig_cameras import BASE_TAG_ID

    cams = default_cameras()
    arm = softarm.SoftArm.blackberry()
    bush = Bush.generate(arm, 6, SEED, view_point=cams.T_base_c1[:3, 3], unripe_fraction=0.3)
    try:
        world = world_for(bush, cams, BASE_TAG_ID, RowLook.named("overcast", SEED), 0.5)
    except RenderUnavailableError as exc:
        pytest.skip(str(exc))
    q = np.asarray(bush.berries[0].q) * 0.9
    world.set_arm(arm_sections(arm, q), arm.forward(q))
    return world


@pytest.fixture(scope="module")
def row() -> Iterator[Any]:
    world = _row()
    yield world
    world.close()


@pytest.fixture(scope="module")
def fine_ground_row() -> Iterator[Any]:
    """The row whose small renders' context draws the ground on MuJoCo's finest grid
    (the grid is made with the context: both are made here, then the setting restored)."""
    from softarm.sim.render import renderer as module

    world = _row()
    kept = module.SMALL_RENDER_GROUND_GRID
    module.SMALL_RENDER_GROUND_GRID = 0.1
    try:
        world.renderer.render("c2")
        world.renderer.render_window("c1_left", _window_origin(world), WINDOW)
    finally:
        module.SMALL_RENDER_GROUND_GRID = kept
    yield world
    world.close()


def _anew(renderer: Any) -> Any:
    """``renderer`` with no render kept: the same scene is drawn again, not handed back
    (softarm.sim.render.last_render)."""
    from softarm.sim.render.last_render import LastRender

    renderer._last = LastRender()
    return renderer


def _window_origin(world: Any) -> tuple[int, int]:
    """The top-left pixel of the window centred on the marker cube (placed by set_arm)."""
    renderer = world.renderer
    cube = renderer.data.mocap_pos[renderer._mocap["arm_cube"]]
    c1 = renderer.cameras["c1_left"]
    x, y, z = (np.linalg.inv(c1.T_parent_camera) @ np.append(cube, 1.0))[:3]
    u, v = c1.focal * x / z + c1.principal[0], c1.focal * y / z + c1.principal[1]
    return int(u - WINDOW / 2), int(v - WINDOW / 2)


def _timed(benchmark: Any, row: Any, view: str) -> Any:
    """``view`` of ``row`` (C2's frame or C1's window at the berry) drawn anew each round."""
    renderer = row.renderer
    if view == "c2":
        return benchmark(lambda: _anew(renderer).render("c2").colour)
    origin = _window_origin(row)
    return benchmark(lambda: _anew(renderer).render_window("c1_left", origin, WINDOW))


@pytest.mark.parametrize("shadow_map", ["small", "full"])
@pytest.mark.parametrize("view", ["c2", "c1_window"])
def test_row_small_render(benchmark, row: Any, view: str, shadow_map: str) -> None:  # type: ignore[no-untyped-def]
    renderer = row.renderer
    place = renderer._sun.place
    if shadow_map == "full":
        renderer._sun.place = lambda *a: False
    try:
        image = _timed(benchmark, row, view)
    finally:
        renderer._sun.place = place
    assert image.ndim == 3


@pytest.mark.parametrize("view", ["c2", "c1_window"])
def test_row_small_render_fine_ground(benchmark, fine_ground_row: Any, view: str) -> None:  # type: ignore[no-untyped-def]
    assert _timed(benchmark, fine_ground_row, view).ndim == 3


@pytest.mark.parametrize("view", ["c2", "c1_window"])
def test_row_small_render_capsule_canes(benchmark, row: Any, view: str) -> None:  # type: ignore[no-untyped-def]
    renderer = row.renderer
    kept = renderer._merged, renderer._members
    renderer._merged = renderer._members = np.zeros(0, np.int64)  # the capsules drawn
    try:
        image = _timed(benchmark, row, view)
    finally:
        renderer._merged, renderer._members = kept
    assert image.ndim == 3


@pytest.mark.parametrize("view", ["c2", "c1_window"])
def test_row_small_render_ground_casting(benchmark, row: Any, view: str) -> None:  # type: ignore[no-untyped-def]
    renderer = row.renderer
    kept = renderer._no_shadow
    renderer._no_shadow = frozenset()  # the ground drawn into the sun's depth map
    try:
        image = _timed(benchmark, row, view)
    finally:
        renderer._no_shadow = kept
    assert image.ndim == 3


@pytest.mark.parametrize("view", ["c2", "c1_window"])
def test_row_small_render_stepped_casters(benchmark, row: Any, view: str) -> None:  # type: ignore[no-untyped-def]
    from row_world import stepped_casters
    from softarm.sim.render import renderer

    module: Any = renderer  # its shadow_casters swapped for the sweep as spheres
    chosen = module.shadow_casters
    module.shadow_casters = stepped_casters
    try:
        image = _timed(benchmark, row, view)
    finally:
        module.shadow_casters = chosen
    assert image.ndim == 3


def test_row_composited_window(benchmark, row: Any) -> None:  # type: ignore[no-untyped-def]
    """The C1 window as the arm drawn over the row kept from one whole render
    (softarm.sim.render.window_composite, off in the harvest), the kept row drawn once
    before the rounds; against ``test_row_small_render[c1_window-small]``, the window
    drawn whole."""
    from softarm.sim.render.window_composite import CompositedWindows

    windows = CompositedWindows(row.renderer)
    origin = _window_origin(row)
    windows.render(origin, WINDOW)  # the row kept
    image = benchmark(lambda: (_anew(row.renderer), windows.render(origin, WINDOW))[1])
    assert image is not None and image.ndim == 3 and windows.scene.drawn == 1
