"""The row's canes drawn as merged meshes in the small renders
(softarm.sim.render.cane_mesh): the mesh is MuJoCo's capsules around each cane (same
outline, outward normals), fewer triangles, and only the small colour renders draw it;
whole C1 frames and renders with ground truth draw the capsules."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

from row_world import sunlit_row_world
from softarm.sim.render import cane_mesh
from softarm.sim.render.cane_mesh import Capsule, capsule_template, chain_mesh
from softarm.sim.render.mjcf import z_to

NSLICE, NSTACK = 14, 8


def _capsule(centre: Any, axis: Any, radius: float = 0.003, half: float = 0.02) -> Capsule:
    return Capsule(np.asarray(centre, float), z_to(np.asarray(axis, float)), radius, half)


def _chain(bend_deg: float, radius2: float = 0.003) -> list[Capsule]:
    """Two capsules meeting end to end at the origin, the second bent by ``bend_deg``."""
    a = np.radians(bend_deg)
    d2 = np.array([np.sin(a), 0.0, np.cos(a)])
    return [_capsule([0, 0, -0.02], [0, 0, 1]), _capsule(0.02 * d2, d2, radius2)]


def test_the_template_with_mujocos_stacks_has_mujocos_triangles() -> None:
    t = capsule_template(NSLICE, NSTACK, cylinder_stacks=NSTACK)
    ends = 2 * (2 * NSLICE * (NSTACK // 2 - 1) + NSLICE)  # quads and pole triangles
    assert len(t.faces) == 2 * NSLICE * NSTACK + ends
    stacks = cane_mesh.CYLINDER_STACKS
    assert len(capsule_template(NSLICE, NSTACK).faces) == 2 * NSLICE * stacks + ends


@pytest.mark.parametrize("stacks", [1, NSTACK])
def test_a_capsules_mesh_lies_on_its_surface_facing_out(stacks: int) -> None:
    c = _capsule([0.1, 0.2, 0.3], [1.0, 2.0, 0.5], radius=0.004, half=0.03)
    v, n, f = chain_mesh([c], capsule_template(NSLICE, NSTACK, stacks))
    axis = c.R[:, 2]
    t = np.clip((v - c.pos) @ axis, -c.half, c.half)
    out = v - (c.pos + np.outer(t, axis))  # from the nearest point of the axis segment
    np.testing.assert_allclose(np.linalg.norm(out, axis=1), c.radius, rtol=1e-5)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, rtol=1e-5)
    assert (np.einsum("ij,ij->i", n, out) > 0).all()
    tri = v[f]
    face_n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    big = np.linalg.norm(face_n, axis=1) > 1e-12
    assert (np.einsum("ij,ij->i", face_n, n[f].mean(axis=1))[big] > 0).all()  # CCW outward


def test_caps_hidden_in_the_next_capsule_are_left_out_only_where_they_are_hidden() -> None:
    t = capsule_template(NSLICE, NSTACK)
    whole = 2 * len(chain_mesh(_chain(0.0)[:1], t)[2])
    for bend, radius2, trimmed in ((3.0, 0.003, True), (20.0, 0.003, False), (3.0, 0.004, False)):
        f = chain_mesh(_chain(bend, radius2), t)[2]
        assert (len(f) < whole) == trimmed, (bend, radius2)
    # What is kept of the first capsule's top: nothing inside the second's inscribed
    # cylinder was needed, and the rest of its surface is there.
    chain = _chain(0.999 * np.degrees(cane_mesh.MAX_HIDDEN_BEND))
    top, _ = cane_mesh._hidden_ends(chain)
    assert top[0]
    cap = np.flatnonzero(t.part == cane_mesh.TOP_CAP)
    c, d = chain[0], chain[1].R[:, 2]
    scaled = t.vertices * c.radius + np.outer(t.end * c.half, [0.0, 0.0, 1.0])
    p = scaled[np.unique(t.faces[cap])] @ c.R.T + c.pos  # the joint is the origin
    along = p @ d
    radial = np.linalg.norm(p - np.outer(along, d), axis=1)
    assert (along > 0).all() and (radial < c.radius * np.cos(np.pi / NSLICE)).all()


@pytest.fixture(scope="module")
def row() -> Iterator[Any]:
    world = sunlit_row_world()
    yield world
    world.close()


def _groups_drawn(renderer: Any, draw: Any) -> np.ndarray:
    """The geom groups as they were when ``draw`` rendered (spying on the context)."""
    seen = []
    made = renderer._renderer

    def spy(*args: Any) -> Any:
        seen.append(renderer.model.geom_group.copy())
        return made(*args)

    renderer._renderer = spy
    try:
        renderer._last.__init__()  # draw anew
        draw()
    finally:
        renderer._renderer = made
    result: np.ndarray = seen[-1]
    return result


def test_small_colour_renders_draw_the_merged_canes_and_the_rest_the_capsules(row: Any) -> None:
    from softarm.sim.render.renderer import CULLED_GROUP

    r = row.renderer
    merged, members = r._merged, r._members
    assert len(merged) and len(members)
    assert merged.min() > max(set(range(r.model.ngeom)) - set(merged.tolist()))  # ids kept
    assert set(r.labels.instance[merged]) == set(r.labels.instance[members])  # cane ids
    small = [
        _groups_drawn(r, lambda: r.render("c2")),
        _groups_drawn(r, lambda: r.render_window("c1_left", (560, 260), 96)),
    ]
    for groups in small:
        assert (groups[members] == CULLED_GROUP).all()
        assert (groups[merged] != cane_mesh.MERGED_GROUP).all()
    whole = [
        _groups_drawn(r, lambda: r.render("c1_left")),
        _groups_drawn(r, lambda: r.render("c2", geoms=True)),
    ]
    for groups in whole:
        # Not drawn: hidden by default, or culled (out of the picture and its shadows).
        assert np.isin(groups[merged], (cane_mesh.MERGED_GROUP, CULLED_GROUP)).all()
        assert (groups[members] != CULLED_GROUP).any()
    np.testing.assert_array_equal(r.model.geom_group, r._groups)  # put back


def test_the_merged_canes_change_few_pixels_of_a_small_render(row: Any) -> None:
    """Against the capsules, in the sun: under 1 % of C2's pixels and of a window
    differ, under 0.2 % by more than 1 level (the specular term along the cylinders),
    a few by more than 8 (shadow texels of the caps left out; BENCHMARKS.md)."""
    r = row.renderer
    kept = r._merged, r._members
    empty = np.zeros(0, np.int64)
    draws: dict[str, Callable[[], np.ndarray]] = {
        "c2": lambda: r.render("c2").colour,
        "window": lambda: r.render_window("c1_left", (560, 260), 96),
    }
    for draw in draws.values():
        r._merged, r._members = empty, empty
        r._last.__init__()
        capsules = draw()
        r._merged, r._members = kept
        r._last.__init__()
        merged = draw()
        diff = np.abs(capsules.astype(int) - merged.astype(int)).max(axis=2)
        counts = np.bincount(diff.ravel())
        assert (diff > 0).mean() < 0.01 and (diff > 1).mean() < 0.002, counts
        assert (diff > 8).sum() <= 10, counts
