"""What C1 sees of the rig itself, for the robot self-filter of the cane fits: both
rigs (the rendered bush and the arm) leave out a fitted curve that is the arm, its
cube or the base tag, and canes out of the arm's reach."""

from __future__ import annotations

import numpy as np

from softarm._core import SoftArm
from softarm.checks import FloatArray
from softarm.harvest_config import HarvestConfig
from softarm.vision.cube import MarkerCube
from softarm.vision.marker_body import panel_corners

__all__ = ["BODY_BOX", "CANE_REACH", "SELF_MARGIN", "a_cane", "rig_parts"]

#: Canes farther than this (m) from the base cannot be touched by the arm (it is
#: 0.56 m long); the map leaves them out.
CANE_REACH = 0.75

#: How near (m) a fitted curve may come to the rig's own parts and still be a cane.
SELF_MARGIN = 0.06


#: Half the side (m) of the box around the marker body's origin that is always the rig's:
#: the paper's cube and its tags.
BODY_BOX = 0.05


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
