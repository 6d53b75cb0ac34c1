"""C1's perception, on the arm and in the rendered worlds alike: the bush map built from
the stereo pair (:func:`~softarm.perception.stereo.locate_berries`,
:func:`~softarm.perception.canes.fit_canes`), the canes filtered of the rig's own
parts (:mod:`softarm.perception.self_filter`): the points seen through the rig before the
fit, the fits that are the rig after it."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from softarm._core import PolynomialCurve
from softarm.checks import FloatArray
from softarm.errors import HardwareUnavailableError, VisionError
from softarm.perception.bush_map import BushMap
from softarm.perception.canes import CaneFit, cane_points, fit_cane_points
from softarm.perception.self_filter import a_cane, behind_rig
from softarm.perception.sight_lines import sight_lines
from softarm.perception.stereo import locate_berries
from softarm.perception.two_eyes import ray_origin
from softarm.vision.stereo_camera import StereoCamera

__all__ = ["Pair", "StereoC1"]

#: A stereo pair's (left, right) frames, each None when its device gave none.
Pair = tuple[Any, Any]


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
        self.bush_map.ray_origin = ray_origin(self.stereo)  # where its positions' rays start
        self.bush_map.note_unplaced(sight_lines(detections, self.stereo))
        return new

    def fit_canes(
        self, parts: FloatArray, reach: float, outline: FloatArray | None = None
    ) -> list[PolynomialCurve]:
        """The canes of one stereo view, the rig's own ``parts`` and what lies beyond
        ``reach`` left out (as in the rendered bush); the map keeps them and the
        view's cane points. ``outline``: the rig as it stands while C1 takes the view
        (:func:`~softarm.perception.self_filter.rig_outline`); the points either eye
        could only have seen through it are dropped before the fit (None: none)."""
        left, right = self.pair()
        points = cane_points(left, right, self.stereo)
        if outline is not None:
            eyes = np.array(
                [self.stereo.T_base_left, self.stereo.T_base_left @ self.stereo.T_left_right]
            )
            points = points[~behind_rig(points, eyes[:, :3, 3], outline)]
        self.bush_map.cane_points = points
        return self._keep(fit_cane_points(points), parts, reach)

    def refit_canes(
        self, parts: FloatArray, reach: float, more: Sequence[FloatArray]
    ) -> list[PolynomialCurve]:
        """The canes of the map's last view fitted again together with the cane points
        ``more`` of other views (the survey's, :mod:`softarm.harvest.runs.cane_survey`),
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
