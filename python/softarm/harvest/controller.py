"""The controller of the harvest loop: the hybrid task-priority resolver (eq. 20) closed
on the measured pose, with an optional branch-avoiding velocity in its null space."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import numpy.typing as npt

__all__ = ["ResolverController"]

FloatArray = npt.NDArray[np.float64]


class ResolverController:
    """Implements :class:`~softarm.harvest.interfaces.Controller` with ``softarm.Resolver``.

    Args:
        resolver: a ``softarm.Resolver`` on the controller's arm MODEL, usually
            ``mode="hybrid"`` (position first, then orientation, then joint limits).
        avoidance: optional ``(q) -> dq`` repulsion from obstacles (m of elongation), added
            in the null space of the position task so it never disturbs positioning.
    """

    def __init__(
        self,
        resolver: object,
        avoidance: Callable[[FloatArray], FloatArray] | None = None,
    ) -> None:
        self.resolver = resolver
        self.avoidance = avoidance
        self.arm = resolver.arm  # type: ignore[attr-defined]

    def step(
        self, q: FloatArray, target: FloatArray, current: FloatArray | None
    ) -> tuple[FloatArray, bool]:
        """One resolver step from ``q`` (commanded elongations) to the 4x4 ``target``, with
        the measured pose ``current`` closing the loop (the Jacobian is the model's at q)."""
        info = self.resolver.step(q, target, current)  # type: ignore[attr-defined]
        q_next = np.asarray(info.q, dtype=np.float64)
        saturated = bool(info.saturated)
        if self.avoidance is not None:
            jv = self.arm.jacobian(q)[:3]  # (3, n) position rows
            null = np.eye(q.size) - np.linalg.pinv(jv) @ jv  # (n, n) projector
            q_next = q_next + null @ self.avoidance(q)
            lo, hi = self.arm.lower, self.arm.upper
            saturated = saturated or bool(np.any((q_next < lo) | (q_next > hi)))
            q_next = np.clip(q_next, lo, hi)
        return q_next, saturated
