"""The hardware's stereo source from ``[perception]``: the calibrated pair placed in the
base frame and its frames read from the ZED2's side-by-side image or from two devices."""

from __future__ import annotations

from collections.abc import Callable
from contextlib import ExitStack
from typing import Any

from softarm.checks import FloatArray
from softarm.errors import ConfigError
from softarm.perception.c1 import Pair
from softarm.perception_config import PerceptionConfig, StereoSource
from softarm.vision.stereo_calibration import split_side_by_side
from softarm.vision.stereo_camera import StereoCamera
from softarm.vision.stereo_files import read_stereo

__all__ = ["open_stereo", "stereo_camera"]


def stereo_camera(perception: PerceptionConfig, T_base_c1: FloatArray) -> StereoCamera:
    """The calibrated pair, its left eye (C1) at ``T_base_c1``.

    Raises:
        ConfigError: the calibration file is missing or broken (the key named).
    """
    try:
        return read_stereo(perception.calibration_path).placed(T_base_c1)
    except ConfigError as exc:
        raise ConfigError(f"perception.calibration: {exc}") from None


def open_stereo(
    perception: PerceptionConfig, open_camera: Callable[[Any], Any], stack: ExitStack
) -> Callable[[], Pair]:
    """The stereo source's frames: the halves of the ZED2's side-by-side frame, or the
    two devices of a pair; each device is closed by ``stack``."""
    cams = []
    for device in perception.devices():
        cams.append(open_camera(device))
        stack.callback(cams[-1].close)
    if perception.stereo is StereoSource.ZED2:
        return lambda: _halves(cams[0].read())
    return lambda: (cams[0].read(), cams[1].read())


def _halves(frame: Any) -> Pair:
    return (None, None) if frame is None else split_side_by_side(frame, "the ZED2's frame")
