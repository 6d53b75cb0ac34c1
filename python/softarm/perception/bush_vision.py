"""The two-camera vision of the markerless harvest: the end effector from the marker
cube in C1 (eq. 22), as in the tag world; the selected berry from the bush map (C1's
stereo, :mod:`softarm.perception.stereo`) while the gripper is far, and from C2 once it
is near (eq. 21): C2 finds the berry without a tag in each frame, and the berry is where
C2's ray to it crosses C1's (:class:`~softarm.perception.approach.RayCrossing`). While
the map holds ripe fruit C1 found but could not place, C2 is also read every
PLACING_EVERY periods wherever the arm is, and a fruit it sees on one of their sight
lines is placed (:mod:`softarm.perception.sight_lines`). A period whose fix the harvest
throws away (the back-out, the moves between berries) reads C2 only for that placing:
up close, C2's frames are the costliest part of a period in the rendered row."""

from __future__ import annotations

from typing import Any

import numpy as np

from softarm.checks import FloatArray
from softarm.perception.approach import RayCrossing, along_spread
from softarm.perception.berries import BerryDetection, DetectorSettings
from softarm.perception.bush_map import BushMap
from softarm.perception.detector.choice import detect_berries  # the chosen detector
from softarm.perception.sight_lines import crossing
from softarm.vision.detector import Detection
from softarm.vision.observation import BerryTarget
from softarm.vision.poses import invert
from softarm.vision.two_cameras import CameraVision

__all__ = ["BushVision"]

#: C2 is read while the grasp point is this close (m) to the mapped berry: beyond, the
#: fusion uses C1 (its hand-over is at 6 cm), so C2's frame would go unused.
C2_RANGE = 0.10
#: While fruit waits to be placed, C2 is read every this many control periods (4 Hz at
#: the 50 ms period): its crossings must come from poses apart anyway, and a C2 frame
#: costs as much as the rest of the period in the rendered bush.
PLACING_EVERY = 5
#: A C2 detection is a mapped berry when its centre lies within the berry's projected
#: radius, or this many pixels, of the berry's projection.
MAPPED_GATE_PX = 8.0


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
        self._track: RayCrossing | None = None
        self._near = False  # the grasp point within C2_RANGE of the selected berry
        self._period = 0
        self._for_fix = False  # this period's C2 frame would serve the fix

    def select(self, berry: BerryTarget) -> None:
        """Track the map's berry ``berry.tag_id``; its C2 sightings start afresh."""
        super().select(berry)
        entry = self.bush_map.get(berry.tag_id)
        origin = self.bush_map.ray_origin
        self._track = None if entry is None else RayCrossing(
            self.T_base_c1[:3, 3] if origin is None else origin, entry.position, entry.radius,
            self._along(origin, entry.position),
        )  # fmt: skip

    def _along(self, origin: FloatArray | None, position: FloatArray) -> float:
        """How far along C1's ray C2 looks for the berry at ``position``: the depth the
        stereo's disparity spread spans there (:func:`along_spread`); 0 where the map's
        positions are not the stereo's (no ray origin: the baseline's middle, half
        the baseline from C1's left eye)."""
        if origin is None:
            return 0.0
        baseline = 2.0 * float(np.linalg.norm(origin - self.T_base_c1[:3, 3]))
        depth = float(np.linalg.norm(position - origin))
        if baseline <= 0.0 or depth <= 0.0:
            return 0.0
        return along_spread(depth, self.model1.focal, baseline)

    def _mapped(self) -> FloatArray | None:
        berry = self.bush_map.get(self.selected.tag_id)
        return None if berry is None else berry.position

    def _berry_c1(self, dets: list[Detection]) -> FloatArray | None:
        p = self._mapped()
        return None if p is None else (invert(self.T_base_c1) @ np.append(p, 1.0))[:3]

    def _want_c2(self, T_c1_ee: FloatArray | None, need_fix: bool) -> bool:
        """Near the berry for the fix (if ``need_fix``), or every PLACING_EVERY periods
        while fruit waits to be placed: the map's placing goes on whatever the fix."""
        self._period += 1  # counted every period: the placing's rhythm is the clock's
        self._for_fix = False
        p = self._mapped()
        if T_c1_ee is None:
            return False
        grasp = (self.T_base_c1 @ T_c1_ee @ self._grasp)[:3]
        self._near = p is not None and float(np.linalg.norm(grasp - p)) < C2_RANGE
        placing = bool(self.bush_map.unplaced) and self._period % PLACING_EVERY == 0
        self._for_fix = self._near and not placing
        return (self._near and need_fix) or placing

    def _want_c2_for_fix(self) -> bool:
        return self._for_fix

    def _berry_c2(self, image: Any, T_c1_ee: FloatArray | None) -> FloatArray | None:
        track = self._track
        if T_c1_ee is None:
            return None
        T_base_c2 = self.T_base_c1 @ T_c1_ee @ self._T_ee_c2
        dets = detect_berries(image, self.model2, settings=self.settings)
        self._place_unplaced(dets, T_base_c2)
        if track is None or not self._near:
            return None
        found = [
            d for d in dets if d.ripeness == "ripe" and track.consistent(d, T_base_c2, self.model2)
        ]
        if len(found) != 1:  # none, or two fruits where one is expected: no fix this frame
            return None
        return track.fix(found[0], T_base_c2, self.model2)

    def place_from_view(self, image: Any, T_base_c2: FloatArray) -> None:
        """Place what of the map's unplaced fruit C2 sees in ``image``, taken at
        ``T_base_c2`` (the cane survey's views: they face the bush from where the
        berries' approaches seldom take C2)."""
        if self.bush_map.unplaced:
            dets = detect_berries(image, self.model2, settings=self.settings)
            self._place_unplaced(dets, T_base_c2)

    def _place_unplaced(self, dets: list[BerryDetection], T_base_c2: FloatArray) -> None:
        """Add the crossings of C2's ripe detections that are no mapped berry with the
        map's sight lines; place each line whose crossings agree."""
        if not self.bush_map.unplaced:
            return
        free = [d for d in dets if d.ripeness == "ripe" and not self._is_mapped(d, T_base_c2)]
        for placing in list(self.bush_map.unplaced):
            for d in free:
                point = crossing(placing.line, d, T_base_c2, self.model2)
                if point is not None:
                    placing.add(point, T_base_c2[:3, 3])
            position = placing.position()
            if position is not None:
                self.bush_map.place(placing, position)

    def _is_mapped(self, det: BerryDetection, T_base_c2: FloatArray) -> bool:
        """Whether ``det`` is where C2 sees a berry of the map."""
        T_c2_base = invert(T_base_c2)
        for berry in self.bush_map.berries:
            p = (T_c2_base @ np.append(berry.position, 1.0))[:3]
            if p[2] <= berry.radius:
                continue
            u, v = self.model2.project(p[None, :])[0]
            reach = max(self.model2.focal * berry.radius / float(p[2]), MAPPED_GATE_PX)
            if np.hypot(det.center[0] - u, det.center[1] - v) <= reach:
                return True
        return False
