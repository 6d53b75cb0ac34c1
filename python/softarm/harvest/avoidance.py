"""Cane avoidance in the resolver's null space (planning paper eq. 9).

For each cane, the closest pair between the arm's arcs and the curve is found exactly
(``softarm.closest``, planning paper eq. 12–18); within ``influence`` of the cane's
surface, the closest backbone point is pushed away from it through the pseudo-inverse of
its point Jacobian: Δq = J_s⁺ F(V_s) (the repulsive term of eq. 9, eq. 8 for J⁺). The
controller projects the sum into the null space of the position task, so the gripper's
placement is not disturbed.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from softarm.harvest.clearance import ACTUATOR_RADIUS, CANE_RADIUS

__all__ = ["CaneRepulsion"]

FloatArray = npt.NDArray[np.float64]


class CaneRepulsion:
    """``(q) -> Δq`` (m of elongation) pushing the arm away from nearby canes.

    Args:
        arm: the controller's model (``SoftArm``).
        canes: ``softarm.PolynomialCurve`` obstacles (known, mapped canes).
        influence: surface gap (m) below which a cane repels.
        speed: backbone displacement (m per step) at zero gap; it falls linearly to 0 at
            ``influence``.
    """

    def __init__(
        self,
        arm: object,
        canes: Sequence[object],
        influence: float = 0.03,
        speed: float = 0.002,
    ) -> None:
        from softarm._core import closest  # type: ignore[attr-defined]

        self._closest = closest
        self.arm, self.canes = arm, list(canes)
        self.influence, self.speed = influence, speed
        sections = arm.sections  # type: ignore[attr-defined]
        self.radii = [s.radius + ACTUATOR_RADIUS + CANE_RADIUS for s in sections]

    def __call__(self, q: FloatArray) -> FloatArray:
        """The repulsive step at ``q`` (zero when every cane is beyond ``influence``)."""
        dq = np.zeros_like(q)
        for cane in self.canes:
            c = self._closest(self.arm, q, cane)
            gap = c.distance - self.radii[c.section]
            if gap >= self.influence or c.distance <= 0.0:
                continue
            away = (np.asarray(c.arm_point) - np.asarray(c.obstacle_point)) / c.distance
            _, jac = self.arm.point(q, c.section, c.s)  # type: ignore[attr-defined]  # (3, n)
            push = self.speed * (1.0 - max(gap, 0.0) / self.influence) * away
            dq += np.linalg.pinv(jac) @ push  # eq. (8)-(9)
        return dq
