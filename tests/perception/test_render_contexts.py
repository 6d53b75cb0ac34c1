"""One OpenGL context of the renderer serves renders of every size its offscreen buffer
holds (softarm.sim.render.renderer.BushRenderer._renderer): the C1 windows come in many
sizes, and each context made costs every mesh and texture uploaded again. A render is
the same whichever size the context last drew."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from row_world import sunlit_row_world
from softarm.sim.render.last_render import LastRender

SIDES = (64, 128)


@pytest.fixture(scope="module")
def row() -> Iterator[Any]:
    world = sunlit_row_world()
    yield world
    world.close()


def _windows(renderer: Any) -> list[np.ndarray]:
    return [renderer.render_window("c1_left", (560, 260), side) for side in SIDES]


def test_windows_of_many_sizes_share_one_context(row: Any) -> None:
    renderer = row.renderer
    renderer.close()
    _windows(renderer)
    renderer.render("c2")
    # The small shadow map's context (and none per size); the full map's where a
    # render does not fit the small one.
    assert len(renderer._renderers) <= 2, list(renderer._renderers)
    assert [key[2] for key in renderer._renderers].count(True) == 1


def test_a_render_is_the_same_whatever_size_the_context_drew_last(row: Any) -> None:
    renderer = row.renderer
    shared = _windows(renderer)
    c2 = renderer.render("c2", depth=True, geoms=True)
    fresh = []
    for side in SIDES:  # each drawn by a context made for it alone
        renderer.close()
        renderer._last = LastRender()  # nothing kept: drawn anew
        fresh.append(renderer.render_window("c1_left", (560, 260), side))
    for a, b in zip(shared, fresh, strict=True):
        assert a.shape == b.shape
        np.testing.assert_array_equal(a, b)
    renderer.close()
    renderer._last = LastRender()
    again = renderer.render("c2", depth=True, geoms=True)
    np.testing.assert_array_equal(c2.colour, again.colour)
    np.testing.assert_array_equal(c2.geoms, again.geoms)
    np.testing.assert_array_equal(c2.depth, again.depth)
