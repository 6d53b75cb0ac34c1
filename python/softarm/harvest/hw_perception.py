"""Perception on the arm: C1 as the ``[perception]`` stereo source, the bush map built
from it by the code the rendered bush runs (:func:`~softarm.perception.stereo.
locate_berries`, :func:`~softarm.perception.canes.fit_canes`), the canes filtered of
the rig's own parts as in simulation (:mod:`softarm.harvest.rig_parts`)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from contextlib import ExitStack
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from softarm._core import PolynomialCurve
from softarm.checks import FloatArray
from softarm.errors import ConfigError, HardwareUnavailableError, VisionError
from softarm.harvest.rig_parts import a_cane
from softarm.perception.bush_map import BushMap
from softarm.perception.canes import CaneFit, cane_points, fit_cane_points
from softarm.perception.sight_lines import sight_lines
from softarm.perception.stereo import locate_berries
from softarm.perception_config import PerceptionConfig
from softarm.vision.stereo_calibration import split_side_by_side
from softarm.vision.stereo_camera import StereoCamera
from softarm.vision.stereo_files import read_stereo

__all__ = ["StereoC1", "open_stereo", "stereo_camera"]

#: A stereo pair's (left, right) frames, each None when its device gave none.
Pair = tuple[Any, Any]


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
    if perception.stereo == "zed2":
        return lambda: _halves(cams[0].read())
    return lambda: (cams[0].read(), cams[1].read())


def _halves(frame: Any) -> Pair:
    return (None, None) if frame is None else split_side_by_side(frame, "the ZED2's frame")


@dataclass
class StereoC1:
    """C1 on the arm: the stereo source, its calibration in the base frame and the map
    perception builds from it."""

    stereo: StereoCamera
    read: Callable[[], Pair]
    bush_map: BushMap = field(default_factory=BushMap)

    def pair(self) -> Pair:
        """One stereo frame.

        Raises:
            HardwareUnavailableError: a device gave no frame.
        """
        left, right = self.read()
        if left is None or right is None:
            raise HardwareUnavailableError("perception: the stereo source gave no frame")
        return left, right

    def look(self) -> int:
        """One stereo view merged into the map; the number of berries new to it. The
        ripe fruit it cannot place are kept as sight lines, for C2 to place."""
        left, right = self.pair()
        detections = locate_berries(left, right, self.stereo)
        new = self.bush_map.update(detections)
        self.bush_map.note_unplaced(sight_lines(detections, self.stereo))
        return new

    def fit_canes(self, parts: FloatArray, reach: float) -> list[PolynomialCurve]:
        """The canes of one stereo view, the rig's own ``parts`` and what lies beyond
        ``reach`` left out (as in the rendered bush); the map keeps them and the
        view's cane points."""
        left, right = self.pair()
        self.bush_map.cane_points = cane_points(left, right, self.stereo)
        return self._keep(fit_cane_points(self.bush_map.cane_points), parts, reach)

    def refit_canes(
        self, parts: FloatArray, reach: float, more: Sequence[FloatArray]
    ) -> list[PolynomialCurve]:
        """The canes of the map's last view fitted again together with the cane points
        ``more`` of other views (the survey's, :mod:`softarm.harvest.cane_survey`),
        filtered as :meth:`fit_canes` does; the map keeps them.

        Raises:
            VisionError: the map has no C1 cane points (no :meth:`fit_canes` before).
        """
        if self.bush_map.cane_points is None:
            raise VisionError("refit_canes: the map has no C1 cane points (fit_canes first)")
        points = np.vstack([self.bush_map.cane_points, *more])
        return self._keep(fit_cane_points(points), parts, reach)

    def _keep(self, fits: list[CaneFit], parts: FloatArray, reach: float) -> list[PolynomialCurve]:
        self.bush_map.canes = [f for f in fits if a_cane(f.points[:, :3], parts, reach)]
        return [c.curve for c in self.bush_map.canes]

    def left(self, t: float) -> Any:
        """C1's image for the vision loop: the left eye (None without a frame)."""
        return self.read()[0]
