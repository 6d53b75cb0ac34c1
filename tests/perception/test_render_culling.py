"""Frustum culling: a sphere is left out only if it covers no pixel, and a culled render
equals the full one pixel for pixel."""

from __future__ import annotations

import numpy as np
import pytest
from perception_world import rendered_world

import softarm
from softarm.sim.render.culling import MARGIN_PX, in_frustum

FOCAL, PRINCIPAL, SIZE = 900.0, (639.5, 359.5), (1280, 720)


def _sphere_at_pixel(u: float, v: float, depth: float, radius: float) -> np.ndarray:
    """The centre (MuJoCo's camera frame: y up, looking along -z) of a sphere whose
    centre projects to pixel (u, v) at ``depth``."""
    x = (u - PRINCIPAL[0]) / FOCAL * depth
    y = -(v - PRINCIPAL[1]) / FOCAL * depth
    return np.array([x, y, -depth])


def test_a_sphere_that_projects_into_the_picture_is_kept() -> None:
    rng = np.random.default_rng(5)
    centres = np.array(
        [_sphere_at_pixel(rng.uniform(0, 1280), rng.uniform(0, 720), rng.uniform(0.2, 5), 0.0)
         for _ in range(200)]
    )  # fmt: skip
    assert in_frustum(centres, np.full(200, 1e-3), SIZE, FOCAL, PRINCIPAL).all()


def test_a_sphere_reaching_in_from_outside_is_kept_and_one_clear_of_it_is_not() -> None:
    depth, radius = 1.0, 0.01  # 9 px at 1 m
    beyond = SIZE[0] - 0.5 + MARGIN_PX
    reaching = _sphere_at_pixel(beyond + 8.0, 300, depth, radius)
    clear = _sphere_at_pixel(beyond + 16.0, 300, depth, radius)  # 9 px x sec(35 deg) off
    above = _sphere_at_pixel(600, -0.5 - MARGIN_PX - 10.0, depth, radius)
    behind = np.array([0.0, 0.0, 0.02])
    kept = in_frustum(
        np.array([reaching, clear, above, behind]), np.full(4, radius), SIZE, FOCAL, PRINCIPAL
    )
    assert kept.tolist() == [True, False, False, False]


def test_an_unbounded_geom_is_always_kept() -> None:
    far_off = np.array([[100.0, 0.0, 1.0]])
    assert in_frustum(far_off, np.array([0.0]), SIZE, FOCAL, PRINCIPAL).all()


def _uncull(world: object) -> None:
    renderer = world.renderer  # type: ignore[attr-defined]
    renderer._cullable = renderer._cullable[:0]


def test_culled_renders_equal_the_full_ones() -> None:
    culled, full = rendered_world(31, 8), rendered_world(31, 8)
    _uncull(full)
    arm = softarm.SoftArm.blackberry()
    q = np.asarray(culled.bush.berries[0].q) * 0.95
    from softarm.sim.render.world import arm_sections

    for world in (culled, full):
        world.set_arm(arm_sections(arm, q), arm.forward(q))
    a, b = culled.c1_left(truth=True), full.c1_left(truth=True)
    np.testing.assert_array_equal(a.colour, b.colour)
    np.testing.assert_array_equal(a.geoms, b.geoms)
    np.testing.assert_array_equal(a.depth, b.depth)
    np.testing.assert_array_equal(culled.c2_frame().colour, full.c2_frame().colour)
    for centre in ((640.0, 360.0), (200.0, 150.0), (1100.0, 600.0)):
        np.testing.assert_array_equal(
            np.asarray(culled.c1_left_window(centre, 192)),
            np.asarray(full.c1_left_window(centre, 192)),
        )


def test_a_window_leaves_most_of_the_bush_out() -> None:
    world = rendered_world(32, 8)
    renderer = world.renderer
    seen = []
    original = renderer._culled

    def spy(camera: str, size: tuple[int, int], principal: tuple[float, float], **how):  # type: ignore[no-untyped-def]
        seen.append(renderer.model.geom_group.copy())
        return original(camera, size, principal, **how)

    renderer._culled = spy
    world.c1_left_window((640.0, 360.0), 192)
    assert seen  # the window went through the culling
    with original("c1_left", (64, 64), (600.0, 400.0)):
        hidden = int((renderer.model.geom_group == 5).sum())
    assert hidden > renderer.model.ngeom // 2, hidden
    assert (renderer.model.geom_group != 5).all()  # restored after the render


