"""The learned berry detector's network at run time: an ONNX segmentation net run through
OpenCV's DNN module (``cv2.dnn.readNetFromONNX``), so that inference needs nothing beyond
softarm's runtime dependencies; the training code (``softarm detector train``, the
``train`` extra) writes the file.

The convention both sides share: the input ``image`` is (1, 3, H, W) float32, the BGR
image divided by 255, less 0.5, over 0.25, with H and W multiples of :data:`STRIDE`; the
output is (1, :data:`N_OUTPUTS`, H, W): one logit per class of :data:`CLASSES` at each
pixel and, last, the logit of the fruit-centre heatmap (a peak at each fruit's centre).
A network with a stride-2 stem (``train.unet``: the full image's detail, the rest of the
network at half its size) gives (1, N_OUTPUTS, H/2, W/2), H and W multiples of
2 × STRIDE; the output's stride is read from the file by a probe. How the heatmap was
trained (:data:`HEATMAPS`: the broad logistic heatmap, or the focal loss's sharp peaks),
which the decoding into fruit must know, is read from the training record beside the
weights (the same name with ``.json``, as ``softarm detector train`` writes it); without
one, the heatmap is the logistic one (the shipped weights'). A record saying
``"boundary": true`` (``softarm detector train --boundary``) adds one output after the
heatmap: the logit that a fruit pixel lies against another fruit (:mod:`.boundary`); a
record without the key is a network without it. A record saying ``"distance": true``
(``softarm detector train --distance``) adds one output after those: the logit of each
fruit pixel's distance to its own fruit's edge, divided by that fruit's largest
(:mod:`.distance`).
Training images are shrunk so that their longer side is at most :data:`MAX_SIDE` pixels
(the scale the training renders were drawn at: C1's 1280 × 720 eye at half size) times
the output's stride; at run time images are shrunk to a network's own longest side, by
default :data:`RUN_SIDE` times its output's stride (C1's eye at half size for a plain
network, at full size for one with the stem).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import InputError, VisionError

__all__ = [
    "CLASSES",
    "DEFAULT_WEIGHTS",
    "HEATMAPS",
    "MAX_SIDE",
    "N_OUTPUTS",
    "RUN_SIDE",
    "STRIDE",
    "Network",
    "NetworkOutput",
    "boundary_of",
    "distance_of",
    "normalise",
]

#: Per-pixel classes, in the order of the network's first outputs.
CLASSES = ("background", "ripe", "turning", "unripe", "cane")
#: Class logits and the centre heatmap's logit.
N_OUTPUTS = len(CLASSES) + 1
#: The network pools three times: input sides must be multiples of 8.
STRIDE = 8
#: The longer side (px) a training image is shrunk to.
MAX_SIDE = 640
#: The longer side (px) of a plain network's input at run time (a stem network's is twice
#: this): its output's longer side is at most this.
RUN_SIDE = 640
#: The weights that ship in the package.
DEFAULT_WEIGHTS = Path(__file__).parent / "weights" / "berries.onnx"
#: The centre heatmap's kinds, by the loss it was trained with (the record's "heatmap").
HEATMAPS = ("logistic", "focal")

_F32 = npt.NDArray[np.float32]
_U8 = npt.NDArray[np.uint8]


def normalise(image: _U8) -> _F32:
    """The network's input scaling of a BGR uint8 image (any shape), as float32."""
    return cast(_F32, (image.astype(np.float32) * np.float32(1 / 255.0) - 0.5) * 4.0)


