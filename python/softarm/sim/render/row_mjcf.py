"""The MJCF of the rendered row (:mod:`softarm.sim.render.row`) in daylight
(:mod:`softarm.sim.render.row_look`): the same scene as the bush's
(:func:`softarm.sim.render.mjcf.scene_xml`: its canes, arm, cameras and tags), with the
row's parts, a sky and a sun that casts shadows.

The sun is a directional light with a position above the scene (MuJoCo renders a
directional light's shadow map only then) and the scene's ``shadowsize`` > 0; its
shadow frustum spans ``shadowclip`` times the scene's extent. Leaflets are meshes with a
leaflet's outline (serrated, pointed, folded along the midrib) and a vein texture, one
face on each side. Fruit are meshes of drupelets around a core; turning fruit have a
red part and a black part; ripe fruit are glossy, their specular strength and
shininess drawn per look. Geom names carry the ground truth as in the bush:
``berry{id}_{k}``, ``cane{i}_{k}``, ``leaf{k}``, ``clutter_*`` (look-alikes: dead
leaves, stones, mulch, the drip line) and ``bg_*`` (ground, posts, wires, the hedge's
depth, the next row).
"""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt
from scipy.spatial import ConvexHull

from softarm.checks import FloatArray
from softarm.sim.render import mjcf
from softarm.sim.render.cane_mesh import merged_canes
from softarm.sim.render.look import _mix
from softarm.sim.render.row import (
    GROUND_Z,
    POSTS_X,
    ROW_FRUIT_ID,
    ROW_HALF,
    ROW_Y,
    WIRES_Z,
    Row,
    RowFruit,
)
from softarm.sim.render.row_look import RowLook
from softarm.vision.cube import FACE_PER_MARKER

__all__ = ["SHADOW_SIZE", "row_scene_xml"]

#: The sun's shadow map (texels a side); 0 turns shadows off.
SHADOW_SIZE = 2048
#: Size bins of the fruit and leaflet meshes (one mesh asset per bin).
FRUIT_BINS = np.linspace(0.8, 1.15, 5)
LEAF_BINS = np.linspace(0.05, 0.09, 5)
#: Drupelets of a row fruit.
ROW_DRUPELETS = 34
#: The row's canes are drawn with fewer segments than the bush's (they are not fitted).
ROW_CANE_SEGMENTS = 10
#: The ground plane's grid pitch (m) as MuJoCo draws it (the third of a plane's sizes):
#: at 0.1 m MuJoCo draws the 80 m ground as its finest grid, 200 x 200 quads, in each of
#: a shadowed render's three passes. The small renders' context draws it coarser
#: (softarm.sim.render.renderer.SMALL_RENDER_GROUND_GRID).
GROUND_GRID = 0.1
#: MuJoCo's tessellation of the scene's primitives (``<quality>``); the merged canes
#: (softarm.sim.render.cane_mesh) are built to it.
NUMSLICES = 14
NUMSTACKS = 8
#: Where the scene is, for the sun's position and shadow frustum.
CENTRE = np.array([0.0, 0.45, 0.2])
EXTENT = 1.6