def test_the_visible_share_of_an_object() -> None:
    world = rendered_world(33, 8)
    renderer = world.renderer
    berries = [g for g in range(renderer.model.ngeom) if renderer.labels.kind[g] == 1]
    background = [g for g in range(renderer.model.ngeom) if renderer.labels.kind[g] == 0]
    share = renderer.visible_share("c1_left", berries)
    assert 0.0 < share <= 1.0
    assert renderer.visible_share("c1_left", background) < 1.0  # the bush stands before it
    assert renderer.visible_share("c1_left", list(range(renderer.model.ngeom))) == 1.0
    world.hide_arm()  # moved out of the picture
    segments = [g for g in range(renderer.model.ngeom) if renderer.labels.kind[g] == 5][1:4]
    assert renderer.visible_share("c1_left", segments) == 0.0
    assert (renderer.model.geom_group != 5).all()  # restored


def test_each_berrys_visible_share_is_the_renderers_measure_of_it() -> None:
    # The world's per-berry shares (C1's lens applied) against the renderer's visible
    # share of each berry's geoms (pinhole, drawn alone against drawn with the scene).
    world = rendered_world(902, 8)  # a bush whose leaves hide two fruit in part
    renderer, labels = world.renderer, world.renderer.labels
    shares = world.berry_shares()
    assert set(shares) == {b.tag_id for b in world.bush.berries}
    for tag, share in shares.items():
        geoms = [g for g in range(renderer.model.ngeom) if labels.kind[g] == 1
                 and labels.instance[g] == tag]  # fmt: skip
        assert share == pytest.approx(renderer.visible_share("c1_left", geoms), abs=0.05)
    assert any(0.0 < s < 0.9 for s in shares.values())


def test_a_picked_berry_leaves_the_picture_and_hides_nothing_any_more() -> None:
    world = rendered_world(902, 8)
    shares = world.berry_shares()
    tag = max(shares, key=lambda t: shares[t])
    world.remove_berry(tag)
    left = world.c1_left(truth=True)
    assert left.geoms is not None
    assert not world.labels.mask(left.geoms, "berry", tag).any()
    after = world.berry_shares(left)
    assert after[tag] == 0.0
    assert all(after[t] >= shares[t] - 1e-9 for t in shares if t != tag)
    world.hide_arm()  # the arm's moves and a render's culling leave it removed
    assert not world.labels.mask(world.c1_left(truth=True).geoms, "berry", tag).any()


def test_the_arms_geoms_out_of_the_picture_are_left_out_and_nothing_changes() -> None:
    """In the sunlit row, with the arm bent towards a berry: C2's frame and C1's windows
    leave out arm geoms (bounded by their sizes, which change as it bends), and draw
    what they drew with the whole arm drawn, shadows included."""
    from row_world import sunlit_row_world
    from softarm.sim.render.renderer import CULLED_GROUP

    world = sunlit_row_world()
    r = world.renderer
    try:
        arm, every = r._arm, r._cullable
        drawn = []
        made = r._renderer

        def spy(*args):  # type: ignore[no-untyped-def]
            drawn.append(r.model.geom_group[arm].copy())
            return made(*args)

        def draws() -> list[np.ndarray]:
            r._last.__init__()  # draw anew
            return [
                r.render("c2").colour,
                *(r.render_window("c1_left", o, 96) for o in ((560, 260), (900, 120))),
            ]

        r._renderer = spy
        culled = draws()
        assert any((groups == CULLED_GROUP).any() for groups in drawn)
        r._cullable = np.setdiff1d(every, arm)  # the arm always drawn, as before
        for a, b in zip(culled, draws(), strict=True):
            np.testing.assert_array_equal(a, b)
    finally:
        r._renderer, r._cullable = made, every
        world.close()