class NetworkOutput:
    """The network's output for one image, at the network's resolution: ``probabilities``
    (h, w, len(CLASSES)) float32 summing to 1 per pixel and ``centres`` (h, w) float32 in
    [0, 1]; ``size`` (W, H) is the image's, :meth:`upsample` brings a map to it;
    ``heatmap`` is how the centres were trained (of HEATMAPS); ``boundary`` the (h, w)
    boundary probability of a network with the boundary class, else None; ``distance``
    the (h, w) normalised distance to the fruit's edge of a network trained with it
    (``--distance``), else None."""

    def __init__(
        self,
        probabilities: _F32,
        centres: _F32,
        size: tuple[int, int],
        heatmap: str = "logistic",
        boundary: _F32 | None = None,
        distance: _F32 | None = None,
    ) -> None:
        self.probabilities = probabilities
        self.centres = centres
        self.size = size
        self.heatmap = heatmap
        #: (h, w) probability that a pixel is fruit against another fruit, for a network
        #: trained with the boundary class; None for one without it.
        self.boundary = boundary
        #: (h, w) predicted distance of a fruit pixel to its own fruit's edge over that
        #: fruit's largest (1 at its centre, near 0 at its edge), for a network trained
        #: with it; None for one without it.
        self.distance = distance

    @property
    def scale(self) -> float:
        """Image pixels per network pixel (1 or more)."""
        return float(self.size[0] / self.probabilities.shape[1])

    def fruit(self) -> _F32:
        """(h, w) probability that a pixel is fruit of any stage."""
        return cast(_F32, self.probabilities[..., 1:4].sum(axis=2))

    def upsample(self, values: _F32) -> _F32:
        """A (h, w) map resized to the image (bilinear)."""
        if values.shape[::-1] == self.size:
            return values
        return cast(_F32, cv2.resize(values, self.size, interpolation=cv2.INTER_LINEAR))


