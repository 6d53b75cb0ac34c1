"""The marker bodies a gripper can carry for C1 to track: the paper's cube, or a frustum.

A marker body is a :class:`~softarm.vision.cube.MarkerCube` (a rigid set of square tags,
id → pose in the body frame); this module names the bodies and lays out their tags.

- ``"cube"``: the paper's cube, four tags on the side faces (normals ±x, ±y), the ends
  open (the arm runs through it, C2 looks out of its front). Seen along the approach,
  from near its open back end, every tag is 50–70° from facing C1.
- ``"frustum"``: the same four tags on the faces of a truncated square pyramid that
  widens towards the gripper (+z), each face tilted :data:`FRUSTUM_TILT_DEG` back
  towards the arm (-z): some tag is within about 45° of facing a camera anywhere
  from 15° to 75° off the body's back axis, where the cube needs 90° (docs/hardware.md).

In both, each tag's y axis points towards the body's front (+z) and the tags are printed
on squares :data:`~softarm.vision.cube.FACE_PER_MARKER` times their side.
"""

from __future__ import annotations

import itertools

import numpy as np

from softarm.errors import ConfigError
from softarm.vision._checks import FloatArray, positive
from softarm.vision.cube import FACE_PER_MARKER, MarkerCube

__all__ = [
    "FRUSTUM_TILT_DEG",
    "MARKER_BODIES",
    "SIMULATED_BODY",
    "body_markers",
    "check_marker_body",
    "marker_body",
    "overlapping_panels",
    "panel_corners",
]

#: The marker bodies by name (``marker_body`` in hw.toml's [calibration], ``--marker-body``).
MARKER_BODIES = ("cube", "frustum")
#: The body the simulator's rig carries unless told otherwise (``--marker-body``,
#: ``SimRigOptions.marker_body``): the frustum, which C1 sees within about 45° from every
#: approach of the harvest. The hardware's default stays the paper's cube (hw.toml's
#: ``[calibration] marker_body``): an hw.toml without the key belongs to an arm built
#: with a cube.
SIMULATED_BODY = "frustum"
#: How far (degrees) the frustum's faces lean back from the cube's towards the arm: C1
#: sees the body from 30–62° off its back axis in the harvest's poses (rendered bushes
#: 400–409), and 40° puts the worst tag angle over all azimuths under 40° there.
FRUSTUM_TILT_DEG = 40.0
#: The frustum's panels stand this much apart (share of the geometric minimum) so that
#: neighbouring panels do not touch at their back corners.
FRUSTUM_CLEARANCE = 1.04


def check_marker_body(name: object, key: str = "marker_body") -> str:
    """``name`` if it names a marker body, else a :class:`ConfigError` naming ``key``."""
    if not isinstance(name, str) or name not in MARKER_BODIES:
        raise ConfigError(f"{key} must be one of {', '.join(MARKER_BODIES)}, got {name!r}")
    return name


def body_markers(
    name: str, marker_length: float, ids: tuple[int, int, int, int] = (0, 1, 2, 3)
) -> dict[int, FloatArray]:
    """Marker id → (4, 4) pose of the tag in the body frame (z out of the tag, y towards
    the body's front), the tags at azimuths 0, 90, 180, 270° in the order of ``ids``."""
    check_marker_body(name, "name")
    length = positive(marker_length, "marker_length")
    side = FACE_PER_MARKER * length
    tilt = np.radians(FRUSTUM_TILT_DEG) if name == "frustum" else 0.0
    # A panel's back corners are side / 2 from its centre line and reach side / 2 · sin t
    # nearer the axis: that far out they clear the next panel's.
    radius = 0.5 * side if tilt == 0.0 else 0.5 * side * (1.0 + np.sin(tilt)) * FRUSTUM_CLEARANCE
    z = np.array([0.0, 0.0, 1.0])
    out = {}
    for k, marker_id in enumerate(ids):
        a = k * np.pi / 2
        radial = np.array([np.cos(a), np.sin(a), 0.0])
        normal = np.cos(tilt) * radial - np.sin(tilt) * z
        up = np.sin(tilt) * radial + np.cos(tilt) * z
        pose = np.eye(4)
        pose[:3, :3] = np.column_stack([np.cross(up, normal), up, normal])
        pose[:3, 3] = radius * radial
        out[marker_id] = pose
    return out


