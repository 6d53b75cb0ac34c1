"""Clearance between the arm's body and the canes.

The body is the core's one description of it, :class:`softarm._core.Body`
(``crates/softarm-core/src/body.rs``): each section's arc with the section's body radius
(actuator ring radius + actuator radius), the inner sections' end plates, and the gripper,
a capsule from the distal arc's tip to the grasp point. The gap is exact for every piece
(the backbone-to-cane distance of ``softarm.closest``, planning paper eq. 12–18) less the
piece's radius and the cane's: below zero the surfaces touch. The Cosserat rod's ground
truth (``softarm.sim.cosserat.clearance``) measures the same radii and gripper.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from softarm._core import Body, PolynomialCurve, SoftArm
from softarm.checks import FloatArray

# The radii are declared once, in the core (softarm.geometry re-exports them).
from softarm.geometry import ACTUATOR_RADIUS, CANE_RADIUS, GRIPPER_RADIUS

__all__ = ["ACTUATOR_RADIUS", "CANE_RADIUS", "GRIPPER_RADIUS", "Clearance"]


class Clearance:
    """Smallest surface gap between an arm (``SoftArm``) at q and the canes.

    Args:
        arm: the arm (the true one for ground truth, the model for planning).
        canes: the canes as ``softarm.PolynomialCurve``.
        grasp_offset: the gripper reaches this far (m) ahead of the end-effector frame.
    """

    def __init__(self, arm: SoftArm, canes: Sequence[PolynomialCurve], grasp_offset: float) -> None:
        self.arm, self.canes, self.offset = arm, list(canes), grasp_offset
        self.body = Body.for_arm(arm, grasp_offset)

    def gap(self, q: FloatArray) -> float:
        """Smallest surface gap (m) at ``q``; inf without canes; < 0 means contact."""
        return self.body.gap(self.arm, q, self.canes, CANE_RADIUS)

    def path_gap(self, q0: FloatArray, q1: FloatArray, steps: int = 12) -> float:
        """Smallest gap along the straight line from ``q0`` to ``q1`` in actuator space."""
        return float(np.min(self.gaps_along(q0, q1, steps)))

    def gaps_along(self, q0: FloatArray, q1: FloatArray, steps: int = 12) -> FloatArray:
        """The gaps (m) at ``steps`` evenly spaced points of the straight line from ``q0``
        to ``q1`` in actuator space, both ends included."""
        return np.array([self.gap(q0 + t * (q1 - q0)) for t in np.linspace(0.0, 1.0, steps)])
