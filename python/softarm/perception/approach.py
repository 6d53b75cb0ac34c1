"""A berry's position from the two cameras together as the gripper closes in on it.

C1's stereo places a berry well across its line of sight (a fifth of a pixel, a fifth
of a millimetre at 1 m) and poorly along it (half a pixel of disparity, ±5 mm). C2
places it well across its own line of sight and, without a tag of known size, not at
all along it: a fruit's width varies by ±15 %, and so would its distance from its
apparent size. The two lines of sight cross at 40–50° (C1 looks across the bush, C2
along the approach), so the berry is where C2's ray through the fruit passes nearest
C1's ray to it: each camera supplies the directions it measures well.

Across both lines of sight (along their common normal) both cameras measure the berry,
and about equally well at the grasp in the bush: C1's ray misses the berry's centre by
0.17 px median at 1.07 m (f 900 px: 0.2 mm), C2's by 0.41 px at 6 cm (f 150 px:
0.16 mm). Given each ray's spread (``spreads``; the bush's: :data:`C1_RAY_PX`,
:data:`C2_CENTRE_PX`), the fix is the point nearest both rays in the least squares
weighted by each one's inverse variance there. The harvest does not weigh them (its fix
stays on C2's ray): in the bush the weighing took the bias's median down and not the
grasps over 0.5 mm, and on two rows, whose rays' spreads were not measured, more grasps
ended over 0.5 mm (docs/harvest-candidates.md, "The fix weighed between the two rays").

C2's ray reaches the base frame through the tracked end effector (eq. 21), and so
does the gripper (eq. 22): an error of the cube tracking moves the fix and the
gripper together and cancels at the grasp, as it does for a tag in the tag world.
"""

from __future__ import annotations

import numpy as np

from softarm.checks import FloatArray, as_array, as_pose, positive
from softarm.errors import ParameterError
from softarm.perception._inputs import instance
from softarm.perception.berries import BerryDetection
from softarm.perception.two_lines import closest_params
from softarm.vision.camera_model import CameraModel

__all__ = [
    "C1_RAY_PX",
    "C2_CENTRE_PX",
    "DISPARITY_SPREAD_PX",
    "RayCrossing",
    "along_spread",
    "distance_from_size",
]

#: A detection is this berry when its size is within this ratio of the expected one...
SIZE_RANGE = (0.6, 1.6)
#: ...and its centre within the expected radius, or this many pixels, of the expected one.
MIN_GATE_PX = 8.0
#: How far (px of C1's disparity) the stereo's match may miss: C2 looks for the berry
#: along C1's ray as far as this many pixels of disparity move it. The placed berries'
#: disparity error on the diagnosis rows 90120-90125 is 0.49 px median, 1.35 px p95;
#: twice the p95 keeps the tail that a wrong cue's match leaves.
DISPARITY_SPREAD_PX = 3.0
#: The spread (px, one image axis) of C1's ray through a berry it placed (its rectified
#: image) and of C2's ray through the fruit it detects at fine positioning (its image):
#: measured on the diagnosis bushes 1500-1509, frustum (c1_lean: 0.167 px median error
#: of C1's ray; c2_lean: 0.41 px of C2's centre at its fixes); a round 2-D error of
#: spread s per axis has a median norm of 1.18 s.
C1_RAY_PX = 0.14
C2_CENTRE_PX = 0.35


def along_spread(depth: float, focal: float, baseline: float) -> float:
    """How far (m) along C1's ray a berry placed at ``depth`` (m) by a stereo pair of
    ``focal`` (px) and ``baseline`` (m) may lie from where it was placed: the depth that
    :data:`DISPARITY_SPREAD_PX` of disparity spans there, z^2 d / (f b).

    Raises:
        ParameterError: an argument that is not a finite number > 0.
    """
    z, f, b = positive(depth, "depth"), positive(focal, "focal"), positive(baseline, "baseline")
    return z * z * DISPARITY_SPREAD_PX / (f * b)


def distance_from_size(radius_m: float, radius_px: float, focal: float) -> float:
    """The distance (m) to the centre of a sphere of ``radius_m`` whose outline has
    ``radius_px`` in an image of focal length ``focal`` (px): R / sin(atan(r / f)).

    Raises:
        ParameterError: an argument that is not a finite number > 0 (a radius of 0 px
            is a fruit infinitely far).
    """
    r, px, f = (
        positive(radius_m, "radius_m"), positive(radius_px, "radius_px"), positive(focal, "focal")
    )  # fmt: skip
    return r / float(np.sin(np.arctan2(px, f)))


