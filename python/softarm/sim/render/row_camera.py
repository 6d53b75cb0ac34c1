"""The row's cameras as a real rig delivers their frames: each rendered frame goes
through its camera's :class:`~softarm.sim.render.camera_effects.CameraEffects` (the
look's), seeded by the look, the camera and the frame's count, so that a run is
repeatable. C1's left eye meters (auto-exposure) and the right eye exposes with the
left's exposure times its own bias, shifted by the pair's rectification error (the
ground truth is not shifted: it is where the scene is). A window of C1's left eye (the
cube tracking's) is metered on itself: the tracker sets the camera's auto-exposure
region of interest to the marker's window (the ZED SDK's ``AEC_AGC_ROI``), so the
marker's white paper does not clip however dark the hedge around it is
(:meth:`~softarm.sim.render.camera_effects.CameraEffects.roi_exposure_of`); it has no
vignetting of its own. A real camera's metering converges over a few frames and
exposes the whole frame so; here each window is metered at once and C1's full frames
keep their own metering (the harvest takes them with the arm at home).

Motion blur comes from the motion (:class:`~softarm.sim.render.rig_motion.RigMotion`,
given by the world with the rig's geometry and the simulation's clock): C2's frames
smear as a whole along the scene's image velocity from C2's own twist; in C1's only the
arm smears, by its image velocity over what it sweeps. C1 also takes the look's
``blur_px_s`` in a random direction each frame: its mount's own shake (wind, the
platform), which the arm's motion does not give. A still arm adds no blur to C2: its
frame is then the same, bit for bit, as a frame blurred by nothing (the random draw
below is still made, and unused, so that the noise that follows is the same). Where
the motion is not known (no clock: a dataset's or a picture's single renders) C2
takes the look's random blur, as C1 does: such frames are as they were before the
motion was known.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import numpy.typing as npt

from softarm.errors import ParameterError
from softarm.sim.render.camera_effects import CameraEffects
from softarm.sim.render.rig_motion import RigMotion
from softarm.sim.render.row_look import RowLook

__all__ = ["RowCameras"]

_CAMERAS = ("c1_left", "c1_right", "c2", "c1_window")


class RowCameras:
    """Applies ``look``'s camera model to the frames of each camera (see the module
    docstring); ``motion``: the rig's motion (None: no motion blur from it)."""

    def __init__(self, look: RowLook, motion: RigMotion | None = None) -> None:
        self.look = look
        self.motion = motion
        self._count = dict.fromkeys(_CAMERAS, 0)
        self._exposure: float | None = None

    def skip(self, camera: str) -> None:
        """A frame of ``camera`` the rig did not take (the harvest needed no C2 fix that
        period): its number is used up, so that the frames taken after it keep the
        numbers, and so the noise, they have in a run that takes every frame.

        Raises:
            ParameterError: ``camera`` is none of c1_left, c1_right, c2, c1_window.
        """
        if camera not in self._count:
            raise ParameterError(f"camera must be one of {', '.join(_CAMERAS)}, got {camera!r}")
        self._count[camera] += 1

    def _rng(self, camera: str) -> np.random.Generator:
        self._count[camera] += 1
        return np.random.default_rng([self.look.seed, _CAMERAS.index(camera), self._count[camera]])

    def _velocity(self, rng: np.random.Generator) -> tuple[float, float]:
        angle = rng.uniform(0.0, 2 * np.pi)
        speed = self.look.blur_px_s * rng.uniform(0.0, 1.0)
        return float(speed * np.cos(angle)), float(speed * np.sin(angle))

    def _c1_flow(
        self, eye: str, image: npt.NDArray[np.uint8], origin: tuple[int, int], exposure_s: float
    ) -> npt.NDArray[np.float32] | None:
        if self.motion is None:
            return None
        size = (image.shape[1], image.shape[0])
        return self.motion.c1_flow(eye, size, origin, exposure_s)

    def apply(
        self,
        camera: str,
        image: npt.NDArray[np.uint8],
        origin: tuple[int, int] = (0, 0),
        scale: float = 1.0,
    ) -> npt.NDArray[np.uint8]:
        """``image`` of ``camera`` (c1_left, c1_right, c2 or c1_window) as delivered;
        ``origin``: a window's top-left pixel in the whole image; ``scale``: the share
        of the scene's light a c1_window was rendered with
        (:mod:`softarm.sim.render.headroom`), 1 for every other camera.

        Raises:
            ParameterError: ``scale`` not 1 for a camera other than c1_window.
        """
        if scale != 1.0 and camera != "c1_window":
            raise ParameterError(f"scale must be 1 for {camera!r}, got {scale}")
        rng = self._rng(camera)
        shake = self._velocity(rng)
        stereo = self.look.stereo
        if camera == "c2":
            if self.motion is None or self.motion.clock is None:  # the motion unknown
                return self.look.c2.apply(image, rng, shake)
            flow = self.motion.c2_flow()
            still = None if flow is None else self.motion.c2_still()
            return self.look.c2.apply(image, rng, flow_px_s=flow, still=still)
        exposure_s = stereo.left.exposure_s
        if camera == "c1_left":
            self._exposure = stereo.left.exposure_of(image)
            flow = self._c1_flow("left", image, origin, exposure_s)
            return stereo.left.apply(image, rng, shake, self._exposure, flow_px_s=flow)
        if camera == "c1_right":
            left = self._exposure or stereo.left.exposure_of(image)
            exposure = left * stereo.right_exposure
            flow = self._c1_flow("right", image, origin, exposure_s)
            right = stereo.right()
            return right.apply(image, rng, shake, exposure, stereo.right_offset_px, flow)
        window: CameraEffects = replace(stereo.left, vignetting=0.0)
        flow = self._c1_flow("left", image, origin, exposure_s)
        exposure = window.roi_exposure_of(image, scale)
        return window.apply(image, rng, shake, exposure=exposure, flow_px_s=flow)
