"""The MuJoCo scene (MJCF) of a rendered bush: canes, berries, leaves, clutter, the
background, the arm and its markers, and the cameras.

Geom names carry the ground truth that the renderer's segmentation is read back with
(:mod:`softarm.sim.render.labels`): ``berry{tag}_{k}``, ``cane{i}_{k}``, ``leaf{k}``,
``clutter{k}``, ``arm_*`` and ``bg_*``. The arm is a set of mocap bodies that the
renderer moves each frame; everything else is static. Poses are quaternions throughout,
so MJCF's degree convention never enters.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from xml.sax.saxutils import quoteattr

import cv2
import numpy as np
import numpy.typing as npt
from scipy.spatial.transform import Rotation

from softarm.checks import FloatArray
from softarm.sim.bush import Berry, Bush
from softarm.sim.render.look import BushLook
from softarm.sim.render.row import Row
from softarm.vision.cube import FACE_PER_MARKER
from softarm.vision.dictionaries import get_dictionary
from softarm.vision.marker_body import SIMULATED_BODY, body_markers

__all__ = ["ARM_SEGMENTS_PER_SECTION", "CameraSpec", "SceneSpec", "scene_xml", "z_to"]

#: Capsules drawn along each section's backbone.
ARM_SEGMENTS_PER_SECTION = 5
#: Radius (m) of the drawn arm: actuator centres at 28 mm plus the 8 mm muscles.
ARM_TUBE_RADIUS = 0.036
#: Nominal fruit half-size (m): 1.9 cm across, 2.4 cm long.
BERRY_HALF = np.array([0.0095, 0.0095, 0.012])
DRUPELETS = 26
#: Ripe fruit is glossy, with bright highlights on each drupelet; unripe fruit is waxy.
FRUIT_MATERIALS = (
    '<material name="glossy" specular="0.9" shininess="0.9"/>'
    '<material name="waxy" specular="0.3" shininess="0.4"/>'
)
#: Multisamples per pixel of the offscreen buffer: none. Mesa's software rasteriser
#: shades every sample, and four of them cost as much as the scene's geometry again
#: (a C1 window around the cube: 17 against 10 ms); the cube tracking, the berries
#: and the canes measured alike on the same bushes with and without
#: (docs/perception.md).
OFFSCREEN_SAMPLES = 0
#: OpenCV's camera frame (z forward, y down) in MuJoCo's (z backward, y up).
CV_TO_MJ = np.diag([1.0, -1.0, -1.0])


@dataclass(frozen=True)
class CameraSpec:
    """A pinhole camera for MuJoCo: ``name``, pose ``T_parent_camera`` (OpenCV axes)
    in its parent body, image ``size`` (w, h), focal length and principal point (px,
    OpenCV pixel-centre convention)."""

    name: str
    T_parent_camera: FloatArray
    size: tuple[int, int]
    focal: float
    principal: tuple[float, float]


@dataclass(frozen=True)
class SceneSpec:
    """What goes into the scene: the bush and its look, the cameras fixed in the world
    and those carried by the gripper, the base tag pose and the cube's markers."""

    bush: Bush
    look: BushLook
    world_cameras: Sequence[CameraSpec]
    hand_cameras: Sequence[CameraSpec]
    T_base_tag: FloatArray
    base_tag_id: int
    tag_length: float
    cube_ids: tuple[int, int, int, int] = (0, 1, 2, 3)
    cube_marker: float = 0.08
    #: The gripper's marker body (softarm.vision.marker_body.MARKER_BODIES).
    marker_body: str = SIMULATED_BODY
    n_sections: int = 3
    dictionary: str = "DICT_4X4_50"
    keep_clear: Sequence[tuple[FloatArray, FloatArray]] = field(default_factory=tuple)
    #: The hedgerow around the bush (``--world row``, :mod:`softarm.sim.render.row`;
    #: ``look`` then a ``RowLook``), None for the bush alone; ``shadows``: the row's sun
    #: casts them.
    row: Row | None = None
    shadows: bool = True


