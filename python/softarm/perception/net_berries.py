"""A learned candidate for the berry detector's pixel stage (issue 23, "Which detector").

:func:`softarm.perception.berries.detect_berries` finds fruit pixels by HSV thresholds
and then keeps the compact, fruit-sized blobs of them. This module swaps the first stage
only: a small per-pixel network (an MLP over a few colour features of each pixel and of
its 9×9 neighbourhood) labels every pixel background, ripe or unripe, and the same
closing, blob and shape stage of ``berries`` follows, so that a comparison of the two
isolates the pixel model. The network is an ONNX file run through OpenCV's DNN module
(``cv2.dnn.readNetFromONNX``); it is trained by :mod:`softarm.experiments.train_pixel_net`
on rendered bushes of tuning seeds only. docs/perception.md ("Which detector") has the
comparison; the harvest uses the colour-and-shape detector, and no weights ship in the
package.
"""

from __future__ import annotations

from pathlib import Path
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import VisionError
from softarm.perception._inputs import instance, instance_or_default
from softarm.perception.berries import (
    BerryDetection,
    DetectorSettings,
    _check,
    _close,
    detections_in_masks,
)
from softarm.vision.camera_model import CameraModel

__all__ = ["N_CLASSES", "N_FEATURES", "NetDetector", "pixel_features"]

#: Pixel classes, in the order of the network's outputs.
CLASSES = ("background", "ripe", "unripe")
N_CLASSES = len(CLASSES)
#: Per-pixel inputs: B, G, R, S, V, S·cos H, S·sin H of the pixel (3×3 blur) and the
#: B, G, R of its 9×9 neighbourhood, all in [0, 1] (or [-1, 1]).
N_FEATURES = 10
#: The neighbourhood (px) whose mean colour is the context.
CONTEXT = 9

_U8 = npt.NDArray[np.uint8]
_F32 = npt.NDArray[np.float32]
# cos and sin of OpenCV's hue (H in [0, 180) is half the angle in degrees), per value.
_HUE = np.arange(256, dtype=np.float32) * np.float32(np.pi / 90.0)
_COS_HUE = np.cos(_HUE).astype(np.float32)
_SIN_HUE = np.sin(_HUE).astype(np.float32)


def pixel_features(image: npt.NDArray[np.uint8]) -> _F32:
    """(H, W, N_FEATURES) float32 features of a BGR uint8 image (the network's input,
    the same in training and at run time)."""
    blur = cast(_U8, cv2.GaussianBlur(image, (3, 3), 0))
    hsv = cast(_U8, cv2.cvtColor(blur, cv2.COLOR_BGR2HSV))
    bgr = cast(_F32, blur.astype(np.float32) * np.float32(1.0 / 255.0))
    sat = hsv[..., 1].astype(np.float32) * np.float32(1.0 / 255.0)
    val = hsv[..., 2].astype(np.float32) * np.float32(1.0 / 255.0)
    context = cast(_F32, cv2.blur(bgr, (CONTEXT, CONTEXT)))
    planes = [
        *cv2.split(bgr), sat, val,
        sat * _COS_HUE[hsv[..., 0]], sat * _SIN_HUE[hsv[..., 0]],
        *cv2.split(context),
    ]  # fmt: skip
    return cast(_F32, cv2.merge(planes))


class NetDetector:
    """The berry detector with a network for its pixel stage: ``detect_berries`` and
    ``fruit_mask`` with the signatures of :mod:`softarm.perception.berries`'s.

    Raises:
        VisionError: ``model`` cannot be read as an ONNX network of
            N_FEATURES inputs and N_CLASSES outputs.
    """

    def __init__(self, model: str | Path | bytes) -> None:
        try:
            if isinstance(model, bytes):
                net = cv2.dnn.readNetFromONNX(np.frombuffer(model, np.uint8))
            else:
                if not Path(model).is_file():
                    raise VisionError(f"no pixel network at {model}")
                net = cv2.dnn.readNetFromONNX(str(model))
        except cv2.error as e:
            raise VisionError(f"cannot read the pixel network: {e}") from e
        if net.empty():
            raise VisionError("the pixel network is empty")
        self._net = net
        probe = self._forward(np.zeros((1, N_FEATURES), np.float32))
        if probe.shape != (1, N_CLASSES):
            raise VisionError(f"the pixel network gives {probe.shape}, not (1, {N_CLASSES})")

    def _forward(self, x: _F32) -> _F32:
        try:
            self._net.setInput(x)
            return cast(_F32, np.asarray(self._net.forward(), np.float32))
        except cv2.error as e:
            raise VisionError(f"the pixel network failed: {e}") from e

    def classes(self, image: npt.NDArray[np.uint8]) -> _U8:
        """(H, W) uint8 class of each pixel of a BGR image: 0 background, 1 ripe,
        2 unripe (the network's largest output)."""
        _check(image, None)
        h, w = image.shape[:2]
        scores = self._forward(pixel_features(image).reshape(h * w, N_FEATURES))
        return cast(_U8, np.argmax(scores, axis=1).astype(np.uint8).reshape(h, w))

    def masks(self, image: npt.NDArray[np.uint8]) -> tuple[_U8, _U8]:
        """(ripe, unripe) masks (0/255), as the colour detector's thresholds give them."""
        c = self.classes(image)
        return (c == 1).astype(np.uint8) * 255, (c == 2).astype(np.uint8) * 255

    def fruit_mask(
        self, image: npt.NDArray[np.uint8], settings: DetectorSettings | None = None
    ) -> _U8:
        """The fruit pixels (0/255), closed over the drupelet gaps (``settings`` is
        accepted for the signature of :func:`~softarm.perception.berries.fruit_mask`)."""
        ripe, unripe = self.masks(image)
        return _close(cast(_U8, cv2.bitwise_or(ripe, unripe)))

    def detect_berries(
        self,
        image: npt.NDArray[np.uint8],
        camera: CameraModel,
        depth: npt.NDArray[np.floating] | None = None,
        settings: DetectorSettings | None = None,
    ) -> list[BerryDetection]:
        """As :func:`~softarm.perception.berries.detect_berries`, with the network's
        masks in place of the HSV thresholds (the same blob, shape and size stage).

        Raises:
            VisionError: ``image`` is not an (H, W, 3) uint8 array, or ``depth`` does
                not match it.
        """
        s = instance_or_default(settings, DetectorSettings, "settings")
        _check(image, depth, instance(camera, CameraModel, "camera"))
        ripe, unripe = self.masks(image)
        return detections_in_masks(ripe, unripe, camera, depth, s)
