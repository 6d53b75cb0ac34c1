"""The cane survey on a rig, simulated or real: planned on the model
(:func:`~softarm.harvest.control.survey.plan_survey`), flown by the machine
(:meth:`~softarm.harvest.machine.harvest_machine.HarvestMachine.survey`), each pair of C2's views
turned into cane points (:func:`~softarm.perception.cane_views.view_pair_points`) and
fitted with those of C1's view (:meth:`~softarm.perception.c1.StereoC1.
refit_canes`); the planner, the resolver and the way check avoid the canes of that map
from then on (:meth:`~softarm.harvest.control.stack.ControlStack.know_canes`). The views also place
the ripe fruit C1 saw but could not (:meth:`~softarm.perception.bush_vision.BushVision.
place_from_view`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from softarm.checks import FloatArray
from softarm.errors import VisionError
from softarm.harvest.control.stack import ControlStack
from softarm.harvest.control.survey import SurveySettings, plan_survey
from softarm.harvest.machine.harvest_machine import HarvestMachine
from softarm.perception.c1 import StereoC1
from softarm.perception.cane_metrics import DEFAULT_REACH
from softarm.perception.cane_views import pixel_size, view_pair_points
from softarm.vision.two_cameras import CameraVision

__all__ = ["CaneSurvey"]


@dataclass
class CaneSurvey:
    """The survey of one rig: its ``machine``, control ``stack``, ``c1`` (the bush
    map's source, its canes fitted) and ``vision`` (C2 and the tracked cube); ``parts``
    and ``reach`` as :meth:`StereoC1.fit_canes` takes them."""

    machine: HarvestMachine
    stack: ControlStack
    c1: StereoC1
    vision: CameraVision
    parts: FloatArray
    reach: float
    settings: SurveySettings = field(default_factory=SurveySettings)

    def run(self) -> int:
        """Survey the bush around the berries C1 mapped and refit the canes; the number
        of pairs of views that gave cane points (0: the map is C1's alone, as before:
        no berry mapped, no pair planned, or none taken)."""
        berries = [b.position for b in self.c1.bush_map.berries]
        berries = [p for p in berries if np.linalg.norm(p) <= DEFAULT_REACH]
        log = self.machine.log
        if not berries:
            log.event("survey_skipped", why="no berry mapped within reach")
            return 0
        centre = np.mean(berries, axis=0)
        plan = plan_survey(
            self.stack.planner, self.machine.q, self.machine.home,
            self.vision.fusion.T_ee_c2, centre, self.settings,
        )  # fmt: skip
        views = self.machine.survey(plan, self.vision.view_c2)
        footprint = pixel_size(self.c1.stereo, centre)
        for pair in views:  # the views also place what C1 could not
            for image, T_base_c2 in pair:
                self.vision.place_from_view(image, T_base_c2)
        points = []
        for (first, T_first), (second, T_second) in views:
            try:
                points.append(view_pair_points(
                    first, second, self.vision.model2, T_first, T_second,
                    footprint=footprint,
                ))  # fmt: skip
            except VisionError as exc:  # the true arm moved C2 other than planned
                log.event("survey_pair_dropped", why=str(exc))
        if points:
            self.stack.know_canes(self.c1.refit_canes(self.parts, self.reach, points))
        log.event("survey_done", planned=len(plan.pairs), taken=len(views), used=len(points))
        return len(points)