def scene_xml(spec: SceneSpec) -> tuple[str, dict[str, bytes]]:
    """The MJCF text of ``spec`` and its texture assets (PNG bytes by file name)."""
    if spec.row is not None:
        from softarm.sim.render.row_mjcf import row_scene_xml

        return row_scene_xml(spec, spec.row, spec.shadows)
    rng = np.random.default_rng([spec.look.seed, 0xB05])
    assets = _tag_assets(spec)
    berries = [_berry(b, spec.look, rng) for b in spec.bush.berries]
    parts = [
        _background(spec.look),
        *(_cane(i, b.points(24), spec.look) for i, b in enumerate(spec.bush.branches)),
        *(body for body, _ in berries),
        _leaves(spec, rng),
        _clutter(spec.look, rng),
        _quad(
            "arm_basetag",
            spec.T_base_tag,
            FACE_PER_MARKER * spec.tag_length,
            f"tag{spec.base_tag_id}",
        ),
        *(_camera(c) for c in spec.world_cameras),
        _arm(spec),
    ]
    look = spec.look
    amb = look.ambient
    meshes = "".join(_quad_mesh(FACE_PER_MARKER * m) for m in {spec.cube_marker, spec.tag_length})
    meshes += "".join(mesh for _, mesh in berries)
    head = (
        f'<mujoco model="bush"><compiler angle="radian"/>'
        f'<visual><global offwidth="1280" offheight="720"/>'
        f'<quality shadowsize="0" offsamples="{OFFSCREEN_SAMPLES}" numslices="14" numstacks="8"/>'
        f'<headlight ambient="{amb} {amb} {amb}" diffuse="0 0 0" specular="0 0 0"/>'
        f'<map znear="0.005" zfar="30"/></visual>'
        f'<statistic extent="1" center="0 0.3 0.3"/>'
        f"<asset>{_tag_materials(spec)}{meshes}{FRUIT_MATERIALS}</asset><worldbody>"
        f'<light directional="true" castshadow="false" dir="{_v(look.light_direction)}" '
        f'diffuse="{_v(look.light_colour * look.light_intensity)}" specular="0.5 0.5 0.5"/>'
    )
    return head + "".join(parts) + "</worldbody></mujoco>", assets


def _icosphere() -> tuple[FloatArray, npt.NDArray[np.int64]]:
    """The unit icosahedron with each face split in four, its new vertices pushed out
    onto the sphere: (42, 3) vertices and (80, 3) faces, counter-clockwise seen from
    outside."""
    t = (1.0 + np.sqrt(5.0)) / 2.0
    verts = [
        (-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
        (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1),
    ]  # fmt: skip
    faces = [
        (0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
        (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
        (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1),
    ]  # fmt: skip
    points = [np.array(v, float) / np.linalg.norm(v) for v in verts]
    middle: dict[tuple[int, int], int] = {}

    def mid(a: int, b: int) -> int:
        key = (min(a, b), max(a, b))
        if key not in middle:
            m = points[a] + points[b]
            points.append(m / np.linalg.norm(m))
            middle[key] = len(points) - 1
        return middle[key]

    split = []
    for a, b, c in faces:
        ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
        split += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
    return np.array(points), np.array(split, dtype=np.int64)


#: The drupelets' sphere (:func:`_sphere_mesh`).
ICOSPHERE = _icosphere()


def _v(x: Sequence[float] | FloatArray) -> str:
    return " ".join(f"{float(a):.6g}" for a in x)


def _rgba(rgb: FloatArray, alpha: float = 1.0) -> str:
    return _v([*np.clip(rgb, 0, 1), alpha])


def _quat(R: FloatArray) -> str:
    x, y, z, w = Rotation.from_matrix(R).as_quat()
    return _v([w, x, y, z])


def z_to(direction: FloatArray) -> FloatArray:
    """A rotation taking +z to ``direction`` (the identity for a zero vector)."""
    n = float(np.linalg.norm(direction))
    if n < 1e-12:
        return np.eye(3)
    rot, _ = Rotation.align_vectors([direction / n], [[0.0, 0.0, 1.0]])
    result: FloatArray = rot.as_matrix()
    return result


def _capsule(name: str, a: FloatArray, b: FloatArray, radius: float, rgba: str) -> str:
    half = 0.5 * float(np.linalg.norm(b - a))
    return (
        f'<geom name="{name}" type="capsule" size="{radius:.6g} {max(half, 1e-4):.6g}" '
        f'pos="{_v(0.5 * (a + b))}" quat="{_quat(z_to(b - a))}" rgba="{rgba}" '
        f'group="2" contype="0" conaffinity="0"/>'
    )


def _background(look: BushLook) -> str:
    """A wall behind the bush and the ground below it (MuJoCo planes)."""
    wall, ground = _rgba(look.background_colour), _rgba(look.ground_colour)
    facing = _quat(np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]]))  # normal -y
    return (
        f'<geom name="bg_wall" type="plane" size="12 6 0.1" pos="0 1.4 0.3" '
        f'quat="{facing}" rgba="{wall}"/>'
        f'<geom name="bg_ground" type="plane" size="12 12 0.1" pos="0 0.5 -0.45" '
        f'rgba="{ground}"/>'
    )


