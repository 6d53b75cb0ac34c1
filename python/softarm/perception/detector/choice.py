"""Which berry detector the harvest uses: ``colour`` (the colour-and-shape thresholds of
:mod:`softarm.perception.berries`, the default), ``net`` (the shipped network,
:mod:`.learned`) or ``net+colour`` (the network's detections that the colour thresholds
confirm). The choice is one per process, set from ``[perception] detector`` of hw.toml
or the simulator's ``--detector``; the stereo (:mod:`softarm.perception.stereo`) and
C2's vision (:mod:`softarm.perception.bush_vision`) call :func:`detect_berries` and
:func:`fruit_mask` of this module, which hand the call to the chosen one."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np
import numpy.typing as npt

from softarm.errors import ParameterError
from softarm.perception import berries
from softarm.perception.berries import BerryDetection, DetectorSettings
from softarm.vision.camera_model import CameraModel

__all__ = [
    "DEFAULT_DETECTOR",
    "DETECTORS",
    "SPLIT_TOUCHING",
    "BerryDetector",
    "current_detector",
    "detect_berries",
    "detector",
    "fruit_mask",
    "use_detector",
]

#: The detectors to choose from.
DETECTORS = ("colour", "net", "net+colour")
#: The harvest's detector unless told otherwise (docs/perception.md, "Which detector").
DEFAULT_DETECTOR = "colour"
_U8 = npt.NDArray[np.uint8]


class BerryDetector(Protocol):
    """What the harvest calls of a detector."""

    def detect_berries(
        self,
        image: npt.NDArray[np.uint8],
        camera: CameraModel,
        depth: npt.NDArray[np.floating] | None = None,
        settings: DetectorSettings | None = None,
    ) -> Sequence[BerryDetection]: ...

    def fruit_mask(
        self, image: npt.NDArray[np.uint8], settings: DetectorSettings | None = None
    ) -> _U8: ...


class _Colour:
    """The colour-and-shape detector as a :class:`BerryDetector`."""

    name = "colour"

    def detect_berries(
        self,
        image: npt.NDArray[np.uint8],
        camera: CameraModel,
        depth: npt.NDArray[np.floating] | None = None,
        settings: DetectorSettings | None = None,
    ) -> list[BerryDetection]:
        return berries.detect_berries(image, camera, depth, settings)

    def fruit_mask(
        self, image: npt.NDArray[np.uint8], settings: DetectorSettings | None = None
    ) -> _U8:
        return berries.fruit_mask(image, settings)


#: Fruit that touch split at the necks of their shape (docs/perception.md, "Splitting
#: touching fruit by their shape"): the network's instances and the colour rule's blobs.
SPLIT_TOUCHING = DetectorSettings(split_touching=True, split_colour_blobs=True)

_chosen = DEFAULT_DETECTOR


def _check_name(name: str) -> None:
    if name not in DETECTORS:
        raise ParameterError(f"detector must be one of {', '.join(DETECTORS)}, got {name!r}")


def detector(name: str) -> BerryDetector:
    """The detector called ``name`` (the network's weights are read on first use).

    Raises:
        ParameterError: ``name`` is not one of DETECTORS.
        VisionError: the shipped weights are missing or broken.
    """
    _check_name(name)
    if name == "colour":
        return _Colour()
    from softarm.perception.detector.learned import default_detector

    return default_detector(confirmed=name == "net+colour")


def use_detector(name: str) -> None:
    """Make ``name`` the detector of this process (its weights read now, so that a broken
    file fails at set-up, not in the middle of a harvest)."""
    global _chosen
    detector(name)
    _chosen = name


def current_detector() -> str:
    """The name of this process's detector."""
    return _chosen


def detect_berries(
    image: npt.NDArray[np.uint8],
    camera: CameraModel,
    depth: npt.NDArray[np.floating] | None = None,
    settings: DetectorSettings | None = None,
) -> list[BerryDetection]:
    """The berries in a BGR ``image`` by this process's detector (:func:`use_detector`);
    ``depth`` (H, W) metres adds each one's position in the camera frame.

    Raises:
        VisionError: ``image`` is not an (H, W, 3) uint8 array, or ``depth`` does not
            match it.
    """
    return list(detector(_chosen).detect_berries(image, camera, depth, settings))


def fruit_mask(image: npt.NDArray[np.uint8], settings: DetectorSettings | None = None) -> _U8:
    """The fruit pixels (0/255) of a BGR image by this process's detector."""
    return detector(_chosen).fruit_mask(image, settings)
