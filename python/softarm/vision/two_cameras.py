"""Perception of the harvest loop from two cameras, simulated or real.

The eye-to-hand camera C1 gives the end-effector pose from the marker cube (eq. 22) and a
first berry position; the eye-in-hand camera C2 gives the berry close up, carried to the
base frame through the tracked end-effector pose (eq. 21). :class:`CameraFusion` picks
the source: C1 until the grasp point is within 6 cm of the berry, C2 after, the most
recent fix while the berry is hidden (section III-D, fig. 4). Implements
:class:`~softarm.harvest.machine.interfaces.Vision`: one :meth:`CameraVision.observe` per
control step reads C1, and C2 where the berry fix is needed (a period whose fix the
harvest throws away reads no C2 frame: the back-out, the moves between berries). (In the
vision layer, so that identification and calibration track the cube without the
harvest.)
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.errors import VisionError
from softarm.vision.base_registration import BaseRegistration
from softarm.vision.camera_model import CameraModel
from softarm.vision.cube import MarkerCube
from softarm.vision.detector import Detection, MarkerDetector, square_marker_poses
from softarm.vision.fusion import CameraFusion
from softarm.vision.observation import BerryFix, BerryTarget, Observation
from softarm.vision.pose_gate import PoseGate
from softarm.vision.poses import invert

__all__ = ["CameraVision", "register_c1"]

Frame = Callable[[float], npt.NDArray[np.uint8] | None]


def register_c1(
    frame: Frame,
    model: CameraModel,
    tag_id: int,
    tag_length: float,
    T_base_tag: FloatArray,
    frames: int = 5,
    dictionary: str = "DICT_4X4_50",
) -> FloatArray:
    """``T_base_c1`` from ``frames`` images of the base tag (section II-C, eq. 22).

    Raises:
        VisionError: the tag was never seen.
    """
    reg = BaseRegistration(model, tag_id, tag_length, T_base_tag, dictionary, frames)
    for _ in range(frames):
        reg.update(frame(0.0))
    if reg.T_base_camera is None:
        raise VisionError(f"the eye-to-hand camera does not see base tag {tag_id}")
    return reg.T_base_camera


class CameraVision:
    """Tracks the cube and the selected berry tag in two cameras.

    Args:
        frame1, frame2: ``(time) -> image or None`` of C1 (eye-to-hand) and C2 (eye-in-hand).
        model1, model2: their intrinsics.
        T_base_c1: C1 in the base frame (from :func:`register_c1`).
        T_ee_c2: C2 in the end-effector frame (hand-eye calibration, eq. 21).
        T_ee_cube: the marker cube in the end-effector frame.
        cube: the cube's markers.
        berry_tag: side (m) of the berry tags.
        grasp_offset: the grasp point (m) ahead of the end effector; the 6 cm hand-over
            is measured from it.
        max_age: how long (s) the most recent berry fix is held while it is hidden.
        max_jump: a cube pose this far (m) from where the arm's tracked motion puts it
            (:class:`~softarm.vision.pose_gate.PoseGate`: the last accepted pose moved on
            at its velocity) is an outlier, a wrong solution of an ambiguous view, and is
            dropped, unless ``max_rejects`` in a row agree it is real.
        max_speed: the fastest (m/s) the end effector is believed to move (the gate's
            velocity is bounded by it).
        c2_unneeded: told the time of each period whose C2 frame is not taken because
            the fix is not needed (:meth:`observe` without ``need_fix``), where it would
            have been taken with it: the simulated row numbers its C2 frames (each
            frame's noise is seeded by its number) and gives that number away, so that
            the frames still read are the ones a run reading every frame sees.
    """

    def __init__(
        self,
        frame1: Frame,
        frame2: Frame,
        model1: CameraModel,
        model2: CameraModel,
        T_base_c1: FloatArray,
        T_ee_c2: FloatArray,
        T_ee_cube: FloatArray,
        cube: MarkerCube,
        berry_tag: float,
        grasp_offset: float,
        max_age: float = 1.0,
        max_jump: float = 0.03,
        max_rejects: int = 3,
        max_speed: float = 2.0,
        c2_unneeded: Callable[[float], None] | None = None,
    ) -> None:
        self.frame1, self.frame2 = frame1, frame2
        self.model1, self.model2 = model1, model2
        self.T_base_c1, self.T_ee_cube, self.cube = T_base_c1, T_ee_cube, cube
        self.berry_tag = berry_tag
        self.detector = MarkerDetector(cube.dictionary)
        self.fusion = CameraFusion(
            T_base_c1, T_ee_c2, max_age=max_age, tool_point=(0.0, 0.0, grasp_offset)
        )
        self.selected = BerryTarget(-1)
        self._cube_prev: FloatArray | None = None
        self.gate = PoseGate(max_jump, max_rejects, max_speed)
        self.c2_unneeded = c2_unneeded
        #: C2 frames taken by :meth:`observe` (read from the camera, dropped ones too).
        self.c2_frames = 0

    def select(self, berry: BerryTarget) -> None:
        """Track ``berry`` from now on (the fusion forgets any held target)."""
        self.selected = berry
        self.fusion.reset()

    def observe(self, time: float, need_fix: bool = True) -> Observation:
        """Both cameras at ``time``: ``T_base_ee`` from the cube in C1 (eq. 22), and the
        berry from the fusion of C1 and C2 (eq. 21), or the held fix. Without
        ``need_fix`` C2 is taken only where something other than the fix wants it
        (:meth:`_want_c2`); the fusion then goes on from C1 and the held fix."""
        T_c1_ee, berry_c1 = self._view_c1(time)
        img = self._take_c2(time, T_c1_ee, need_fix)
        berry_c2 = None if img is None else self._berry_c2(img, T_c1_ee)
        est = self.fusion.update(time, T_c1_ee, berry_c1, berry_c2)
        fix = None
        if est.target is not None and est.source != "none":
            fix = BerryFix(est.target, est.source, est.target_age)
        pose = None if T_c1_ee is None else self.T_base_c1 @ T_c1_ee
        return Observation(time, pose, fix)

    def track(self, time: float) -> FloatArray | None:
        """C1 alone: ``T_base_ee`` from the cube (eq. 22), or None; for the callers that
        need no berry (calibration, identification)."""
        T_c1_ee, _ = self._view_c1(time)
        return None if T_c1_ee is None else self.T_base_c1 @ T_c1_ee

    def place_from_view(self, image: Any, T_base_c2: FloatArray) -> None:
        """Place fruit C1 found but could not place, from C2's ``image`` taken at
        ``T_base_c2`` (the cane survey's views). Nothing here: the tags' vision keeps no
        map; the markerless vision (:class:`softarm.perception.bush_vision.BushVision`)
        places its map's unplaced fruit."""

    def view_c2(self, time: float) -> tuple[Any, FloatArray] | None:
        """C2's frame at ``time`` and C2's pose in the base frame, from the cube in C1's
        frame and the hand-eye calibration (eq. 21, 22); None without either, or when
        no marker of the cube is consistent on its own (:meth:`MarkerCube.estimate`):
        two views' depth is only as good as their poses. The tracking loop's state
        (its last pose, the jump rule) is left as it was."""
        dets = self.detector.detect(_frame(self.frame1, time), self.model1)
        est = self.cube.estimate(dets, self.model1)
        if est is None or not est.consistent:
            return None
        image = self.frame2(time)
        if image is None:
            return None
        T_c1_ee = est.T_camera_cube @ invert(self.T_ee_cube)
        return image, self.T_base_c1 @ T_c1_ee @ self.fusion.T_ee_c2

    def _view_c1(self, time: float) -> tuple[FloatArray | None, FloatArray | None]:
        """C1's frame at ``time``: ``T_c1_ee`` (None when the cube is not seen or the pose
        is an outlier) and the selected berry's tag position in C1 (None if not seen)."""
        self.gate.looked(time)
        dets = self.detector.detect(_frame(self.frame1, time), self.model1)
        est = self.cube.estimate(dets, self.model1, self._cube_prev)
        berry_c1 = self._berry_c1(dets)
        if est is None:
            return None, berry_c1
        T_c1_ee = est.T_camera_cube @ invert(self.T_ee_cube)
        if not self.gate.accept(time, T_c1_ee[:3, 3]):
            return None, berry_c1
        self._cube_prev = est.T_camera_cube
        return T_c1_ee, berry_c1

    def _take_c2(self, time: float, T_c1_ee: FloatArray | None, need_fix: bool) -> Any:
        """C2's frame at ``time`` if this period wants one, else None (nothing read)."""
        wanted = self._want_c2(T_c1_ee, need_fix)
        if wanted:
            self.c2_frames += 1
            return self.frame2(time)
        if self.c2_unneeded is not None and not need_fix and self._want_c2_for_fix():
            self.c2_unneeded(time)
        return None

    def _want_c2(self, T_c1_ee: FloatArray | None, need_fix: bool) -> bool:
        """Whether to read C2 this period: where the fix is needed (every such period,
        for tags: they are cheap to find). Called once a period."""
        return need_fix

    def _want_c2_for_fix(self) -> bool:
        """Whether this period's C2 frame would have been read were the fix needed
        (after :meth:`_want_c2` this period)."""
        return True

    def _berry_c1(self, dets: list[Detection]) -> FloatArray | None:
        """The selected berry in C1's frame from C1's marker detections (its tag)."""
        return self._tag_position(dets, self.model1)

    def _berry_c2(self, image: Any, T_c1_ee: FloatArray | None) -> FloatArray | None:
        """The selected berry in C2's frame from C2's image (its tag); ``T_c1_ee`` is
        this period's tracked end effector, for finders that predict where to look."""
        return self._tag_position(self.detector.detect(image, self.model2), self.model2)

    def _tag_position(self, dets: list[Detection], model: CameraModel) -> FloatArray | None:
        for d in dets:
            if d.marker_id == self.selected.tag_id:
                sols = square_marker_poses(d.corners, model, self.berry_tag)
                if sols:
                    return sols[0].T_camera_marker[:3, 3]
        return None


def _frame(frame: Frame, time: float) -> Any:
    """A frame, or an empty image (no detections) when the camera dropped one."""
    img = frame(time)
    return np.zeros((8, 8), np.uint8) if img is None else img