def _cane(index: int, points: FloatArray, look: BushLook) -> str:
    """A cane as capsules along its curve, 5–8 mm across."""
    radius = 0.0025 + 0.0015 * ((index * 7919) % 100) / 100.0
    rgba = _rgba(look.cane_colour)
    return "".join(
        _capsule(f"cane{index}_{k}", points[k], points[k + 1], radius, rgba)
        for k in range(len(points) - 1)
    )


def _berry(berry: Berry, look: BushLook, rng: np.random.Generator) -> tuple[str, str]:
    """A fruit hanging down: an ellipsoid core and drupelets on its surface; the body's
    MJCF and its drupelet mesh's (an asset)."""
    tag, pos = berry.tag_id, berry.position
    ripe = berry.ripeness >= 0.5
    half = BERRY_HALF * rng.uniform(*look.berry_scale)
    drupelet = f"drupelet{tag}"
    colour = look.ripe_colour if ripe else look.unripe_colour(rng)
    spec = 'material="glossy"' if ripe else 'material="waxy"'
    core = colour * 0.8
    out = [
        f'<body name="berry{tag}" pos="{_v(pos)}">'
        f'<geom name="berry{tag}_0" type="ellipsoid" size="{_v(half * 0.9)}" '
        f'rgba="{_rgba(core)}" {spec} group="1" contype="0" conaffinity="0"/>'
    ]
    golden = np.pi * (3.0 - np.sqrt(5.0))
    for k in range(DRUPELETS):  # a Fibonacci lattice on the ellipsoid
        z = 1 - 2 * (k + 0.5) / DRUPELETS
        r = np.sqrt(1 - z * z)
        unit = np.array([r * np.cos(golden * k), r * np.sin(golden * k), z])
        shade = colour * rng.uniform(0.85, 1.15)
        out.append(
            f'<geom name="berry{tag}_{k + 1}" type="mesh" mesh="{drupelet}" '
            f'pos="{_v(unit * half * 0.85)}" rgba="{_rgba(shade)}" {spec} '
            f'group="1" contype="0" conaffinity="0"/>'
        )
    out.append("</body>")
    return "".join(out), _sphere_mesh(drupelet, half[0] * 0.34)


def _sphere_mesh(name: str, radius: float) -> str:
    """A sphere of ``radius`` as a mesh asset: an icosahedron subdivided once (80
    faces). The 26 drupelets of each of a bush's berries are most of its triangles;
    MuJoCo's own spheres (``numslices`` × ``numstacks`` of the scene's quality, 224
    faces) cost the software rasteriser three times as much for a 2-4 px drupelet at
    C1's range, and are no rounder to the eye at C2's few centimetres."""
    vertices, faces = ICOSPHERE
    return (
        f'<mesh name="{name}" vertex="{_v((vertices * radius).ravel())}" '
        f'face="{" ".join(str(i) for i in faces.ravel())}"/>'
    )


