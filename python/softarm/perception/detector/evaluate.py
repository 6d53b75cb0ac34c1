"""``softarm detector evaluate``'s work: a detector run over labelled images (COCO from
``softarm dataset``, CVAT or Label Studio), scored (:mod:`.scoring`) and drawn
(:mod:`.draw`), with depth where the user gives it.

Depth: a folder with, for each image, a file of the same stem: a 16-bit PNG in
millimetres (as ``softarm dataset`` and RealSense tools write it) or a ``.npy`` in metres,
aligned with the colour image. The camera: a file (``CameraModel.load``'s formats), else
each image record's ``camera`` (``softarm dataset``), else an ideal camera whose focal
length is the image's longer side (only the depth check and positions use it)."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any, cast

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import InputError
from softarm.files.images import read_image
from softarm.perception._inputs import MAX_FRAME_PIXELS
from softarm.perception.berries import DetectorSettings, _position
from softarm.perception.detector.choice import BerryDetector
from softarm.perception.detector.draw import draw_detections, write_image
from softarm.perception.detector.labels import LabelledImage, LabelledObject, read_coco
from softarm.perception.detector.scoring import Tally
from softarm.vision.camera_model import CameraModel

__all__ = ["evaluate", "read_depth"]


def read_depth(folder: Path, image: Path, shape: tuple[int, int]) -> npt.NDArray[np.float32] | None:
    """The depth (m, NaN unknown) of ``image`` in ``folder``, None when there is none of
    its size (or none that reads as a depth image)."""
    for suffix, reader, per_metre in ((".png", _depth_png, 1000.0), (".npy", _depth_npy, 1.0)):
        path = folder / (image.stem + suffix)
        if not path.is_file():
            continue
        raw = reader(path)
        if raw is None:
            continue
        if raw.shape != shape:
            return None
        depth = np.array(raw, np.float32) / np.float32(per_metre)
        depth[~np.isfinite(depth) | (depth <= 0)] = np.nan
        return cast(npt.NDArray[np.float32], depth)
    return None


def _depth_png(path: Path) -> npt.NDArray[Any] | None:
    """A 16-bit PNG's millimetres, read as every image is (:mod:`softarm.files.images`:
    bytes to OpenCV, the header's size checked first); None when it is no such image."""
    try:
        raw = read_image(path, "depth", cv2.IMREAD_UNCHANGED, max_pixels=MAX_FRAME_PIXELS)
    except InputError:
        return None
    return raw if raw.dtype == np.uint16 and raw.ndim == 2 else None


def _depth_npy(path: Path) -> npt.NDArray[Any] | None:
    """A ``.npy`` of metres, mapped before it is read (its shape is checked before its
    bytes are): a 2-D array of numbers, else None (no pickles, no broken files)."""
    try:
        raw = np.load(path, mmap_mode="r", allow_pickle=False)
    except (OSError, ValueError, EOFError):
        return None
    if not isinstance(raw, np.ndarray) or raw.ndim != 2 or raw.dtype.kind not in "fiu":
        return None
    return raw


def _camera(item: LabelledImage, camera: CameraModel | None) -> CameraModel:
    if camera is not None:
        return camera
    record = item.record.get("camera")
    if isinstance(record, dict) and "matrix" in record:
        try:
            distortion = np.asarray(record.get("distortion") or np.zeros(5), float)
            return CameraModel(np.asarray(record["matrix"], float), distortion)
        except (ValueError, TypeError):
            pass
    return CameraModel.ideal(float(max(item.width, item.height)), item.width, item.height)


def _truth(
    fruit: list[LabelledObject], camera: CameraModel, depth: npt.NDArray[np.float32] | None
) -> list[np.ndarray[Any, Any] | None] | None:
    """Each fruit's true position: the labels' where they give it, else its mask and the
    depth placed as the detector places a berry."""
    if depth is None:
        return None
    out: list[np.ndarray[Any, Any] | None] = []
    for f in fruit:
        if f.position is not None:
            out.append(f.position)
            continue
        rows, cols = np.nonzero(f.mask)
        radius = float(np.sqrt(rows.size / np.pi))
        out.append(_position(f.mask, (cols.mean(), rows.mean()), radius, camera, depth))
    return out


def evaluate(
    detector: BerryDetector,
    labels: str | Path,
    images: str | Path,
    depth: str | Path | None = None,
    camera: CameraModel | None = None,
    out: str | Path | None = None,
    on_image: Callable[[], None] = lambda: None,
    settings: DetectorSettings | None = None,
) -> dict[str, Any]:
    """The figures of ``detector`` (with ``settings``; None: its own) on the labelled
    images (also written to OUT/metrics.json with one annotated picture per image when
    ``out`` is given).

    Raises:
        InputError: the labels cannot be read, or name no image found in ``images``.
    """
    items = read_coco(labels, images)
    if not items:
        raise InputError(f"labels {labels}: none of its images is in {images}")
    tally, per_image = Tally(), list[dict[str, Any]]()
    for item in items:
        try:  # bytes to OpenCV, never the path; the header's size checked first
            image = cast(
                npt.NDArray[np.uint8],
                read_image(item.path, "image", cv2.IMREAD_COLOR, max_pixels=MAX_FRAME_PIXELS),
            )
        except InputError as exc:
            per_image.append({"image": item.path.name, "error": str(exc)})
            continue
        if image.shape[:2] != (item.height, item.width):  # the labels' masks would not fit
            h, w = image.shape[:2]
            size = f"is {w} x {h} pixels, its labels say {item.width} x {item.height}"
            per_image.append({"image": item.path.name, "error": size})
            continue
        cam = _camera(item, camera)
        d = None if depth is None else read_depth(Path(depth), item.path, image.shape[:2])
        dets = list(detector.detect_berries(image, cam, d, settings))
        fruit = [o for o in item.objects() if o.is_fruit]
        pairs = tally.add(dets, fruit, _truth(fruit, cam, d))
        per_image.append({"image": item.path.name, "detections": len(dets), "matched": len(pairs)})
        if out is not None:
            write_image(
                Path(out) / (item.path.stem + ".png"), draw_detections(image, dets, fruit, pairs)
            )
        on_image()
    figures = tally.figures()
    figures["per_image"] = per_image
    if out is not None:
        from softarm.files import write_text

        write_text(Path(out) / "metrics.json", json.dumps(figures, indent=1) + "\n", "metrics")
    return figures
