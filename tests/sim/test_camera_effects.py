"""The camera model (softarm.sim.render.camera_effects) against its definitions: the
noise's variance, the blur kernel's energy, clipping at full well, vignetting, the
white balance, the two eyes' differences; seeded and repeatable."""

from __future__ import annotations

import numpy as np
import pytest

from softarm.errors import ParameterError
from softarm.sim.render.camera_effects import (
    AUTO_HIGHLIGHT_DN,
    AUTO_RANGE,
    AUTO_TARGET_DN,
    CameraEffects,
    StereoEffects,
    blur_kernel,
)


def _flat(value: int, size: int = 200) -> np.ndarray:
    return np.full((size, size, 3), value, np.uint8)


@pytest.mark.parametrize("signal", [20, 80, 160])
def test_noise_variance_is_gain_times_signal_plus_read_squared(signal: int) -> None:
    effects = CameraEffects(exposure=1.0, gain=0.5, read_noise=3.0)
    out = effects.apply(_flat(signal), np.random.default_rng(0)).astype(np.float64)
    expected = 0.5 * signal + 3.0**2
    # 120 000 samples: the variance's standard error is about 0.4 % of it; rounding to
    # integers adds 1/12.
    assert out.var() == pytest.approx(expected + 1 / 12, rel=0.03)
    assert out.mean() == pytest.approx(signal, abs=0.1)


def test_no_noise_leaves_a_flat_image_flat() -> None:
    out = CameraEffects(exposure=1.0).apply(_flat(77), np.random.default_rng(1))
    assert np.all(out == 77)


def test_seeded_and_repeatable() -> None:
    effects = CameraEffects(gain=1.0, read_noise=2.0, vignetting=0.3, jpeg_quality=80)
    image = np.random.default_rng(5).integers(0, 255, (60, 80, 3)).astype(np.uint8)
    a = effects.apply(image, np.random.default_rng(9), velocity_px=(300.0, 40.0))
    b = effects.apply(image, np.random.default_rng(9), velocity_px=(300.0, 40.0))
    c = effects.apply(image, np.random.default_rng(10), velocity_px=(300.0, 40.0))
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


@pytest.mark.parametrize("velocity", [(0.0, 0.0), (50.0, 0.0), (300.0, -120.0), (0.0, 900.0)])
def test_blur_kernel_sums_to_one_and_is_as_long_as_the_motion(
    velocity: tuple[float, float],
) -> None:
    exposure = 0.02
    kernel = blur_kernel(velocity, exposure)
    assert kernel.sum() == pytest.approx(1.0)
    assert np.all(kernel >= 0)
    length = np.hypot(*velocity) * exposure
    if length < 1:
        assert kernel.shape == (1, 1)
        return
    ys, xs = np.nonzero(kernel > 1e-9)
    extent = np.hypot(xs.max() - xs.min(), ys.max() - ys.min())
    assert length - 1.5 <= extent <= length + 2.5
    # Its centre of mass at the kernel's centre: blur moves no feature on average.
    yy, xx = np.indices(kernel.shape)
    c = (kernel.shape[0] - 1) / 2
    assert (kernel * xx).sum() == pytest.approx(c, abs=1e-6)
    assert (kernel * yy).sum() == pytest.approx(c, abs=1e-6)


def test_blur_keeps_the_light_and_smears_along_the_motion() -> None:
    image = np.zeros((41, 41, 3), np.uint8)
    image[20, 20] = 200
    out = CameraEffects(exposure=1.0, exposure_s=0.01).apply(
        image, np.random.default_rng(0), velocity_px=(1000.0, 0.0)
    )
    row = out[20, :, 0].astype(float)
    assert out[:, :, 0].astype(float).sum() == pytest.approx(200, abs=12)  # rounding
    assert np.count_nonzero(row) >= 9 and np.count_nonzero(out[:, 20, 0]) <= 2


def test_clipping_at_full_well_and_black_level() -> None:
    effects = CameraEffects(exposure=4.0, full_well=240.0, black_level=10.0)
    image = np.zeros((4, 3, 3), np.uint8)
    image[0] = 100  # 400 DN of light: saturates
    image[1] = 2  # 8 DN: under the black level, crushed to 0
    image[2] = 20  # 80 DN - 10
    out = effects.apply(image, np.random.default_rng(0))
    assert np.all(out[0] == 240) and np.all(out[1] == 0) and np.all(out[2] == 70)


def test_auto_exposure_brings_the_mean_to_its_target_and_the_bias_scales_it() -> None:
    effects = CameraEffects()
    out = effects.apply(_flat(40), np.random.default_rng(0))
    assert out.mean() == pytest.approx(AUTO_TARGET_DN, abs=0.6)
    biased = CameraEffects(exposure_bias=0.5).exposure_of(_flat(40))
    assert biased == pytest.approx(0.5 * AUTO_TARGET_DN / 40)


def test_auto_exposure_keeps_the_highlights_under_their_level() -> None:
    image = _flat(40)
    image[:3, :] = 120  # 1.5 % of the frame bright: a sunlit marker
    exposure = CameraEffects().exposure_of(image)
    assert exposure == pytest.approx(AUTO_HIGHLIGHT_DN / 120)
    out = CameraEffects().apply(image, np.random.default_rng(0))
    assert out.max() < 255  # not clipped, though the frame's mean is far from its target
    image[:3, :] = 250  # brighter still: half the mean's exposure, and it clips
    mean = float(image.mean())
    assert CameraEffects().exposure_of(image) == pytest.approx(0.5 * AUTO_TARGET_DN / mean)
    image[:3, :] = 40
    image[0, :10] = 250  # a few glints (0.005 % of the frame) may clip
    assert CameraEffects().exposure_of(image) == pytest.approx(
        AUTO_TARGET_DN / image.mean(), rel=0.01
    )


