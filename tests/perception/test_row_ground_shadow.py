"""The row's ground plane is left out of the sun's depth pass
(softarm.sim.render.renderer.BushRenderer._draw): it lies below everything drawn and the
sun is above the horizon, so it shades nothing, and its own pixels are lit whether or
not it is in the map. Every pixel of a C2 frame, a C1 window and a whole C1 frame is the
same with it and without it, in the sun, against the light and at dusk."""

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
    categories = []
    made = r._renderer

    def spy(*args: Any) -> Any:  # the scene's category of the ground as it is drawn
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
        assert categories[-1] == [mujoco.mjtCatBit.mjCAT_DECOR], name
        kept, r._no_shadow = r._no_shadow, frozenset()
        r._last.__init__()
        try:
            with_ground = view()
        finally:
            r._no_shadow = kept
        np.testing.assert_array_equal(without, with_ground, err_msg=name)
