"""The controller of the harvest loop: the core resolver's hybrid step (eq. 20) closed on
the measured pose, with the known canes as obstacles inside it (planning paper eq. 9, the
lowest-priority task, in the null space of position and orientation) and, when the
actuators' lag is known, a lag model predicting the motion still in flight (a Smith
predictor; docs/control.md). All the control math is in Rust; this only keeps the
predictor's state and adapts the call to the harvest's Controller."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from softarm._core import LagModel

__all__ = ["ResolverController"]

FloatArray = npt.NDArray[np.float64]


class ResolverController:
    """Implements :class:`~softarm.harvest.interfaces.Controller` with ``softarm.Resolver``.

    Args:
        resolver: a ``softarm.Resolver`` on the controller's arm MODEL, usually
            ``mode="hybrid"``.
        obstacles: the known obstacles (``softarm.closest`` forms, e.g. the canes as
            ``PolynomialCurve``) that repel the arm's body in every step.
        lag: ``(tau_s, period_s)`` of the actuators (sensor filtering included), or None.
            With it each step gets a :class:`softarm.LagModel`'s prediction of the
            elongations reached as ``plant_q``; the model restarts, settled, whenever the
            state it is given is not the command it returned last (something else, a hold
            or a ramp, commanded in between).
    """

    def __init__(
        self,
        resolver: object,
        obstacles: Sequence[object] = (),
        lag: tuple[float, float] | None = None,
    ) -> None:
        self.resolver = resolver
        self.obstacles = list(obstacles)
        self.arm = resolver.arm  # type: ignore[attr-defined]
        self.lag = lag
        self._predictor: LagModel | None = None
        self._sent: FloatArray | None = None

    def _plant_q(self, q: FloatArray) -> FloatArray | None:
        """The predicted elongations after ``q`` was held one period (None without lag)."""
        if self.lag is None:
            return None
        if self._predictor is None or self._sent is None or not np.array_equal(q, self._sent):
            self._predictor = LagModel(self.lag[0], self.lag[1], q)
        else:
            self._predictor.advance(q)
        return np.asarray(self._predictor.q)

    def step(
        self, q: FloatArray, target: FloatArray, current: FloatArray | None
    ) -> tuple[FloatArray, bool]:
        """One resolver step from ``q`` (commanded elongations) to the 4x4 ``target``, with
        the measured pose ``current`` closing the loop (the Jacobian is the model's at q)."""
        q = np.asarray(q, dtype=np.float64)
        plant_q = self._plant_q(q) if current is not None else None
        info = self.resolver.step(  # type: ignore[attr-defined]
            q, target, current, obstacles=self.obstacles or None, plant_q=plant_q
        )
        self._sent = np.asarray(info.q, dtype=np.float64)
        return self._sent.copy(), bool(info.saturated)

    def model_pose(self, q: FloatArray) -> FloatArray:
        """The model's end-effector pose (4, 4) at ``q``: where a planned waypoint puts the
        gripper, the target the loop closes on while following a plan."""
        return np.asarray(self.arm.forward(q), dtype=np.float64)
