"""A cane's chain of capsules as one mesh of fewer triangles, for the small renders.

The bush's canes in the row are chains of capsules (``mjcf._cane``: 23 a cane). MuJoCo
draws a capsule as an open cylinder and two half spheres tessellated by the scene's
``numslices`` (14) and ``numstacks`` (8): 420 triangles, drawn in each of a shadowed
render's three passes. On Mesa's software rasteriser a small render's cost follows the
vertices it transforms, and the canes' were a third of it. The merged mesh here
(:func:`chain_mesh`) keeps MuJoCo's triangles around each capsule (the same 14 sides, so
the same outline, and its normals), with three differences, 112 triangles a capsule:

- **two rings of quads along each cylinder** (CYLINDER_STACKS), not 8: along a straight cylinder a
  directional light's diffuse and ambient terms do not vary, and the texture
  coordinates of the sun's shadow map are linear in position (interpolated exactly
  either way); only the specular term, lit per vertex with a local viewer, is
  interpolated between farther vertices;
- **the end caps hidden inside the next capsule are left out**: where two capsules
  of a chain meet end to end (bent less than MAX_HIDDEN_BEND), each one's end above
  its first ring of quads lies inside the other's tessellated cylinder, never the
  nearest surface to a camera; in the sun's depth map MuJoCo's polygon offset can
  still bring such a triangle forward by a fraction of a millimetre, which moves a
  few shadow texels;
- rounding: the mesh's vertices are placed once in double precision and stored in
  single, MuJoCo's are placed each draw in single.

The triangles are MuJoCo's builtins (``render_context.c``: ``cylinder``,
``halfSphere``, ``setVertexSphere``) scaled and placed as ``renderGeom`` places a
capsule, each quad split as Mesa splits one ((0, 1, 3) and (1, 2, 3), OpenGL's last
provoking vertex). BENCHMARKS.md counts the pixels that differ and by how much. A
whole C1 frame and every render with ground truth (depth, geom ids) draw the
capsules (softarm.sim.render.renderer).

Capsules are read from the MJCF text the scene is built from (``pos``, ``quat`` and
``size`` as written, the numbers MuJoCo compiles). The mesh is written as MuJoCo's
binary ``.msh`` (text would be megabytes).
"""

from __future__ import annotations

import itertools
import re
import struct
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.spatial.transform import Rotation

from softarm.checks import FloatArray
from softarm.sim.render.labels import KINDS, GeomLabels

__all__ = [
    "CHUNK",
    "MERGED_GROUP",
    "Capsule",
    "capsule_template",
    "capsules_in",
    "chain_mesh",
    "merged_and_members",
    "merged_canes",
    "msh_bytes",
]

IntArray = npt.NDArray[np.int64]

_MERGED = re.compile(r"^cane\d+_merged\d+$")
#: MuJoCo's ``mjGEOM_CAPSULE`` (mujoco itself is an optional import).
CAPSULE = 3
_CAPSULE = re.compile(
    r'type="capsule" size="(?P<size>[^"]*)" pos="(?P<pos>[^"]*)" quat="(?P<quat>[^"]*)"'
)


@dataclass(frozen=True)
class Capsule:
    """A capsule: centre, rotation (its axis local z), radius and half-length (m)."""

    pos: FloatArray
    R: FloatArray
    radius: float
    half: float


def capsules_in(xml: str) -> list[Capsule]:
    """Every capsule of ``xml`` written as ``mjcf._capsule`` writes one (size, pos and
    quat in that order), in order; its quaternion normalised as MuJoCo's compiler does."""
    out = []
    for m in _CAPSULE.finditer(xml):
        radius, half = (float(x) for x in m["size"].split())
        pos = np.array([float(x) for x in m["pos"].split()])
        w, x, y, z = (float(v) for v in m["quat"].split())
        out.append(Capsule(pos, Rotation.from_quat([x, y, z, w]).as_matrix(), radius, half))
    return out


#: Rings of quads along a merged capsule's cylinder (MuJoCo draws ``numstacks``, 8).
CYLINDER_STACKS = 2
#: Parts of a capsule's triangles (:attr:`CapsuleTemplate.part`).
CYLINDER, TOP_BAND, TOP_CAP, BOTTOM_BAND, BOTTOM_CAP = range(5)
#: The sharpest bend (rad) between two capsules of a chain at which each one's end
#: cap (the end's triangles above its first band of quads, within 67.5 degrees of the
#: axis) lies wholly inside the other capsule's tessellated cylinder: a vertex there is
#: at most r sin(67.5 deg + bend) from the other's axis, inside its inscribed radius
#: r cos(pi / numslices) (0.975 r at 14 slices) below 9.7 degrees; 8 keeps a margin.
MAX_HIDDEN_BEND = np.radians(8.0)