class Network:
    """An ONNX segmentation network of this module's convention, read from ``path``, run
    on images shrunk to at most ``max_side`` pixels on their longer side (the scale it
    was trained for; None: RUN_SIDE times the network's output stride).

    Raises:
        VisionError: the file is missing, is not an ONNX network, or gives outputs of
            the wrong shape, or its training record is unreadable or names an unknown
            heatmap (the message names the file).
        InputError: ``max_side`` is not None or an integer of at least STRIDE.
    """

    def __init__(self, path: str | Path = DEFAULT_WEIGHTS, max_side: int | None = None) -> None:
        if max_side is not None and (
            isinstance(max_side, bool) or not isinstance(max_side, int) or max_side < STRIDE
        ):
            raise InputError(f"max_side must be an integer >= {STRIDE}, got {max_side!r}")
        self.path = Path(path)
        if not self.path.is_file():
            raise VisionError(f"detector weights {self.path}: no such file")
        try:
            net = cv2.dnn.readNetFromONNX(str(self.path))
        except cv2.error as exc:
            reason = str(exc).strip().splitlines()[-1] if str(exc).strip() else "unreadable"
            raise VisionError(
                f"detector weights {self.path}: not a readable ONNX network ({reason})"
            ) from None
        if net.empty():
            raise VisionError(f"detector weights {self.path}: the ONNX network is empty")
        self._net = net
        #: Whether the network gives the boundary class (its record says so).
        self.boundary = boundary_of(self.path)
        #: Whether the network gives the normalised distance to the fruit's edge.
        self.distance = distance_of(self.path)
        n = N_OUTPUTS + int(self.boundary) + int(self.distance)
        side = STRIDE * 4
        probe = self._forward(np.zeros((1, 3, side, side), np.float32))
        shapes = {(1, n, side // k, side // k): k for k in (1, 2)}
        if probe.shape not in shapes:
            raise VisionError(
                f"detector weights {self.path}: the network gives {probe.shape} for a "
                f"{side} x {side} image, not (1, {n}, H, W) or (1, {n}, H/2, W/2)"
            )
        #: Image pixels per output pixel of the network (2 for a network with the stem).
        self.stride = shapes[probe.shape]
        self.max_side = RUN_SIDE * self.stride if max_side is None else max_side
        #: How the centre heatmap was trained (of HEATMAPS), from the record beside it.
        self.heatmap = heatmap_of(self.path)

    def _forward(self, blob: _F32) -> _F32:
        try:
            self._net.setInput(blob)
            return cast(_F32, np.asarray(self._net.forward(), np.float32))
        except cv2.error as exc:
            raise VisionError(f"detector weights {self.path}: the network failed: {exc}") from None

    def run(self, image: _U8) -> NetworkOutput:
        """The class probabilities and centre heatmap of a BGR uint8 (H, W, 3) image, at
        the network's resolution (the image shrunk to ``max_side``)."""
        h, w = image.shape[:2]
        scale = min(1.0, self.max_side / max(h, w))
        sw, sh = max(1, round(w * scale)), max(1, round(h * scale))
        small = image if scale == 1.0 else cv2.resize(image, (sw, sh), interpolation=cv2.INTER_AREA)
        k = self.stride
        pw, ph = -sw % (STRIDE * k), -sh % (STRIDE * k)
        padded = cast(_U8, cv2.copyMakeBorder(small, 0, ph, 0, pw, cv2.BORDER_REFLECT))
        blob = normalise(padded).transpose(2, 0, 1)[None]
        out = self._forward(np.ascontiguousarray(blob))[0, :, : -(-sh // k), : -(-sw // k)]
        logits = out[: len(CLASSES)]
        e = np.exp(logits - logits.max(axis=0, keepdims=True))
        probs = (e / e.sum(axis=0, keepdims=True)).transpose(1, 2, 0)
        centres = 1.0 / (1.0 + np.exp(-out[len(CLASSES)]))
        boundary = distance = None
        if self.boundary:
            boundary = (1.0 / (1.0 + np.exp(-out[N_OUTPUTS]))).astype(np.float32)
        if self.distance:  # the last output, after the boundary class where there is one
            distance = (1.0 / (1.0 + np.exp(-out[-1]))).astype(np.float32)
        return NetworkOutput(
            np.ascontiguousarray(probs, np.float32), centres.astype(np.float32), (w, h),
            self.heatmap, boundary, distance,
        )  # fmt: skip


def _record(weights: Path) -> object:
    """The training record beside ``weights`` (parsed JSON), or {} where there is none.

    Raises:
        VisionError: the record is not readable JSON.
    """
    record = weights.with_suffix(".json")
    if not record.is_file():
        return {}
    try:
        return json.loads(record.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise VisionError(f"detector record {record}: not readable JSON ({exc})") from None


def _flag(weights: Path, key: str) -> bool:
    """The true-or-false ``key`` of the training record of ``weights``; False where there
    is no record or it has no such key (records written before the option existed).

    Raises:
        VisionError: the record is unreadable, or its ``key`` is not true or false.
    """
    data = _record(weights)
    flag = data.get(key, False) if isinstance(data, dict) else None
    if not isinstance(flag, bool):
        raise VisionError(
            f"detector record {weights.with_suffix('.json')}: {key} {flag!r} is not true or false"
        )
    return flag


def boundary_of(weights: Path) -> bool:
    """Whether ``weights`` give the boundary class: their training record's "boundary"
    (``weights`` with ``.json``); False where there is no record or it has no such key.

    Raises:
        VisionError: the record is unreadable, or its "boundary" is not true or false.
    """
    return _flag(weights, "boundary")


def distance_of(weights: Path) -> bool:
    """Whether ``weights`` give the normalised distance to the fruit's edge: their
    training record's "distance"; False where there is no record or it has no such key.

    Raises:
        VisionError: the record is unreadable, or its "distance" is not true or false.
    """
    return _flag(weights, "distance")


def heatmap_of(weights: Path) -> str:
    """The heatmap kind of ``weights`` (of HEATMAPS): its training record's "heatmap"
    (``weights`` with ``.json``), "logistic" where there is no record or it names none
    (records written before the focal loss existed).

    Raises:
        VisionError: the record is not a JSON object, or names an unknown heatmap.
    """
    record = weights.with_suffix(".json")
    data = _record(weights)
    kind = data.get("heatmap", "logistic") if isinstance(data, dict) else None
    if kind not in HEATMAPS:
        raise VisionError(
            f"detector record {record}: heatmap {kind!r} is not one of {', '.join(HEATMAPS)}"
        )
    return str(kind)
