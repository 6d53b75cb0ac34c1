"""Adversarial frames for the berry detector: a grid of thousands of fruit-sized,
fruit-coloured discs (a patterned sheet, a shaded net), each a blob the detector must
consider (issue 42, item 21)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

#: Black-purple (BGR), the ripe colour class.
RIPE_BGR = (40, 8, 25)
#: Leaf green (BGR), the background.
LEAF_BGR = (60, 110, 70)


def speck_frame(
    columns: int = 80, rows: int = 45, size: tuple[int, int] = (1280, 720), radius: int = 5
) -> npt.NDArray[np.uint8]:
    """A ``size`` = (width, height) BGR frame of ``columns`` x ``rows`` ripe discs of
    ``radius`` px on leaf green, evenly spaced (80 x 45 = 3,600 at 1280 x 720, 16 px
    apart: gaps of 5 px, wider than the detector's closing bridges)."""
    width, height = size
    image = np.empty((height, width, 3), np.uint8)
    image[:] = LEAF_BGR
    yy, xx = np.mgrid[-radius : radius + 1, -radius : radius + 1]
    disc = xx**2 + yy**2 <= radius**2
    dx, dy = width / columns, height / rows
    for i in range(columns):
        for j in range(rows):
            x, y = int(dx * (i + 0.5)) - radius, int(dy * (j + 0.5)) - radius
            image[y : y + 2 * radius + 1, x : x + 2 * radius + 1][disc] = RIPE_BGR
    return image
