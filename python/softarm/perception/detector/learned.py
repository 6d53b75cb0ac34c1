"""The learned berry detector: the shipped segmentation network (:mod:`.network`) and its
post-processing (:mod:`.instances`) behind the two calls the harvest makes of a detector,
``detect_berries`` and ``fruit_mask`` (the silhouettes the stereo matches), plus the
network's cane pixels."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np
import numpy.typing as npt

from softarm.perception._inputs import depth_metres, instance, instance_or_default
from softarm.perception.berries import DetectorSettings, _check, _close, fruit_mask
from softarm.perception.detector.instances import FRUIT_THRESHOLD, StagedDetection, instances
from softarm.perception.detector.network import (
    CLASSES,
    DEFAULT_WEIGHTS,
    Network,
    NetworkOutput,
)
from softarm.vision.camera_model import CameraModel

__all__ = ["CONFIRM_SHARE", "ConfirmedDetector", "LearnedDetector", "default_detector"]

#: ``net+colour`` keeps a network detection when at least this share of its pixels is in
#: the colour detector's fruit mask.
CONFIRM_SHARE = 0.2
_U8 = npt.NDArray[np.uint8]


class LearnedDetector:
    """The network's berries (``net``); ``weights`` an ONNX file (default: the shipped one)
    run on images shrunk to ``max_side`` (default: RUN_SIDE times the network's output
    stride, the size it was trained for).

    Raises:
        VisionError: the weights file is missing or broken (named in the message).
        InputError: ``max_side`` is not None or an integer of at least STRIDE.
    """

    name = "net"

    def __init__(self, weights: str | Path = DEFAULT_WEIGHTS, max_side: int | None = None) -> None:
        self.network = Network(weights, max_side)

    def output(self, image: npt.NDArray[np.uint8]) -> NetworkOutput:
        """The network's output for a BGR uint8 image (checked as detect_berries does)."""
        _check(image, None)
        return self.network.run(image)

    def detect_berries(
        self,
        image: npt.NDArray[np.uint8],
        camera: CameraModel,
        depth: npt.NDArray[np.floating] | None = None,
        settings: DetectorSettings | None = None,
    ) -> list[StagedDetection]:
        """As :func:`softarm.perception.berries.detect_berries`, each with its ``stage``.

        Raises:
            VisionError: ``image`` is not an (H, W, 3) uint8 array, or ``depth`` does
                not match it.
        """
        s = instance_or_default(settings, DetectorSettings, "settings")
        _check(image, depth, instance(camera, CameraModel, "camera"))
        metres = depth_metres(depth, image.shape[:2])
        return instances(self.network.run(image), camera, metres, s)

    def fruit_mask(
        self, image: npt.NDArray[np.uint8], settings: DetectorSettings | None = None
    ) -> _U8:
        """The fruit pixels (0/255) at the image's size, closed over small gaps."""
        out = self.output(image)
        fruit = out.upsample(out.fruit()) > FRUIT_THRESHOLD
        return _close(fruit.astype(np.uint8) * 255)

    def cane_mask(self, image: npt.NDArray[np.uint8]) -> _U8:
        """The pixels (0/255) the network calls cane, at the image's size."""
        out = self.output(image)
        cane = out.upsample(out.probabilities[..., CLASSES.index("cane")]) > 0.5
        return cane.astype(np.uint8) * 255


class ConfirmedDetector(LearnedDetector):
    """``net+colour``: the network proposes, the colour thresholds confirm (a detection
    is kept when CONFIRM_SHARE of its pixels have a fruit colour)."""

    name = "net+colour"

    def detect_berries(
        self,
        image: npt.NDArray[np.uint8],
        camera: CameraModel,
        depth: npt.NDArray[np.floating] | None = None,
        settings: DetectorSettings | None = None,
    ) -> list[StagedDetection]:
        dets = super().detect_berries(image, camera, depth, settings)
        if not dets:
            return dets
        colour = fruit_mask(image, settings) > 0
        return [d for d in dets if _share(colour, d) >= CONFIRM_SHARE]


def _share(colour: npt.NDArray[np.bool_], det: StagedDetection) -> float:
    """The share of ``det``'s pixels that ``colour`` holds."""
    x, y = det.mask_offset
    h, w = det.mask.shape
    return float(colour[y : y + h, x : x + w][det.mask].mean())


@lru_cache(maxsize=2)
def default_detector(confirmed: bool = False) -> LearnedDetector:
    """The shipped network, read once per process."""
    return ConfirmedDetector() if confirmed else LearnedDetector()


def cane_pixels(image: npt.NDArray[np.uint8]) -> _U8:
    """The shipped network's cane pixels (0/255) of a BGR image."""
    return default_detector().cane_mask(image)