def row_scene_xml(spec: mjcf.SceneSpec, row: Row, shadows: bool) -> tuple[str, dict[str, bytes]]:
    """The MJCF text of ``spec`` drawn as the row ``row`` (``spec.look`` a
    :class:`RowLook`) and its assets; ``shadows``: the sun casts them."""
    look = spec.look
    assert isinstance(look, RowLook)  # the caller's choice of this builder
    rng = np.random.default_rng([look.seed, 0xD0C])
    assets = {
        **mjcf._tag_assets(spec),
        "leafvein.png": _leaf_png(),
        "hedge.png": _hedge_png(look, rng),
    }
    n_bush = len(spec.bush.branches)
    canes = [mjcf._cane(i, b.points(24), look) for i, b in enumerate(spec.bush.branches)]
    merged = merged_canes(canes, mjcf._rgba(look.cane_colour), NUMSLICES, NUMSTACKS)
    assets.update(merged[0])
    parts = [
        _ground(look, rng),
        _trellis(),
        _next_row(look, rng),
        *canes,
        *(
            _row_cane(n_bush + i, b.points(ROW_CANE_SEGMENTS + 1), look)
            for i, b in enumerate(row.canes)
        ),
        *(_fruit(f, look, rng) for f in row.fruit),
        _leaflets(row, look, rng),
        _stones(row, rng),
        mjcf._quad(
            "arm_basetag",
            spec.T_base_tag,
            FACE_PER_MARKER * spec.tag_length,
            f"tag{spec.base_tag_id}",
        ),
        *(mjcf._camera(c) for c in spec.world_cameras),
        mjcf._arm(spec),
        merged[2],  # the last body: every other geom keeps its id
    ]
    sides = {spec.cube_marker, spec.tag_length}
    meshes = "".join(mjcf._quad_mesh(FACE_PER_MARKER * m) for m in sides)
    meshes += _fruit_meshes() + _leaf_meshes() + merged[1]
    meshes += "".join(
        _tube_mesh(
            f"canetube{n_bush + i}", b.points(ROW_CANE_SEGMENTS + 1), _cane_radius(n_bush + i)
        )
        for i, b in enumerate(row.canes)
    )
    return _head(spec, look, meshes, shadows) + "".join(parts) + "</worldbody></mujoco>", assets


def _head(spec: mjcf.SceneSpec, look: RowLook, meshes: str, shadows: bool) -> str:
    # The sky's light: the ambient tinted by the sky (blue under a clear sky, grey under
    # cloud, cold at dusk against the orange sun).
    amb = mjcf._v(look.ambient * (0.6 + 0.4 * look.sky_zenith / look.sky_zenith.max()))
    sun = look.light_colour * look.light_intensity
    pos = CENTRE - 6.0 * look.light_direction  # above the scene, where the sun is
    fill = 0.12 + 0.25 * float(np.mean(look.sky_horizon)) * (look.ambient > 0.4)
    return (
        f'<mujoco model="row"><compiler angle="radian"/>'
        f'<visual><global offwidth="1280" offheight="720"/>'
        f'<quality shadowsize="{SHADOW_SIZE if shadows else 0}" '
        f'offsamples="{mjcf.OFFSCREEN_SAMPLES}" numslices="{NUMSLICES}" numstacks="{NUMSTACKS}"/>'
        f'<headlight ambient="{amb}" diffuse="0 0 0" specular="0 0 0"/>'
        f'<map znear="0.005" zfar="40" shadowclip="1.2"/></visual>'
        f'<statistic extent="{EXTENT}" center="{mjcf._v(CENTRE)}"/>'
        f"<asset>{mjcf._tag_materials(spec)}{meshes}{_materials(look)}</asset><worldbody>"
        f'<light name="sun" directional="true" castshadow="{str(shadows).lower()}" '
        f'pos="{mjcf._v(pos)}" dir="{mjcf._v(look.light_direction)}" '
        f'diffuse="{mjcf._v(sun)}" specular="{mjcf._v(sun * 0.9)}"/>'
        f'<light name="sky" directional="true" castshadow="false" pos="0 0 6" dir="0 0.3 -1" '
        f'diffuse="{fill:.3g} {fill:.3g} {fill * 1.05:.3g}" specular="0 0 0"/>'
    )


def _materials(look: RowLook) -> str:
    spec, shine = look.fruit_specular, look.fruit_shininess
    sky1, sky2 = mjcf._v(look.sky_zenith), mjcf._v(look.sky_horizon)
    ripe = "".join(
        f'<material name="ripe{k}" specular="{min(1.0, spec * f):.3g}" '
        f'shininess="{min(1.0, shine * g):.3g}"/>'
        for k, (f, g) in enumerate([(0.8, 0.9), (1.0, 1.0), (1.2, 1.1)])
    )
    soil = mjcf._v(look.ground_colour)
    soil2 = mjcf._v(look.ground_colour * 0.6)
    return (
        f'<texture name="sky" type="skybox" builtin="gradient" rgb1="{sky1}" rgb2="{sky2}" '
        f'width="256" height="256"/>'
        f'<texture name="soil" type="2d" builtin="flat" rgb1="{soil}" rgb2="{soil2}" '
        f'mark="random" random="0.25" markrgb="{soil2}" width="512" height="512"/>'
        f'<material name="soil" texture="soil" texrepeat="80 80" specular="0.05"/>'
        f'<texture name="leafvein" type="2d" file="leafvein.png"/>'
        f'<material name="leaf" texture="leafvein" specular="0.25" shininess="0.3"/>'
        f'<material name="deadleaf" texture="leafvein" specular="0.5" shininess="0.6"/>'
        f'<texture name="hedge" type="2d" file="hedge.png"/>'
        f'<material name="hedge" texture="hedge" texrepeat="12 4" specular="0.1"/>'
        f'{ripe}<material name="waxy" specular="0.35" shininess="0.45"/>'
        f'<material name="plastic" specular="0.6" shininess="0.7"/>'
    )


