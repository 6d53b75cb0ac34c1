"""Clearance between the arm's body and the canes.

The arm is its three arcs, each with the section's body radius (actuator ring radius +
actuator radius), plus the gripper, a cylinder from the distal plate to the grasp point.
The arc-to-cane distance is exact (``softarm.closest``, planning paper eq. 12–18); the
gripper's straight part is sampled (6 points against canes sampled every ~2 mm). The gap is
distance minus the body radius and the cane radius: below zero the surfaces touch.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from softarm._core import PolynomialCurve, SoftArm, closest
from softarm.checks import FloatArray

# The radii are defined once in softarm.geometry (the Cosserat plant uses them too).
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
        sections = arm.sections
        self.radii = [s.radius + ACTUATOR_RADIUS + CANE_RADIUS for s in sections]
        self.plate = sections[-1].offset
        self.samples = [c(np.linspace(*c.u_range, 150)) for c in self.canes]  # (150, 3) each

    def gap(self, q: FloatArray) -> float:
        """Smallest surface gap (m) at ``q``; inf without canes; < 0 means contact."""
        if not self.canes:
            return float("inf")
        gaps = []
        for cane in self.canes:
            c = closest(self.arm, q, cane)
            gaps.append(c.distance - self.radii[c.section])
        ee = self.arm.forward(q)
        tip = ee[:3, 3] + np.outer(np.linspace(-self.plate, self.offset, 6), ee[:3, 2])
        pts = np.concatenate(self.samples)
        d = np.linalg.norm(tip[:, None, :] - pts[None], axis=2).min()
        gaps.append(float(d) - GRIPPER_RADIUS - CANE_RADIUS)
        return float(min(gaps))

    def path_gap(self, q0: FloatArray, q1: FloatArray, steps: int = 12) -> float:
        """Smallest gap along the straight line from ``q0`` to ``q1`` in actuator space."""
        return float(np.min(self.gaps_along(q0, q1, steps)))

    def gaps_along(self, q0: FloatArray, q1: FloatArray, steps: int = 12) -> FloatArray:
        """The gaps (m) at ``steps`` evenly spaced points of the straight line from ``q0``
        to ``q1`` in actuator space, both ends included."""
        return np.array([self.gap(q0 + t * (q1 - q0)) for t in np.linspace(0.0, 1.0, steps)])