def _leaves(spec: SceneSpec, rng: np.random.Generator) -> str:
    """Leaflets (5–10 cm) around each cane, kept out of the approach corridors."""
    out = []
    k = 0
    for branch in spec.bush.branches:
        pts = branch.points(40)
        for _ in range(spec.look.leaves_per_cane):
            centre = pts[rng.integers(len(pts))] + rng.normal(0.0, 0.04, 3)
            length = rng.uniform(0.025, 0.05)
            if any(_near_segment(centre, a, b) < length + 0.02 for a, b in spec.keep_clear):
                continue
            R = Rotation.random(random_state=int(rng.integers(2**31))).as_matrix()
            colour = spec.look.leaf_colour * rng.uniform(0.7, 1.2)
            out.append(
                f'<geom name="leaf{k}" type="ellipsoid" '
                f'size="{_v([length, 0.45 * length, 0.0015])}" '
                f'pos="{_v(centre)}" quat="{_quat(R)}" rgba="{_rgba(colour)}" '
                f'group="2" contype="0" conaffinity="0"/>'
            )
            k += 1
    return "".join(out)


def _clutter(look: BushLook, rng: np.random.Generator) -> str:
    """Dark look-alikes: black mulch and dead leaves on the ground, a black irrigation
    line, dark stones in front of the wall."""
    out = [
        _capsule(f"clutter_line{k}", np.array([x, 0.75, -0.2]), np.array([x + 0.25, 0.75, -0.2]),
                 0.008, _rgba(np.array([0.05, 0.05, 0.05])))
        for k, x in enumerate(np.arange(-1.0, 1.0, 0.25))
    ]  # fmt: skip
    for k in range(look.clutter):
        pos = np.array([rng.uniform(-0.6, 0.6), rng.uniform(0.55, 1.3), rng.uniform(-0.44, 0.6)])
        dark = np.array([0.06, 0.05, 0.06]) * rng.uniform(0.5, 2.0)
        if k % 2:  # a dark round stone or shadowed lump
            shape = f'type="sphere" size="{rng.uniform(0.008, 0.02):.4g}"'
        else:  # a dead leaf or a scrap of mulch
            shape = f'type="ellipsoid" size="{_v([rng.uniform(0.02, 0.05), 0.015, 0.002])}"'
        R = Rotation.random(random_state=int(rng.integers(2**31))).as_matrix()
        out.append(
            f'<geom name="clutter{k}" {shape} pos="{_v(pos)}" quat="{_quat(R)}" '
            f'rgba="{_rgba(dark)}" group="2" contype="0" conaffinity="0"/>'
        )
    return "".join(out)


def _near_segment(p: FloatArray, a: FloatArray, b: FloatArray) -> float:
    ab = b - a
    u = float(np.clip((p - a) @ ab / (ab @ ab), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + u * ab)))


def _camera(cam: CameraSpec) -> str:
    """A camera from OpenCV intrinsics. MuJoCo takes the principal point as the offset of
    the image centre from it; OpenCV's is measured from the top-left pixel's centre."""
    w, h = cam.size
    dx = cam.principal[0] - (w - 1) / 2
    dy = cam.principal[1] - (h - 1) / 2
    R = cam.T_parent_camera[:3, :3] @ CV_TO_MJ
    return (
        f'<camera name="{cam.name}" pos="{_v(cam.T_parent_camera[:3, 3])}" quat="{_quat(R)}" '
        f'resolution="{w} {h}" sensorsize="{w * 1e-6:.6g} {h * 1e-6:.6g}" '
        f'focalpixel="{cam.focal:.6g} {cam.focal:.6g}" principalpixel="{-dx:.6g} {-dy:.6g}"/>'
    )


