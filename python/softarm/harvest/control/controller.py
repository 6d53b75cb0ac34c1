"""The controller of the harvest loop: the core resolver's hybrid step (eq. 20) closed on
the measured pose, with the known canes as obstacles inside it (planning paper eq. 9, the
lowest-priority task, in the null space of position and orientation) and, when the
actuators' lag is known, the motion still in flight taken out of the measured error (a
Smith predictor; docs/control.md, section 6). All the control math is in Rust; the lag
model's state is the actuator's (it sees every command sent); this only adapts the call
to the harvest's Controller."""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from softarm._core import Resolver
from softarm.checks import FloatArray
from softarm.harvest.control.clearance import Clearance

__all__ = ["ResolverController"]


class ResolverController:
    """Implements :class:`~softarm.harvest.machine.interfaces.Controller` with ``softarm.Resolver``.

    Args:
        resolver: a ``softarm.Resolver`` on the controller's arm MODEL, usually
            ``mode="hybrid"``.
        obstacles: the known obstacles (``softarm.closest`` forms, e.g. the canes as
            ``PolynomialCurve``) that repel the arm's body in every step.
        plant_q: where the actuators are now by a lag model, e.g.
            :attr:`SafeActuator.plant_q <softarm.harvest.control.actuator.SafeActuator.plant_q>`
            (the actuator sees every command sent, ramps and holds included); each
            closed-loop step then corrects the measured error by the motion still in
            flight (a Smith predictor). None: no prediction.
        transport: a resolver for :meth:`follow_step` (following a placement plan), or
            None to use ``resolver`` there too.
        clearance: the model arm's gap to the same canes (a
            :class:`~softarm.harvest.control.clearance.Clearance` on the model, the planner's),
            for :meth:`way_gaps`; None: no known canes.
    """

    def __init__(
        self,
        resolver: Resolver,
        obstacles: Sequence[object] = (),
        plant_q: Callable[[], FloatArray | None] | None = None,
        transport: Resolver | None = None,
        clearance: Clearance | None = None,
    ) -> None:
        self.resolver = resolver
        self.obstacles = list(obstacles)
        self.arm = resolver.arm
        self.plant_q = plant_q
        self.transport = transport
        self.clearance = clearance

    def avoid(self, clearance: Clearance) -> None:
        """Keep the arm from ``clearance``'s canes from now on (the resolver's obstacles
        and the way check), unless this controller avoids none."""
        if self.clearance is not None:
            self.clearance = clearance
            self.obstacles = list(clearance.canes)

    def follow_step(
        self, q: FloatArray, target: FloatArray, current: FloatArray
    ) -> tuple[FloatArray, bool]:
        """The correction while following a plan: the ``transport`` resolver (its gain
        bounded by the whole lag, no prediction) when given, else :meth:`step`."""
        if self.transport is None:
            return self.step(q, target, current)
        info = self.transport.step(
            np.asarray(q, dtype=np.float64), target, current, obstacles=self.obstacles or None
        )
        return np.asarray(info.q, dtype=np.float64), bool(info.saturated)

    def step(
        self, q: FloatArray, target: FloatArray, current: FloatArray | None
    ) -> tuple[FloatArray, bool]:
        """One resolver step from ``q`` (commanded elongations) to the 4x4 ``target``, with
        the measured pose ``current`` closing the loop (the Jacobian is the model's at q)."""
        q = np.asarray(q, dtype=np.float64)
        plant_q = self.plant_q() if current is not None and self.plant_q is not None else None
        info = self.resolver.step(
            q, target, current, obstacles=self.obstacles or None, plant_q=plant_q
        )
        return np.asarray(info.q, dtype=np.float64), bool(info.saturated)

    def model_pose(self, q: FloatArray) -> FloatArray:
        """The model's end-effector pose (4, 4) at ``q``: where a planned waypoint puts the
        gripper, the target the loop closes on while following a plan."""
        return np.asarray(self.arm.forward(q), dtype=np.float64)

    def limits(self) -> tuple[FloatArray, FloatArray]:
        """The model's (lower, upper) elongations (m)."""
        return np.asarray(self.arm.lower, dtype=np.float64), np.asarray(
            self.arm.upper, dtype=np.float64
        )

    def way_gaps(self, q0: FloatArray, q1: FloatArray, steps: int = 8) -> FloatArray | None:
        """The model arm's gaps (m) to the canes at ``steps`` points of the straight line
        from ``q0`` to ``q1`` in actuator space, ends included; None without known canes."""
        if self.clearance is None:
            return None
        return self.clearance.gaps_along(
            np.asarray(q0, dtype=np.float64), np.asarray(q1, dtype=np.float64), steps
        )