def test_vignetting_darkens_the_corners_by_its_strength() -> None:
    out = CameraEffects(exposure=1.0, vignetting=0.4).apply(
        _flat(200, 101), np.random.default_rng(0)
    )
    assert out[50, 50, 0] == 200
    assert out[0, 0, 0] == pytest.approx(120, abs=1)
    assert out[0, 50, 0] > out[0, 0, 0]


def test_white_balance_scales_each_channel() -> None:
    out = CameraEffects(exposure=1.0, white_balance=(1.2, 1.0, 0.8)).apply(
        _flat(100, 8), np.random.default_rng(0)
    )
    assert tuple(out[0, 0]) == (120, 100, 80)


def test_jpeg_is_lossy_but_close() -> None:
    image = np.random.default_rng(2).integers(60, 190, (64, 64, 3)).astype(np.uint8)
    out = CameraEffects(exposure=1.0, jpeg_quality=70).apply(image, np.random.default_rng(0))
    diff = np.abs(out.astype(int) - image.astype(int))
    assert diff.max() > 0 and diff.mean() < 40


def test_the_right_eye_exposes_and_sits_apart_as_set() -> None:
    pair = StereoEffects(
        CameraEffects(exposure=1.0), right_exposure=1.1, right_offset_px=(0.0, 0.5)
    )
    image = np.zeros((20, 20, 3), np.uint8)
    image[10:, :] = 100
    right = pair.right().apply(image, np.random.default_rng(0), offset_px=pair.right_offset_px)
    left = pair.left.apply(image, np.random.default_rng(0))
    assert left[15, 5, 0] == 100 and right[15, 5, 0] == 110
    # The edge moved half a pixel down: the row above it takes half of the step.
    assert left[10, 5, 0] == 100 and right[10, 5, 0] == 55


@pytest.mark.parametrize(
    "bad",
    [{"gain": -1.0}, {"full_well": 300.0}, {"vignetting": 1.0}, {"jpeg_quality": 0},
     {"exposure": 0.0}, {"white_balance": (1.0, 0.0, 1.0)}],
)  # fmt: skip
def test_bad_parameters_are_one_clear_error(bad: dict[str, object]) -> None:
    with pytest.raises(ParameterError, match=next(iter(bad))):
        CameraEffects(**bad)  # type: ignore[arg-type]


def test_a_bad_image_shape_is_refused() -> None:
    with pytest.raises(ParameterError, match="image"):
        CameraEffects().apply(np.zeros((4, 4), np.uint8), np.random.default_rng(0))


def test_roi_metering_puts_the_roi_s_highlights_at_their_level_whatever_the_mean() -> None:
    roi = _flat(10)
    roi[:10, :] = 200  # a marker's white paper, a twentieth of its window, on a dark hedge
    frame = CameraEffects(exposure_bias=0.9)
    # The frame's rule gives up half the mean's exposure and clips the white ...
    assert 200 * frame.exposure_of(roi) > 255
    # ... the ROI's rule gives up nothing for the mean.
    assert frame.roi_exposure_of(roi) == pytest.approx(0.9 * AUTO_HIGHLIGHT_DN / 200)
    out = frame.apply(roi, np.random.default_rng(0), exposure=frame.roi_exposure_of(roi))
    assert out.max() < 255


def test_roi_metering_of_a_render_at_part_of_the_light_is_for_the_scene() -> None:
    effects = CameraEffects()
    roi = _flat(10)
    roi[:40, :] = 200
    half = roi // 2
    # Twice the exposure for a render at half the light: the same DN delivered.
    assert effects.roi_exposure_of(half, 0.5) == pytest.approx(2 * effects.roi_exposure_of(roi))
    # The exposure's range is the scene's: a dark ROI at half the light gets twice the
    # largest exposure, which brings it to where the scene at full light would be.
    dark = _flat(2)
    assert effects.roi_exposure_of(dark, 0.5) == pytest.approx(2 * AUTO_RANGE[1])
    assert CameraEffects(exposure=1.5).roi_exposure_of(roi, 0.5) == pytest.approx(3.0)


@pytest.mark.parametrize("scale", [0.0, -1.0, 1.5, float("nan")])
def test_roi_metering_refuses_a_scale_outside_0_1(scale: float) -> None:
    with pytest.raises(ParameterError, match="scale"):
        CameraEffects().roi_exposure_of(_flat(10), scale)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_the_read_out_is_its_formula_value_for_value(dtype: type) -> None:
    """The read-out works in place; its values are the formula's written out in full,
    with the same draws (OpenCV's generator seeded from ``rng``)."""
    import cv2

    effects = CameraEffects(gain=0.7, read_noise=2.5, black_level=3.0, full_well=240.0)
    light: np.ndarray = np.random.default_rng(3).uniform(-20, 300, (50, 70, 3)).astype(dtype)
    out = np.maximum(light, 0.0)
    std = np.sqrt(0.7 * out + 2.5**2)
    noise = np.empty(light.shape, np.float32)
    cv2.setRNGSeed(int(np.random.default_rng(4).integers(2**31)))
    cv2.randn(noise.reshape(50, -1), 0.0, 1.0)  # type: ignore[call-overload]
    expected = ((np.clip(out + std * noise - 3.0, 0.0, 240.0)) + np.float32(0.5)).astype(np.uint8)
    got = effects.sensor(light.copy(), np.random.default_rng(4))
    np.testing.assert_array_equal(got, expected)
