import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from softarm.errors import ParameterError
from softarm.sim.camera import SyntheticCamera
from softarm.sim.markers import SceneMarker
from softarm.vision import BaseRegistration, CameraModel
from softarm.vision.poses import invert, rotation_angle


def test_camera_pose_in_base_frame_from_base_tag(
    camera: CameraModel, renderer: SyntheticCamera
) -> None:
    # Base frame: z up; the tag lies flat 5 cm in front of the base origin, facing up.
    t_base_tag = np.eye(4)
    t_base_tag[:3, 3] = [0.05, 0.0, 0.0]
    # Camera 1.2 m away looking down at the base at ~40°.
    t_base_cam = np.eye(4)
    look = Rotation.from_euler("x", 140, degrees=True)  # camera z towards the base, down
    t_base_cam[:3, :3] = look.as_matrix()
    t_base_cam[:3, 3] = [0.05, 0.8, 0.95]  # optical axis through the tag
    t_cam_tag = invert(t_base_cam) @ t_base_tag
    reg = BaseRegistration(camera, tag_id=20, tag_length=0.1, T_base_tag=t_base_tag)
    assert reg.T_base_camera is None
    for _ in range(5):
        img = renderer.render([SceneMarker(20, "DICT_4X4_50", 0.1, t_cam_tag)])
        est = reg.update(img)
    assert est is not None
    assert np.linalg.norm(est[:3, 3] - t_base_cam[:3, 3]) < 2e-3
    assert np.degrees(rotation_angle(est, t_base_cam)) < 0.2
    # A frame without the tag adds nothing.
    assert reg.observe(np.full((720, 1280), 128, np.uint8)) is None
    reg.reset()
    assert reg.T_base_camera is None


def test_bad_parameters(camera: CameraModel) -> None:
    with pytest.raises(ParameterError, match="tag_length"):
        BaseRegistration(camera, 0, -0.1)
    with pytest.raises(ParameterError, match="window"):
        BaseRegistration(camera, 0, 0.1, window=0)
