"""The geoms drawn for their shadow alone (softarm.sim.render.shadow_casters): a
sweep along the sunlight that meets the picture only below the ground, or passes it,
is left out, and the row's renders are the same pixel for pixel with fewer geoms drawn
than the sweep as spheres 0.25 m apart drew."""

from __future__ import annotations

from typing import Any

import numpy as np

from softarm.sim.render.shadow_casters import shadow_casters

# A camera 2 m above the ground looking straight down: MuJoCo's camera frame (x right,
# y up, looking along -z) is then the world's, shifted. 100 px square, 90 degrees wide.
HEIGHT = 2.0
VIEW = ((100, 100), 50.0, (49.5, 49.5))
SUN = np.array([0.6, 0.0, -0.8])  # the sunlight's direction, down and along +x


def _kept(world: list[float], ground: float | None) -> bool:
    centre = np.array([world])
    in_camera = centre - [0.0, 0.0, HEIGHT]
    return bool(shadow_casters(in_camera, centre[:, 2], np.array([0.05]), SUN, SUN[2],
                               ground, VIEW)[0])  # fmt: skip


def test_a_sweep_that_meets_the_picture_only_below_the_ground_is_left_out() -> None:
    # 3.5 m to the side, 1 m up: its sweep reaches the ground at x = -2.75 (the
    # picture spans |x| <= 2.08 there) and meets the picture 1.4 m underground.
    assert _kept([-3.5, 0.0, 1.0], ground=None)
    assert not _kept([-3.5, 0.0, 1.0], ground=0.0)


def test_a_caster_whose_shadow_falls_on_the_ground_in_the_picture_is_kept() -> None:
    # Its shadow lands at x = -1.75 on the ground, inside the picture.
    assert _kept([-2.125, 0.0, 0.5], ground=0.0)
    # Under the ground beside the picture: nothing of it shows, nor its shadow.
    assert _kept([-3.0, 0.0, -0.5], ground=None)
    assert not _kept([-3.0, 0.0, -0.5], ground=0.0)


def test_a_geom_beside_the_picture_whose_shadow_goes_away_from_it_is_left_out() -> None:
    # A sphere of 5 cm, its centre 10 cm outside the picture's side plane 1 m below
    # the camera, the sunlight carrying its shadow out faster than the picture widens:
    # the sweep as spheres grown by 12.5 cm kept it.
    away = np.array([-0.8, 0.0, -0.6])
    centre = np.array([[-1.04 * 1.0 - 0.1 * np.sqrt(1 + 1.04**2), 0.0, 1.0]])
    in_camera = centre - [0.0, 0.0, HEIGHT]
    kept = shadow_casters(in_camera, centre[:, 2], np.array([0.05]), away, away[2], 0.0, VIEW)
    assert not kept[0]


def test_the_row_renders_the_same_with_fewer_shadow_casters() -> None:
    """The sunlit row (seed 4, the arm reaching for a berry): C2's frame, two C1
    windows and C1's whole left eye are the same pixel for pixel as with every geom
    drawn, and fewer geoms are drawn than with the sweep as spheres."""
    from row_world import stepped_casters, sunlit_row_world
    from softarm.sim.render import renderer

    module: Any = renderer  # its shadow_casters swapped for the reference sweeps

    world = sunlit_row_world()
    r = world.renderer
    made, chosen = r._renderer, module.shadow_casters
    drawn: list[int] = []

    def spy(*args):  # type: ignore[no-untyped-def]
        drawn.append(int((r.model.geom_group != module.CULLED_GROUP).sum()))
        return made(*args)

    def draws(casters) -> tuple[list[np.ndarray], list[int]]:  # type: ignore[no-untyped-def]
        module.shadow_casters = casters
        r._last.__init__()  # draw anew
        drawn.clear()
        images = [
            r.render("c2").colour,
            *(r.render_window("c1_left", o, 96) for o in ((560, 260), (900, 120))),
            r.render("c1_left").colour,
        ]
        return images, list(drawn)

    try:
        r._renderer = spy
        swept, counts = draws(chosen)
        every, _ = draws(lambda centres, *rest: np.ones(len(centres), bool))
        _, stepped = draws(stepped_casters)
        for a, b in zip(swept, every, strict=True):
            np.testing.assert_array_equal(a, b)
        assert sum(counts[:3]) < 0.8 * sum(stepped[:3])  # the small renders
    finally:
        r._renderer, module.shadow_casters = made, chosen
        world.close()
