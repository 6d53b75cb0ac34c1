"""Simulated perception of the harvest loop: the synthetic eye-to-hand camera C1 renders
the base tag, the end-effector marker cube and the berry tags; the synthetic eye-in-hand
camera C2 renders the berry tags in front of the gripper. Images go through the real
vision pipeline (ArUco detection, cube pose, base-tag registration) and the two-camera
fusion of eq. (21)–(22). Implements both
:class:`~softarm.harvest.interfaces.EndEffectorTracker` and
:class:`~softarm.harvest.interfaces.BerryLocator`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from softarm.harvest.interfaces import BerryFix, BerryTarget, FloatArray
from softarm.sim.bush import Berry
from softarm.sim.camera import SyntheticCamera
from softarm.sim.markers import SceneMarker, cube_scene_markers
from softarm.vision import BaseRegistration, CameraFusion, CameraModel, MarkerCube, MarkerDetector
from softarm.vision.detector import square_marker_poses
from softarm.vision.poses import invert

__all__ = ["SimCameras", "SimVision", "look_at"]

DICT = "DICT_4X4_50"


def look_at(
    eye: FloatArray, target: FloatArray, up: tuple[float, float, float] = (0.0, 0.0, 1.0)
) -> FloatArray:
    """``T_base_camera`` of a camera at ``eye`` whose optical axis (z) points at
    ``target``, image y (down) along -``up`` as far as possible."""
    z = (target - eye) / np.linalg.norm(target - eye)
    x = np.cross(-np.asarray(up), z)
    x /= np.linalg.norm(x)
    pose = np.eye(4)
    pose[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    pose[:3, 3] = eye
    return pose


@dataclass
class SimCameras:
    """Geometry of the simulated cameras and markers (true values).

    ``scale`` multiplies both image sizes and focal lengths (0.5 = quarter the pixels).
    """

    T_base_c1: FloatArray
    T_ee_c2: FloatArray
    T_ee_cube: FloatArray
    T_base_tag: FloatArray
    c1_size: tuple[int, int] = (1280, 720)
    c1_focal: float = 900.0
    c2_size: tuple[int, int] = (640, 480)
    c2_focal: float = 300.0
    noise_std: float = 2.0
    cube_marker: float = 0.08
    base_tag: float = 0.08
    berry_tag: float = 0.03
    scale: float = 1.0

    def model(self, which: int) -> CameraModel:
        """The intrinsics of C1 (``which`` = 1) or C2 (2), mild barrel distortion."""
        size, f = (self.c1_size, self.c1_focal) if which == 1 else (self.c2_size, self.c2_focal)
        w, h = round(size[0] * self.scale), round(size[1] * self.scale)
        return CameraModel.ideal(f * self.scale, w, h, [-0.05, 0.01, 0.0, 0.0, 0.0])


class SimVision:
    """Renders and measures both cameras at the true arm pose ``true_pose()``.

    ``berries()`` gives the berries still on the bush; ``hidden(t)`` (optional) hides
    the selected berry's tag from both cameras, like a leaf; ``max_age`` is how long
    the last berry fix is held (section III-D).
    """

    def __init__(
        self,
        cams: SimCameras,
        true_pose: Callable[[], FloatArray],
        berries: Callable[[], Sequence[Berry]],
        grasp_offset: float,
        seed: int = 0,
        max_age: float = 1.0,
        registration_frames: int = 5,
        hidden: Callable[[float], bool] | None = None,
    ) -> None:
        self.cams, self.true_pose, self.berries = cams, true_pose, berries
        self.hidden = hidden or (lambda t: False)
        self.model1, self.model2 = cams.model(1), cams.model(2)
        self.c1 = SyntheticCamera(
            self.model1, *self.model1.image_size, noise_std=cams.noise_std, seed=seed, supersample=2
        )
        self.c2 = SyntheticCamera(
            self.model2,
            *self.model2.image_size,
            noise_std=cams.noise_std,
            seed=seed + 1,
            supersample=2,
        )
        self.cube = MarkerCube.standard(cams.cube_marker)
        self.detector = MarkerDetector(DICT)
        self.selected = BerryTarget(-1)
        self._cube_prev: FloatArray | None = None
        self._c1: tuple[FloatArray | None, FloatArray | None] = (None, None)
        # Online registration of C1 from the base tag (section II-C): T_C1^Base of eq. (22).
        reg = BaseRegistration(
            self.model1, 4, cams.base_tag, cams.T_base_tag, DICT, registration_frames
        )
        for _ in range(registration_frames):
            reg.update(self._render_c1(include_berries=False))
        if reg.T_base_camera is None:
            raise RuntimeError("the eye-to-hand camera does not see the base tag")
        self.T_base_c1 = reg.T_base_camera
        self.fusion = CameraFusion(
            self.T_base_c1, cams.T_ee_c2, max_age=max_age, tool_point=(0, 0, grasp_offset)
        )

    # -- BerryLocator / EndEffectorTracker ------------------------------------------

    def select(self, berry: BerryTarget) -> None:
        """Track ``berry`` from now on (the fusion forgets any held target)."""
        self.selected = berry
        self.fusion.reset()

    def track(self, time: float) -> FloatArray | None:
        """C1: ``T_base_ee`` from the cube (eq. 22), also the berry in C1 for :meth:`locate`."""
        img = self._render_c1(include_berries=True, time=time)
        dets = self.detector.detect(img, self.model1)
        est = self.cube.estimate(dets, self.model1, self._cube_prev)
        berry_c1 = self._tag_position(dets, self.model1)
        if est is None:
            self._c1 = (None, berry_c1)
            return None
        self._cube_prev = est.T_camera_cube
        T_c1_ee = est.T_camera_cube @ invert(self.cams.T_ee_cube)
        self._c1 = (T_c1_ee, berry_c1)
        return self.T_base_c1 @ T_c1_ee

    def locate(self, time: float, T_base_ee: FloatArray | None) -> BerryFix | None:
        """C2 and the fusion: the berry in the base frame (eq. 21), held while hidden."""
        T_c1_ee, berry_c1 = self._c1
        berry_c2 = None
        if not self.hidden(time):
            T_c2_base = invert(self.true_pose() @ self.cams.T_ee_c2)
            img = self.c2.render(self._berry_markers(T_c2_base))
            berry_c2 = self._tag_position(self.detector.detect(img, self.model2), self.model2)
        est = self.fusion.update(time, T_c1_ee, berry_c1, berry_c2)
        if est.target is None or est.source == "none":
            return None
        return BerryFix(est.target, est.source, est.target_age)

    # -- rendering ------------------------------------------------------------------

    def _render_c1(self, include_berries: bool, time: float = 0.0) -> np.ndarray:
        T_c1_base = invert(self.cams.T_base_c1)
        items = [SceneMarker(4, DICT, self.cams.base_tag, T_c1_base @ self.cams.T_base_tag)]
        T_c1_cube = T_c1_base @ self.true_pose() @ self.cams.T_ee_cube
        items += cube_scene_markers(self.cube.markers, self.cube.marker_length, DICT, T_c1_cube)
        if include_berries and not self.hidden(time):
            items += self._berry_markers(T_c1_base)
        return self.c1.render(items)

    def _berry_markers(self, T_cam_base: FloatArray) -> list[SceneMarker]:
        out = []
        for b in self.berries():
            pose = T_cam_base @ b.tag_pose()
            if pose[2, 3] > 0.01:  # in front of the camera
                out.append(SceneMarker(b.tag_id, DICT, self.cams.berry_tag, pose))
        return out

    def _tag_position(self, dets: list, model: CameraModel) -> FloatArray | None:
        for d in dets:
            if d.marker_id == self.selected.tag_id:
                sols = square_marker_poses(d.corners, model, self.cams.berry_tag)
                if sols:
                    return sols[0].T_camera_marker[:3, 3]
        return None
