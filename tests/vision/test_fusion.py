import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from softarm.errors import InputError, PoseError
from softarm.vision import CameraFusion
from softarm.vision.poses import invert


def _pose(rotvec: list[float], pos: list[float]) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, :3] = Rotation.from_rotvec(rotvec).as_matrix()
    pose[:3, 3] = pos
    return pose


T_BASE_C1 = _pose([0.2, -0.1, 2.5], [1.2, 0.1, 0.3])
T_EE_C2 = _pose([0.0, 0.3, 0.1], [0.0, 0.02, 0.05])
BERRY = np.array([0.05, 0.4, 0.6])  # base frame


def _measure(t_base_ee: np.ndarray) -> dict[str, np.ndarray]:
    """Exact measurements of the EE pose and the berry in both cameras."""
    c1_ee = invert(T_BASE_C1) @ t_base_ee
    c1 = invert(T_BASE_C1)[:3, :3] @ BERRY + invert(T_BASE_C1)[:3, 3]
    t_c2_base = invert(t_base_ee @ T_EE_C2)
    c2 = t_c2_base[:3, :3] @ BERRY + t_c2_base[:3, 3]
    return {"T_c1_ee": c1_ee, "target_c1": c1, "target_c2": c2}


def _ee_at(distance: float) -> np.ndarray:
    return _pose([0.1, 0.2, 0.3], list(BERRY - [0.0, 0.0, distance]))


def test_eq21_and_eq22_carry_measurements_to_the_base_frame() -> None:
    fusion = CameraFusion(T_BASE_C1, T_EE_C2)
    ee = _ee_at(0.3)
    m = _measure(ee)
    est = fusion.update(0.0, m["T_c1_ee"], None, m["target_c2"])  # berry from C2 only
    np.testing.assert_allclose(est.T_base_ee, ee, atol=1e-12)
    np.testing.assert_allclose(est.target, BERRY, atol=1e-12)
    assert est.source == "eye_in_hand"
    est = fusion.update(0.1, m["T_c1_ee"], m["target_c1"], None)
    np.testing.assert_allclose(est.target, BERRY, atol=1e-12)
    assert est.source == "eye_to_hand"


def test_hand_over_at_threshold_with_hysteresis() -> None:
    fusion = CameraFusion(T_BASE_C1, T_EE_C2, handover_distance=0.06, hysteresis=0.01)
    offset = np.array([0.0, 0.0, 0.003])  # C1 sees the berry 3 mm off: tells sources apart
    # C1's 3 mm offset can move the measured distance by up to 3 mm: stay clear of it.
    seq = [
        (0.20, "eye_to_hand"),
        (0.065, "eye_to_hand"),
        (0.055, "eye_in_hand"),
        (0.066, "eye_in_hand"),
        (0.075, "eye_to_hand"),
        (0.02, "eye_in_hand"),
    ]
    for k, (dist, mode) in enumerate(seq):
        m = _measure(_ee_at(dist))
        est = fusion.update(k * 0.1, m["T_c1_ee"], m["target_c1"] + offset, m["target_c2"])
        assert est.mode == mode, (dist, est.mode)
        assert est.source == mode
        err = np.linalg.norm(est.target - BERRY)
        assert err == pytest.approx(0.0 if mode == "eye_in_hand" else 0.003, abs=1e-9)


def test_hidden_target_is_held_until_max_age() -> None:
    fusion = CameraFusion(T_BASE_C1, T_EE_C2, max_age=0.5)
    m = _measure(_ee_at(0.03))
    fusion.update(0.0, m["T_c1_ee"], None, m["target_c2"])
    est = fusion.update(0.3, m["T_c1_ee"], None, None)
    assert est.source == "held"
    assert est.target_age == pytest.approx(0.3)
    np.testing.assert_allclose(est.target, BERRY, atol=1e-12)
    est = fusion.update(0.5, m["T_c1_ee"], None, None)
    assert est.source == "held"
    est = fusion.update(0.51, m["T_c1_ee"], None, None)
    assert est.source == "none"
    assert est.target is None


def test_close_to_berry_prefers_held_eye_in_hand_over_eye_to_hand() -> None:
    fusion = CameraFusion(T_BASE_C1, T_EE_C2, max_age=0.5)
    m = _measure(_ee_at(0.03))
    fusion.update(0.0, m["T_c1_ee"], None, m["target_c2"])
    shifted = m["target_c1"] + 0.01
    est = fusion.update(0.1, m["T_c1_ee"], shifted, None)
    assert est.source == "held"  # the gripper occludes: C1 is not trusted up close
    est = fusion.update(1.0, m["T_c1_ee"], shifted, None)
    assert est.source == "eye_to_hand"  # held target too old: fall back to C1


def test_lost_end_effector_pose_is_held_then_dropped() -> None:
    fusion = CameraFusion(T_BASE_C1, T_EE_C2, ee_max_age=0.2)
    m = _measure(_ee_at(0.3))
    fusion.update(0.0, m["T_c1_ee"], None, None)
    assert fusion.update(0.1, None, None, m["target_c2"]).source == "eye_in_hand"
    est = fusion.update(0.3, None, None, m["target_c2"])
    assert est.T_base_ee is None
    assert est.source == "held"  # C2 cannot be used without an EE pose (eq. 21)


def test_bad_input() -> None:
    with pytest.raises(PoseError, match="T_base_c1"):
        CameraFusion(np.zeros((4, 4)), T_EE_C2)
    fusion = CameraFusion(T_BASE_C1, T_EE_C2)
    with pytest.raises(InputError, match="target_c1"):
        fusion.update(0.0, None, [1.0, 2.0], None)
    fusion.update(1.0)
    with pytest.raises(InputError, match="time"):
        fusion.update(0.5)
