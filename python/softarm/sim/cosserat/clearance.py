"""Clearance between the Cosserat rod's body and the canes (ground truth of contact).

The same body as :class:`softarm.harvest.control.clearance.Clearance`, the core's one description
of it (:class:`softarm._core.Body`: each section's radius, the gripper as a capsule from
the distal arc's tip to the grasp point; 5 mm canes), measured on the rod's *current*
centre line, a polyline: exact point-to-segment distances from every centre-line segment
and from the gripper's axis to the canes sampled at 150 points each. The rod's shape
depends on gravity and its history, not on q alone, so ``gap`` ignores q.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from softarm._core import Body, PolynomialCurve
from softarm.checks import FloatArray as F64
from softarm.geometry import CANE_RADIUS

if TYPE_CHECKING:
    from softarm.sim.cosserat.plant import CosseratPlant

__all__ = ["RodClearance"]


def _point_segment_distances(points: F64, a: F64, b: F64) -> F64:
    """(S, P) distances from points (P, 3) to segments a -> b (S, 3)."""
    ab = b - a
    t = (
        np.einsum("spk,sk->sp", points[None] - a[:, None], ab)
        / np.maximum(np.einsum("sk,sk->s", ab, ab), 1e-18)[:, None]
    )
    closest = a[:, None] + np.clip(t, 0.0, 1.0)[..., None] * ab[:, None]
    result: F64 = np.linalg.norm(points[None] - closest, axis=2)
    return result


class RodClearance:
    """Smallest surface gap between a :class:`~softarm.sim.cosserat.plant.CosseratPlant`
    as it is now and the canes; the interface of ``Clearance`` (``gap``, ``path_gap``)."""

    def __init__(
        self, plant: CosseratPlant, canes: Sequence[PolynomialCurve], grasp_offset: float
    ) -> None:
        self.plant, self.canes, self.offset = plant, list(canes), grasp_offset
        self.body = Body.for_arm(plant.arm, grasp_offset)
        self.radii = self.body.section_radii + CANE_RADIUS
        self.points = (
            np.concatenate([c(np.linspace(*c.u_range, 150)) for c in self.canes])
            if self.canes
            else np.zeros((0, 3))
        )

    def gap(self, q: F64 | None = None) -> float:
        """Smallest surface gap (m) now; inf without canes; < 0 means contact."""
        if not self.canes:
            return float("inf")
        line = self.plant.centreline()
        sec = self.plant.centreline_sections()[1:]
        d = _point_segment_distances(self.points, line[:-1], line[1:]).min(axis=1)
        body = float((d - self.radii[sec]).min())
        # The gripper's capsule: its axis along the end-effector's z, from the distal arc's
        # tip (gripper_back behind the end-effector frame) to the grasp point.
        ee = self.plant.pose()
        z = ee[:3, 2]
        a = ee[:3, 3] - self.body.gripper_back * z
        b = ee[:3, 3] + self.body.grasp_offset * z
        dg = _point_segment_distances(self.points, a[None], b[None]).min()
        return min(body, float(dg) - self.body.gripper_radius - CANE_RADIUS)

    def path_gap(self, q0: F64, q1: F64, steps: int = 12) -> float:
        """The rod cannot be evaluated at other commands: the gap now."""
        return self.gap()
