"""What the harvesting state machine depends on, as structural ``Protocol`` classes.

The machine never talks to a camera, a DAQ board or the simulated arm directly: the
simulated rig (:mod:`softarm.harvest.rigs.sim.rig`), the hardware rig and the test fakes each
provide these few objects.

The devices have one vocabulary, :mod:`softarm.hardware.protocols` (``PressureBank``,
``Gripper``, ``RipenessSensor``, ``Camera``); the machine takes a ``Gripper`` and a
``RipenessSensor`` from there. What is defined here is what
the harvest loop adds on top of the devices: the estimates, the controller, the clock.
The vision's vocabulary (``BerryTarget``, ``BerryFix``, ``Observation``, ``Vision``) is
defined in :mod:`softarm.vision.observation`, the simulation's ``GroundTruth`` in
:mod:`softarm.sim.world`; both are gathered here with the machine's own protocols.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from softarm.checks import FloatArray as FloatArray  # re-exported (machine, observe, servo)
from softarm.errors import CapabilityError
from softarm.hardware.protocols import Gripper, RipenessSensor
from softarm.sim.world import GroundTruth
from softarm.vision.observation import BerryFix, BerryTarget, CameraName, Observation, Vision

__all__ = [
    "CONTROLLER_METHODS",
    "BerryFix",
    "BerryTarget",
    "CameraName",
    "Clock",
    "Controller",
    "Gripper",
    "GroundTruth",
    "Observation",
    "PlacementPlanner",
    "PressureActuator",
    "RipenessSensor",
    "Vision",
    "require_controller",
]


class Clock(Protocol):
    """Time of the control loop. On hardware ``sleep`` waits for the next period; in the
    simulator it advances the simulated arm."""

    def now(self) -> float:
        """Seconds, monotonic."""
        ...

    def sleep(self, dt: float) -> None:
        """Let ``dt`` seconds pass."""
        ...


class Controller(Protocol):
    """The resolved-rate step towards a target pose (the hybrid resolver, eq. 20), and
    what the servo needs of the controller's model to follow a plan and keep its way
    clear of the known canes. Every method is required (:func:`require_controller`): a
    controller without them would silently lose plan following and the cane checks."""

    def step(
        self, q: FloatArray, target: FloatArray, current: FloatArray | None
    ) -> tuple[FloatArray, bool]:
        """``(q_next, saturated)``: the next elongations (m) from ``q`` towards the 4x4
        ``target``, with ``current`` the measured pose (None = use the model), and whether
        a joint limit clipped the step."""
        ...

    def follow_step(
        self, q: FloatArray, target: FloatArray, current: FloatArray
    ) -> tuple[FloatArray, bool]:
        """As :meth:`step`, while following a placement plan (its gain may differ)."""
        ...

    def model_pose(self, q: FloatArray) -> FloatArray:
        """The model's end-effector pose (4, 4) at ``q``: the target while following a plan."""
        ...

    def limits(self) -> tuple[FloatArray, FloatArray]:
        """The model's (lower, upper) elongations (m), which every command stays inside."""
        ...

    def way_gaps(self, q0: FloatArray, q1: FloatArray, steps: int = 8) -> FloatArray | None:
        """The model arm's gaps (m) to the known canes along the straight line ``q0`` to
        ``q1`` in actuator space at ``steps`` points, ends included; None when no canes
        are known."""
        ...


#: The methods of :class:`Controller`, checked by :func:`require_controller`.
CONTROLLER_METHODS = ("step", "follow_step", "model_pose", "limits", "way_gaps")


def require_controller(controller: object) -> Controller:
    """``controller``, once it has every method of :class:`Controller`.

    Raises:
        CapabilityError: the methods it lacks, named.
    """
    missing = [m for m in CONTROLLER_METHODS if not callable(getattr(controller, m, None))]
    if missing:
        raise CapabilityError(
            f"controller {type(controller).__name__} lacks {', '.join(missing)} "
            "(softarm.harvest.machine.interfaces.Controller)"
        )
    return controller  # type: ignore[return-value]


class PlacementPlanner(Protocol):
    """Plans initial placement on the controller's model before the loop closes."""

    def plan(
        self,
        q: FloatArray,
        berry: FloatArray,
        current: FloatArray,
        avoid: Sequence[FloatArray] = (),
    ) -> tuple[list[FloatArray], FloatArray] | None:
        """``(waypoints, approach_axis)``: elongations (m) to ramp through, the last one
        putting the gripper at the pre-grasp pose of the berry at ``berry`` (base frame),
        and the unit axis it approaches along; None when nothing in the allowed cone is
        reachable (clear of known obstacles). The axes in ``avoid`` (tried already, and
        the true arm could not reach the berry along them) are not used again."""
        ...


class PressureActuator(Protocol):
    """Elongations (m) to pressures (psi) through the safety layer."""

    def send(self, q: FloatArray) -> FloatArray:
        """Command elongations ``q`` (m); returns the elongations actually sent (the
        safety layer clamps and rate-limits), the state the controller goes on from.
        Raises HardwareError/SafetyError on a fault."""
        ...

    @property
    def sent(self) -> FloatArray:
        """The elongations (m) last sent, after the safety layer's clamp and rate limit
        (zero after a vent): the one copy of the command."""
        ...

    def vent(self, reason: str) -> None:
        """Exhaust every channel now (the safe state)."""
        ...

    def in_flight(self) -> FloatArray | None:
        """The motion (m) the arm will still make towards the last q sent, by a lag model
        of the actuators; None when there is none (the arm is taken to be there)."""
        ...

    def play_band(self) -> tuple[FloatArray, FloatArray] | None:
        """The lag model's play output now and its band widths (m); None without one."""
        ...
