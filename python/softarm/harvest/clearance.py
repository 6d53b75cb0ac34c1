"""Clearance between the arm's body and the canes, as point samples.

The arm is its backbone (``samples`` points per section, each with the section's body
radius: actuator ring radius + actuator radius) plus the gripper from the distal plate to
the grasp point; a cane is sampled along its curve. Distance is centre-line to sample
minus the body radius and the cane radius: below zero the surfaces touch.

This sampled form stands in for the exact arc-to-curve distance of the planning paper
(eq. 10–18) until ``softarm.closest`` is available; with 8 samples per 15 cm section and
canes sampled every few mm it under-estimates the gap by at most ~1 mm.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

__all__ = ["Clearance"]

FloatArray = npt.NDArray[np.float64]

#: Radius (m) of one pneumatic artificial muscle (5/8" braided sleeve, section II-A).
ACTUATOR_RADIUS = 0.008
#: Radius (m) of the gripper with its fingers, around its axis.
GRIPPER_RADIUS = 0.025
#: Radius (m) of a blackberry cane.
CANE_RADIUS = 0.005


class Clearance:
    """Smallest surface gap between an arm (``SoftArm``) at q and the sampled canes.

    Args:
        arm: the arm (the true one for ground truth, the model for planning).
        canes: (m, 3) points along the canes.
        grasp_offset: the gripper reaches this far (m) ahead of the end-effector frame.
        samples: backbone points per section.
    """

    def __init__(
        self, arm: object, canes: Sequence[FloatArray], grasp_offset: float, samples: int = 8
    ) -> None:
        self.arm = arm
        self.canes = np.concatenate(canes) if len(canes) else np.zeros((0, 3))
        self.offset, self.samples = grasp_offset, samples
        body = [s.radius + ACTUATOR_RADIUS for s in arm.sections]  # type: ignore[attr-defined]
        tip = np.full(6, GRIPPER_RADIUS)
        self.radii = np.concatenate([np.repeat(body, samples), tip]) + CANE_RADIUS

    def points(self, q: FloatArray) -> FloatArray:
        """(k, 3) centre-line samples of the arm at ``q``."""
        body = self.arm.backbone(q, self.samples)  # type: ignore[attr-defined]
        ee = self.arm.forward(q)  # type: ignore[attr-defined]
        plate = self.arm.sections[-1].offset  # type: ignore[attr-defined]
        tip = ee[:3, 3] + np.outer(np.linspace(-plate, self.offset, 6), ee[:3, 2])
        return np.concatenate([body, tip])

    def gap(self, q: FloatArray) -> float:
        """Smallest surface gap (m) at ``q``; inf without canes; < 0 means contact."""
        if self.canes.shape[0] == 0:
            return float("inf")
        pts = self.points(q)
        d = np.linalg.norm(pts[:, None, :] - self.canes[None], axis=2).min(axis=1)
        return float(np.min(d - self.radii))

    def path_gap(self, q0: FloatArray, q1: FloatArray, steps: int = 12) -> float:
        """Smallest gap along the straight line from ``q0`` to ``q1`` in actuator space."""
        return min(self.gap(q0 + t * (q1 - q0)) for t in np.linspace(0.0, 1.0, steps))
