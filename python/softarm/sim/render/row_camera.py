"""The row's cameras as a real rig delivers their frames: each rendered frame goes
through its camera's :class:`~softarm.sim.render.camera_effects.CameraEffects` (the
look's), seeded by the look, the camera and the frame's count, so that a run is
repeatable. C1's left eye meters (auto-exposure) and the right eye exposes with the
left's exposure times its own bias, shifted by the pair's rectification error (the
ground truth is not shifted: it is where the scene is). A window of C1's left eye (the
cube tracking's) keeps that eye's last exposure and has no vignetting of its own.
Motion blur: the look's ``blur_px_s`` in a random direction each frame (the camera's
and the arm's motion, which the renderer does not know).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import numpy.typing as npt

from softarm.sim.render.camera_effects import CameraEffects
from softarm.sim.render.row_look import RowLook

__all__ = ["RowCameras"]

_CAMERAS = ("c1_left", "c1_right", "c2", "c1_window")


class RowCameras:
    """Applies ``look``'s camera model to the frames of each camera (see the module
    docstring)."""

    def __init__(self, look: RowLook) -> None:
        self.look = look
        self._count = dict.fromkeys(_CAMERAS, 0)
        self._exposure: float | None = None

    def _rng(self, camera: str) -> np.random.Generator:
        self._count[camera] += 1
        return np.random.default_rng([self.look.seed, _CAMERAS.index(camera), self._count[camera]])

    def _velocity(self, rng: np.random.Generator) -> tuple[float, float]:
        angle = rng.uniform(0.0, 2 * np.pi)
        speed = self.look.blur_px_s * rng.uniform(0.0, 1.0)
        return float(speed * np.cos(angle)), float(speed * np.sin(angle))

    def apply(self, camera: str, image: npt.NDArray[np.uint8]) -> npt.NDArray[np.uint8]:
        """``image`` of ``camera`` (c1_left, c1_right, c2 or c1_window) as delivered."""
        rng = self._rng(camera)
        velocity = self._velocity(rng)
        stereo = self.look.stereo
        if camera == "c2":
            return self.look.c2.apply(image, rng, velocity)
        if camera == "c1_left":
            self._exposure = stereo.left.exposure_of(image)
            return stereo.left.apply(image, rng, velocity, exposure=self._exposure)
        if camera == "c1_right":
            left = self._exposure or stereo.left.exposure_of(image)
            exposure = left * stereo.right_exposure
            return stereo.right().apply(image, rng, velocity, exposure, stereo.right_offset_px)
        window: CameraEffects = replace(stereo.left, vignetting=0.0)
        return window.apply(image, rng, velocity, exposure=self._exposure)