@dataclass(frozen=True)
class CapsuleTemplate:
    """A capsule of radius 1 and half-length 1: vertices and normals (V, 3), one per
    triangle corner, and CCW triangles (F, 3). ``end`` (V,): 0 for the open
    cylinder's vertices (x, y scale by the radius, z by the half-length), +1 and -1
    for the top's and bottom's (all scale by the radius, then move along z by the
    half-length); ``part`` (F,): each triangle's part (CYLINDER ... BOTTOM_CAP)."""

    vertices: FloatArray
    normals: FloatArray
    faces: IntArray
    end: FloatArray
    part: IntArray


def _quad_faces(n_quads: int) -> IntArray:
    """Quads given as 4 consecutive vertices (0, 1, 2, 3), each as Mesa splits it."""
    q = 4 * np.arange(n_quads)[:, None]
    both = np.stack([np.add(q, [0, 1, 3]), np.add(q, [1, 2, 3])], axis=1)
    return both.reshape(-1, 3)


def _sphere_point(az: FloatArray, el: float) -> FloatArray:
    """MuJoCo's ``setVertexSphere`` less its offset: the unit sphere at azimuths ``az``
    and elevation ``el``, in single precision (also the normal there)."""
    a, e = az.astype(np.float32), np.float32(el)
    return np.stack([np.cos(a) * np.cos(e), np.sin(a) * np.cos(e), np.full_like(a, np.sin(e))], 1)


def _half_sphere(sign: int, az: FloatArray, stacks: int) -> tuple[FloatArray, IntArray, IntArray]:
    """One end (``sign`` +1 top, -1 bottom) of a unit capsule about its own centre,
    in MuJoCo's order: corner points (they are the normals too), triangles, and each
    triangle's part (band: the quads next to the cylinder; cap: the rest)."""
    ring = [_sphere_point(az, np.pi / 2 * sign * i / stacks) for i in range(stacks)]
    nslice = len(az) - 1
    quads = [
        [lo[j], lo[j + 1], hi[j + 1], hi[j]]
        for lo, hi in itertools.pairwise(ring)
        for j in range(nslice)
    ]
    corners = np.array(quads, float).reshape(-1, 4, 3)
    if sign < 0:  # the bottom's quads are given as (v4, v3, v2, v1)
        corners = corners[:, ::-1]
    pole, top = np.array([0.0, 0.0, float(sign)]), ring[-1]
    tris = [
        [top[j], top[j + 1], pole] if sign > 0 else [pole, top[j + 1], top[j]]
        for j in range(nslice)
    ]
    points = np.vstack([corners.reshape(-1, 3), np.array(tris, float).reshape(-1, 3)])
    faces = np.vstack(
        [_quad_faces(len(corners)), 4 * len(corners) + np.arange(3 * nslice).reshape(-1, 3)]
    )
    band, cap = (TOP_BAND, TOP_CAP) if sign > 0 else (BOTTOM_BAND, BOTTOM_CAP)
    part = np.where(np.arange(len(faces)) < 2 * nslice, band, cap)
    return points, faces, part


