"""What C1 saw at IDLE, before the arm moved: the picture ``softarm harvest --sim --world
bush --plot RUN.png`` saves as ``RUN_c1.png`` (docs/perception.md, "The C1 picture").

C1's left image, brightened for the eye where it is dim (the rendered bush is lit as a
field at dusk), with the bush map drawn on it (:func:`~softarm.perception.overlay.draw_bush_map`:
a magenta circle for a ripe berry and a green one for an unripe berry, each with its
map number, the number the console and harvest.png give it; an amber line for each
fitted cane) over what only the simulation knows (a thin white line along each true
cane, a white cross on each true ripe berry, a green cross on each unripe one), with a
title band above and a legend band below.
"""

from __future__ import annotations

import itertools
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from softarm.perception.overlay import CANE, RIPE, UNRIPE, draw_bush_map
from softarm.vision.poses import invert

__all__ = ["c1_picture"]

Image = npt.NDArray[np.uint8]

#: The truth's colours (BGR): canes and ripe berries white, unripe berries light green.
TRUE, TRUE_UNRIPE = (255, 255, 255), (150, 255, 150)
#: The mean grey a dim render is lifted to for the eye, by a gamma of at least MIN_GAMMA
#: (below 1 brightens the shadows most).
MEAN_GREY, MIN_GAMMA = 100.0, 0.4
#: The legend: (kind, BGR colour, text).
LEGEND = (
    ("circle", RIPE, "ripe berry in the bush map (its number)"),
    ("circle", UNRIPE, "unripe berry in the map"),
    ("line", CANE, "cane fitted by C1"),
    ("cross", TRUE, "true berry (simulation only)"),
    ("cross", TRUE_UNRIPE, "true unripe berry"),
    ("thin", TRUE, "true cane"),
)


def c1_picture(scene: Any, seed: int) -> Image:
    """The picture of ``scene`` (a :class:`~softarm.harvest.rigs.sim.bush_world.BushScene` whose
    C1 is registered) now, titled with the bush's ``seed``."""
    stereo = scene.c1()
    image = _brighten(scene.c1_whole(0.0))
    _draw_truth(image, scene.bush, stereo)
    drawn = draw_bush_map(image, scene.bush_map, stereo)
    n = len(scene.bush_map.berries)
    title = (
        f"What C1 saw at IDLE, before the arm moved (seed {seed}): the bush map, "
        f"{n} berr{'y' if n == 1 else 'ies'}, over the truth"
    )
    return _framed(drawn, title)


def _brighten(image: Image) -> Image:
    """``image`` through a gamma that lifts a dim render's mean grey to about
    :data:`MEAN_GREY` (a daylight one is left as it is)."""
    mean = float(np.clip(image.mean(), 1.0, 254.0))
    gamma = float(np.clip(np.log(MEAN_GREY / 255.0) / np.log(mean / 255.0), MIN_GAMMA, 1.0))
    lut = np.round(255.0 * (np.arange(256) / 255.0) ** gamma).astype(np.uint8)
    return np.asarray(cv2.LUT(image, lut), np.uint8)


def _project(stereo: Any, points: npt.NDArray[np.float64], shape: tuple[int, ...]) -> Any:
    """Pixels (n, 2) of base-frame ``points`` in C1's left eye; NaN where a point is
    behind the eye or far outside the image."""
    T = invert(stereo.T_base_left)
    cam_pts = points @ T[:3, :3].T + T[:3, 3]
    px = np.full((len(points), 2), np.nan)
    front = cam_pts[:, 2] > 0.01
    if front.any():
        px[front] = stereo.left.project(cam_pts[front])
    height, width = shape[:2]
    off = (np.abs(px[:, 0] - width / 2) > width) | (np.abs(px[:, 1] - height / 2) > height)
    px[off] = np.nan
    return px


def _draw_truth(image: Image, bush: Any, stereo: Any) -> None:
    """The true canes (thin white) and berries (crosses) on ``image``, in place."""
    for branch in bush.branches:
        px = _project(stereo, np.asarray(branch.points(80)), image.shape)
        for a, b in itertools.pairwise(px):
            if np.isfinite(a).all() and np.isfinite(b).all():
                cv2.line(image, _pt(a), _pt(b), TRUE, 1, cv2.LINE_AA)
    positions = np.array([b.position for b in bush.berries]).reshape(-1, 3)
    for berry, p in zip(bush.berries, _project(stereo, positions, image.shape), strict=True):
        if np.isfinite(p).all():
            colour = TRUE_UNRIPE if berry.ripeness < 0.5 else TRUE
            cv2.drawMarker(image, _pt(p), colour, cv2.MARKER_CROSS, 12, 1, cv2.LINE_AA)


def _pt(p: npt.NDArray[np.float64]) -> tuple[int, int]:
    return round(float(p[0])), round(float(p[1]))


def _framed(image: Image, title: str) -> Image:
    """``image`` with a title band above and the legend band below (white on black)."""
    width = image.shape[1]
    top = np.zeros((34, width, 3), np.uint8)
    cv2.putText(top, title, (10, 23), cv2.FONT_HERSHEY_SIMPLEX, 0.55, TRUE, 1, cv2.LINE_AA)
    per_row = 3
    rows = -(-len(LEGEND) // per_row)
    bottom = np.zeros((12 + 24 * rows, width, 3), np.uint8)
    for k, (kind, colour, text) in enumerate(LEGEND):
        x, y = 14 + (k % per_row) * (width // per_row), 22 + 24 * (k // per_row)
        if kind == "circle":
            cv2.circle(bottom, (x, y - 4), 7, colour, 2, cv2.LINE_AA)
        elif kind == "cross":
            cv2.drawMarker(bottom, (x, y - 4), colour, cv2.MARKER_CROSS, 12, 1, cv2.LINE_AA)
        else:
            cv2.line(bottom, (x - 8, y - 4), (x + 8, y - 4), colour, 2 if kind == "line" else 1)
        cv2.putText(bottom, text, (x + 16, y), cv2.FONT_HERSHEY_SIMPLEX, 0.45, TRUE, 1,
                    cv2.LINE_AA)  # fmt: skip
    return np.vstack([top, image, bottom])