class RayCrossing:
    """The berry where C2's ray to it crosses C1's (see the module docstring).

    Args:
        c1_centre: where C1's ray starts, in the base frame: the middle of its stereo
            baseline for a berry :func:`~softarm.perception.stereo.locate_berries`
            placed (:func:`~softarm.perception.two_eyes.ray_origin`: the berry's
            direction from there is the mean of the two eyes'), else its optical centre.
        position: the berry's position from C1's stereo (base frame), which gives C1's
            ray and, with ``radius`` (m), where and how large C2 should see it.
        along: how far (m) along C1's ray the berry may lie from ``position``
            (:func:`along_spread`): the stereo places it well across its line of sight
            and poorly along it, so C2's gate (:meth:`consistent`) is centred on the
            point of C1's ray within ``along`` of ``position`` nearest C2's ray through
            the detection. 0: centred on ``position``.
        spreads: the spread (rad, one axis) of C1's ray and of C2's ray through a
            detection's centre (px: divided by C2's focal length at each fix), weighing
            the fix between the two rays (:meth:`fix`); None: the fix on C2's ray.

    Raises:
        InputError: a point that is not a finite (3,) array, the two the same, a radius
            that is not a finite number > 0, ``along`` not a finite number >= 0, or a
            spread not a finite number > 0.
    """

    def __init__(
        self,
        c1_centre: FloatArray,
        position: FloatArray,
        radius: float,
        along: float = 0.0,
        spreads: tuple[float, float] | None = None,
    ) -> None:
        self.c1_centre = as_array(c1_centre, (3,), "c1_centre")
        self.position = as_array(position, (3,), "position")
        ray = self.position - self.c1_centre
        length = float(np.linalg.norm(ray))
        if length == 0.0:
            raise ParameterError("position must differ from c1_centre: C1 has no ray to it")
        self.c1_ray = ray / length
        self.radius = positive(radius, "radius")
        self.along = 0.0 if along == 0.0 else positive(along, "along")
        self.spreads = None if spreads is None else (
            positive(spreads[0], "spreads[0]"), positive(spreads[1], "spreads[1]")
        )  # fmt: skip

    def fix(
        self, det: BerryDetection, T_base_camera: FloatArray, camera: CameraModel
    ) -> FloatArray | None:
        """The berry's centre in the camera's frame, on the ray through ``det`` where it
        passes nearest C1's ray, or with ``spreads`` between that point and C1's ray's
        nearest, weighted by the inverse variance of each ray's spread there (the
        weighted least-squares point of the two lines); None when the two rays are too
        near parallel.

        Raises:
            InputError: ``T_base_camera`` is not a finite rigid 4x4 pose (PoseError),
                ``det`` not a BerryDetection or ``camera`` not a CameraModel.
        """
        T_base_camera = _checked(det, T_base_camera, camera)
        x, y = camera.normalize(np.array([det.center]))[0]
        local = np.array([x, y, 1.0]) / np.linalg.norm([x, y, 1.0])
        origin, ray = T_base_camera[:3, 3], T_base_camera[:3, :3] @ local
        params = closest_params(self.c1_centre, self.c1_ray, origin, ray)
        if params is None:
            return None
        result: FloatArray = local * params[1]
        if self.spreads is not None:
            on_c1 = self.c1_centre + params[0] * self.c1_ray
            towards = T_base_camera[:3, :3].T @ (on_c1 - origin) - result
            result = result + _c1_share(params, self.spreads, camera.focal) * towards
        return result

    def consistent(
        self, det: BerryDetection, T_base_camera: FloatArray, camera: CameraModel
    ) -> bool:
        """Whether ``det`` can be this berry: within its apparent radius of where C1
        puts it (the point of C1's ray within ``along`` of the stereo's position nearest
        the detection's ray), and of a size within SIZE_RANGE of what C1's radius gives
        there. Arguments and errors as :meth:`fix`."""
        T_base_camera = _checked(det, T_base_camera, camera)
        centre = self._nearest_on_c1(det, T_base_camera, camera)
        p = np.linalg.inv(T_base_camera) @ np.append(centre, 1.0)
        dist = float(np.linalg.norm(p[:3]))
        if p[2] <= 0.0 or dist <= self.radius:
            return False
        centre = camera.project(p[None, :3])[0]
        expected = camera.focal * float(np.tan(np.arcsin(self.radius / dist)))
        offset = float(np.hypot(det.center[0] - centre[0], det.center[1] - centre[1]))
        ratio = det.radius / expected
        return offset <= max(expected, MIN_GATE_PX) and SIZE_RANGE[0] <= ratio <= SIZE_RANGE[1]

    def _nearest_on_c1(
        self, det: BerryDetection, T_base_camera: FloatArray, camera: CameraModel
    ) -> FloatArray:
        """The point of C1's ray, within ``along`` of the stereo's position, nearest the
        camera's ray through ``det`` (the position itself where the rays are near
        parallel: then C2 cannot tell where along C1's ray the fruit is)."""
        x, y = camera.normalize(np.array([det.center]))[0]
        ray = T_base_camera[:3, :3] @ (np.array([x, y, 1.0]) / np.linalg.norm([x, y, 1.0]))
        params = closest_params(self.position, self.c1_ray, T_base_camera[:3, 3], ray)
        if self.along == 0.0 or params is None:
            return self.position
        s = float(np.clip(params[0], -self.along, self.along))
        out: FloatArray = self.position + s * self.c1_ray
        return out


def _c1_share(params: tuple[float, float], spreads: tuple[float, float], focal: float) -> float:
    """How far (0-1) from C2's ray towards C1's the fix lies: C2's variance over both
    rays' at the distances ``params`` (m along C1's ray, C2's) of their nearest points,
    ``spreads`` (C1's rad, C2's px at ``focal``)."""
    var1 = (spreads[0] * params[0]) ** 2
    var2 = (spreads[1] / focal * params[1]) ** 2
    return var2 / (var1 + var2) if var1 + var2 > 0.0 else 0.0


def _checked(det: object, T_base_camera: object, camera: object) -> FloatArray:
    """``T_base_camera`` as a checked pose, after ``det`` and ``camera``'s types."""
    instance(det, BerryDetection, "det")
    instance(camera, CameraModel, "camera")
    return as_pose(T_base_camera, "T_base_camera")