def _arm(spec: SceneSpec) -> str:
    """Mocap bodies for the arm: capsules along the backbone, the plates at the section
    ends, the gripper with its fingers and the hand cameras, and the marker cube."""
    grey, dark = "0.82 0.82 0.80 1", "0.25 0.25 0.27 1"
    out = []
    for k in range(spec.n_sections * ARM_SEGMENTS_PER_SECTION):
        out.append(
            f'<body name="arm_seg{k}" mocap="true"><geom name="arm_seg{k}" type="cylinder" '
            f'size="{ARM_TUBE_RADIUS} 0.01" rgba="0.70 0.68 0.62 1" group="2" '
            f'contype="0" conaffinity="0"/></body>'
        )
    for k in range(spec.n_sections + 1):
        out.append(
            f'<body name="arm_plate{k}" mocap="true"><geom name="arm_plate{k}" type="cylinder" '
            f'size="0.045 0.004" rgba="{grey}" group="2" contype="0" conaffinity="0"/></body>'
        )
    fingers = "".join(
        f'<geom name="arm_finger{i}" type="box" size="0.004 0.006 0.022" '
        f'pos="{_v([0.024 * np.cos(a), 0.024 * np.sin(a), 0.022])}" '
        f'quat="{_quat(Rotation.from_euler("z", a).as_matrix())}" rgba="{dark}" '
        f'group="2" contype="0" conaffinity="0"/>'
        for i, a in enumerate(np.arange(3) * 2 * np.pi / 3 + np.pi / 2)
    )
    cams = "".join(_camera(c) for c in spec.hand_cameras)
    out.append(f'<body name="arm_ee" mocap="true">{fingers}{cams}</body>')
    s = FACE_PER_MARKER * spec.cube_marker
    poses = body_markers(spec.marker_body, spec.cube_marker, spec.cube_ids)
    faces = "".join(_quad(f"arm_cubeface{i}", poses[i], s, f"tag{i}") for i in spec.cube_ids)
    # The body's four tagged panels and no lid: C2 looks out through the open end (it
    # sits in the palm, inside the body's outline).
    out.append(f'<body name="arm_cube" mocap="true">{faces}</body>')
    return "".join(out)


def _quad(name: str, pose: FloatArray, side: float, material: str) -> str:
    """A square of side ``side`` at ``pose`` (x right, y up, visible from +z) showing
    ``material``'s texture upright."""
    return (
        f'<geom name="{name}" type="mesh" mesh="{_mesh_name(side)}" material="{material}" '
        f'pos="{_v(pose[:3, 3])}" quat="{_quat(pose[:3, :3])}" group="2" '
        f'contype="0" conaffinity="0"/>'
    )


def _mesh_name(side: float) -> str:
    return f"quad{round(side * 1e4)}"


def _quad_mesh(side: float) -> str:
    """A square of side ``side`` at z = 0 facing +z with texture coordinates (a shell:
    MuJoCo's inertia of a flat mesh)."""
    h = side / 2
    return (
        f'<mesh name="{_mesh_name(side)}" inertia="shell" '
        f'vertex="{_v([-h, -h, 0, h, -h, 0, h, h, 0, -h, h, 0])}" face="0 1 2  0 2 3" '
        'texcoord="0 1  1 1  1 0  0 0"/>'
    )


def _tag_png(dictionary: str, marker_id: int, marker: float, face: float) -> bytes:
    """A marker image with its white quiet zone, ``marker`` m printed on a ``face`` m
    square (the cube's 80 mm tags on 100 mm faces)."""
    cells = get_dictionary(dictionary).markerSize + 2
    per_cell = 24
    bits = cv2.aruco.generateImageMarker(get_dictionary(dictionary), int(marker_id), cells)
    big = np.repeat(np.repeat(bits, per_cell, 0), per_cell, 1)
    pad = round(0.5 * (face - marker) / marker * big.shape[0])
    img = np.pad(big, pad, constant_values=255)
    ok, png = cv2.imencode(".png", cv2.cvtColor(img, cv2.COLOR_GRAY2BGR))
    return png.tobytes() if ok else b""


def _tag_assets(spec: SceneSpec) -> dict[str, bytes]:
    ids = [*spec.cube_ids, spec.base_tag_id]
    lengths = [spec.cube_marker] * 4 + [spec.tag_length]
    return {
        f"tag{i}.png": _tag_png(spec.dictionary, i, m, FACE_PER_MARKER * m)
        for i, m in zip(ids, lengths, strict=True)
    }


def _tag_materials(spec: SceneSpec) -> str:
    ids = [*spec.cube_ids, spec.base_tag_id]
    return "".join(
        f'<texture name="tag{i}" type="2d" file={quoteattr(f"tag{i}.png")}/>'
        f'<material name="tag{i}" texture="tag{i}" specular="0" shininess="0"/>'
        for i in ids
    )
