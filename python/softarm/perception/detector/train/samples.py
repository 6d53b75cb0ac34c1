"""Training samples: each labelled image (:mod:`..labels`) as the network sees it (shrunk
to MAX_SIDE, or twice it for a network with the stem), its class map (an index into
CLASSES per pixel, IGNORE where a fruit has no known stage) and its centre heatmap (a
Gaussian peak of height 1 at each fruit's centre, its width a third of the fruit's
radius). With the boundary class (``softarm detector train --boundary``), the pixels of a
fruit within BOUNDARY_RADIUS of a different fruit's mask carry BOUNDARY_FLAG in the
class map besides their stage: riding in the class map, the flag is scaled, cropped,
mirrored and cut out with it by every augmentation. With the distance target
(``--distance``), a sample carries each fruit pixel's normalised distance to its own
fruit's edge (:mod:`.distance_target`) as a map of its own, moved as the heatmap is."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import InputError
from softarm.files.images import read_image
from softarm.perception.detector.labels import LabelledImage, read_coco
from softarm.perception.detector.network import CLASSES, MAX_SIDE
from softarm.perception.detector.train.distance_target import distance_target

__all__ = [
    "BOUNDARY_FLAG",
    "BOUNDARY_RADIUS",
    "IGNORE",
    "Sample",
    "boundary_target",
    "find_labels",
    "load_samples",
    "stages",
]

#: Class-map value of pixels the loss leaves out.
IGNORE = 255
#: Bit of the class map marking a boundary pixel (the classes are 0-4, IGNORE has every
#: bit and stays IGNORE).
BOUNDARY_FLAG = 16
#: A fruit pixel within this distance (px at the training images' scale, the network's
#: own) of another fruit's mask is a boundary pixel: a band of two pixels on each side
#: of the contact, so that a fruit of 5 px radius keeps a core of its own.
BOUNDARY_RADIUS = 2
_U8 = npt.NDArray[np.uint8]
_F32 = npt.NDArray[np.float32]


@dataclass(frozen=True)
class Sample:
    """One training image: ``image`` (H, W, 3) BGR uint8, ``classes`` (H, W) uint8 and
    ``centres`` (H, W) float32; ``zoom`` multiplies the augmentation's scale (2 for a
    render drawn at half the camera's size, trained for a network run at full size);
    ``distance`` (H, W) float32 the normalised distance target, where it was asked for."""

    image: _U8
    classes: _U8
    centres: _F32
    zoom: float = 1.0
    distance: _F32 | None = None


def find_labels(data: str | Path) -> Path:
    """The COCO file of a data folder (its ``annotations.json``, else its one ``.json``),
    or ``data`` itself when it is a file.

    Raises:
        InputError: no COCO file there.
    """
    path = Path(data)
    if path.is_file():
        return path
    if not path.is_dir():
        raise InputError(f"--data {path}: no such folder or file")
    if (path / "annotations.json").is_file():
        return path / "annotations.json"
    found = sorted(path.glob("*.json"))
    if len(found) != 1:
        raise InputError(
            f"--data {path}: expected annotations.json or one COCO .json file, found {len(found)}"
        )
    return found[0]


def stages(classes: _U8) -> _U8:
    """``classes`` without BOUNDARY_FLAG: each pixel's class index (or IGNORE)."""
    return cast(_U8, np.where(classes == IGNORE, classes, classes & ~np.uint8(BOUNDARY_FLAG)))


def boundary_target(
    owner: npt.NDArray[np.int32], radius: int = BOUNDARY_RADIUS
) -> npt.NDArray[np.bool_]:
    """The boundary class of an instance map ``owner`` (0 off fruit, k > 0 on fruit k):
    the fruit pixels within ``radius`` px (Euclidean) of a different fruit's pixel. A
    lone fruit has none."""
    out = np.zeros(owner.shape, bool)
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * radius + 1, 2 * radius + 1))
    h, w = owner.shape
    for k in np.unique(owner[owner > 0]).tolist():
        rows, cols = np.nonzero(owner == k)
        y0, y1 = max(0, rows.min() - radius), min(h, rows.max() + radius + 1)
        x0, x1 = max(0, cols.min() - radius), min(w, cols.max() + radius + 1)
        window = owner[y0:y1, x0:x1]
        near = cv2.dilate((window == k).astype(np.uint8), kernel) > 0
        out[y0:y1, x0:x1] |= near & (window > 0) & (window != k)
    return out


