"""Berries C1 finds but cannot place, placed by C2.

C1's stereo leaves a fruit without a position where its two eyes do not match it: the
outline matches a neighbour, the shading of a dark fruit on a dark ground is flat, or a
leaf hides it from one eye only. Every C1 look then sees the same view, so such a fruit,
ripe and in full view of the left eye, would never be picked. It still gives its line of
sight: the ray from C1's left eye through it. C2 moves with the arm; where the ray
through a fruit C2 sees passes within a few millimetres of that line, at a crossing
angle that fixes the depth, the fruit is there (:mod:`softarm.perception.approach`
crosses the same two rays for a mapped berry). One crossing may be chance (another fruit
on C2's ray), so a :class:`Placing` takes the fruit's position only from several
crossings seen from C2 poses apart from each other that agree.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from softarm.checks import FloatArray, as_pose
from softarm.perception._inputs import instance
from softarm.perception.berries import BerryDetection, ripe_by_votes
from softarm.perception.two_lines import closest_params
from softarm.vision.camera_model import CameraModel
from softarm.vision.stereo_camera import StereoCamera

__all__ = ["Placing", "SightLine", "crossing", "sight_lines"]

#: The two rays must pass within this distance (m) of each other: about a fruit's radius.
RAY_GAP = 0.008
#: A fruit's radius (m) along its outline: 1.5-2.5 cm across, with a margin either side.
FRUIT_RADIUS = (0.0065, 0.016)
#: Crossings that agree within this distance (m) are the same fruit...
AGREEMENT = 0.01
#: ...and this many of them, from C2 poses this far (m) apart, place it.
CROSSINGS = 3
SPREAD = 0.02
#: Sight lines within this angle (rad) are the same fruit seen again (5 mm at 1 m).
SAME_LINE = 0.005


@dataclass
class SightLine:
    """The ray from C1's left eye (``origin``, base frame) along unit ``direction``
    through a fruit C1 found but could not place; ``half_angle`` (rad) is the angular
    radius of its outline, ``ripe_votes`` and ``sightings`` as a map berry's."""

    origin: FloatArray
    direction: FloatArray
    half_angle: float
    ripe_votes: float
    sightings: int = 1

    @property
    def ripe(self) -> bool:
        """Ripe when most of C1's sightings said so."""
        return ripe_by_votes(self.ripe_votes, self.sightings)


def sight_lines(detections: list[BerryDetection], stereo: StereoCamera) -> list[SightLine]:
    """The sight lines of ``detections`` (from :func:`~softarm.perception.stereo.
    locate_berries`: centres in the rectified left image) that have no position.

    Raises:
        InputError: ``stereo`` is not a StereoCamera.
    """
    rect = instance(stereo, StereoCamera, "stereo").rectification
    K = rect.P1[:3, :3]
    R = stereo.T_base_left[:3, :3] @ rect.R1.T  # rectified left frame -> base
    out = []
    for d in detections:
        if d.position is not None:
            continue
        ray = np.array([(d.center[0] - K[0, 2]) / K[0, 0], (d.center[1] - K[1, 2]) / K[1, 1], 1.0])
        out.append(
            SightLine(
                stereo.T_base_left[:3, 3].copy(),
                R @ ray / np.linalg.norm(ray),
                float(np.arctan2(d.radius, K[0, 0])),
                d.ripe_vote,
            )
        )
    return out


def crossing(
    line: SightLine, det: BerryDetection, T_base_camera: FloatArray, camera: CameraModel
) -> FloatArray | None:
    """Where the ray of ``camera`` (at ``T_base_camera``) through ``det`` crosses
    ``line`` (the midpoint of their closest points, base frame), or None: the rays pass
    farther apart than RAY_GAP, cross at less than two_lines.MIN_CROSSING, meet behind either
    camera, or the fruit's size in either image does not fit a fruit there.

    Raises:
        InputError: ``T_base_camera`` is not a finite rigid 4x4 pose (PoseError), or
            ``camera`` not a CameraModel.
    """
    T_base_camera = as_pose(T_base_camera, "T_base_camera")
    instance(camera, CameraModel, "camera")
    x, y = camera.normalize(np.array([det.center]))[0]
    local = np.array([x, y, 1.0]) / np.linalg.norm([x, y, 1.0])
    o2, u2 = T_base_camera[:3, 3], T_base_camera[:3, :3] @ local
    o1, u1 = line.origin, line.direction
    params = closest_params(o1, u1, o2, u2)
    if params is None:
        return None
    s, t = params
    p1, p2 = o1 + s * u1, o2 + t * u2
    if s <= 0.0 or t <= 0.0 or np.linalg.norm(p1 - p2) > RAY_GAP:
        return None
    for distance, half_angle in ((s, line.half_angle), (t, np.arctan2(det.radius, camera.focal))):
        radius = distance * np.sin(half_angle)
        if not FRUIT_RADIUS[0] <= radius <= FRUIT_RADIUS[1]:
            return None
    result: FloatArray = 0.5 * (p1 + p2)
    return result


@dataclass(eq=False)
class Placing:
    """The crossings of one sight line seen so far (their points and the C2 positions
    they were seen from); :meth:`position` once enough agree. Each is its own fruit:
    two are equal only when they are the same object (their arrays have no truth
    value to compare by)."""

    line: SightLine
    points: list[FloatArray] = field(default_factory=list)
    seen_from: list[FloatArray] = field(default_factory=list)

    def add(self, point: FloatArray, camera_position: FloatArray) -> None:
        """One crossing, seen by a camera at ``camera_position`` (base frame)."""
        self.points.append(np.asarray(point, dtype=np.float64))
        self.seen_from.append(np.asarray(camera_position, dtype=np.float64))

    def position(self) -> FloatArray | None:
        """The mean of the largest group of crossings within AGREEMENT of their
        median, once it holds CROSSINGS of them seen from C2 positions spanning
        SPREAD; else None."""
        if len(self.points) < CROSSINGS:
            return None
        pts, origins = np.array(self.points), np.array(self.seen_from)
        near = np.linalg.norm(pts - np.median(pts, axis=0), axis=1) <= AGREEMENT
        if near.sum() < CROSSINGS:
            return None
        seen = origins[near]
        if float(np.linalg.norm(seen.max(axis=0) - seen.min(axis=0))) < SPREAD:
            return None
        result: FloatArray = pts[near].mean(axis=0)
        return result


def same_line(a: SightLine, b: SightLine) -> bool:
    """Whether two sight lines are one fruit seen again (from the same eye)."""
    return bool(float(a.direction @ b.direction) >= np.cos(SAME_LINE))
