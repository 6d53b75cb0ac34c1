"""The berry-harvesting state machine and its simulated and hardware rigs (paper section
III-D, fig. 4)."""

from softarm.harvest.actuator import SafeActuator
from softarm.harvest.config import HarvestConfig
from softarm.harvest.interfaces import (
    BerryFix,
    BerryLocator,
    BerryTarget,
    Clock,
    Controller,
    EndEffectorTracker,
    GripperDevice,
    GroundTruth,
    PressureActuator,
    RipenessProbe,
)
from softarm.harvest.log import HarvestLog, read_log
from softarm.harvest.machine import HarvestMachine
from softarm.harvest.report import BerryResult, HarvestReport
from softarm.harvest.states import FAULTS_THAT_STOP, FaultReason, HarvestState

__all__ = [
    "FAULTS_THAT_STOP",
    "BerryFix",
    "BerryLocator",
    "BerryResult",
    "BerryTarget",
    "Clock",
    "Controller",
    "EndEffectorTracker",
    "FaultReason",
    "GripperDevice",
    "GroundTruth",
    "HarvestConfig",
    "HarvestLog",
    "HarvestMachine",
    "HarvestReport",
    "HarvestState",
    "PressureActuator",
    "RipenessProbe",
    "SafeActuator",
    "read_log",
]
