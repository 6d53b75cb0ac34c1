"""In the small renders (C2's frames, C1's windows: the small shadow map) the row's ground
plane is left out of the sun's depth pass (softarm.sim.render.renderer.BushRenderer._draw):
it lies below everything drawn and the sun is above the horizon, so it shades nothing.
Every pixel of a C2 frame and a C1 window is the same with it and without it, in the
sun, against the light and at dusk (where the small map holds what the render sees:
else the full map is drawn, the ground in it). Whole C1 frames keep it: there the polygon offset of
its depth darkens what lies within millimetres of it (the mulch's top), which the cane
fit reads."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

from row_world import sunlit_row_world

WINDOW_ORIGIN, WINDOW = (560, 260), 96


def _looked(name: str) -> Any:
    """The sunlit row's bush and arm in the look ``name`` (seed 4)."""
    import softarm
    from softarm.harvest.rigs.sim.options import default_cameras
    from softarm.sim.bush import Bush
    from softarm.sim.render.row_look import RowLook
    from softarm.sim.render.world import arm_sections, world_for
    from softarm.sim.rig_cameras import BASE_TAG_ID

    cams = default_cameras()
    arm = softarm.SoftArm.blackberry()
    bush = Bush.generate(arm, 6, 4, view_point=cams.T_base_c1[:3, 3], unripe_fraction=0.4)
    world = world_for(bush, cams, BASE_TAG_ID, RowLook.named(name, 4), 0.5)
    q = np.asarray(bush.berries[0].q) * 0.9
    world.set_arm(arm_sections(arm, q), arm.forward(q))
    return world


@pytest.fixture(scope="module", params=["sun", "backlight", "dusk"])
def row(request: pytest.FixtureRequest) -> Iterator[Any]:
    world = sunlit_row_world() if request.param == "sun" else _looked(request.param)
    yield world
    world.close()


def _views(r: Any) -> dict[str, Callable[[], np.ndarray]]:
    return {
        "c2": lambda: r.render("c2").colour,
        "window": lambda: r.render_window("c1_left", WINDOW_ORIGIN, WINDOW),
        "c1": lambda: r.render("c1_left").colour,
    }


def test_the_ground_casts_no_shadow_and_no_pixel_changes(row: Any) -> None:
    import mujoco

    r = row.renderer
    ground = r.model.geom("bg_ground").id
    assert r._no_shadow == {ground}
    categories, local = [], []
    made = r._renderer

    def spy(*args: Any) -> Any:  # the scene's category of the ground as it is drawn
        local.append(bool(args[1]) if len(args) > 1 else False)
        inner = made(*args)
        draw = inner.render

        def render(*a: Any, **k: Any) -> Any:
            scene = inner._scene
            cats = [scene.geoms[i].category for i in range(scene.ngeom)
                    if scene.geoms[i].objid == ground
                    and scene.geoms[i].objtype == int(mujoco.mjtObj.mjOBJ_GEOM)]  # fmt: skip
            categories.append(cats)
            return draw(*a, **k)

        inner.render = render
        return inner

    for name, view in _views(r).items():
        r._last.__init__()
        r._renderer = spy
        try:
            without = view()
        finally:
            r._renderer = made
            for ctx in r._renderers.values():
                ctx.__dict__.pop("render", None)
        decor = categories[-1] == [mujoco.mjtCatBit.mjCAT_DECOR]
        assert decor == local[-1], name  # with the small shadow map only
        assert not (name == "c1" and decor)  # whole C1 frames keep the ground in the map
        kept, r._no_shadow = r._no_shadow, frozenset()
        r._last.__init__()
        try:
            with_ground = view()
        finally:
            r._no_shadow = kept
        np.testing.assert_array_equal(without, with_ground, err_msg=name)
