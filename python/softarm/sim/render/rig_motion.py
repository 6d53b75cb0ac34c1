"""How fast the rendered rig's parts move, for the motion blur of each camera's frames
(:mod:`softarm.sim.render.motion_blur`): the one record of where the arm was drawn and
when, and the image velocity it gives each camera.

The world reports every drawing of the arm (:meth:`RigMotion.moved`: the end effector's
pose and the arm's body as discs, the points the leaves are pushed by), stamped by the
simulation's clock. A frame taken at time ``t`` sees the arm as last drawn; its motion
is the step from the drawing before that one, over the time between them. If the arm
was last drawn before ``t`` it has held still since, and nothing blurs. Without a clock
(single renders: datasets, pictures, the robustness map) there is no motion.

C2 rides on the end effector: its frames move as a whole, each pixel at the image
velocity of the scene there given C2's twist (:func:`camera_twist`, :func:`twist_flow`,
on the pinhole grid: the lens's mild distortion moves a smear by a fraction of its
length), the scene taken as the plane of the bush's berries facing the arm
(:func:`plane_inverse_depth`: C2's frames look at the bush's face, the target berry
on it; past its edge, the sky). What of the rig C2 sees (the fingers, the marker
body's panels) moves with it and stays sharp: its pixels, the same in every C2 frame,
are found once (``rig_in_c2``, the world's segmentation of one C2 frame).

C1 is fixed: only the arm moves in its frames, each disc of its body at the image
velocity of its centre over the band it sweeps (:func:`swept_flow`); the bush, the row
and the sky stay sharp. (The look's ``blur_px_s`` adds a whole-frame blur of C1's own,
its mount shaking; :mod:`softarm.sim.render.row_camera`.)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.sim.render.motion_blur import (
    Flow,
    camera_twist,
    plane_inverse_depth,
    swept_flow,
    twist_flow,
)
from softarm.vision.camera_model import CameraModel
from softarm.vision.poses import invert
from softarm.vision.stereo_camera import StereoCamera

__all__ = ["ArmDrawn", "RigMotion"]

#: Drawings kept (the last two are all a frame needs).
KEEP = 4
#: Times (s) this close are one instant (a clock read twice, summed differently).
TIME_TOLERANCE = 1e-9


@dataclass(frozen=True)
class ArmDrawn:
    """One drawing of the arm: when (s), the end effector's pose, and the body as
    discs: centres (N, 3, base frame) and radii (N,) m, the fast end last."""

    t: float
    T_base_ee: FloatArray
    body: FloatArray
    radius: FloatArray


@dataclass
class RigMotion:
    """Where the rig's cameras are (C1's pair, C2's intrinsics and pose on the end
    effector), the scene's plane (a point on the bush's face and its normal, base
    frame), the clock, and the arm's last drawings (see the module docstring)."""

    stereo: StereoCamera
    c2: CameraModel
    T_ee_c2: FloatArray
    plane: tuple[FloatArray, FloatArray]
    clock: Callable[[], float] | None = None
    rig_in_c2: Callable[[], npt.NDArray[np.bool_]] | None = None
    drawn: list[ArmDrawn] = field(default_factory=list)
    _still: npt.NDArray[np.bool_] | None = None

    def c2_still(self) -> npt.NDArray[np.bool_] | None:
        """C2's pixels of the rig (they move with it), found at the first call."""
        if self._still is None and self.rig_in_c2 is not None:
            self._still = self.rig_in_c2()
        return self._still

    def moved(self, T_base_ee: FloatArray, body: FloatArray, radius: FloatArray) -> None:
        """The arm drawn anew at the clock's time (nothing kept without a clock)."""
        if self.clock is None:
            return
        entry = ArmDrawn(float(self.clock()), np.array(T_base_ee), np.array(body), np.array(radius))
        self.drawn = [*self.drawn[-(KEEP - 1) :], entry]

    def step(self) -> tuple[ArmDrawn, ArmDrawn, float] | None:
        """(before, now, dt): the arm's last step if it is moving at the clock's time,
        None if it holds still, was drawn once, or there is no clock."""
        if self.clock is None or not self.drawn:
            return None
        now = self.drawn[-1]
        if now.t < float(self.clock()) - TIME_TOLERANCE:
            return None  # drawn before this frame and not since: still
        before = next((d for d in reversed(self.drawn[:-1]) if d.t < now.t - TIME_TOLERANCE), None)
        if before is None:
            return None
        return before, now, now.t - before.t

    def c2_flow(self) -> Flow | None:
        """C2's image velocity (H, W, 2) px/s now, None while it is still."""
        step = self.step()
        if step is None:
            return None
        before, now, dt = step
        T_now, T_before = now.T_base_ee @ self.T_ee_c2, before.T_base_ee @ self.T_ee_c2
        v, w = camera_twist(T_before, T_now, dt)
        if not (np.any(v) or np.any(w)):
            return None
        K = self.c2.matrix
        focal, principal = float(K[0, 0]), (float(K[0, 2]), float(K[1, 2]))
        size = self.c2.image_size or (int(2 * principal[0] + 1), int(2 * principal[1] + 1))
        depth = plane_inverse_depth(T_now, *self.plane, focal, principal, size)
        return twist_flow(v, w, focal, principal, size, depth)

    def c1_flow(
        self, eye: str, size: tuple[int, int], origin: tuple[int, int], exposure_s: float
    ) -> Flow | None:
        """The image velocity (H, W, 2) px/s of C1's ``eye`` ("left" or "right") over a
        frame of ``size`` (W, H) at ``origin`` of the whole image: the arm's swept
        discs, still elsewhere; None while the arm is still or out of view."""
        step = self.step()
        if step is None:
            return None
        before, now, dt = step
        model = self.stereo.left if eye == "left" else self.stereo.right
        T_base_eye = self.stereo.T_base_left
        if eye != "left":
            T_base_eye = T_base_eye @ self.stereo.T_left_right
        if now.body.shape != before.body.shape:
            return None  # another arm drawn: no step to take
        T_eye_base = invert(T_base_eye)
        p_now = now.body @ T_eye_base[:3, :3].T + T_eye_base[:3, 3]
        p_before = before.body @ T_eye_base[:3, :3].T + T_eye_base[:3, 3]
        front = (p_now[:, 2] > 0.05) & (p_before[:, 2] > 0.05)
        if not front.any():
            return None
        centres = model.project(p_now[front])
        velocity = (centres - model.project(p_before[front])) / dt
        radii = float(model.matrix[0, 0]) * now.radius[front] / p_now[front, 2]
        flow = swept_flow(size, centres, velocity, radii, exposure_s, origin)
        return flow if flow.any() else None
