"""COCO encoding of instance masks: boxes, polygons and the categories of the labelled
images (:mod:`softarm.sim.render.dataset`).

Boxes are ``[x, y, width, height]`` in pixels, a pixel ``(u, v)`` covering
``[u, u + 1) x [v, v + 1)``, so a box always lies inside the image. Polygons trace the
outer boundary of each connected part of a mask through its pixel centres
(``cv2.findContours``); a part of one or two pixels (a thin cane seen edge on) becomes
the rectangle of its pixels. The exact masks are in the per-image instance PNGs.
"""

from __future__ import annotations

from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

__all__ = ["CATEGORIES", "ROW_CATEGORIES", "category_id", "mask_bbox", "mask_polygons"]

#: The categories of the labelled images, COCO style (ids from 1).
CATEGORIES: list[dict[str, Any]] = [
    {"id": 1, "name": "berry_ripe", "supercategory": "berry"},
    {"id": 2, "name": "berry_unripe", "supercategory": "berry"},
    {"id": 3, "name": "cane", "supercategory": "plant"},
]
#: The row's (``--world row``): its turning fruit (part red, part black; not ripe) too.
ROW_CATEGORIES: list[dict[str, Any]] = [
    *CATEGORIES,
    {"id": 4, "name": "berry_turning", "supercategory": "berry"},
]


def category_id(name: str) -> int:
    """The id of the category called ``name``."""
    result: int = next(c["id"] for c in ROW_CATEGORIES if c["name"] == name)
    return result


def mask_bbox(mask: npt.NDArray[np.bool_]) -> list[int]:
    """``[x, y, width, height]`` of the pixels of a non-empty ``mask``."""
    rows = np.flatnonzero(mask.any(axis=1))
    cols = np.flatnonzero(mask.any(axis=0))
    x, y = int(cols[0]), int(rows[0])
    return [x, y, int(cols[-1]) + 1 - x, int(rows[-1]) + 1 - y]


def mask_polygons(mask: npt.NDArray[np.bool_]) -> list[list[float]]:
    """One flat ``[x0, y0, x1, y1, ...]`` polygon (at least three points) for each
    connected part of ``mask``."""
    contours, _ = cv2.findContours(
        mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE
    )
    return [_polygon(c.reshape(-1, 2)) for c in contours]


def _polygon(points: npt.NDArray[Any]) -> list[float]:
    if len(points) >= 3:
        return [float(v) for v in points.ravel()]
    (x0, y0), (x1, y1) = points.min(axis=0) - 0.5, points.max(axis=0) + 0.5
    return [float(v) for v in (x0, y0, x1, y0, x1, y1, x0, y1)]
