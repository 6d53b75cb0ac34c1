"""The drupelets' sphere mesh: on the sphere, closed, and facing out."""

from __future__ import annotations

import numpy as np

from softarm.sim.render.mjcf import ICOSPHERE


def test_the_icosphere_lies_on_the_unit_sphere_and_faces_out() -> None:
    vertices, faces = ICOSPHERE
    assert vertices.shape == (42, 3) and faces.shape == (80, 3)
    np.testing.assert_allclose(np.linalg.norm(vertices, axis=1), 1.0, atol=1e-12)
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    normals = np.cross(b - a, c - a)
    assert (np.einsum("ij,ij->i", normals, a + b + c) > 0).all()


def test_the_icosphere_is_closed() -> None:
    _, faces = ICOSPHERE
    edges: dict[tuple[int, int], int] = {}
    for f in faces:
        for i in range(3):
            e = (int(f[i]), int(f[(i + 1) % 3]))
            edges[e] = edges.get(e, 0) + 1
    # every directed edge once, and its reverse once: a closed, consistently wound surface
    assert all(n == 1 for n in edges.values())
    assert all((b, a) in edges for a, b in edges)
