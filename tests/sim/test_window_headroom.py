"""C1's marker window in the row: drawn with headroom (softarm.sim.render.headroom) and
metered on itself (CameraEffects.roi_exposure_of through RowCameras), so that the sun
clips the marker's white neither at the render nor at the simulated sensor."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import cv2
import numpy as np
import pytest

import softarm
from softarm.errors import ParameterError
from softarm.sim.bush import Bush
from softarm.sim.render.headroom import MARGIN, dimmed, window_share
from softarm.sim.render.row_camera import RowCameras
from softarm.sim.render.row_look import RowLook

SEED = 90120  # sun 1.17 at 66° elevation, exposure bias 0.997: the marker's white clips
SCALE = 0.5

_LIGHT = """<mujoco><visual><headlight ambient="0.3 0.3 0.3" diffuse="0.1 0.1 0.1"/></visual>
<worldbody><light diffuse="0.8 0.7 0.6" specular="0.5 0.5 0.5" ambient="0.2 0.2 0.2"/>
<geom type="sphere" size="0.1"/></worldbody></mujoco>"""


def _lights(model: Any) -> list[np.ndarray]:
    h = model.vis.headlight
    return [np.array(a, copy=True) for a in (model.light_ambient, model.light_diffuse,
            model.light_specular, h.ambient, h.diffuse, h.specular)]  # fmt: skip


def test_dimmed_scales_every_light_and_restores_them_after_an_error() -> None:
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_string(_LIGHT)
    before = _lights(model)
    with pytest.raises(RuntimeError), dimmed(model, 0.5):
        for inside, was in zip(_lights(model), before, strict=True):
            np.testing.assert_allclose(inside, 0.5 * was, rtol=1e-6)
        raise RuntimeError("a render failing inside")
    for after, was in zip(_lights(model), before, strict=True):
        np.testing.assert_array_equal(after, was)


def test_the_share_keeps_the_brightest_white_under_full_scale() -> None:
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_string(_LIGHT)  # the light shines down (-z)
    up, down = np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, 0.0, -1.0]])
    # Facing the light: diffuse 0.8 plus the ambients 0.2 + 0.3 in the brightest channel.
    assert window_share(model, up) == pytest.approx(1.0 / (MARGIN * 1.3))
    assert window_share(model, np.vstack([down, up])) == window_share(model, up)
    assert window_share(model, down) == 1.0  # ambient alone: no dimming


@pytest.mark.parametrize("share", [0.0, -0.5, 1.5, float("nan")])
def test_dimmed_refuses_a_share_outside_0_1(share: float) -> None:
    with pytest.raises(ParameterError, match="share"), dimmed(object(), share):
        pass


def test_the_window_is_metered_on_itself_not_on_the_dark_frame() -> None:
    look = RowLook.named("sun", SEED)
    cameras = RowCameras(look)
    frame = np.full((90, 160, 3), 12, np.uint8)  # a dark hedge: the frame meters up
    cameras.apply("c1_left", frame)
    window = np.full((64, 64, 3), 12, np.uint8)
    window[16:48, 16:48] = 200  # the marker's white paper, unclipped in the render
    out = cameras.apply("c1_window", window, (40, 10))
    white = out[20:44, 20:44].astype(np.float64)
    # The window's highlights go to AUTO_HIGHLIGHT_DN times the bias (230 x 0.997), with
    # the camera's noise; metered on the frame (x 4 or more) they would be 255.
    assert (white >= 254).mean() < 0.01
    assert np.median(white) == pytest.approx(230 * look.stereo.left.exposure_bias, abs=6)


def test_a_window_at_half_the_light_comes_out_as_at_full_light() -> None:
    look = RowLook.named("sun", SEED)
    window = np.full((64, 64, 3), 12, np.uint8)
    window[16:48, 16:48] = 200
    full = RowCameras(look).apply("c1_window", window, (40, 10))
    half = RowCameras(look).apply("c1_window", window // 2, (40, 10), 0.5)
    assert abs(float(np.median(full[20:44, 20:44])) - float(np.median(half[20:44, 20:44]))) <= 3


def test_scale_is_for_the_window_alone() -> None:
    with pytest.raises(ParameterError, match="scale"):
        RowCameras(RowLook.named("sun", SEED)).apply("c1_left", np.zeros((8, 8, 3), np.uint8),
                                                     scale=0.5)  # fmt: skip


@pytest.fixture(scope="module")
def sunny_row() -> Iterator[Any]:
    from softarm.harvest.rigs.sim.options import default_cameras
    from softarm.sim.render import RenderUnavailableError
    from softarm.sim.render.world import arm_sections, world_for
    from softarm.sim.rig_cameras import BASE_TAG_ID

    pytest.importorskip("mujoco")
    arm = softarm.SoftArm.blackberry()
    cams = default_cameras(scale=SCALE)
    bush = Bush.generate(arm, 4, SEED, view_point=cams.T_base_c1[:3, 3])
    try:
        world = world_for(bush, cams, BASE_TAG_ID, look=RowLook.named("sun", SEED))
    except RenderUnavailableError as exc:
        pytest.skip(str(exc))
    q = np.asarray(bush.berries[0].q) * 0.95
    T_base_ee = arm.forward(q)
    world.set_arm(arm_sections(arm, q), T_base_ee)
    yield world, T_base_ee @ cams.T_ee_cube
    world.close()


def test_the_row_s_window_is_rendered_with_headroom(sunny_row: Any, monkeypatch: Any) -> None:
    world, T_base_cube = sunny_row
    drawn: list[tuple[np.ndarray, tuple[int, int]]] = []
    render_window = world.renderer.render_window

    def spy(camera: str, origin: tuple[int, int], span: int) -> np.ndarray:
        drawn.append((render_window(camera, origin, span), origin))
        return drawn[-1][0]

    monkeypatch.setattr(world.renderer, "render_window", spy)
    world.cube_window(T_base_cube)
    effects, world.effects = world.effects, None  # the bush's way: at full light
    try:
        world.cube_window(T_base_cube)
    finally:
        world.effects = effects
    (dimmed, origin), (full, _) = drawn
    tags = _tag_squares(world, T_base_cube, origin, dimmed.shape[:2])
    # The headroom is for the tags (the arm's sunlit sleeve may still clip).
    assert (full.max(axis=2)[tags] >= 255).mean() > 0.003  # the sun clips some of their white
    assert (dimmed.max(axis=2)[tags] >= 255).mean() == 0.0


def _tag_squares(
    world: Any, T_base_cube: np.ndarray, origin: tuple[int, int], shape: tuple[int, ...]
) -> np.ndarray:
    """The pixels of the body's printed squares in a pinhole window of C1's left eye
    whose top-left pixel is ``origin``, as a boolean mask of ``shape``."""
    from softarm.vision.poses import invert

    T_c1_cube = invert(world.stereo.T_base_left) @ T_base_cube
    K = world.stereo.left.matrix
    mask = np.zeros(shape, np.uint8)
    for square in world._cube_corners.reshape(-1, 4, 3):  # the body's panels
        p = square @ T_c1_cube[:3, :3].T + T_c1_cube[:3, 3]
        uv = (p @ K.T)[:, :2] / p[:, 2:] - np.asarray(origin)
        cv2.fillConvexPoly(mask, np.round(uv).astype(np.int32), 1)
    return mask.astype(bool)


def test_the_row_s_marker_window_does_not_clip(sunny_row: Any) -> None:
    world, T_base_cube = sunny_row
    window = np.asarray(world.cube_window(T_base_cube))
    # ROI metering puts the brightest 0.5 % at 230 DN x 0.997: only noise reaches 255
    # (metered as C1's frame, 4-6 % of this window was at 255).
    assert (window.max(axis=2) >= 255).mean() < 0.005
