"""Synthetic cameras for the simulated harvest: C1 (eye-to-hand) renders the base tag, the
end-effector marker cube and the berry tags; C2 (eye-in-hand) renders the berry tags in
front of the gripper. The images go through the real pipeline of
:class:`~softarm.vision.two_cameras.CameraVision`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from softarm.checks import FloatArray
from softarm.sim.bush import Berry
from softarm.sim.camera import SyntheticCamera
from softarm.sim.markers import SceneMarker, cube_scene_markers
from softarm.vision import CameraModel
from softarm.vision.marker_body import SIMULATED_BODY, marker_body
from softarm.vision.poses import invert
from softarm.vision.two_cameras import CameraVision, register_c1

__all__ = ["BASE_TAG_ID", "SimCameras", "look_at", "sim_vision"]

DICT = "DICT_4X4_50"
#: The base tag's id; the cube uses 0–3 and the berries 10 and up.
BASE_TAG_ID = 4


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

    ``scale`` multiplies both image sizes and focal lengths (0.5 = a quarter of the pixels).
    ``crop`` (default) renders and searches only the window of each frame that holds the
    markers looked for (:meth:`~softarm.sim.SyntheticCamera.render_crop`: the same pixels
    there, the same detections, a fraction of the time; in C1 the cube and berry tags while
    tracking, the base tag while registering); False renders whole frames.
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
    #: The gripper's marker body (:data:`softarm.vision.marker_body.MARKER_BODIES`).
    marker_body: str = SIMULATED_BODY
    base_tag: float = 0.08
    berry_tag: float = 0.03
    scale: float = 1.0
    crop: bool = True

    def size(self, which: int) -> tuple[int, int]:
        """Image (width, height) of C1 (``which`` = 1) or C2 (2) after ``scale``."""
        size = self.c1_size if which == 1 else self.c2_size
        return round(size[0] * self.scale), round(size[1] * self.scale)

    def model(self, which: int) -> CameraModel:
        """Intrinsics of C1 (``which`` = 1) or C2 (2), mild barrel distortion."""
        f = self.c1_focal if which == 1 else self.c2_focal
        return CameraModel.ideal(f * self.scale, *self.size(which), [-0.05, 0.01, 0.0, 0.0, 0.0])


def sim_vision(
    cams: SimCameras,
    true_pose: Callable[[], FloatArray],
    berries: Callable[[], Sequence[Berry]],
    grasp_offset: float,
    seed: int = 0,
    max_age: float = 1.0,
    hidden: Callable[[float], bool] | None = None,
) -> CameraVision:
    """:class:`CameraVision` on synthetic images of the scene at the arm's true pose
    ``true_pose()``. ``berries()`` are the berries still on the bush; while ``hidden(t)``
    no berry tag is drawn (a leaf in front of the berry)."""
    hide = hidden or (lambda t: False)
    m1, m2 = cams.model(1), cams.model(2)
    (w1, h1), (w2, h2) = cams.size(1), cams.size(2)
    c1 = SyntheticCamera(m1, w1, h1, noise_std=cams.noise_std, supersample=2, seed=seed)
    c2 = SyntheticCamera(m2, w2, h2, noise_std=cams.noise_std, supersample=2, seed=seed + 1)
    render1 = c1.render_crop if cams.crop else c1.render
    render2 = c2.render_crop if cams.crop else c2.render
    cube = marker_body(cams.marker_body, cams.cube_marker)
    T_c1_base = invert(cams.T_base_c1)

    base_tag = SceneMarker(BASE_TAG_ID, DICT, cams.base_tag, T_c1_base @ cams.T_base_tag)
    # C1's berry tags stay put until picked: keep their (checked) scene markers.
    still: dict[tuple[int, bytes], SceneMarker] = {}

    def tags(
        T_cam_base: FloatArray, memo: dict[tuple[int, bytes], SceneMarker]
    ) -> list[SceneMarker]:
        out = []
        for b in berries():
            pose = T_cam_base @ b.tag_pose()
            if pose[2, 3] > 0.01:  # in front of the camera
                key = (b.tag_id, pose.tobytes())
                if key not in memo:
                    if len(memo) > 64:
                        memo.clear()
                    memo[key] = SceneMarker(b.tag_id, DICT, cams.berry_tag, pose)
                out.append(memo[key])
        return out

    def frame1(t: float, with_berries: bool = True) -> np.ndarray:
        items = [base_tag]
        T_c1_cube = T_c1_base @ true_pose() @ cams.T_ee_cube
        items += cube_scene_markers(cube.markers, cube.marker_length, DICT, T_c1_cube)
        if not with_berries:  # registration: the base tag is what is looked for
            return render1(items)
        if not hide(t):
            items += tags(T_c1_base, still)
        if cams.crop:
            # Tracking looks for the cube and the berries: the window holds those (the
            # base tag, which only registers C1, is drawn if it reaches into it).
            return c1.render_crop(items, around=lambda item: item is not base_tag)
        return render1(items)

    def frame2(t: float) -> np.ndarray:
        return render2([] if hide(t) else tags(invert(true_pose() @ cams.T_ee_c2), {}))

    T_base_c1 = register_c1(
        lambda t: frame1(t, False), m1, BASE_TAG_ID, cams.base_tag, cams.T_base_tag
    )
    return CameraVision(
        frame1, frame2, m1, m2, T_base_c1, cams.T_ee_c2, cams.T_ee_cube, cube,
        cams.berry_tag, grasp_offset, max_age,
    )  # fmt: skip
