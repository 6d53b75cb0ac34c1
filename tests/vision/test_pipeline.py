"""The whole vision path on rendered images: cube in the eye-to-hand camera, berry tag in
the eye-in-hand camera, fused in the base frame (eq. 21–22)."""

import numpy as np
from scipy.spatial.transform import Rotation

from softarm.sim.camera import SyntheticCamera
from softarm.sim.markers import SceneMarker, cube_scene_markers
from softarm.vision import (
    CameraFusion,
    CameraModel,
    MarkerCube,
    MarkerDetector,
    estimate_marker_poses,
)
from softarm.vision.poses import invert


def _pose(rotvec: list[float], pos: list[float]) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = Rotation.from_rotvec(rotvec).as_matrix()
    out[:3, 3] = pos
    return out


def test_berry_in_base_frame_from_both_cameras(
    camera: CameraModel, renderer: SyntheticCamera, cube: MarkerCube
) -> None:
    # Base: z up. C1 1 m in front of the arm (−y), looking along +y, image y down.
    t_base_c1 = _pose([-np.pi / 2, 0, 0], [0.0, -1.0, 0.5])
    # End effector (the cube's frame) at 0.5 m height, pointing down, with a yaw.
    t_base_ee = _pose([0.0, 0.0, 0.4], [0.02, 0.0, 0.5]) @ _pose([np.pi, 0, 0], [0, 0, 0])
    t_ee_c2 = _pose([0.0, 0.0, 0.0], [0.0, 0.0, 0.06])  # looking along EE +z (down)
    berry = np.array([0.03, 0.01, 0.39])  # 5 cm below the eye-in-hand camera
    # The berry tag faces C2 (its z towards the camera, i.e. up in the base frame).
    t_base_tag = np.eye(4)
    t_base_tag[:3, 3] = berry
    t_c1_ee = invert(t_base_c1) @ t_base_ee
    img1 = renderer.render(cube_scene_markers(cube.markers, 0.08, cube.dictionary, t_c1_ee))
    t_c2_tag = invert(t_base_ee @ t_ee_c2) @ t_base_tag
    img2 = renderer.render([SceneMarker(9, "DICT_4X4_50", 0.012, t_c2_tag)])

    est_ee = cube.estimate_pose(img1, camera)
    tags = estimate_marker_poses(MarkerDetector().detect(img2, camera), camera, 0.012)
    assert est_ee is not None and 9 in tags
    fusion = CameraFusion(t_base_c1, t_ee_c2, tool_point=[0.0, 0.0, 0.06])  # gripper tip
    out = fusion.update(0.0, est_ee, None, tags[9][:3, 3])
    assert out.source == "eye_in_hand" and out.mode == "eye_in_hand"
    assert out.T_base_ee is not None and out.target is not None
    assert np.linalg.norm(out.T_base_ee[:3, 3] - t_base_ee[:3, 3]) < 1e-3
    assert np.linalg.norm(out.target - berry) < 1e-3
