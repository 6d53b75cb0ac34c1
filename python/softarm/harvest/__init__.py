"""The berry-harvesting state machine and its simulated and hardware rigs (paper section
III-D, fig. 4)."""

from softarm.harvest.control.actuator import SafeActuator
from softarm.harvest.machine.harvest_machine import HarvestMachine
from softarm.harvest.machine.interfaces import (
    BerryFix,
    BerryTarget,
    Clock,
    Controller,
    Gripper,
    GroundTruth,
    Observation,
    PressureActuator,
    RipenessSensor,
    Vision,
)
from softarm.harvest.machine.states import FAULTS_THAT_STOP, FaultReason, HarvestState
from softarm.harvest.records.log import HarvestLog, read_log
from softarm.harvest.records.report import BerryResult, HarvestReport
from softarm.harvest.rigs.sim.simulate import simulate
from softarm.harvest_config import HarvestConfig

__all__ = [
    "FAULTS_THAT_STOP",
    "BerryFix",
    "BerryResult",
    "BerryTarget",
    "Clock",
    "Controller",
    "FaultReason",
    "Gripper",
    "GroundTruth",
    "HarvestConfig",
    "HarvestLog",
    "HarvestMachine",
    "HarvestReport",
    "HarvestState",
    "Observation",
    "PressureActuator",
    "RipenessSensor",
    "SafeActuator",
    "Vision",
    "read_log",
    "simulate",
]