def _sample(
    item: LabelledImage, max_side: int, zoom: float, boundary: bool = False, distance: bool = False
) -> Sample | None:
    try:  # bytes to OpenCV, never the path; the header's size checked first
        image = cast(_U8, read_image(item.path, "image", cv2.IMREAD_COLOR))
    except InputError:
        return None
    if image.shape[:2] != (item.height, item.width):
        return None
    h, w = image.shape[:2]
    scale = min(1.0, max_side / max(h, w))
    size = (max(1, round(w * scale)), max(1, round(h * scale)))
    if scale < 1.0:
        image = cast(_U8, cv2.resize(image, size, interpolation=cv2.INTER_AREA))
    classes = np.zeros(image.shape[:2], np.uint8)
    centres = np.zeros(image.shape[:2], np.float32)
    owner = np.zeros(image.shape[:2], np.int32)
    objects = sorted(item.objects(), key=lambda o: o.is_fruit)  # fruit painted over canes
    for k, obj in enumerate(objects, start=1):
        mask = obj.mask
        if scale < 1.0:
            mask = cv2.resize(mask.astype(np.uint8), size, interpolation=cv2.INTER_NEAREST) > 0
        if not mask.any():
            continue
        classes[mask] = CLASSES.index(obj.stage) if obj.stage in CLASSES else IGNORE
        owner[mask] = k if obj.is_fruit else 0
        if obj.is_fruit:
            _add_peak(centres, mask)
    if boundary:
        classes[boundary_target(owner) & (classes != IGNORE)] |= np.uint8(BOUNDARY_FLAG)
    return Sample(image, classes, centres, zoom, distance_target(owner) if distance else None)


def _add_peak(centres: _F32, mask: npt.NDArray[np.bool_]) -> None:
    rows, cols = np.nonzero(mask)
    cy, cx = rows.mean(), cols.mean()
    sigma = max(1.0, np.sqrt(rows.size / np.pi) / 3.0)
    r = int(np.ceil(3 * sigma))
    y0, y1 = max(0, int(cy) - r), min(centres.shape[0], int(cy) + r + 1)
    x0, x1 = max(0, int(cx) - r), min(centres.shape[1], int(cx) + r + 1)
    yy, xx = np.mgrid[y0:y1, x0:x1]
    g = np.exp(-((yy - cy) ** 2 + (xx - cx) ** 2) / (2 * sigma**2)).astype(np.float32)
    np.maximum(centres[y0:y1, x0:x1], g, out=centres[y0:y1, x0:x1])


def load_samples(
    folders: list[str | Path],
    max_side: int = MAX_SIDE,
    zooms: list[float] | None = None,
    boundary: bool = False,
    distance: bool = False,
) -> tuple[list[Sample], list[str]]:
    """The samples of every data folder (or COCO file), shrunk to ``max_side``, each
    folder's with its zoom of ``zooms`` (default 1 each), with the boundary class in
    their class maps when ``boundary`` and the distance target when ``distance``, and a
    line per folder saying what it held.

    Raises:
        InputError: a folder has no COCO file, or none of its images could be read, or
            ``zooms`` is not one positive factor per folder.
    """
    zooms = [1.0] * len(folders) if zooms is None else list(zooms)
    if len(zooms) != len(folders) or not all(np.isfinite(z) and z > 0 for z in zooms):
        raise InputError(
            f"zoom {zooms!r}: one positive factor per --data folder ({len(folders)}) expected"
        )
    out: list[Sample] = []
    notes = []
    for folder, zoom in zip(folders, zooms, strict=True):
        labels = find_labels(folder)
        items = read_coco(labels, labels.parent)
        samples = [
            s
            for s in (_sample(i, max_side, zoom, boundary, distance) for i in items)
            if s is not None
        ]
        if not samples:
            raise InputError(f"--data {folder}: no readable labelled image in {labels}")
        zoomed = "" if zoom == 1 else f", zoom {zoom:g}"
        notes.append(f"{folder}: {len(samples)} images ({labels.name}{zoomed})")
        out += samples
    return out, notes


def describe(samples: list[Sample]) -> str:
    """Pixel counts per class (and of the boundary class where the maps hold it), as one
    JSON line (the training record's)."""
    counts = {name: 0 for name in CLASSES}
    flagged = 0
    for s in samples:
        plain = stages(s.classes)
        for k, name in enumerate(CLASSES):
            counts[name] += int(np.count_nonzero(plain == k))
        flagged += int(np.count_nonzero((s.classes != IGNORE) & ((s.classes & BOUNDARY_FLAG) > 0)))
    if flagged:
        counts["boundary"] = flagged
    return json.dumps(counts)