def _ground(look: RowLook, rng: np.random.Generator) -> str:
    """Soil, black plastic mulch along the row's foot and the drip line on it."""
    mulch_y = ROW_Y - 0.05
    black = rng.uniform() < 0.6  # black plastic; else dark wood-chip mulch
    colour = np.array([0.05, 0.05, 0.055]) if black else np.array([0.16, 0.11, 0.07])
    return (
        f'<geom name="bg_ground" type="plane" size="40 40 {GROUND_GRID}" pos="0 0.5 {GROUND_Z}" '
        f'material="soil" rgba="{mjcf._rgba(look.ground_colour * 1.6)}"/>'
        f'<geom name="clutter_mulch0" type="box" size="{ROW_HALF + 0.6} 0.4 0.002" '
        f'pos="0 {mulch_y} {GROUND_Z + 0.002}" material="plastic" rgba="{mjcf._rgba(colour)}" '
        f'group="2" contype="0" conaffinity="0"/>'
        f'<geom name="clutter_drip0" type="capsule" size="0.008 {ROW_HALF + 0.6}" '
        f'pos="0 {ROW_Y - 0.25} {GROUND_Z + 0.012}" quat="0.7071068 0 0.7071068 0" '
        f'material="plastic" rgba="0.03 0.03 0.03 1" group="2" contype="0" conaffinity="0"/>'
    )


def _trellis() -> str:
    """Wooden posts and the galvanised wires between them; the hedge's shadowed depth
    behind its canes (a textured slab)."""
    top = 1.0
    half = 0.5 * (top - GROUND_Z)
    posts = "".join(
        f'<geom name="bg_post{k}" type="box" size="0.035 0.035 {half:.4g}" '
        f'pos="{x} {ROW_Y} {GROUND_Z + half:.4g}" rgba="0.45 0.36 0.26 1" group="2" '
        f'contype="0" conaffinity="0"/>'
        for k, x in enumerate(POSTS_X)
    )
    wires = "".join(
        f'<geom name="bg_wire{k}" type="capsule" size="0.0015 {ROW_HALF + 0.4}" '
        f'pos="0 {ROW_Y - 0.04} {z}" quat="0.7071068 0 0.7071068 0" rgba="0.62 0.63 0.65 1" '
        f'group="2" contype="0" conaffinity="0"/>'
        for k, z in enumerate(WIRES_Z)
    )
    depth = (
        f'<geom name="bg_hedge" type="box" size="{ROW_HALF + 0.6} 0.05 0.7" '
        f'pos="0 {ROW_Y + 0.3} 0.3" material="hedge" rgba="0.6 0.6 0.6 1"/>'
    )
    return posts + wires + depth


def _next_row(look: RowLook, rng: np.random.Generator) -> str:
    """The next row, 2.8 m behind: its hedge and a few big foliage masses."""
    y = ROW_Y + 2.8
    out = [
        f'<geom name="bg_nextrow" type="box" size="30 0.25 0.75" pos="0 {y} 0.3" '
        f'material="hedge" rgba="0.7 0.75 0.7 1"/>'
    ]
    for k in range(24):
        pos = np.array([rng.uniform(-8, 3), y - rng.uniform(0.2, 0.4), rng.uniform(-0.2, 1.0)])
        size = rng.uniform(0.12, 0.3, 3)
        colour = look.leaf_colour * rng.uniform(0.5, 1.0)
        out.append(
            f'<geom name="bg_nextrow{k}" type="ellipsoid" size="{mjcf._v(size)}" '
            f'pos="{mjcf._v(pos)}" rgba="{mjcf._rgba(colour)}"/>'
        )
    return "".join(out)


