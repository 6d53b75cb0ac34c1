"""C2 sees the gripper's fingers in every frame; the markerless vision drops the
detections centred on them (perception/bush_vision.py: finger_outlines, off_fingers)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from softarm.harvest.rigs.sim.options import SimRigOptions
from softarm.harvest.rigs.sim.rig import build_sim_rig
from softarm.perception.berries import BerryDetection
from softarm.perception.bush_vision import finger_outlines, off_fingers
from softarm.perception.detector.choice import detect_berries
from softarm.vision.camera_model import CameraModel

#: A test seed (90000-90999): row 90155 in sun, where the fingers pass as ripe fruit.
SEED = 90155


def _det(x: float, y: float) -> BerryDetection:
    return BerryDetection((x, y), 10.0, (0, 0, 1, 1), np.ones((1, 1), bool), 1.0, "ripe", 1.0)


def _c2() -> tuple[np.ndarray, CameraModel]:
    T_ee_c2 = np.eye(4)
    T_ee_c2[2, 3] = -0.03  # in the palm, looking along the gripper's axis
    return T_ee_c2, CameraModel.ideal(150.0, 320, 240)


def test_a_detection_on_a_finger_is_dropped_and_one_between_them_kept() -> None:
    T_ee_c2, camera = _c2()
    outlines = finger_outlines(T_ee_c2, camera)
    assert len(outlines) == 3
    on_finger = [_det(*o.mean(axis=0)) for o in outlines]
    between = _det(160.0, 120.0)  # the berry between the fingers at the grasp
    assert off_fingers([*on_finger, between], outlines) == [between]


def test_a_finger_behind_the_camera_has_no_outline() -> None:
    T_ee_c2, camera = _c2()
    T_ee_c2[2, 3] = 0.2  # the camera ahead of the fingers, looking away from them
    assert finger_outlines(T_ee_c2, camera) == []


@pytest.fixture(scope="module")
def row_c2():  # type: ignore[no-untyped-def]
    rig = build_sim_rig(SimRigOptions(n_berries=2, seed=SEED, world="row", look="sun"))
    try:
        world = rig.scene.world
        yield rig.vision, world.c2_frame().colour, world._rig_in_c2()
    finally:
        rig.close()


def test_the_outlines_are_the_rendered_fingers(row_c2) -> None:  # type: ignore[no-untyped-def]
    vision, _, rig_pixels = row_c2
    inside = np.zeros(rig_pixels.shape, np.uint8)
    for o in finger_outlines(vision._T_ee_c2, vision.model2):
        cv2.fillConvexPoly(inside, np.round(o).astype(np.int32), 1)
    inside = inside.astype(bool)
    assert (inside & rig_pixels).sum() >= 0.9 * rig_pixels.sum()
    assert (inside & rig_pixels).sum() >= 0.9 * inside.sum()


def test_c2_in_sun_finds_no_finger_as_fruit(row_c2) -> None:  # type: ignore[no-untyped-def]
    vision, image, rig_pixels = row_c2

    def on_rig(dets: list[BerryDetection]) -> int:
        return sum(bool(rig_pixels[round(d.center[1]), round(d.center[0])]) for d in dets)

    # The detector alone takes the black fingers for ripe fruit (the case this guards)...
    assert on_rig(detect_berries(image, vision.model2, settings=vision.settings)) >= 2
    # ...the markerless vision's C2 does not.
    assert on_rig(vision.c2_berries(image)) == 0
