"""The berry-harvesting state machine and its simulated and hardware rigs (paper section
III-D, fig. 4)."""

from softarm.harvest.actuator import SafeActuator
from softarm.harvest.interfaces import (
    BerryFix,
    BerryTarget,
    Clock,
    Controller,
    GripperDevice,
    GroundTruth,
    Observation,
    PressureActuator,
    RipenessProbe,
    Vision,
)
from softarm.harvest.log import HarvestLog, read_log
from softarm.harvest.machine import HarvestMachine
from softarm.harvest.report import BerryResult, HarvestReport
from softarm.harvest.simulated import simulate
from softarm.harvest.states import FAULTS_THAT_STOP, FaultReason, HarvestState
from softarm.harvest_config import HarvestConfig

__all__ = [
    "FAULTS_THAT_STOP",
    "BerryFix",
    "BerryResult",
    "BerryTarget",
    "Clock",
    "Controller",
    "FaultReason",
    "GripperDevice",
    "GroundTruth",
    "HarvestConfig",
    "HarvestLog",
    "HarvestMachine",
    "HarvestReport",
    "HarvestState",
    "Observation",
    "PressureActuator",
    "RipenessProbe",
    "SafeActuator",
    "Vision",
    "read_log",
    "simulate",
]