def _fruit(fruit: RowFruit, look: RowLook, rng: np.random.Generator) -> str:
    """A fruit hanging down: a core and its drupelets (one mesh, two for turning fruit:
    a red part and a black part)."""
    b = int(np.argmin(np.abs(FRUIT_BINS - fruit.scale)))
    half = mjcf.BERRY_HALF * FRUIT_BINS[b]
    tag = fruit.fruit_id
    if fruit.stage == "ripe":
        colours, material = [look.ripe_shade(rng)], f"ripe{int(rng.integers(3))}"
    elif fruit.stage == "green":
        colours, material = [_mix(rng, [0.45, 0.65, 0.2], [0.62, 0.72, 0.32])], "waxy"
    elif fruit.stage == "red":
        colours, material = [_mix(rng, [0.62, 0.07, 0.07], [0.42, 0.04, 0.09])], "waxy"
    else:
        red = _mix(rng, [0.55, 0.06, 0.08], [0.38, 0.04, 0.08])
        colours, material = [look.ripe_shade(rng), red], f"ripe{int(rng.integers(3))}"
    mesh = f"fruit{b}" if tag < ROW_FRUIT_ID else f"fruitc{b}"
    meshes = [mesh] if len(colours) == 1 else [f"{mesh}_low", f"{mesh}_high"]
    out = [
        f'<body name="berry{tag}" pos="{mjcf._v(fruit.position)}">'
        f'<geom name="berry{tag}_0" type="ellipsoid" size="{mjcf._v(half * 0.9)}" '
        f'rgba="{mjcf._rgba(colours[0] * 0.7)}" material="{material}" group="1" '
        f'contype="0" conaffinity="0"/>'
    ]
    for k, (mesh, colour) in enumerate(zip(meshes, colours, strict=True)):
        out.append(
            f'<geom name="berry{tag}_{k + 1}" type="mesh" mesh="{mesh}" '
            f'rgba="{mjcf._rgba(colour)}" material="{material}" group="1" '
            f'contype="0" conaffinity="0"/>'
        )
    out.append("</body>")
    return "".join(out)


def _coarse_sphere() -> tuple[FloatArray, npt.NDArray[np.int64]]:
    """The unit icosahedron (12 vertices, 20 faces outward): the row's own fruit's
    drupelets, a few pixels each in C1."""
    vertices = mjcf.ICOSPHERE[0][:12]  # the subdivided sphere keeps them first
    faces = ConvexHull(vertices).simplices
    normals = np.cross(
        vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]]
    )
    inward = np.einsum("ij,ij->i", normals, vertices[faces].mean(axis=1)) < 0
    faces[inward] = faces[inward][:, ::-1]
    return vertices, faces.astype(np.int64)


def _fruit_meshes() -> str:
    """Each size bin's drupelets: all of them, and split into the part below and above
    the fruit's middle (turning fruit); 80-face drupelets for the bush's berries (C2
    sees them from a few centimetres), 20-face ones for the row's (``fruitc``): the
    row's 30-70 fruit were most of its triangles, drawn twice with the shadow map."""
    return _drupelet_meshes("fruit", mjcf.ICOSPHERE) + _drupelet_meshes("fruitc", _coarse_sphere())


def _drupelet_meshes(prefix: str, sphere: tuple[FloatArray, npt.NDArray[np.int64]]) -> str:
    out = []
    vertices, faces = sphere
    golden = np.pi * (3.0 - np.sqrt(5.0))
    for b, scale in enumerate(FRUIT_BINS):
        half = mjcf.BERRY_HALF * scale
        centres = []
        for k in range(ROW_DRUPELETS):
            z = 1 - 2 * (k + 0.5) / ROW_DRUPELETS
            r = np.sqrt(1 - z * z)
            centres.append(
                np.array([r * np.cos(golden * k), r * np.sin(golden * k), z]) * half * 0.86
            )
        radius = half[0] * 0.32
        parts = {
            f"{prefix}{b}": centres,
            f"{prefix}{b}_low": [c for c in centres if c[2] < 0.1 * half[2]],
            f"{prefix}{b}_high": [c for c in centres if c[2] >= 0.1 * half[2]],
        }
        for name, cs in parts.items():
            verts = np.vstack([vertices * radius + c for c in cs])
            faces_all = np.vstack([faces + k * len(vertices) for k in range(len(cs))])
            out.append(
                f'<mesh name="{name}" vertex="{mjcf._v(verts.ravel())}" '
                f'face="{" ".join(str(i) for i in faces_all.ravel())}"/>'
            )
    return "".join(out)


