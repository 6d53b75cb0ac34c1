"""Perception without tags: ripe and unripe berries in colour images, their 3D positions
from C1's stereo pair or C2's view, and the canes fitted as curves from C1's depth.

The public surface, what the harvest and a user call:

* berries: :func:`detect_berries` (one image, positions from an optional depth image,
  camera frame; by the detector :func:`use_detector` chose), :func:`locate_berries`
  (C1's stereo pair, base frame), each giving :class:`BerryDetection` objects whose
  ``frame`` says which;
* canes: :func:`fit_canes` (C1's pair or a depth image), :func:`cane_points` and
  :func:`fit_cane_points` (points from several views, fitted together),
  :func:`view_pair_points` (two C2 views), :func:`cane_map_error`;
* the map: :class:`BushMap` of :class:`MappedBerry`, the fruit C1 cannot place as
  :class:`SightLine` objects placed by C2 (:func:`sight_lines`, :func:`crossing`,
  :class:`Placing`), the fix near the berry (:class:`RayCrossing`), the vision of the
  markerless harvest (:class:`BushVision`) and :func:`draw_bush_map`;
* C1 on either rig: :class:`StereoC1` (its looks merged into the map, its canes fitted
  without the rig's own parts); the cane pixels' source, :func:`use_cane_source`;
* the calibrated pair: :class:`StereoCamera` and its :class:`Rectification`.

Every entry point checks its arguments and raises a typed
:class:`~softarm.errors.SoftarmError` naming the one at fault. Frames larger than
:data:`MAX_FRAME_PIXELS` are refused; a frame gives at most :data:`MAX_BLOBS` berries.

At the level of :mod:`softarm.vision` (it imports vision and the leaf modules, never the
simulation), so that the simulated and the real rig run the same code."""

from softarm.perception._inputs import MAX_FRAME_PIXELS
from softarm.perception.approach import RayCrossing, distance_from_size
from softarm.perception.berries import (
    MAX_BLOBS,
    BerryDetection,
    DetectorSettings,
    Frame,
    Ripeness,
    detections_in_masks,
    ripe_by_votes,
)
from softarm.perception.bush_map import BushMap, MappedBerry
from softarm.perception.bush_vision import BushVision
from softarm.perception.c1 import StereoC1
from softarm.perception.cane_curves import CurveSearch
from softarm.perception.cane_metrics import cane_map_error
from softarm.perception.cane_pixels import CaneLook
from softarm.perception.cane_source import use_cane_source
from softarm.perception.cane_views import view_pair_points
from softarm.perception.canes import CaneFit, CaneSettings, cane_points, fit_cane_points, fit_canes
from softarm.perception.detector.choice import detect_berries, fruit_mask, use_detector
from softarm.perception.overlay import draw_bush_map
from softarm.perception.sight_lines import Placing, SightLine, crossing, sight_lines
from softarm.perception.stereo import locate_berries
from softarm.vision.stereo_camera import Rectification, StereoCamera

__all__ = [
    "MAX_BLOBS",
    "MAX_FRAME_PIXELS",
    "BerryDetection",
    "BushMap",
    "BushVision",
    "CaneFit",
    "CaneLook",
    "CaneSettings",
    "CurveSearch",
    "DetectorSettings",
    "Frame",
    "MappedBerry",
    "Placing",
    "RayCrossing",
    "Rectification",
    "Ripeness",
    "SightLine",
    "StereoC1",
    "StereoCamera",
    "cane_map_error",
    "cane_points",
    "crossing",
    "detect_berries",
    "detections_in_masks",
    "distance_from_size",
    "draw_bush_map",
    "fit_cane_points",
    "fit_canes",
    "fruit_mask",
    "locate_berries",
    "ripe_by_votes",
    "sight_lines",
    "use_cane_source",
    "use_detector",
    "view_pair_points",
]
