"""A render asked for again with nothing moved is handed back (copied), not drawn again;
anything the harvest changes (the arm, a picked berry, a window's place) draws anew."""

from __future__ import annotations

import numpy as np
from perception_world import rendered_world

import softarm
from softarm.sim.render.last_render import LastRender
from softarm.sim.render.world import arm_sections


def test_a_kept_render_is_a_copy_of_the_one_drawn_from_the_same_state() -> None:
    last = LastRender()
    image = np.arange(12, dtype=np.uint8).reshape(2, 2, 3)
    assert last.put("c1", b"a", image) is image
    image[0, 0, 0] = 99  # the caller's copy changes, the kept one does not
    kept = last.get("c1", b"a")
    assert kept is not None and kept[0, 0, 0] == 0
    kept[0, 0, 1] = 77
    again = last.get("c1", b"a")
    assert again is not None and again[0, 0, 1] == 1
    assert last.get("c1", b"b") is None and last.get("c2", b"a") is None


def test_the_renderer_draws_only_what_changed() -> None:
    world = rendered_world(34, 6)
    renderer = world.renderer
    drawn = []
    passes = renderer._render_passes

    def counted(*args, **kwargs):  # type: ignore[no-untyped-def]
        drawn.append(args[1])
        return passes(*args, **kwargs)

    renderer._render_passes = counted
    arm = softarm.SoftArm.blackberry()
    q = np.asarray(world.bush.berries[0].q) * 0.9
    world.set_arm(arm_sections(arm, q), arm.forward(q))
    first, again = renderer.render("c2"), renderer.render("c2")
    assert drawn == ["c2"]  # the second was kept
    np.testing.assert_array_equal(first.colour, again.colour)
    assert first.colour is not again.colour
    truth = renderer.render("c2", geoms=True)  # asked for more: drawn
    assert drawn == ["c2", "c2"] and truth.geoms is not None
    window = renderer.render_window("c1_left", (500, 300), 96)
    np.testing.assert_array_equal(window, renderer.render_window("c1_left", (500, 300), 96))
    moved = renderer.render_window("c1_left", (510, 300), 96)  # another place: drawn
    assert not np.array_equal(window, moved)
    world.set_arm(arm_sections(arm, q * 0.8), arm.forward(q * 0.8))
    after = renderer.render("c2")
    assert drawn == ["c2", "c2", "c2"]  # the arm moved: drawn again
    assert not np.array_equal(first.colour, after.colour)
    world.remove_berry(world.bush.berries[1].tag_id)
    renderer.render("c2")
    assert drawn == ["c2", "c2", "c2", "c2"]  # a berry picked: drawn again
    world.close()