def _cane_radius(index: int) -> float:
    """A cane's radius, as :func:`softarm.sim.render.mjcf._cane` draws it."""
    return 0.0025 + 0.0015 * ((index * 7919) % 100) / 100.0


def _row_cane(index: int, points: FloatArray, look: RowLook) -> str:
    """A row cane: its first segment a capsule (``cane{i}_0``, whose radius the dataset
    reads), the whole cane one six-sided tube mesh (``canetube{i}``): a capsule chain
    costs the rasteriser a few hundred triangles a segment."""
    rgba = mjcf._rgba(look.cane_colour * (0.85 + 0.3 * ((index * 31) % 10) / 10))
    radius = _cane_radius(index)
    return mjcf._capsule(f"cane{index}_0", points[0], points[1], radius, rgba) + (
        f'<geom name="cane{index}_1" type="mesh" mesh="canetube{index}" rgba="{rgba}" '
        f'group="2" contype="0" conaffinity="0"/>'
    )


def _tube_mesh(name: str, points: FloatArray, radius: float, sides: int = 6) -> str:
    """A tube of ``radius`` along ``points`` (N, 3) as a mesh asset, open at its ends,
    its faces outward."""
    tangents = np.gradient(points, axis=0)
    rings = []
    for p, t in zip(points, tangents, strict=True):
        R = mjcf.z_to(t)
        angles = np.arange(sides) * 2 * np.pi / sides
        ring = np.column_stack([np.cos(angles), np.sin(angles), np.zeros(sides)]) * radius
        rings.append(ring @ R.T + p)
    verts = np.vstack(rings)
    faces = []
    for i in range(len(points) - 1):
        for k in range(sides):
            a, b = i * sides + k, i * sides + (k + 1) % sides
            faces += [(a, b, b + sides), (a, b + sides, a + sides)]
    return (
        f'<mesh name="{name}" inertia="shell" vertex="{mjcf._v(verts.ravel())}" '
        f'face="{" ".join(str(i) for i in np.array(faces).ravel())}"/>'
    )


def leaf_outline(length: float, stations: int = 9) -> tuple[FloatArray, FloatArray]:
    """A leaflet's midrib and one edge: (stations, 3) points each, along +x from its base
    (0) to its tip (``length``); the edge serrated, the blade folded a little along
    the midrib (the midrib raised)."""
    t = np.linspace(0.0, 1.0, stations)
    width = 0.3 * length * np.sin(np.pi * t**0.75) * np.where(np.arange(stations) % 2, 0.88, 1.0)
    midrib = np.column_stack(
        [t * length, np.zeros(stations), 0.08 * width.max() * np.sin(np.pi * t)]
    )
    edge = np.column_stack([t * length, width, np.zeros(stations)])
    return midrib, edge


def _leaf_meshes() -> str:
    """A leaflet mesh per size bin: the blade on both sides of the midrib, top and
    bottom faces (0.4 mm apart) with texture coordinates on the vein texture."""
    out = []
    for b, length in enumerate(LEAF_BINS):
        midrib, edge = leaf_outline(float(length))
        n = len(midrib)
        right = edge * np.array([1.0, -1.0, 1.0])
        top = np.vstack([midrib, edge, right]) - np.array([0.5 * length, 0.0, 0.0])
        bottom = top - np.array([0.0, 0.0, 0.0004])
        verts = np.vstack([top, bottom])
        uv = np.column_stack([0.5 + top[:, 1] / (0.62 * length), 1.0 - top[:, 0] / length - 0.5])
        uv = np.clip(np.vstack([uv, uv]), 0.0, 1.0)
        faces = []
        for i in range(n - 1):
            m0, m1, l0, l1, r0, r1 = i, i + 1, n + i, n + i + 1, 2 * n + i, 2 * n + i + 1
            faces += [(m0, l0, l1), (m0, l1, m1), (m0, r1, r0), (m0, m1, r1)]
        front = np.array(faces)
        back = front[:, ::-1] + len(top)
        out.append(
            f'<mesh name="leaflet{b}" inertia="shell" vertex="{mjcf._v(verts.ravel())}" '
            f'texcoord="{mjcf._v(uv.ravel())}" '
            f'face="{" ".join(str(i) for i in np.vstack([front, back]).ravel())}"/>'
        )
    return "".join(out)


