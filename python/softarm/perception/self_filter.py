"""What C1 sees of the rig itself, for the robot self-filter of the cane fits: both
rigs (the rendered bush and the arm) leave out a fitted curve that is the arm, its
cube or the base tag, and canes out of the arm's reach; and, before the fit, every cane
point C1 could only have seen through the rig (:func:`behind_rig`)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm._core import SoftArm
from softarm.checks import FloatArray, as_array, finite_real, numeric_array
from softarm.errors import ParameterError, ShapeError
from softarm.harvest_config import HarvestConfig
from softarm.vision.cube import MarkerCube
from softarm.vision.marker_body import panel_corners

__all__ = [
    "BODY_BOX",
    "CANE_REACH",
    "SELF_MARGIN",
    "SIGHT_MARGIN",
    "TUBE_RADIUS",
    "a_cane",
    "behind_rig",
    "rig_outline",
    "rig_parts",
]

#: Canes farther than this (m) from the base cannot be touched by the arm (it is
#: 0.56 m long); the map leaves them out.
CANE_REACH = 0.75

#: How near (m) a fitted curve may come to the rig's own parts and still be a cane.
SELF_MARGIN = 0.06


#: Half the side (m) of the box around the marker body's origin that is always the rig's:
#: the paper's cube and its tags.
BODY_BOX = 0.05

#: The radius (m) of the arm's tube, as built (docs/hardware.md) and as the simulator
#: draws it.
TUBE_RADIUS = 0.036

#: How far (m) outside the rig's outline a sight line must pass for what lies along it to
#: be seen: a little more than the outline's own error (the true arm at rest against
#: the model's, a few millimetres).
SIGHT_MARGIN = 0.01

#: The step (m) of the grid of spheres that covers each tag plate of the outline.
_PLATE_STEP = 0.01


def rig_parts(
    model: SoftArm,
    cfg: HarvestConfig,
    T_ee_cube: FloatArray,
    T_base_tag: FloatArray | None,
    body: MarkerCube | None = None,
) -> FloatArray:
    """(N, 3) points of what C1 sees of the rig itself when it looks (the arm's model
    at rest and at home, its marker body, the base tag when its pose is known), in the
    base frame. The body is the cube's box, and the corners of ``body``'s tag plates
    that reach beyond it (the frustum's plates lean out about 7 cm further)."""
    corners = BODY_BOX * np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
    plates = np.zeros((0, 3)) if body is None else panel_corners(body).reshape(-1, 3)
    beyond = plates[np.max(np.abs(plates), axis=1) > BODY_BOX + 1e-9]
    parts = []
    for q in (np.zeros(model.n_actuators), np.full(model.n_actuators, cfg.home_elongation)):
        parts.append(model.backbone(q, 12))
        cube = model.forward(q) @ T_ee_cube
        parts.append(cube[:3, 3] + np.vstack([corners, beyond]) @ cube[:3, :3].T)
    if T_base_tag is not None:
        square = np.array([[x, y, 0.0] for x in (-1, 0, 1) for y in (-1, 0, 1)]) * 0.05
        parts.append(T_base_tag[:3, 3] + square @ T_base_tag[:3, :3].T)
    return np.vstack(parts)


def a_cane(points: FloatArray, parts: FloatArray, reach: float) -> bool:
    """Whether a fitted curve's ``points`` (N, 3) are a cane: none within SELF_MARGIN
    of the rig's ``parts``, some within ``reach`` (m) of the base."""
    gaps = np.linalg.norm(points[:, None, :] - parts[None, :, :], axis=2)
    in_reach = np.linalg.norm(points, axis=1) <= reach
    return bool(gaps.min() > SELF_MARGIN and in_reach.any())


def rig_outline(
    model: SoftArm, q: FloatArray, T_ee_cube: FloatArray, body: MarkerCube
) -> FloatArray:
    """(N, 4) spheres (centre in the base frame, radius; m) that cover what of the rig
    stands in front of the bush at ``q``: the arm's tube along its backbone and each
    tag plate of ``body`` (the cube's faces, the frustum's leaning plates)."""
    spine = np.asarray(model.backbone(np.asarray(q, np.float64), 40))
    plates = panel_corners(body)
    side = float(np.linalg.norm(plates[0, 1] - plates[0, 0]))
    n = max(1, int(np.ceil(side / _PLATE_STEP)))
    share = (np.arange(n) + 0.5) / n  # the centres of n x n cells; a sphere covers each
    a, b = np.meshgrid(share, share)
    a, b = a.ravel()[:, None], b.ravel()[:, None]
    grid = [p[0] + a * (p[1] - p[0]) + b * (p[3] - p[0]) for p in plates]
    pose = model.forward(np.asarray(q, np.float64)) @ T_ee_cube
    cover = np.vstack(grid) @ pose[:3, :3].T + pose[:3, 3]
    step = side / n
    return np.vstack([
        np.column_stack([spine, np.full(len(spine), TUBE_RADIUS)]),
        np.column_stack([cover, np.full(len(cover), step / np.sqrt(2.0))]),
    ])  # fmt: skip


def behind_rig(
    points: FloatArray, eyes: FloatArray, outline: FloatArray, margin: float = SIGHT_MARGIN
) -> npt.NDArray[np.bool_]:
    """Whether each of ``points`` (N, 3+; base frame) lies at or behind the rig's
    ``outline`` (:func:`rig_outline`) on its sight line from any of ``eyes`` (K, 3):
    no eye saw it there. A stereo match there is of the rig's own pixels (a plate's dark
    ink or edge) or of a cane one eye could not see, put at some wrong depth behind the
    rig, which the fit-level filter (:func:`a_cane`, by the distance to the rig's parts)
    does not catch.

    Raises:
        InputError: ``points``, ``eyes`` or ``outline`` of the wrong shape or not
            finite (ShapeError, NonFiniteError); ``margin`` not finite and >= 0
            (ParameterError).
    """
    p = numeric_array(points, "points")
    if p.ndim != 2 or p.shape[1] < 3:
        raise ShapeError(f"points must have shape (N, 3) or more columns, got {p.shape}")
    p = as_array(p[:, :3], (None, 3), "points")
    outline = as_array(outline, (None, 4), "outline")
    if not (finite_real(margin) and margin >= 0.0):
        raise ParameterError(f"margin must be finite and >= 0 m, got {margin!r}")
    centres, radii = outline[:, :3], outline[:, 3] + float(margin)
    hidden = np.zeros(len(p), bool)
    for eye in as_array(eyes, (None, 3), "eyes"):
        ray = p - eye
        length = np.linalg.norm(ray, axis=1)
        unit = ray / np.maximum(length, 1e-12)[:, None]
        along = unit @ (centres - eye).T  # (N, M): each sphere's centre along each ray
        off = np.linalg.norm(centres - eye, axis=1) ** 2 - along**2
        blocks = (along > 0.0) & (along < length[:, None] + radii) & (off < radii**2)
        hidden |= blocks.any(axis=1)
    return hidden
