"""The two-camera vision of the markerless harvest: the end effector from the marker
cube in C1 (eq. 22), as in the tag world; the selected berry from the bush map (C1's
stereo, :mod:`softarm.perception.stereo`) while the gripper is far, and from C2 once it
is near (eq. 21): C2 finds the berry without a tag in each frame, and its views from the
tracked poses of the approach, with the map's position as a prior, give the berry's
centre (:class:`~softarm.perception.approach.ApproachTriangulation`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from softarm.checks import FloatArray
from softarm.perception.approach import ApproachTriangulation
from softarm.perception.berries import BerryDetection, DetectorSettings, detect_berries
from softarm.perception.bush_map import BushMap
from softarm.vision.detector import Detection
from softarm.vision.observation import BerryTarget
from softarm.vision.poses import invert
from softarm.vision.two_cameras import CameraVision

__all__ = ["BushVision"]

#: C2 is read while the grasp point is this close (m) to the mapped berry: beyond, the
#: fusion uses C1 (its hand-over is at 6 cm), so C2's frame would go unused.
C2_RANGE = 0.10
#: How far (px) a detection may lie from where the mapped berry projects, beyond the
#: detection's own radius.
GATE_PX = 40.0


class BushVision(CameraVision):
    """:class:`CameraVision` whose berry is a :class:`BushMap` entry, found without tags;
    ``selected.tag_id`` is the map id. Takes CameraVision's arguments (``berry_tag``
    unused) and the ``bush_map``."""

    def __init__(self, *args: Any, bush_map: BushMap, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.bush_map = bush_map
        self.settings = DetectorSettings()
        self._T_ee_c2 = self.fusion.T_ee_c2
        self._grasp = np.array([0.0, 0.0, self.fusion.tool_point[2], 1.0])
        self._track: ApproachTriangulation | None = None

    def select(self, berry: BerryTarget) -> None:
        """Track the map's berry ``berry.tag_id``; its C2 sightings start afresh."""
        super().select(berry)
        p = self._mapped()
        self._track = None if p is None else ApproachTriangulation(p)

    def _mapped(self) -> FloatArray | None:
        berry = self.bush_map.get(self.selected.tag_id)
        return None if berry is None else berry.position

    def _berry_c1(self, dets: list[Detection]) -> FloatArray | None:
        p = self._mapped()
        return None if p is None else (invert(self.T_base_c1) @ np.append(p, 1.0))[:3]

    def _want_c2(self, T_c1_ee: FloatArray | None) -> bool:
        p = self._mapped()
        if T_c1_ee is None or p is None:
            return False
        grasp = (self.T_base_c1 @ T_c1_ee @ self._grasp)[:3]
        return float(np.linalg.norm(grasp - p)) < C2_RANGE

    def _berry_c2(self, image: Any, T_c1_ee: FloatArray | None) -> FloatArray | None:
        p = self._mapped()
        if T_c1_ee is None or p is None:
            return None
        T_c2_base = invert(self.T_base_c1 @ T_c1_ee @ self._T_ee_c2)
        predicted = (T_c2_base @ np.append(p, 1.0))[:3]
        if predicted[2] <= 0.0:
            return None
        det = self._nearest(detect_berries(image, self.model2, settings=self.settings), predicted)
        if det is None or self._track is None:
            return None
        self._track.add(invert(T_c2_base), self.model2, det)
        return (T_c2_base @ np.append(self._track.estimate(), 1.0))[:3]

    def _nearest(self, dets: list[BerryDetection], predicted: FloatArray) -> BerryDetection | None:
        """The ripe detection nearest where the mapped berry projects, within the gate."""
        centre = self.model2.project(predicted[None])[0]
        best, gap = None, np.inf
        for d in dets:
            g = float(np.hypot(d.center[0] - centre[0], d.center[1] - centre[1]))
            if d.ripeness == "ripe" and g < min(gap, GATE_PX + 2.0 * d.radius):
                best, gap = d, g
        return best