def _leaflets(row: Row, look: RowLook, rng: np.random.Generator) -> str:
    out = []
    dead_k = 0
    for k, leaf in enumerate(row.leaflets):
        b = int(np.argmin(np.abs(LEAF_BINS - leaf.length)))
        if leaf.dead:  # dry and dark: a look-alike of ripe fruit
            colour = _mix(rng, [0.10, 0.07, 0.05], [0.20, 0.13, 0.08])
            name, material = f"clutter_deadleaf{dead_k}", "deadleaf"
            dead_k += 1
        else:
            colour = (
                look.leaf_colour
                * rng.uniform(0.6, 1.25)
                * np.array([1.0, rng.uniform(0.9, 1.1), 1.0])
            )
            name, material = f"leaf{k}", "leaf"
        out.append(
            f'<geom name="{name}" type="mesh" mesh="leaflet{b}" material="{material}" '
            f'pos="{mjcf._v(leaf.centre)}" quat="{mjcf._quat(leaf.rotation)}" '
            f'rgba="{mjcf._rgba(colour)}" group="2" contype="0" conaffinity="0"/>'
        )
    return "".join(out)


def _stones(row: Row, rng: np.random.Generator) -> str:
    out = []
    for k, (x, y, r) in enumerate(row.stones):
        grey = rng.uniform(0.08, 0.4) * np.array(
            [1.0, rng.uniform(0.95, 1.05), rng.uniform(0.9, 1.1)]
        )
        size = r * np.array([1.0, rng.uniform(0.7, 1.0), rng.uniform(0.5, 0.8)])
        out.append(
            f'<geom name="clutter_stone{k}" type="ellipsoid" size="{mjcf._v(size)}" '
            f'pos="{x:.4g} {y:.4g} {GROUND_Z + 0.5 * size[2]:.4g}" rgba="{mjcf._rgba(grey)}" '
            f'material="waxy" group="2" contype="0" conaffinity="0"/>'
        )
    return "".join(out)


def _leaf_png() -> bytes:
    """The vein texture (multiplied by each leaflet's colour): a light midrib down the
    middle, lateral veins running out to the edge, the blade slightly mottled."""
    h, w = 256, 128
    img = np.full((h, w), 200, np.uint8)
    noise = np.random.default_rng(7).normal(0, 6, (h // 8, w // 8))
    img = np.clip(img + cv2.resize(noise, (w, h)), 0, 255).astype(np.uint8)
    cv2.line(img, (w // 2, 0), (w // 2, h), 255, 3)
    for v in range(20, h - 10, 22):
        cv2.line(img, (w // 2, v), (2, v - 30), 240, 1)
        cv2.line(img, (w // 2, v), (w - 3, v - 30), 240, 1)
    ok, png = cv2.imencode(".png", cv2.cvtColor(img, cv2.COLOR_GRAY2BGR))
    return png.tobytes() if ok else b""


def _hedge_png(look: RowLook, rng: np.random.Generator) -> bytes:
    """The hedge's shadowed depth: leaves over leaves and dark gaps."""
    h = w = 256
    leaf = np.asarray(look.leaf_colour)[::-1] * 255  # BGR
    img = np.zeros((h, w, 3), np.uint8) + (leaf * 0.15).astype(np.uint8)
    for _ in range(260):
        c = (int(rng.integers(w)), int(rng.integers(h)))
        axes = (int(rng.integers(6, 16)), int(rng.integers(3, 8)))
        shade = leaf * rng.uniform(0.25, 0.8)
        cv2.ellipse(img, c, axes, float(rng.uniform(0, 180)), 0, 360, shade.tolist(), -1)
    ok, png = cv2.imencode(".png", img)
    return png.tobytes() if ok else b""
