"""The contact trace's pieces (softarm.experiments.row_contacts): the cause of a contact,
the episodes of contact steps, the point touched and the map's distance to it."""

from __future__ import annotations

import numpy as np
import pytest

import softarm
from softarm.experiments.row_contacts import (
    MAPPED_MM,
    Step,
    cause_of,
    covered,
    episodes,
    main,
    nearest_mm,
    touched_point,
)
from softarm.perception.self_filter import CANE_REACH


def _step(t: float, cane: int = 0, state: str = "initial_placement", gap: float = -1.0) -> Step:
    return Step(t, state, 3, gap, cane, "gripper", [0.1, 0.0, 0.3], 0.32, True, 2.0, 5.0, -1.0,
                False)  # fmt: skip


def test_cause_beyond_reach_first_then_not_seen_then_mapped() -> None:
    assert cause_of(CANE_REACH + 0.01, 1.0) == "beyond reach"
    assert cause_of(0.4, MAPPED_MM + 0.1) == "not seen"
    assert cause_of(0.4, float("inf")) == "not seen"  # an empty map
    assert cause_of(0.4, float("nan")) == "not seen"
    assert cause_of(0.4, MAPPED_MM) == "mapped"


def test_episodes_split_on_cane_stage_and_time_gap() -> None:
    steps = [_step(0.00), _step(0.01, gap=-3.0), _step(0.02, cane=1), _step(0.5, cane=1),
             _step(0.51, cane=1, state="return_home")]  # fmt: skip
    found = episodes(steps)
    assert [(e.cane, e.state, e.steps) for e in found] == [
        (0, "initial_placement", 2),
        (1, "initial_placement", 1),
        (1, "initial_placement", 1),
        (1, "return_home", 1),
    ]
    assert found[0].min_gap_mm == -3.0 and found[0].cause == "mapped"
    assert episodes([]) == []


def test_touched_point_names_the_piece() -> None:
    backbone = np.array([[0.0, 0.0, z] for z in np.linspace(0, 0.4, 40)])
    gripper = np.array([[0.0, 0.0, z] for z in np.linspace(0.4, 0.5, 8)])
    cane = np.array([[0.02, y, 0.1] for y in np.linspace(-0.1, 0.1, 21)])
    point, piece = touched_point(backbone, gripper, cane, 2)
    np.testing.assert_allclose(point, [0.02, 0.0, 0.1])
    assert piece == "section 0"
    point, piece = touched_point(backbone, gripper, cane + np.array([0, 0, 0.38]), 2)
    assert piece == "gripper"
    _, piece = touched_point(backbone, gripper, cane + np.array([0, 0, 0.3]), 2)
    assert piece == "section 1"


def test_nearest_mm_of_a_straight_cane_and_of_none() -> None:
    line = softarm.PolynomialCurve(np.array([[0.0, 0.0], [0.0, 1.0], [0.3, 0.0]]), (0.0, 0.2))
    assert nearest_mm(np.array([0.01, 0.1, 0.3]), [line]) == pytest.approx(10.0, abs=0.1)
    assert nearest_mm(np.zeros(3), []) == float("inf")


def test_covered_is_the_share_of_the_cane_near_the_map() -> None:
    cane = softarm.PolynomialCurve(np.array([[0.0, 0.0], [0.0, 1.0], [0.3, 0.0]]), (0.0, 0.2))
    half = softarm.PolynomialCurve(np.array([[0.005, 0.0], [0.0, 1.0], [0.3, 0.0]]), (0.0, 0.1))
    far = softarm.PolynomialCurve(np.array([[0.05, 0.0], [0.0, 1.0], [0.3, 0.0]]), (0.0, 0.2))
    assert covered(cane, [cane]) == 1.0
    assert covered(cane, [half]) == pytest.approx(0.54, abs=0.02)  # 10 mm past its end
    assert covered(cane, [far]) == 0.0
    assert covered(cane, []) == 0.0


def test_the_trace_draws_the_berries_as_the_harvest_does() -> None:
    from softarm.commands.harvest import BUSH_UNRIPE_FRACTION
    from softarm.experiments.row_contacts import UNRIPE_FRACTION

    assert UNRIPE_FRACTION == BUSH_UNRIPE_FRACTION


def test_main_refuses_bad_arguments(capsys: pytest.CaptureFixture[str]) -> None:
    for argv, named in ((["90120"], "look"), (["90120", "sun", "--speed", "2"], "--speed")):
        with pytest.raises(SystemExit) as stop:
            main(argv)
        assert stop.value.code == 2
        err = capsys.readouterr().err
        assert err.startswith("usage: row_contacts") and named in err
        assert "Traceback" not in err