def capsule_template(
    nslice: int, nstack: int, cylinder_stacks: int = CYLINDER_STACKS
) -> CapsuleTemplate:
    """MuJoCo's capsule with ``numslices`` ``nslice`` and ``numstacks`` ``nstack``, its
    open cylinder in ``cylinder_stacks`` rings of quads along its length (MuJoCo's:
    ``nstack``; see the module's note)."""
    az = (2.0 * np.pi * np.arange(nslice + 1)) / nslice
    around = _sphere_point(az, 0.0)
    heights = 2.0 * np.arange(cylinder_stacks + 1) / cylinder_stacks - 1.0
    cyl, cyl_n = [], []
    for h1, h2 in itertools.pairwise(heights):
        for j in range(nslice):
            a, b = around[j], around[j + 1]
            cyl += [[*a[:2], h1], [*b[:2], h1], [*b[:2], h2], [*a[:2], h2]]
            cyl_n += [a, b, b, a]
    verts, normals, faces, ends, parts = (
        [np.array(cyl, float)],
        [np.array(cyl_n, float)],
        [_quad_faces(cylinder_stacks * nslice)],
        [np.zeros(len(cyl))],
        [np.full(2 * cylinder_stacks * nslice, CYLINDER)],
    )
    for sign in (1, -1):
        points, f, part = _half_sphere(sign, az, nstack // 2)
        faces.append(f + sum(len(v) for v in verts))
        verts.append(points)
        normals.append(points)
        ends.append(np.full(len(points), float(sign)))
        parts.append(part)
    return CapsuleTemplate(
        np.vstack(verts),
        np.vstack(normals),
        np.vstack(faces),
        np.concatenate(ends),
        np.concatenate(parts),
    )


def _hidden_ends(capsules: list[Capsule]) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
    """Which capsules' top and bottom caps lie inside their neighbour in the chain:
    the two meet end to end (the top's centre on the bottom's, within 10 um), with
    the same radius, bent by at most MAX_HIDDEN_BEND, each at least a radius long."""
    n = len(capsules)
    top, bottom = np.zeros(n, bool), np.zeros(n, bool)
    for k, (a, b) in enumerate(itertools.pairwise(capsules)):
        za, zb = a.R[:, 2], b.R[:, 2]
        meet = np.linalg.norm((a.pos + a.half * za) - (b.pos - b.half * zb)) < 1e-5
        bend = np.arccos(np.clip(za @ zb, -1.0, 1.0))
        ok = meet and a.radius == b.radius and bend <= MAX_HIDDEN_BEND
        ok = ok and min(a.half, b.half) >= a.radius
        top[k] = bottom[k + 1] = ok
    return top, bottom


def chain_mesh(
    capsules: list[Capsule], template: CapsuleTemplate
) -> tuple[FloatArray, FloatArray, IntArray]:
    """``capsules`` drawn as ``template`` as one mesh in the frame they are placed in:
    vertices (V, 3), unit normals (V, 3), triangles (F, 3). Where two capsules meet
    end to end, the caps inside the other are left out (:func:`_hidden_ends`): a
    triangle inside the other's closed surface is never the nearest surface, to a
    camera outside the cane or to the sun's shadow map."""
    t = template
    cyl = (t.end == 0)[:, None]
    top, bottom = _hidden_ends(capsules)
    verts, normals, faces, base = [], [], [], 0
    for k, c in enumerate(capsules):
        scaled = np.where(
            cyl,
            t.vertices * [c.radius, c.radius, c.half],
            t.vertices * c.radius + np.outer(t.end * c.half, [0.0, 0.0, 1.0]),
        )
        keep = ~((top[k] & (t.part == TOP_CAP)) | (bottom[k] & (t.part == BOTTOM_CAP)))
        used = np.unique(t.faces[keep])
        index = np.full(len(t.vertices), -1)
        index[used] = np.arange(len(used)) + base
        verts.append(scaled[used] @ c.R.T + c.pos)
        normals.append(t.normals[used] @ c.R.T)
        faces.append(index[t.faces[keep]])
        base += len(used)
    return np.vstack(verts), np.vstack(normals), np.vstack(faces)


def msh_bytes(vertices: FloatArray, normals: FloatArray, faces: IntArray) -> bytes:
    """A mesh in MuJoCo's binary ``.msh`` format: four int32 counts (vertices,
    normals, texture coordinates, faces), then float32 vertices and normals and int32
    faces."""
    head = struct.pack("<4i", len(vertices), len(normals), 0, len(faces))
    return (
        head
        + np.ascontiguousarray(vertices, "<f4").tobytes()
        + np.ascontiguousarray(normals, "<f4").tobytes()
        + np.ascontiguousarray(faces, "<i4").tobytes()
    )


#: Geoms named ``cane{i}_merged{c}`` are chunk c of cane i's capsules as one mesh
#: (labelled as cane i); they are drawn in no render but the small ones
#: (softarm.sim.render.renderer), in this group, hidden by MuJoCo's default options.
MERGED_GROUP = 4
#: Capsules a merged chunk holds: a whole cane's bounding sphere would keep all of it in
#: a render that sees a few centimetres of it (culling.py culls by bounding spheres).
CHUNK = 6


def merged_canes(
    canes: list[str], rgba: str, nslice: int, nstack: int
) -> tuple[dict[str, bytes], str, str]:
    """The bush's canes (``canes[i]``: cane i's capsules as MJCF) as merged chunks:
    the mesh files (assets), the ``<mesh>`` elements and the geoms (``rgba`` as the
    capsules')."""
    template = capsule_template(nslice, nstack)
    files, meshes, geoms = {}, [], []
    for i, xml in enumerate(canes):
        capsules = capsules_in(xml)
        for c, start in enumerate(range(0, len(capsules), CHUNK)):
            name = f"canemerged{i}_{c}"
            files[f"{name}.msh"] = msh_bytes(*chain_mesh(capsules[start : start + CHUNK], template))
            meshes.append(f'<mesh name="{name}" file="{name}.msh" inertia="shell"/>')
            geoms.append(
                f'<geom name="cane{i}_merged{c}" type="mesh" mesh="{name}" rgba="{rgba}" '
                f'group="{MERGED_GROUP}" contype="0" conaffinity="0"/>'
            )
    # A body of their own, written last: MuJoCo numbers geoms body by body, so every
    # other geom keeps its id.
    body = f'<body name="canes_merged">{"".join(geoms)}</body>'
    return files, "".join(meshes), body


def merged_and_members(model: Any, labels: GeomLabels) -> tuple[IntArray, IntArray]:
    """The geom ids of ``model``'s merged canes and of the capsules they stand for
    (both empty in a scene without them)."""
    names = [model.geom(g).name for g in range(model.ngeom)]
    merged = np.array([g for g, n in enumerate(names) if _MERGED.match(n)], np.int64)
    canes = set(labels.instance[merged].tolist())
    cane = KINDS.index("cane")
    members = np.flatnonzero(
        (labels.kind == cane) & np.isin(labels.instance, list(canes)) & (model.geom_type == CAPSULE)
    )
    return merged, members.astype(np.int64)
