"""The tag world (``world = "tags"``): every berry wears an ArUco tag that the synthetic
cameras see (:mod:`softarm.sim.rig_cameras`), and the control stack is told of the true
canes (mapped). Fast, for controller sweeps."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from softarm._core import PolynomialCurve
from softarm.checks import FloatArray
from softarm.harvest.control.stack import ControlStack
from softarm.harvest.machine.harvest_machine import HarvestMachine
from softarm.harvest.machine.interfaces import BerryTarget
from softarm.harvest.records.report import BerryResult, HarvestReport
from softarm.harvest.rigs.sim.devices import SimGripper
from softarm.harvest.runs.cane_survey import CaneSurvey
from softarm.harvest.runs.policy import run_targets
from softarm.sim.bush import Berry, Bush
from softarm.sim.world import WorldName
from softarm.vision.two_cameras import CameraVision

__all__ = ["TagWorld"]


@dataclass
class TagWorld:
    """The :class:`~softarm.sim.world.World` of the tagged bush."""

    bush: Bush
    vision: CameraVision
    gripper: SimGripper
    canes: list[PolynomialCurve] = field(default_factory=list)
    name: WorldName = WorldName.TAGS
    #: No rendered scene: the tags are drawn by the synthetic cameras.
    scene: None = None

    def known_canes(self) -> Sequence[PolynomialCurve]:
        """The true canes: the tag world maps them."""
        return self.canes

    def truth_of(self, berry_id: int) -> Berry | None:
        """The true berry of tag ``berry_id``."""
        return next((b for b in self.bush.berries if b.tag_id == berry_id), None)

    def report_extra(self) -> dict[str, object]:
        """Nothing: the report's berries are the bush's, by their tags."""
        return {}

    def close(self) -> None:
        """Nothing to free."""

    def survey(
        self, machine: HarvestMachine, stack: ControlStack, parts: FloatArray
    ) -> CaneSurvey | None:
        """None: the tag world's canes are mapped, there is nothing to survey."""
        return None

    def harvest(
        self, machine: HarvestMachine, on_berry: Callable[[int, BerryResult], None] | None
    ) -> HarvestReport:
        """Every berry of the bush by its tag, by the run policy
        (:func:`~softarm.harvest.runs.policy.run_targets`)."""
        targets = [BerryTarget(b.tag_id) for b in self.bush.berries]
        return run_targets(machine.run_berry, targets, machine.log, on_berry)
