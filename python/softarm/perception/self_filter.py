"""What C1 sees of the rig itself, for the robot self-filter of the cane fits: both
rigs (the rendered bush and the arm) leave out a fitted curve that is the arm, its
cube or the base tag, and canes out of the arm's reach."""

from __future__ import annotations

import numpy as np

from softarm._core import SoftArm
from softarm.checks import FloatArray
from softarm.harvest_config import HarvestConfig

__all__ = ["CANE_REACH", "SELF_MARGIN", "a_cane", "rig_parts"]

#: Canes farther than this (m) from the base cannot be touched by the arm (it is
#: 0.56 m long); the map leaves them out.
CANE_REACH = 0.75

#: How near (m) a fitted curve may come to the rig's own parts and still be a cane.
SELF_MARGIN = 0.06


def rig_parts(
    model: SoftArm, cfg: HarvestConfig, T_ee_cube: FloatArray, T_base_tag: FloatArray | None
) -> FloatArray:
    """(N, 3) points of what C1 sees of the rig itself when it looks (the arm's model
    at rest and at home, its cube, the base tag when its pose is known), in the base
    frame."""
    parts = []
    for q in (np.zeros(model.n_actuators), np.full(model.n_actuators, cfg.home_elongation)):
        parts.append(model.backbone(q, 12))
        cube = model.forward(q) @ T_ee_cube
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
        parts.append(cube[:3, 3] + 0.05 * corners @ cube[:3, :3].T)
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
