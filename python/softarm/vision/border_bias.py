"""How far a camera's clipping has moved a marker's edges towards its paper, measured on
the marker itself: the width of its black border.

A clipped edge profile biases the gradient centroid (:mod:`softarm.vision.refine`):
a black level subtracted and then clipped at 0 crushes the foot of the ramp on the ink's
side, so the edge is found a few hundredths of a pixel towards the paper; a white clipped
at full scale moves it towards the ink. Neither the foot's true level nor the blur is
known, and a model fitted to one profile cannot tell them apart (a lower ink level and a
wider blur give the same visible part of the ramp). But the bias is the same, in pixels
towards the paper, on both edges of the black border cell: the outer edge (border to
quiet zone) and the inner one (border to a white data cell). Moved towards the paper,
the outer edge goes out and the inner one in, so the border looks wider by twice the
bias: comparing the inner edge, measured across where a data cell is white, with where
the quad of the outer edges puts it gives the bias, whatever the blur, the black level or
which side clipped.

With the outer edges each moved out by ``d`` the quad is scaled about the marker's
centre, so it puts the inner edge out by ``d * (cells - 2) / cells``, while the inner
edge itself sits ``d`` in: the measured minus the predicted position, along the outward
normal, is ``-d * (2 * cells - 2) / cells``.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

import cv2
import numpy as np
import numpy.typing as npt

from softarm.vision._checks import FloatArray

__all__ = ["MIN_ASPECT", "MIN_INNER_PROFILES", "SHRINK_SE", "border_bias"]

#: Inner-edge profiles per data cell, spread over the middle of its side (clear of the
#: cell's corners, where the next cell's colour blurs in).
_PER_CELL = 5
_CELL_SPAN = (0.25, 0.75)
#: A white data cell's inner edge: at least this share of the 90th percentile of the
#: inner profiles' contrast (a black cell there has no edge).
_WHITE_SHARE = 0.5
#: A quad whose shortest side is under this share of its longest: no measurement. Seen
#: this obliquely (about 50° or more) the blur across the foreshortened sides is not
#: the blur across the others, nor is their bias, and one bias for all four moves
#: the corners the wrong way as often as the right one (diagnosis bushes 400-409).
MIN_ASPECT = 0.6
#: Fewer usable inner profiles than this: no measurement.
MIN_INNER_PROFILES = 6
#: The bias is shrunk towards 0 by this many of its standard errors (a clean camera's
#: border measures 0 within its noise, and an unshrunk estimate would add that noise).
SHRINK_SE = 0.5
_TRIM_MADS = 2.5  # inner offsets further than this many MADs from the median are left out


def border_bias(
    crop: npt.NDArray[np.float32],
    crop_origin: npt.NDArray[np.int_],
    quad: FloatArray,
    cells: int,
    offsets: FloatArray,
    outward: FloatArray,
    locate: Callable[[FloatArray, FloatArray, FloatArray], FloatArray] | None = None,
) -> float:
    """The marker's edge bias (px, towards the paper; negative: towards the ink), from
    its border's inner edge, shrunk by SHRINK_SE standard errors; 0 when it cannot be
    measured. ``crop``: the marker's neighbourhood (float), its top-left pixel at
    ``crop_origin`` (x, y) of ``quad``'s pixels; ``quad``: the (4, 2) corners the outer
    edges gave; ``cells``: bits + 2; ``offsets``: the profile's sample offsets (px);
    ``outward``: (4, 2) each side's unit normal from the ink to the quiet zone."""
    sides = np.roll(quad, -1, axis=0) - quad
    lengths = np.sqrt(np.einsum("ij,ij->i", sides, sides))
    if lengths.min() < MIN_ASPECT * lengths.max():
        return 0.0
    unit = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    H = cv2.getPerspectiveTransform(unit, quad.astype(np.float32))
    uv, side = _inner_points(cells)
    centre = cv2.perspectiveTransform(uv[None], H)[0]  # the inner edge, as the quad says
    across = offsets[None, :, None] * outward[side][:, None, :]
    pts = ((centre - crop_origin)[:, None, :] + across).astype(np.float32)
    prof = cv2.remap(crop, pts, None, cv2.INTER_LINEAR)  # type: ignore[call-overload]  # map2 None is valid
    grad = np.diff(prof, axis=1).astype(np.float64)
    fall = -grad.sum(axis=1)  # a white cell inside: the level falls outwards, into the border
    white = fall > _WHITE_SHARE * _quantile(np.abs(fall), 0.9)
    mid = 0.5 * (offsets[1:] + offsets[:-1])
    measured = (grad @ mid) / np.where(white, -fall, 1.0)
    if locate is not None and np.any(white):
        measured[white] = locate(prof[white], offsets, measured[white])
    usable = white & (np.abs(measured) < offsets[-1])
    if usable.sum() < MIN_INNER_PROFILES:
        return 0.0
    return _shrunk(measured[usable]) * cells / (2.0 * cells - 2.0)


@functools.cache
def _inner_points(cells: int) -> tuple[FloatArray, npt.NDArray[np.intp]]:
    """Where the inner-edge profiles sit on the unit square (its corners the quad's):
    _PER_CELL points over the middle of each data cell's side along the inner edge, and
    the side (0..3) of each."""
    c = 1.0 / cells
    inner = np.array([[c, c], [1 - c, c], [1 - c, 1 - c], [c, 1 - c]])
    bits = cells - 2
    along = np.linspace(*_CELL_SPAN, _PER_CELL)
    t = (np.arange(bits)[:, None] + along[None, :]).ravel() / bits
    side = np.repeat(np.arange(4), t.size)
    start, end = inner[side], np.roll(inner, -1, axis=0)[side]
    uv: FloatArray = start + np.tile(t, 4)[:, None] * (end - start)
    uv.flags.writeable = False
    side.flags.writeable = False
    return uv, side


def _quantile(values: FloatArray, q: float) -> float:
    """``np.percentile(values, 100 * q)`` (linear), by a partial sort: numpy's own costs
    ten times more on the few dozen values here."""
    pos = q * (values.size - 1)
    lo = int(pos)
    hi = min(lo + 1, values.size - 1)
    part = np.partition(values, (lo, hi))
    return float(part[lo] + (pos - lo) * (part[hi] - part[lo]))


def _shrunk(measured: FloatArray) -> float:
    """Minus the trimmed mean of the inner edges' offsets, shrunk towards 0 by SHRINK_SE
    of its standard errors."""
    median = _quantile(measured, 0.5)
    mad = 1.4826 * _quantile(np.abs(measured - median), 0.5)
    kept = measured[np.abs(measured - median) <= _TRIM_MADS * max(mad, 1e-3)]
    mean = -float(kept.mean())
    se = float(kept.std()) / np.sqrt(kept.size)
    return float(np.sign(mean) * max(abs(mean) - SHRINK_SE * se, 0.0))
