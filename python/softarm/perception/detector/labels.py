"""Labelled images in COCO, as ``softarm dataset`` writes them and as CVAT and Label Studio
export them: each image's fruit and canes as masks with a stage, for training and for
evaluating the detector.

A mask comes from the image's instance PNG where the record names one (``softarm
dataset``: ``instance_file`` and each annotation's ``instance``), else from the
annotation's ``segmentation`` (polygons, or RLE: CVAT writes uncompressed counts for
``iscrowd`` masks, pycocotools' compressed strings are read too), else from its ``bbox``
(the ellipse inscribed in the box, for box-only labels). A category's stage is read from
its name (see :func:`stage_of`) or from an annotation's ``stage`` attribute (CVAT's
attributes); fruit of no known stage counts as fruit but for no stage.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import InputError
from softarm.files.images import read_image
from softarm.perception._inputs import MAX_FRAME_PIXELS

__all__ = ["FRUIT_STAGES", "LabelledImage", "LabelledObject", "read_coco", "stage_of"]

#: The fruit stages, ripest first; "turning" (part red, part black) is not ripe.
FRUIT_STAGES = ("ripe", "turning", "unripe")
_WORDS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("cane", ("cane", "stem", "branch", "stalk")),
    ("turning", ("turning", "semi", "half", "partial", "colouring", "coloring")),
    ("unripe", ("unripe", "green", "red", "immature", "raw")),
    ("ripe", ("ripe", "black", "mature")),
    ("fruit", ("berry", "berries", "fruit", "blackberry")),
)


def stage_of(name: str) -> str | None:
    """What a category or stage name labels: "ripe", "turning", "unripe", "cane", "fruit"
    (a fruit of no stage) or None (anything else: leaves, the arm). The name's words
    (split at anything not a letter) are checked in that order, so "berry_unripe" is
    unripe, "Ripe blackberry" ripe and "blackberry" a fruit of no stage."""
    tokens = set(re.split(r"[^a-z]+", name.lower()))
    for stage, words in _WORDS:
        if tokens.intersection(words):
            return stage
    return None


@dataclass(frozen=True)
class LabelledObject:
    """One labelled fruit or cane: ``stage`` (see :func:`stage_of`; "fruit" for no stage),
    its (H, W) ``mask``, its ``visible`` share when the labels give it, and its
    ``position`` (3,) in the camera frame (m) when they give that."""

    stage: str
    mask: npt.NDArray[np.bool_]
    visible: float | None = None
    position: npt.NDArray[np.float64] | None = None

    @property
    def is_fruit(self) -> bool:
        return self.stage != "cane"


@dataclass(frozen=True)
class LabelledImage:
    """An image file of a COCO document, its size and its labelled objects (masks are
    built on first use of :meth:`objects`)."""

    path: Path
    width: int
    height: int
    record: dict[str, Any]
    annotations: tuple[dict[str, Any], ...]
    stages: dict[int, str | None]
    #: The COCO file's folder, which instance PNGs are named relative to.
    folder: Path

    def objects(self) -> list[LabelledObject]:
        """The fruit and canes of this image."""
        instances = self._instances()
        out = []
        for a in self.annotations:
            stage = _annotation_stage(a, self.stages)
            if stage is None:
                continue
            mask = _mask(a, instances, self.height, self.width)
            if not mask.any():
                continue
            attrs: dict[str, Any] = a["attributes"] if isinstance(a.get("attributes"), dict) else {}
            visible = attrs.get("visible_fraction")
            position = attrs.get("position_camera_m")
            out.append(
                LabelledObject(
                    stage, mask,
                    float(visible) if isinstance(visible, int | float) else None,
                    np.asarray(position, float) if _is_vector(position) else None,
                )
            )  # fmt: skip
        return out

    def _instances(self) -> npt.NDArray[np.uint16] | None:
        name = self.record.get("instance_file")
        if not isinstance(name, str):
            return None
        try:  # bytes to OpenCV, never the path; the header's size checked first
            image = read_image(self.folder / name, "instance file", cv2.IMREAD_UNCHANGED)
        except InputError:
            return None
        if image.shape[:2] != (self.height, self.width):
            return None
        return np.asarray(image, np.uint16)


def _is_vector(value: object) -> bool:
    return (
        isinstance(value, list)
        and len(value) == 3
        and all(isinstance(v, int | float) for v in value)
    )


def _annotation_stage(a: dict[str, Any], stages: dict[int, str | None]) -> str | None:
    stage = stages.get(int(a.get("category_id", -1)))
    attrs = a.get("attributes")
    if stage in ("fruit", None) and isinstance(attrs, dict):
        own = attrs.get("stage") or attrs.get("ripeness")
        if isinstance(own, str) and stage_of(own) in ("ripe", "turning", "unripe"):
            return stage_of(own)
    return stage


def _mask(
    a: dict[str, Any], instances: npt.NDArray[np.uint16] | None, h: int, w: int
) -> npt.NDArray[np.bool_]:
    if instances is not None and isinstance(a.get("instance"), int):
        return np.asarray(instances == a["instance"])
    seg = a.get("segmentation")
    if isinstance(seg, list) and seg:
        return _polygons(seg, h, w)
    if isinstance(seg, dict) and "counts" in seg:
        return _rle(seg, h, w)
    return _box_ellipse(a.get("bbox"), h, w)


def _polygons(seg: list[Any], h: int, w: int) -> npt.NDArray[np.bool_]:
    mask = np.zeros((h, w), np.uint8)
    for poly in seg:
        if isinstance(poly, list) and len(poly) >= 6:
            pts = np.round(np.asarray(poly, float).reshape(-1, 2)).astype(np.int32)
            cv2.fillPoly(mask, [pts], 1)
    return mask > 0


def _rle(seg: dict[str, Any], h: int, w: int) -> npt.NDArray[np.bool_]:
    counts = seg["counts"]
    if isinstance(counts, str):
        counts = _decode_counts(counts)
    size = seg.get("size", [h, w])
    flat = np.zeros(int(size[0]) * int(size[1]), bool)
    pos, value = 0, False
    for c in counts:
        flat[pos : pos + int(c)] = value
        pos, value = pos + int(c), not value
    mask = flat.reshape(int(size[1]), int(size[0])).T  # COCO RLE runs down the columns
    return mask if mask.shape == (h, w) else np.zeros((h, w), bool)


def _decode_counts(s: str) -> list[int]:
    """pycocotools' compressed RLE: 5 bits per character, continued by bit 0x20,
    each count after the second a difference from the one two before."""
    counts: list[int] = []
    p = 0
    while p < len(s):
        x, k, more = 0, 0, True
        while more:
            c = ord(s[p]) - 48
            x |= (c & 0x1F) << (5 * k)
            more = bool(c & 0x20)
            p, k = p + 1, k + 1
            if not more and c & 0x10:
                x |= -1 << (5 * k)
        if len(counts) > 2:
            x += counts[-2]
        counts.append(x)
    return counts


def _box_ellipse(box: object, h: int, w: int) -> npt.NDArray[np.bool_]:
    mask = np.zeros((h, w), np.uint8)
    if isinstance(box, list) and len(box) == 4:
        x, y, bw, bh = (float(v) for v in box)
        centre = (round(x + bw / 2), round(y + bh / 2))
        axes = (max(1, round(bw / 2)), max(1, round(bh / 2)))
        cv2.ellipse(mask, centre, axes, 0, 0, 360, 1, thickness=-1)
    return mask > 0


#: Label Studio stores uploads as "<8 hex digits>-<the file's own name>".
_UPLOAD = re.compile(r"^[0-9a-f]{8}-(.+)$")


def _find(folder: Path, name: str) -> Path | None:
    """The image ``name`` of a COCO record: relative to ``folder``, else by its base
    name, else by its base name less Label Studio's upload prefix."""
    base = Path(name).name
    stripped = _UPLOAD.match(base)
    for candidate in (name, base, stripped.group(1) if stripped else None):
        if candidate is not None and (folder / candidate).is_file():
            return folder / candidate
    return None


