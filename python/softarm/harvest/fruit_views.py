"""Views of C2 for the ripe fruit C1 saw but could not place, once nothing else is left
to pick: the fruit lies on C1's sight line to it (:mod:`softarm.perception.sight_lines`),
and C2, taken to look at the stretch of that line within the arm's reach as the cane
survey takes it to the bush (:func:`~softarm.harvest.survey.plan_survey`, flown by
:meth:`~softarm.harvest.machine.HarvestMachine.survey`), places it where its rays cross
the line (:meth:`~softarm.perception.bush_vision.BushVision.place_from_view`). Without
them such a fruit is placed only if C2 happens to see it on a berry's approach.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from softarm.checks import FloatArray
from softarm.harvest.machine import HarvestMachine
from softarm.harvest.rig import ControlStack
from softarm.harvest.survey import SurveySettings, plan_survey
from softarm.perception.bush_vision import BushVision
from softarm.perception.cane_metrics import DEFAULT_REACH
from softarm.perception.sight_lines import SightLine

__all__ = ["FruitViews", "reach_centre"]


@dataclass
class FruitViews:
    """The views of one rig: its ``machine``, control ``stack`` and markerless
    ``vision`` (its map's waiting fruit); ``settings`` of the views, ``reach`` (m) of
    the arm from its base."""

    machine: HarvestMachine
    stack: ControlStack
    vision: BushVision
    settings: SurveySettings = field(default_factory=lambda: SurveySettings(pairs=2))
    reach: float = DEFAULT_REACH
    _tried: list[SightLine] = field(default_factory=list)

    def run(self) -> bool:
        """Fly C2 to look along the first waiting sight line not looked along yet;
        whether there was one (the map then holds the fruit its views placed)."""
        tried = self._tried  # by identity: a line's arrays do not compare as one bool
        waiting = [
            p.line for p in self.vision.bush_map.unplaced if not any(p.line is t for t in tried)
        ]
        if not waiting:
            return False
        line = waiting[0]
        self._tried.append(line)
        centre = reach_centre(line, self.reach)
        log = self.machine.log
        if centre is None:
            log.event("fruit_views_skipped", why="the sight line passes out of reach")
            return True
        before = len(self.vision.bush_map.berries)
        plan = plan_survey(
            self.stack.planner, self.machine.q, self.machine.home,
            self.vision.fusion.T_ee_c2, centre, self.settings,
        )  # fmt: skip
        views = self.machine.survey(plan, self.vision.view_c2)
        for pair in views:
            for image, T_base_c2 in pair:
                self.vision.place_from_view(image, T_base_c2)
        placed = len(self.vision.bush_map.berries) - before
        log.event("fruit_views_done", planned=len(plan.pairs), taken=len(views), placed=placed)
        return True


def reach_centre(line: SightLine, reach: float) -> FloatArray | None:
    """The middle of the stretch of ``line`` within ``reach`` (m) of the base origin;
    None where the line passes farther (``|o + t d| <= reach`` for t >= 0, ``d`` unit)."""
    o, d = np.asarray(line.origin, np.float64), np.asarray(line.direction, np.float64)
    b = float(o @ d)
    disc = b * b - (float(o @ o) - reach * reach)
    if disc <= 0.0:
        return None
    near, far = max(-b - np.sqrt(disc), 0.0), -b + np.sqrt(disc)
    if far <= 0.0:
        return None
    centre: FloatArray = o + 0.5 * (near + far) * d
    return centre
