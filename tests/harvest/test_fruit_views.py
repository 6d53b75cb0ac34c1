"""C2's views of the fruit C1 could not place (softarm.harvest.fruit_views): where they
look (the middle of the sight line's stretch within reach, in closed form) and that
each waiting line is looked along once, every view offered to the vision."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

import softarm.harvest.fruit_views as fruit_views
from softarm.harvest.fruit_views import FruitViews, reach_centre
from softarm.harvest.log import HarvestLog
from softarm.harvest.survey import SurveyPlan
from softarm.perception.bush_map import BushMap
from softarm.perception.sight_lines import Placing, SightLine


def _line(origin: list[float], direction: list[float]) -> SightLine:
    d = np.asarray(direction, float)
    return SightLine(np.asarray(origin, float), d / np.linalg.norm(d), 0.01, 1.0)


def test_the_centre_is_the_middle_of_the_stretch_in_reach() -> None:
    # From (0, -1, 0) along +y: inside the 0.6 m sphere from y = -0.6 to 0.6.
    np.testing.assert_allclose(reach_centre(_line([0, -1, 0], [0, 1, 0]), 0.6), [0, 0, 0])
    # Offset 0.36 m in x: the chord's middle is still the foot of the perpendicular.
    np.testing.assert_allclose(reach_centre(_line([0.36, -1, 0], [0, 1, 0]), 0.6), [0.36, 0, 0])
    # From inside the sphere, the stretch starts at the origin of the line.
    np.testing.assert_allclose(reach_centre(_line([0, 0.2, 0], [0, 1, 0]), 0.6), [0, 0.4, 0])


def test_a_line_that_passes_out_of_reach_has_no_centre() -> None:
    assert reach_centre(_line([0.7, -1, 0], [0, 1, 0]), 0.6) is None
    assert reach_centre(_line([0, 1, 0], [0, 1, 0]), 0.6) is None  # pointing away


class _Vision:
    def __init__(self, bush_map: BushMap) -> None:
        self.bush_map = bush_map
        self.fusion = SimpleNamespace(T_ee_c2=np.eye(4))
        self.offered: list[Any] = []

    def view_c2(self, t: float) -> None:  # the machine's survey is faked: never read
        raise AssertionError

    def place_from_view(self, image: Any, T_base_c2: np.ndarray) -> None:
        self.offered.append(image)


class _Machine:
    def __init__(self) -> None:
        self.q = self.home = np.zeros(9)
        self.log = HarvestLog()
        self.flown: list[SurveyPlan] = []

    def survey(self, plan: SurveyPlan, view: Any) -> list[Any]:
        self.flown.append(plan)
        return [(("first", np.eye(4)), ("second", np.eye(4)))]


def test_each_waiting_line_is_looked_along_once_and_every_view_offered(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    centres: list[np.ndarray] = []

    def plan(ik: Any, q: Any, home: Any, T: Any, centre: np.ndarray, settings: Any) -> SurveyPlan:
        centres.append(centre)
        return SurveyPlan([(np.zeros(9), np.zeros(9))])

    monkeypatch.setattr(fruit_views, "plan_survey", plan)
    bush_map = BushMap()
    bush_map.unplaced = [
        Placing(_line([0, -1, 0], [0, 1, 0])),
        Placing(_line([0.7, -1, 0], [0, 1, 0])),
    ]
    machine, vision = _Machine(), _Vision(bush_map)
    views = FruitViews(machine, SimpleNamespace(planner=None), vision)  # type: ignore[arg-type]
    assert views.run() and views.run()  # the first line flown, the second out of reach
    assert not views.run()  # none left to look along
    assert len(machine.flown) == 1 and vision.offered == ["first", "second"]
    np.testing.assert_allclose(centres[0], [0, 0, 0])
    kinds = [r["kind"] for r in machine.log.records]
    assert kinds == ["fruit_views_done", "fruit_views_skipped"]
