"""Motion blur from the motion (softarm.sim.render.motion_blur, rig_motion, row_camera):
a still camera gives no blur, bit for bit; a known twist at a known depth smears by the
predicted length and direction, keeping the light; a fixed camera blurs only where the
arm sweeps; what moves with the camera stays sharp; seeded and repeatable."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from softarm.errors import ParameterError
from softarm.sim.render.camera_effects import CameraEffects
from softarm.sim.render.motion_blur import (
    MIN_DEPTH,
    camera_twist,
    flow_blur,
    plane_inverse_depth,
    swept_flow,
    twist_flow,
)
from softarm.sim.render.rig_motion import RigMotion
from softarm.sim.render.row_camera import RowCameras
from softarm.sim.render.row_look import RowLook
from softarm.vision.camera_model import CameraModel
from softarm.vision.stereo_camera import StereoCamera

SIZE = (80, 60)  # (W, H)
FOCAL = 100.0
CENTRE = ((SIZE[0] - 1) / 2, (SIZE[1] - 1) / 2)


def _impulse(x: int = 40, y: int = 30) -> np.ndarray:
    light = np.zeros((SIZE[1], SIZE[0], 3), np.float32)
    light[y, x] = 1000.0
    return light


def _pose(x: float = 0.0, yaw: float = 0.0) -> np.ndarray:
    """A camera looking along base +Y from (x, 0, 0), turned ``yaw`` rad about its y."""
    T = np.eye(4)
    look = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]).T  # x, y, z axes
    c, s = np.cos(yaw), np.sin(yaw)
    T[:3, :3] = look @ np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    T[:3, 3] = [x, 0.0, 0.0]
    return T


def test_camera_twist_from_two_poses() -> None:
    v, w = camera_twist(_pose(0.0), _pose(0.01), 0.05)
    assert v == pytest.approx([0.2, 0.0, 0.0])  # 1 cm along the camera's x in 50 ms
    assert w == pytest.approx([0.0, 0.0, 0.0])
    v, w = camera_twist(_pose(yaw=0.0), _pose(yaw=0.02), 0.05)
    assert v == pytest.approx([0.0, 0.0, 0.0])
    assert w == pytest.approx([0.0, 0.4, 0.0])


@pytest.mark.parametrize("bad", [0.0, -0.1, float("nan")])
def test_camera_twist_refuses_a_bad_time(bad: float) -> None:
    with pytest.raises(ParameterError, match="dt"):
        camera_twist(_pose(), _pose(0.01), bad)


def test_a_known_twist_at_a_known_depth_smears_as_predicted() -> None:
    # 0.3 m/s sideways, the scene 0.5 m away: f v / Z = 60 px/s everywhere, and over
    # 0.1 s a 6 px smear against the motion, along x.
    flow = twist_flow(np.array([0.3, 0.0, 0.0]), np.zeros(3), FOCAL, CENTRE, SIZE, 1 / 0.5)
    assert flow[..., 0] == pytest.approx(np.full(flow.shape[:2], -60.0))
    assert np.all(flow[..., 1] == 0)
    out = flow_blur(_impulse(), flow * np.float32(0.1))
    assert out.sum() == pytest.approx(_impulse().sum(), rel=1e-5)  # the light kept
    lit = np.argwhere(out[..., 0] > 1e-3)
    assert set(lit[:, 0]) == {30}  # along x only
    assert lit[:, 1].max() - lit[:, 1].min() == pytest.approx(6, abs=1)
    weights = out[30, :, 0] / out[30, :, 0].sum()
    assert float(weights @ np.arange(SIZE[0])) == pytest.approx(40.0, abs=0.05)  # centred


def test_rotation_blurs_alike_at_any_depth_and_roll_spares_the_centre() -> None:
    pan = np.array([0.0, 0.5, 0.0])
    near = twist_flow(np.zeros(3), pan, FOCAL, CENTRE, SIZE, 1 / 0.1)
    far = twist_flow(np.zeros(3), pan, FOCAL, CENTRE, SIZE, 0.0)
    assert np.array_equal(near, far)
    assert far[30, 40, 0] == pytest.approx(-FOCAL * 0.5, rel=0.01)
    roll = twist_flow(np.zeros(3), np.array([0.0, 0.0, 2.0]), FOCAL, CENTRE, SIZE, 2.0)
    speed = np.hypot(roll[..., 0], roll[..., 1])
    assert speed[int(CENTRE[1]), int(CENTRE[0])] < 2.0  # half a pixel from the axis
    assert speed[0, 0] == pytest.approx(2.0 * np.hypot(*CENTRE), rel=1e-3)


def test_plane_depth_straight_on_and_looking_away() -> None:
    inverse = plane_inverse_depth(
        _pose(), np.array([0.0, 0.5, 0.0]), np.array([0.0, 1.0, 0.0]), FOCAL, CENTRE, SIZE
    )
    assert inverse == pytest.approx(np.full(inverse.shape, 2.0))  # 0.5 m along the axis
    behind = plane_inverse_depth(
        _pose(), np.array([0.0, -0.5, 0.0]), np.array([0.0, 1.0, 0.0]), FOCAL, CENTRE, SIZE
    )
    assert np.all(behind == 0.0)  # the plane behind: the camera sees the sky
    touching = plane_inverse_depth(
        _pose(), np.array([0.0, 0.001, 0.0]), np.array([0.0, 1.0, 0.0]), FOCAL, CENTRE, SIZE
    )
    assert touching.max() == pytest.approx(1 / MIN_DEPTH)


def test_a_fixed_camera_blurs_only_where_the_arm_sweeps() -> None:
    flow = swept_flow(
        SIZE, np.array([[40.0, 30.0]]), np.array([[200.0, 0.0]]), np.array([3.0]), 0.05
    )
    moving = np.hypot(flow[..., 0], flow[..., 1]) > 0
    ys, xs = np.nonzero(moving)
    assert xs.min() >= 40 - 5 - 4 and xs.max() <= 40 + 5 + 4  # the 10 px sweep, 3 px disc
    assert ys.min() >= 30 - 4 and ys.max() <= 30 + 4
    image = np.random.default_rng(0).uniform(0, 255, (SIZE[1], SIZE[0], 3)).astype(np.float32)
    out = flow_blur(image, flow * np.float32(0.05))
    assert np.array_equal(out[~moving], image[~moving])  # the rest of the frame sharp
    assert not np.array_equal(out[moving], image[moving])


def test_a_part_moving_with_the_camera_stays_sharp_and_lends_no_light() -> None:
    image = np.full((SIZE[1], SIZE[0], 3), 50.0, np.float32)
    still = np.zeros(SIZE[::-1], bool)
    still[:, :30] = True
    image[still] = 200.0  # a bright finger on the left
    flow = np.zeros((SIZE[1], SIZE[0], 2), np.float32)
    flow[..., 0] = 12.0
    out = flow_blur(image, flow, still)
    assert np.all(out[still] == 200.0)
    assert out[~still] == pytest.approx(np.full(out[~still].shape, 50.0))
    # Without the mask the finger's light would smear over the scene beside it.
    assert flow_blur(image, flow)[0, 31, 0] > 60.0


def _rig(clock: list[float]) -> RigMotion:
    c1 = CameraModel.ideal(FOCAL, *SIZE)
    T_left_right = np.eye(4)
    T_left_right[0, 3] = 0.12
    stereo = StereoCamera(c1, c1, _pose(0.0), T_left_right)
    plane = (np.array([0.0, 0.5, 0.0]), np.array([0.0, 1.0, 0.0]))
    return RigMotion(stereo, c1, np.eye(4), plane, clock=lambda: clock[0])


def _draw(rig: RigMotion, clock: list[float], T_base_ee: np.ndarray) -> None:
    body = T_base_ee[None, :3, 3] + np.array([[0.0, 0.4, 0.0]])
    rig.moved(T_base_ee, body, np.array([0.03]))
    clock[0] += 0.05


def test_the_arm_still_gives_no_motion_and_moving_gives_its_step() -> None:
    clock = [0.0]
    rig = _rig(clock)
    assert rig.c2_flow() is None  # never drawn
    _draw(rig, clock, _pose(0.0))
    clock[0] -= 0.05
    assert rig.c2_flow() is None  # drawn once: no step yet
    clock[0] += 0.05
    _draw(rig, clock, _pose(0.01))
    clock[0] -= 0.05
    flow = rig.c2_flow()
    assert flow is not None
    assert flow[30, 40, 0] == pytest.approx(-FOCAL * 0.2 * 2.0, rel=1e-3)  # 0.2 m/s at 0.5 m
    c1 = rig.c1_flow("left", SIZE, (0, 0), 0.05)  # the arm 0.4 m from C1: 2.5 px
    assert c1 is not None and np.abs(c1).max() > 0
    clock[0] += 0.05  # a frame later with no drawing since: the arm holds still
    assert rig.c2_flow() is None
    assert rig.c1_flow("left", SIZE, (0, 0), 0.05) is None


def _frames(motion: RigMotion | None, clock: list[float]) -> list[np.ndarray]:
    look = RowLook.named("sun", 90104)
    if motion is None:  # the reference: the look's random blur made nothing
        look = replace(look, blur_px_s=0.0)
    cams = RowCameras(look, motion)
    image = np.random.default_rng(3).integers(0, 255, (SIZE[1], SIZE[0], 3)).astype(np.uint8)
    out = []
    for x in (0.0, 0.0, 0.1):  # still, still, 2 m/s: a 4 px smear
        if motion is not None:
            _draw(motion, clock, _pose(x))
            clock[0] -= 0.05
        out.append(cams.apply("c2", image))
        clock[0] += 0.05
    return out


def test_a_still_c2_frame_is_bit_identical_and_a_moving_one_blurs_repeatably() -> None:
    plain = _frames(None, [0.0])
    clock = [0.0]
    moved = _frames(_rig(clock), clock)
    assert np.array_equal(moved[0], plain[0]) and np.array_equal(moved[1], plain[1])
    assert not np.array_equal(moved[2], plain[2])
    clock = [0.0]
    assert all(
        np.array_equal(a, b) for a, b in zip(moved, _frames(_rig(clock), clock), strict=True)
    )


def test_without_a_clock_c2_keeps_the_looks_random_blur() -> None:
    look = RowLook.named("dusk", 90104)  # blur_px_s 60-300: a smear of 0.6-3 px
    image = np.random.default_rng(3).integers(0, 255, (SIZE[1], SIZE[0], 3)).astype(np.uint8)
    rig = _rig([0.0])
    rig.clock = None
    timeless = RowCameras(look, rig).apply("c2", image)
    assert np.array_equal(timeless, RowCameras(look).apply("c2", image))
    assert not np.array_equal(timeless, RowCameras(replace(look, blur_px_s=0.0)).apply("c2", image))


def test_a_zero_flow_changes_nothing_and_a_bad_flow_is_refused() -> None:
    effects = CameraEffects(gain=0.5, read_noise=2.0, jpeg_quality=90)
    image = np.random.default_rng(4).integers(0, 255, (SIZE[1], SIZE[0], 3)).astype(np.uint8)
    zero = np.zeros((SIZE[1], SIZE[0], 2), np.float32)
    a = effects.apply(image, np.random.default_rng(1))
    b = effects.apply(image, np.random.default_rng(1), flow_px_s=zero)
    assert np.array_equal(a, b)
    with pytest.raises(ParameterError, match="flow_px_s"):
        effects.apply(image, np.random.default_rng(1), flow_px_s=zero[:10])
    with pytest.raises(ParameterError, match="still"):
        effects.apply(image, np.random.default_rng(1), flow_px_s=zero, still=np.zeros((2, 2), bool))


def test_an_arm_drawn_with_another_body_is_no_step_for_c1() -> None:
    clock = [0.0]
    rig = _rig(clock)
    _draw(rig, clock, _pose(0.0))
    rig.moved(_pose(0.01), np.tile([0.0, 0.4, 0.0], (2, 1)), np.full(2, 0.03))
    assert rig.c1_flow("left", SIZE, (0, 0), 0.05) is None


def test_a_sweep_far_outside_the_frame_paints_nothing() -> None:
    flow = swept_flow(SIZE, np.array([[1e12, 5.0]]), np.array([[1e9, 0.0]]), np.array([2.0]), 0.01)
    assert not flow.any()


def test_a_windows_swept_flow_is_the_whole_frames_there() -> None:
    """Parts whose sweep misses a window are skipped; what the window holds is the
    whole frame's flow at its pixels, parts reaching in from outside included."""
    rng = np.random.default_rng(7)
    centres = rng.uniform(-40, 360, (40, 2))
    velocities = rng.normal(0, 1500, (40, 2))
    radii = rng.uniform(0.5, 12, 40)
    whole = swept_flow((400, 400), centres + 20, velocities, radii, 0.01)
    for x0, y0 in ((20, 20), (100, 60), (250, 200), (280, 290)):
        window = swept_flow((64, 48), centres, velocities, radii, 0.01, (x0 - 20, y0 - 20))
        np.testing.assert_array_equal(window, whole[y0 : y0 + 48, x0 : x0 + 64])
