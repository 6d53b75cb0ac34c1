"""States of the harvesting state machine and the reasons it can fault.

The workflow is the paper's fig. 4 (section III-D): eye-to-hand placement of the gripper
in front of the berry, eye-in-hand fine positioning, grasp, back home.
"""

from __future__ import annotations

from enum import StrEnum

__all__ = ["FAULTS_THAT_STOP", "FaultReason", "HarvestState"]


class HarvestState(StrEnum):
    """One state of :class:`~softarm.harvest.machine.harvest_machine.HarvestMachine`."""

    IDLE = "idle"
    #: Before the first berry, C2 is taken to pairs of views of the bush that fill in
    #: the canes C1 cannot place (:mod:`softarm.harvest.control.survey`).
    SURVEY = "survey"
    #: Eye-to-hand feedback drives the gripper to the pre-grasp pose (fig. 4, first stage).
    INITIAL_PLACEMENT = "initial_placement"
    #: Eye-in-hand feedback (eq. 21) drives the gripper onto the berry (fig. 4, second stage).
    FINE_POSITIONING = "fine_positioning"
    GRASP = "grasp"
    RETURN_HOME = "return_home"
    DONE = "done"
    #: The safe state: every channel vented, the reason logged.
    FAULT = "fault"


class FaultReason(StrEnum):
    """Why the machine entered :attr:`HarvestState.FAULT`."""

    #: The end-effector cube or the berry tag was not seen for longer than allowed.
    MARKER_LOST = "marker_lost"
    #: The controller saturated without progress: the pose cannot be reached.
    UNREACHABLE = "unreachable"
    #: A stage took longer than its time budget.
    TIMEOUT = "timeout"
    #: A driver raised (serial disconnect, DAQ error, camera gone).
    HARDWARE_ERROR = "hardware_error"
    #: A measurement (pose, berry position, ripeness) was NaN or infinite.
    NAN_MEASUREMENT = "nan_measurement"
    #: The safety layer refused a command (emergency stop latched, bank closed).
    SAFETY_STOP = "safety_stop"
    #: A camera frame could not be used (corrupt, empty, wrong size or type). A property
    #: of that frame, like a lost marker: the run goes on with the next berry.
    VISION_ERROR = "vision_error"


#: Faults after which the whole run stops; the others abandon only the current berry.
#: A driver error, a refused command or a NaN says the system itself is unsound, so going
#: on to the next berry would repeat the fault with a live arm. A lost marker, an
#: unreachable berry or a timeout are properties of this berry (occluding leaves, a berry
#: outside the workspace), and after the vent the arm is back at its rest pose.
FAULTS_THAT_STOP: frozenset[FaultReason] = frozenset(
    {FaultReason.HARDWARE_ERROR, FaultReason.NAN_MEASUREMENT, FaultReason.SAFETY_STOP}
)
