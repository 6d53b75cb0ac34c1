"""A berry's position from the eye-in-hand camera as the gripper closes in on it.

One C2 view gives the ray the berry lies on, and its apparent size gives its distance
only as well as its width is known (z = f D / d: a fruit's width varies by ±15 %, so
±15 % of the distance). As the arm approaches, C2 sees the berry from a sequence of
tracked poses (eq. 21): the rays cross, and the growth of the apparent radius with the
known advance fixes the distance whatever the fruit's true width (the looming of a
fruit, r_i = f R / |p − c_i| for every view i, with R unknown but shared). The
estimate solves for the centre p and the radius R by least squares over the recent
views, with C1's stereo position and the nominal fruit size as priors.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from softarm.checks import FloatArray
from softarm.perception.berries import BerryDetection
from softarm.vision.camera_model import CameraModel

__all__ = ["ApproachTriangulation", "Sighting"]

#: The farthest (m, per axis) the estimate may move from C1's position: C1's stereo
#: puts a berry within a centimetre, so a farther estimate is another fruit's.
MAX_SHIFT = 0.015
#: The nominal fruit radius (m) and its spread: 1.5–2.5 cm across.
FRUIT_RADIUS = (0.011, 0.003)


@dataclass(frozen=True)
class Sighting:
    """One C2 view: the optical centre and the unit ray to the berry's image centre (base
    frame), its apparent radius and the focal length (px)."""

    centre: FloatArray
    ray: FloatArray
    radius_px: float
    focal: float


class ApproachTriangulation:
    """The berry's centre from its C2 sightings (see the module docstring).

    Args:
        prior: the berry's position from C1's stereo (base frame, m).
        prior_sigma: its uncertainty (m).
        ray_px, size_px: the uncertainty (px) of a detection's centre and radius.
        bin_width: sightings are kept one per ``bin_width`` (m) of distance to the
            prior, the latest in each: the fine positioning holds the camera at one
            distance for hundreds of frames, and a window of the latest views alone
            would lose the spread of distances that the looming needs.
    """

    def __init__(
        self,
        prior: FloatArray,
        prior_sigma: float = 0.006,
        ray_px: float = 1.0,
        size_px: float = 1.5,
        bin_width: float = 0.004,
    ) -> None:
        self.prior = np.asarray(prior, dtype=np.float64)
        self.prior_sigma, self.ray_px, self.size_px = prior_sigma, ray_px, size_px
        self.bin_width = bin_width
        self._bins: dict[int, Sighting] = {}
        self._last = np.append(self.prior, FRUIT_RADIUS[0])

    def add(self, T_base_camera: FloatArray, camera: CameraModel, det: BerryDetection) -> None:
        """Record ``det``, seen by ``camera`` at ``T_base_camera``."""
        x, y = camera.normalize(np.array([det.center]))[0]
        ray = T_base_camera[:3, :3] @ np.array([x, y, 1.0])
        centre = T_base_camera[:3, 3].copy()
        key = round(float(np.linalg.norm(self.prior - centre)) / self.bin_width)
        self._bins[key] = Sighting(centre, ray / np.linalg.norm(ray), det.radius, camera.focal)

    @property
    def sightings(self) -> list[Sighting]:
        """The sightings in use, one per distance bin."""
        return list(self._bins.values())

    def estimate(self) -> FloatArray:
        """The berry's centre (base frame, m): the prior until a sighting is added."""
        if not self.sightings:
            return self.prior.copy()
        lower = np.append(self.prior - MAX_SHIFT, FRUIT_RADIUS[0] - 2 * FRUIT_RADIUS[1])
        upper = np.append(self.prior + MAX_SHIFT, FRUIT_RADIUS[0] + 2 * FRUIT_RADIUS[1])
        start = np.clip(self._last, lower + 1e-9, upper - 1e-9)
        # soft-L1: a view of a neighbour, or of a fruit half behind a finger, is
        # outvoted rather than averaged in.
        fit = least_squares(self._residuals, start, bounds=(lower, upper), loss="soft_l1")
        self._last = fit.x
        return fit.x[:3].copy()

    def _residuals(self, x: FloatArray) -> FloatArray:
        p, radius = x[:3], x[3]
        out = [(p - self.prior) / self.prior_sigma,
               [(radius - FRUIT_RADIUS[0]) / FRUIT_RADIUS[1]]]  # fmt: skip
        for s in self.sightings:
            v = p - s.centre
            dist = max(float(np.linalg.norm(v)), 1e-3)
            px_per_m = s.focal / dist
            off_ray = v - (v @ s.ray) * s.ray  # perpendicular to the ray
            out.append(off_ray * px_per_m / self.ray_px)
            out.append([(s.focal * radius / dist - s.radius_px) / self.size_px])
        return np.concatenate(out)