def read_coco(labels: str | Path, images: str | Path | None = None) -> list[LabelledImage]:
    """The images of a COCO file whose image files exist; ``images`` is the folder their
    ``file_name`` is relative to (default: the COCO file's folder); a name not found
    there is looked up by its base name, with or without Label Studio's upload prefix
    (``/data/upload/1/3f2a9c1b-IMG_0042.jpg`` is ``IMG_0042.jpg``).

    Raises:
        InputError: ``labels`` is missing, not JSON, or not COCO (named in the message).
    """
    path = Path(labels)
    try:
        doc = json.loads(path.read_text())
    except FileNotFoundError:
        raise InputError(f"labels {path}: no such file") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"labels {path}: not a readable JSON file ({exc})") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("images"), list):
        raise InputError(f"labels {path}: not COCO (no 'images' list)")
    folder = Path(images) if images is not None else path.parent
    try:
        stages = {int(c["id"]): stage_of(str(c["name"])) for c in doc.get("categories", [])}
        by_image: dict[int, list[dict[str, Any]]] = {}
        for a in doc.get("annotations", []):
            by_image.setdefault(int(a["image_id"]), []).append(a)
        return list(_images(doc["images"], by_image, stages, folder, path.parent))
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError(f"labels {path}: not COCO ({type(exc).__name__}: {exc})") from None


def _images(
    records: list[dict[str, Any]],
    by_image: dict[int, list[dict[str, Any]]],
    stages: dict[int, str | None],
    folder: Path,
    label_folder: Path,
) -> Iterator[LabelledImage]:
    for r in records:
        name = str(r["file_name"])
        path = _find(folder, name)
        if path is None:
            continue
        width, height = int(r["width"]), int(r["height"])
        if width <= 0 or height <= 0 or width * height > MAX_FRAME_PIXELS:
            # Its masks are drawn at this size: a made-up size must not allocate them.
            raise ValueError(
                f"image {name!r} is {width} x {height} pixels; an image has 1 to "
                f"{MAX_FRAME_PIXELS} pixels"
            )
        yield LabelledImage(
            path, width, height, r,
            tuple(by_image.get(int(r["id"]), [])), stages, label_folder,
        )  # fmt: skip