def marker_body(
    name: str = "cube", marker_length: float = 0.08, dictionary: str = "DICT_4X4_50"
) -> MarkerCube:
    """The marker body ``name`` (:data:`MARKER_BODIES`) with tags of side ``marker_length``
    (m); ``"cube"`` is :meth:`MarkerCube.standard`."""
    return MarkerCube(body_markers(name, marker_length), marker_length, dictionary)


def panel_corners(body: MarkerCube) -> FloatArray:
    """(N, 4, 3) corners of each tag's printed square (its quiet zone included) in the
    body frame, in the order of ``sorted(body.markers)``: the body's outline."""
    h = 0.5 * FACE_PER_MARKER * body.marker_length
    square = np.array([[-h, h, 0.0], [h, h, 0.0], [h, -h, 0.0], [-h, -h, 0.0]])
    out = []
    for i in sorted(body.markers):
        pose = body.markers[i]
        out.append(square @ pose[:3, :3].T + pose[:3, 3])
    return np.array(out)


def overlapping_panels(body: MarkerCube, tol: float = 1e-6) -> list[tuple[int, int]]:
    """Pairs of tag ids whose printed squares pass through each other (a body that
    cannot be built); squares meeting along an edge, as the cube's do, do not count
    (each square is shrunk by ``tol`` m before the test)."""
    ids = sorted(body.markers)
    corners = panel_corners(body)
    scale = 1.0 - tol / (0.5 * FACE_PER_MARKER * body.marker_length)
    shrunk = [c.mean(axis=0) + scale * (c - c.mean(axis=0)) for c in corners]
    pairs = []
    for (a, pa), (b, pb) in itertools.combinations(zip(ids, shrunk, strict=True), 2):
        if _squares_meet(pa, pb, tol):
            pairs.append((a, b))
    return pairs


def _squares_meet(quad: FloatArray, square: FloatArray, tol: float) -> bool:
    """Whether the convex ``quad`` (4, 3) and the square ``square`` share a point: the
    segment where ``quad`` crosses the square's plane, clipped to the square."""
    centre = square.mean(axis=0)
    ex, ey = square[1] - square[0], square[0] - square[3]
    half = 0.5 * float(np.linalg.norm(ex))
    ex, ey = ex / np.linalg.norm(ex), ey / np.linalg.norm(ey)
    depth = (quad - centre) @ np.cross(ex, ey)
    if np.all(depth > tol) or np.all(depth < -tol):
        return False
    if np.all(np.abs(depth) <= tol):  # coplanar: no side of either separates them
        qx, qy = quad[1] - quad[0], quad[0] - quad[3]
        return all(
            (quad @ axis).min() < (square @ axis).max()
            and (square @ axis).min() < (quad @ axis).max()
            for axis in (ex, ey, qx, qy)
        )
    points = [p for p, d in zip(quad, depth, strict=True) if abs(d) <= tol]
    for k in range(4):
        d0, d1 = depth[k], depth[(k + 1) % 4]
        if (d0 > tol and d1 < -tol) or (d0 < -tol and d1 > tol):
            points.append(quad[k] + (quad[(k + 1) % 4] - quad[k]) * d0 / (d0 - d1))
    uv = (np.array(points) - centre) @ np.column_stack([ex, ey])
    return _segment_in_square(uv.min(axis=0), uv.max(axis=0), uv, half)


def _segment_in_square(lo: FloatArray, hi: FloatArray, uv: FloatArray, half: float) -> bool:
    """Whether the segment through the points ``uv`` (collinear, in the square's plane)
    reaches into the square |u|, |v| < ``half``: clipped to it, something is left."""
    start, end = uv[np.argmin(uv @ (hi - lo))], uv[np.argmax(uv @ (hi - lo))]
    t0, t1 = 0.0, 1.0
    step = end - start
    for axis in range(2):
        for bound, sign in ((-half, -1.0), (half, 1.0)):
            # the part with sign * (start + t step) <= sign * bound is kept
            p, q = sign * step[axis], sign * (bound - start[axis])
            if p == 0.0:
                if q < 0.0:
                    return False
            elif p > 0.0:
                t1 = min(t1, q / p)
            else:
                t0 = max(t0, q / p)
    return t0 <= t1
