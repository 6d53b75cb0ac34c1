"""OpenCV's own errors as :class:`~softarm.errors.VisionError`.

The argument checks (:mod:`softarm.vision._checks`) catch what can be told in advance; an
input that is well formed but numerically hopeless (a camera with fx = 1e300, k1 = 1e6,
corners that leave a solver nothing to work with) is found only inside OpenCV, which
raises ``cv2.error`` with a multi-line C++ message. Every call into OpenCV's solvers and
calibration runs inside :func:`opencv_errors`, so it ends as one typed line instead.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import cv2

from softarm.errors import VisionError

__all__ = ["opencv_errors"]


def _reason(exc: cv2.error) -> str:
    """The human part of a ``cv2.error``: ``OpenCV(5.0.0) file:line: error: (-215:
    Assertion failed) what in function 'f'`` -> ``what``."""
    text = " ".join(str(exc).split())
    if ")" in text.partition("error: ")[2]:
        text = text.partition("error: ")[2].partition(") ")[2]
    return text.partition(" in function")[0][:160]


@contextmanager
def opencv_errors(what: str) -> Iterator[None]:
    """Inside the block, a ``cv2.error`` is a one-line :class:`VisionError` naming
    ``what`` (the operation and the argument it could not use)."""
    try:
        yield
    except cv2.error as exc:
        raise VisionError(f"{what}: OpenCV could not use the input ({_reason(exc)})") from None
