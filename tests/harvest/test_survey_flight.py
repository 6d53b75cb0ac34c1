"""The machine flies the cane survey: each view's configuration is reached and settled
before C2 is read there, the arm ends at the ready pose, a view C1 or C2 misses drops
its pair, and a fault ends the survey vented and logged with the pairs taken so far."""

from __future__ import annotations

import numpy as np

from softarm.errors import HardwareError
from softarm.harvest import HarvestState
from softarm.harvest.control.survey import SurveyPlan

from .fakes import make_rig

S = HarvestState
A, B = np.array([0.01, 0.0, 0.005]), np.array([0.012, 0.0, 0.005])
C, D = np.array([0.0, 0.01, 0.004]), np.array([0.0, 0.012, 0.004])


def _viewer(rig, missing=()):
    """C2's view: the commanded q at the time (where the arm is, the fake's plant
    following its commands at once), or None at the times in ``missing``."""
    seen = []

    def view(t):
        q = np.array(rig.machine.q)
        seen.append(q)
        if len(seen) - 1 in missing:
            return None
        return ("image", rig.plant.pose())

    return view, seen


def test_each_view_is_taken_where_its_configuration_was_reached() -> None:
    rig = make_rig()
    view, seen = _viewer(rig)
    pairs = rig.machine.survey(SurveyPlan([(A, B), (C, D)]), view)
    assert len(pairs) == 2
    for q, want in zip(seen, (A, B, C, D), strict=True):
        assert np.allclose(q, want, atol=1e-9)
    assert np.allclose(rig.machine.q, rig.machine.home)  # back at the ready pose
    assert rig.transitions(-1) == [S.SURVEY, S.IDLE]
    assert not rig.vented()


def test_a_missed_view_drops_its_pair_only() -> None:
    rig = make_rig()
    view, _ = _viewer(rig, missing=(1,))
    pairs = rig.machine.survey(SurveyPlan([(A, B), (C, D)]), view)
    assert len(pairs) == 1
    first, second = pairs[0]
    assert first[0] == second[0] == "image"
    taken = [r["taken"] for r in rig.machine.log.records if r["kind"] == "survey_view"]
    assert taken == [True, False, True, True]


def test_a_fault_ends_the_survey_vented_with_the_pairs_taken() -> None:
    rig = make_rig()
    view, _ = _viewer(rig)

    calls: list[float] = []

    def failing(t):
        if len(calls) == 2:
            raise HardwareError("C2 unplugged")
        calls.append(t)
        return view(t)

    pairs = rig.machine.survey(SurveyPlan([(A, B), (C, D)]), failing)
    assert len(pairs) == 1
    assert rig.vented()
    assert rig.transitions(-1) == [S.SURVEY, S.FAULT]
    faults = [r for r in rig.machine.log.records if r["kind"] == "fault"]
    assert faults and faults[-1]["reason"] == "hardware_error"


def test_an_empty_plan_only_goes_home() -> None:
    rig = make_rig()
    view, seen = _viewer(rig)
    assert rig.machine.survey(SurveyPlan([]), view) == []
    assert seen == [] and np.allclose(rig.machine.q, rig.machine.home)
