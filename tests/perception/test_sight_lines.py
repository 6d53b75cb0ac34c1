"""Fruit C1 finds but cannot place, placed where C2's rays cross its sight line: the
geometry against closed forms, the agreement rule, and the map's bookkeeping."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.perception.berries import BerryDetection
from softarm.perception.bush_map import BushMap, MappedBerry
from softarm.perception.sight_lines import (
    CROSSINGS,
    Placing,
    SightLine,
    crossing,
    sight_lines,
)
from softarm.sim.rig_cameras import look_at
from softarm.vision.camera_model import CameraModel
from softarm.vision.stereo_camera import StereoCamera

K1 = np.array([[900.0, 0, 639.5], [0, 900.0, 359.5], [0, 0, 1]])
C1 = CameraModel(K1, np.zeros(5), (1280, 720))
K2 = np.array([[300.0, 0, 319.5], [0, 300.0, 239.5], [0, 0, 1]])
C2 = CameraModel(K2, np.zeros(5), (640, 480))
FRUIT = np.array([0.05, 0.40, 0.30])  # base frame


def _stereo() -> StereoCamera:
    T_left_right = np.eye(4)
    T_left_right[0, 3] = 0.12
    return StereoCamera(C1, C1, look_at(np.array([0.6, -0.5, 0.5]), FRUIT), T_left_right)


def _det(center: tuple[float, float], radius: float, ripe: bool = True) -> BerryDetection:
    return BerryDetection(
        center, radius, (0, 0, 1, 1), np.zeros((1, 1), bool), 1.0,
        "ripe" if ripe else "unripe", 0.9,
    )  # fmt: skip


def _seen(T_base_camera: np.ndarray, camera: CameraModel, point: np.ndarray) -> tuple[float, float]:
    p = (np.linalg.inv(T_base_camera) @ np.append(point, 1.0))[:3]
    u, v = camera.project(p[None, :])[0]
    return float(u), float(v)


def _line() -> SightLine:
    stereo = _stereo()
    left = _seen(stereo.T_base_left, C1, FRUIT)
    rectified = stereo.rectification.to_rectified_pixels(np.array([left]))[0]
    (line,) = sight_lines([_det((float(rectified[0]), float(rectified[1])), 9.0)], stereo)
    return line


def _c2(eye: np.ndarray) -> np.ndarray:
    return look_at(eye, FRUIT + np.array([0.0, 0.0, 0.01]))


def _distance_to_line(line: SightLine, point: np.ndarray) -> float:
    along = point - line.origin
    return float(np.linalg.norm(along - (along @ line.direction) * line.direction))


def test_the_sight_line_passes_through_the_fruit() -> None:
    line = _line()
    assert _distance_to_line(line, FRUIT) < 1e-6
    np.testing.assert_allclose(line.origin, _stereo().T_base_left[:3, 3])
    assert line.half_angle == pytest.approx(np.arctan2(9.0, 900.0))


def test_placed_fruit_keep_their_position() -> None:
    stereo = _stereo()
    left = _seen(stereo.T_base_left, C1, FRUIT)
    rectified = stereo.rectification.to_rectified_pixels(np.array([left]))[0]
    placed = BerryDetection(
        (float(rectified[0]), float(rectified[1])), 9.0, (0, 0, 1, 1), np.zeros((1, 1), bool),
        1.0, "ripe", 0.9, position=FRUIT,
    )  # fmt: skip
    assert sight_lines([placed], stereo) == []


def test_c2_rays_cross_the_sight_line_at_the_fruit() -> None:
    line = _line()
    T = _c2(np.array([0.0, 0.15, 0.32]))
    point = crossing(line, _det(_seen(T, C2, FRUIT), 12.0), T, C2)
    assert point is not None
    np.testing.assert_allclose(point, FRUIT, atol=1e-6)


def test_a_ray_that_misses_the_line_or_runs_along_it_gives_nothing() -> None:
    line = _line()
    T = _c2(np.array([0.0, 0.15, 0.32]))
    beside = FRUIT + np.array([0.0, 0.0, 0.03])  # another fruit 3 cm off the line
    assert crossing(line, _det(_seen(T, C2, beside), 12.0), T, C2) is None
    along = look_at(line.origin - 0.2 * line.direction, FRUIT)  # C2 behind C1, in line
    assert crossing(line, _det(_seen(along, C2, FRUIT), 12.0), along, C2) is None


def test_a_size_that_fits_no_fruit_gives_nothing() -> None:
    line = _line()
    T = _c2(np.array([0.0, 0.15, 0.32]))
    centre = _seen(T, C2, FRUIT)
    assert crossing(line, _det(centre, 12.0), T, C2) is not None
    assert crossing(line, _det(centre, 80.0), T, C2) is None  # 8 cm across at 25 cm


def test_a_fruit_is_placed_by_agreeing_crossings_from_poses_apart() -> None:
    placing = Placing(_line())
    for k in range(CROSSINGS):
        placing.add(FRUIT + 1e-3 * k, np.array([0.0, 0.15, 0.32]))
    assert placing.position() is None  # all from one pose: chance is not ruled out
    placing = Placing(_line())
    placing.add(FRUIT + 0.05, np.array([0.1, 0.1, 0.3]))  # another fruit, once
    for k in range(CROSSINGS - 1):
        placing.add(FRUIT, np.array([0.015 * k, 0.15, 0.32]))
    assert placing.position() is None
    placing.add(FRUIT + 0.002, np.array([0.05, 0.15, 0.32]))
    position = placing.position()
    assert position is not None
    np.testing.assert_allclose(position, FRUIT + 0.002 / CROSSINGS, atol=1e-12)


def test_the_map_keeps_ripe_unplaced_fruit_once_and_places_it() -> None:
    line = _line()
    unripe = SightLine(line.origin, line.direction, line.half_angle, 0.1)
    bush_map = BushMap()
    bush_map.note_unplaced([line, unripe])
    bush_map.note_unplaced([SightLine(line.origin, line.direction, line.half_angle, 0.9)])
    assert len(bush_map.unplaced) == 1 and bush_map.unplaced[0].line.sightings == 2
    berry = bush_map.place(bush_map.unplaced[0], FRUIT)
    assert bush_map.unplaced == [] and bush_map.ripe() == [berry]
    expected = np.linalg.norm(FRUIT - line.origin) * np.sin(line.half_angle)
    assert berry.radius == pytest.approx(expected)
    bush_map.note_unplaced([line])  # now mapped: the line is that berry
    assert bush_map.unplaced == []


def test_the_second_of_two_waiting_fruit_can_be_placed_first() -> None:
    # Placing the second waiting fruit compares it with the first on the way: compared
    # by their arrays, two placings ended a harvest in a ValueError here.
    line = _line()
    other = SightLine(line.origin, -line.direction, line.half_angle, 0.9)
    bush_map = BushMap()
    bush_map.note_unplaced([line, other])
    assert len(bush_map.unplaced) == 2
    first, second = bush_map.unplaced
    bush_map.place(second, FRUIT)
    assert bush_map.unplaced == [first] and bush_map.unplaced[0] is first


def test_a_line_through_a_mapped_berry_is_that_berry() -> None:
    bush_map = BushMap(berries=[MappedBerry(0, FRUIT + 0.01, 0.01, 1.0)])
    bush_map.note_unplaced([_line()])
    assert bush_map.unplaced == []


def _vision(bush_map: BushMap):  # type: ignore[no-untyped-def]
    """C2-side vision with C2 the only camera that matters here (C1 at the stereo's
    left eye)."""
    from softarm.perception.bush_vision import BushVision
    from softarm.vision import MarkerCube

    return BushVision(
        lambda t: None, lambda t: None, C1, C2, _stereo().T_base_left, np.eye(4), np.eye(4),
        MarkerCube.standard(0.08), 0.03, 0.03, bush_map=bush_map,
    )  # fmt: skip


def test_c2_places_the_fruit_of_a_waiting_line_and_not_a_mapped_one() -> None:
    bush_map = BushMap()
    bush_map.note_unplaced([_line()])
    vision = _vision(bush_map)
    for k in range(CROSSINGS):
        T = _c2(np.array([0.015 * k, 0.15, 0.32]))
        vision._place_unplaced([_det(_seen(T, C2, FRUIT), 12.0)], T)
    (berry,) = bush_map.berries
    np.testing.assert_allclose(berry.position, FRUIT, atol=1e-6)
    assert bush_map.unplaced == [] and berry.ripeness == "ripe"
    # A second waiting line through the same fruit: C2's detection is the mapped berry.
    bush_map.unplaced.clear()
    bush_map.unplaced.append(Placing(_line()))
    for k in range(CROSSINGS):
        T = _c2(np.array([0.015 * k, 0.15, 0.32]))
        vision._place_unplaced([_det(_seen(T, C2, FRUIT), 12.0)], T)
    assert len(bush_map.berries) == 1 and bush_map.unplaced[0].points == []


def test_unripe_detections_place_nothing() -> None:
    bush_map = BushMap()
    bush_map.note_unplaced([_line()])
    vision = _vision(bush_map)
    for k in range(CROSSINGS):
        T = _c2(np.array([0.015 * k, 0.15, 0.32]))
        vision._place_unplaced([_det(_seen(T, C2, FRUIT), 12.0, ripe=False)], T)
    assert bush_map.berries == [] and bush_map.unplaced[0].points == []


def test_a_survey_view_places_a_waiting_fruit_and_costs_nothing_without_one(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import softarm.perception.bush_vision as bush_vision

    frames: list[np.ndarray] = []  # what the detector was given, and where C2 stood
    poses = [_c2(np.array([0.015 * k, 0.15, 0.32])) for k in range(CROSSINGS)]

    def detect(image: np.ndarray, camera: CameraModel, **_: object) -> list[BerryDetection]:
        frames.append(image)
        return [_det(_seen(poses[len(frames) - 1], C2, FRUIT), 12.0)]

    monkeypatch.setattr(bush_vision, "detect_berries", detect)
    image = np.zeros((8, 8, 3), np.uint8)
    bush_map = BushMap()
    vision = _vision(bush_map)
    vision.place_from_view(image, poses[0])
    assert frames == []  # nothing waits to be placed: no detection run
    bush_map.note_unplaced([_line()])
    for T in poses:
        vision.place_from_view(image, T)
    (berry,) = bush_map.berries
    np.testing.assert_allclose(berry.position, FRUIT, atol=1e-6)
    assert len(frames) == CROSSINGS and bush_map.unplaced == []
