"""C2 is read only where the harvest needs the berry fix (issue 37: the row's wall time).

The back-out holds the berry frozen and the moves between berries throw the fix away
(``need_fix=False``); in the rendered row each C2 frame is a shadowed render and a
detector pass. Counting fake cameras show that no C2 frame is taken for the fix there,
that the map's placing of unplaced fruit keeps its own rhythm, and that the row's camera
model numbers the frames as a run that takes every frame does."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from softarm.errors import ParameterError
from softarm.harvest import HarvestState
from softarm.harvest.machine.interfaces import BerryTarget
from softarm.harvest.machine.observe import BerryWatch
from softarm.harvest.records.log import HarvestLog
from softarm.perception.bush_map import BushMap, MappedBerry
from softarm.perception.bush_vision import PLACING_EVERY, BushVision
from softarm.perception.sight_lines import Placing
from softarm.sim.render.row_camera import RowCameras
from softarm.sim.render.row_look import RowLook
from softarm.vision.camera_model import CameraModel
from softarm.vision.marker_body import marker_body
from softarm.vision.two_cameras import CameraVision

from .fakes import FakeClock

GRASP_OFFSET = 0.05
#: The mapped berry 1 cm beyond the grasp point (identity poses: C1, the end effector
#: and C2 at the origin, the grasp point on z): within C2_RANGE, so C2 serves the fix.
BERRY = np.array([0.0, 0.0, GRASP_OFFSET + 0.01])


class _Frames:
    """A counting camera: the times it was read at, a blank frame each time."""

    def __init__(self) -> None:
        self.read: list[float] = []

    def __call__(self, t: float) -> np.ndarray:
        self.read.append(t)
        return np.zeros((48, 64, 3), np.uint8)


def _vision(c2: _Frames, skipped: list[float], cls: Any = CameraVision, **kw: Any) -> Any:
    model = CameraModel.ideal(60.0, 64, 48)
    eye = np.eye(4)
    blank = lambda t: np.zeros((48, 64, 3), np.uint8)  # noqa: E731  (C1 sees no marker)
    return cls(
        blank, c2, model, model, eye, eye, eye, marker_body("cube", 0.08), 0.03,
        GRASP_OFFSET, c2_unneeded=skipped.append, **kw,
    )  # fmt: skip


def test_the_tags_vision_reads_c2_only_where_the_fix_is_needed() -> None:
    c2, skipped = _Frames(), list[float]()
    vision = _vision(c2, skipped)
    vision.observe(0.0)
    vision.observe(0.05, need_fix=False)
    vision.observe(0.10, need_fix=True)
    assert c2.read == [0.0, 0.10]
    assert skipped == [0.05]  # the frame it would have read, given away
    assert vision.c2_frames == 2


def test_the_watch_tells_the_vision_whether_the_fix_is_needed() -> None:
    c2, skipped = _Frames(), list[float]()
    clock = FakeClock()
    watch = BerryWatch(_vision(c2, skipped), clock, BerryTarget(1), HarvestLog(), 10.0)
    watch.observe(need_fix=False)
    assert c2.read == [] and skipped == [0.0]
    watch.observe()
    assert c2.read == [0.0]


def _bush_vision(c2: _Frames, skipped: list[float], unplaced: bool) -> BushVision:
    bush_map = BushMap(berries=[MappedBerry(7, BERRY.copy(), 0.01, 1.0)])
    if unplaced:  # a ripe fruit C1 found without a position, never crossed here
        bush_map.unplaced.append(Placing(line=None))  # type: ignore[arg-type]
    vision: BushVision = _vision(c2, skipped, BushVision, bush_map=bush_map)
    vision.select(BerryTarget(7))
    # The cube seen at the origin each period (C1's marker detection is not the test's).
    vision._view_c1 = lambda t: (np.eye(4), None)  # type: ignore[method-assign,assignment]
    return vision


def test_the_markerless_vision_reads_no_c2_for_a_fix_thrown_away() -> None:
    c2, skipped = _Frames(), list[float]()
    vision = _bush_vision(c2, skipped, unplaced=False)
    times = [0.05 * k for k in range(10)]
    for t in times[:5]:
        vision.observe(t, need_fix=False)  # near the berry, backing out
    assert c2.read == [] and skipped == times[:5]
    for t in times[5:]:
        vision.observe(t)  # near the berry, the fix needed: every period
    assert c2.read == times[5:]


def test_the_maps_placing_keeps_its_rhythm_whatever_the_fix() -> None:
    """With fruit waiting to be placed C2 is read every PLACING_EVERY periods, needed
    fix or not; only the frames the fix alone wanted are given away."""
    c2, skipped = _Frames(), list[float]()
    vision = _bush_vision(c2, skipped, unplaced=True)
    times = [0.05 * k for k in range(1, 2 * PLACING_EVERY + 1)]
    for t in times:
        vision.observe(t, need_fix=False)
    placing = times[PLACING_EVERY - 1 :: PLACING_EVERY]
    assert c2.read == placing
    assert skipped == [t for t in times if t not in placing]


def test_a_skipped_row_frame_leaves_the_next_its_noise() -> None:
    """The frame after a skipped one is the frame a run reading every frame has there."""
    look = RowLook.named("sun", 90001)
    image = np.full((48, 64, 3), 120, np.uint8)
    every = RowCameras(look)
    every.apply("c2", image)
    second = every.apply("c2", image)
    skipping = RowCameras(look)
    skipping.skip("c2")
    assert np.array_equal(skipping.apply("c2", image), second)
    assert not np.array_equal(RowCameras(look).apply("c2", image), second)  # noise differs


def test_skipping_an_unknown_camera_names_it() -> None:
    with pytest.raises(ParameterError, match="c3"):
        RowCameras(RowLook.named("sun", 90001)).skip("c3")


@pytest.mark.slow
def test_no_c2_frame_is_read_in_the_back_out_or_on_the_way_home() -> None:
    """The tag world end to end: the berry harvested, C2 read in fine positioning and
    never in RETURN_HOME (the back-out holds the berry frozen, the way home needs none)."""
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig

    rig = build_sim_rig(SimRigOptions(n_berries=1, seed=0))
    vision, machine = rig.vision, rig.machine
    states: list[HarvestState] = []
    frame2 = vision.frame2

    def counted(t: float) -> Any:
        states.append(machine.state)
        return frame2(t)

    vision.frame2 = counted
    (berry,) = rig.run().berries
    assert berry.harvested
    assert HarvestState.FINE_POSITIONING in states
    assert HarvestState.RETURN_HOME not in states
    assert vision.c2_frames == len(states)
