"""Annotated pictures of berry detections: each detection's outline in its stage's colour
with its stage and score; with labels, a detection that matches no fruit boxed in red and
a counted fruit no detection found ringed in yellow; the labelled outlines thin and white."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import OutputError
from softarm.perception.berries import BerryDetection
from softarm.perception.detector.labels import LabelledObject
from softarm.perception.detector.scoring import MIN_VISIBLE, stage_of_detection

__all__ = ["STAGE_COLOURS", "draw_detections", "write_image"]

#: BGR colour of each stage's outlines.
STAGE_COLOURS = {"ripe": (255, 0, 255), "turning": (0, 165, 255), "unripe": (0, 220, 0)}
_U8 = npt.NDArray[np.uint8]


def _outline(
    image: _U8, mask: npt.NDArray[np.bool_], colour: tuple[int, int, int], width: int
) -> None:
    contours, _ = cv2.findContours(
        mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE
    )
    cv2.drawContours(image, contours, -1, colour, width, cv2.LINE_AA)


def draw_detections(
    image: _U8,
    dets: list[BerryDetection],
    fruit: list[LabelledObject] | None = None,
    matches: dict[int, int] | None = None,
) -> _U8:
    """A copy of the BGR ``image`` with ``dets`` drawn, and the labelled ``fruit`` with
    the ``matches`` (detection index -> fruit index) when given."""
    out = image.copy()
    width = max(1, round(max(image.shape[:2]) / 640))
    font = 0.35 * width
    for f in fruit or []:
        _outline(out, f.mask, (255, 255, 255), 1)
    for i, d in enumerate(dets):
        stage = stage_of_detection(d)
        colour = STAGE_COLOURS.get(stage, (255, 255, 255))
        _outline(out, d.full_mask(image.shape), colour, width)
        x, y, w, h = d.box
        if matches is not None and i not in matches:
            cv2.rectangle(out, (x - 2, y - 2), (x + w + 1, y + h + 1), (0, 0, 255), width)
        label = f"{stage} {d.score:.2f}"
        cv2.putText(
            out, label, (x, max(8, y - 3)), cv2.FONT_HERSHEY_SIMPLEX, font, colour, 1, cv2.LINE_AA
        )
    found = set((matches or {}).values())
    for j, f in enumerate(fruit or []):
        if j in found or (f.visible is not None and f.visible < MIN_VISIBLE):
            continue
        rows, cols = np.nonzero(f.mask)
        centre = (int(cols.mean()), int(rows.mean()))
        radius = int(max(np.ptp(rows), np.ptp(cols)) / 2 + 3 * width)
        cv2.circle(out, centre, radius, (0, 255, 255), width, cv2.LINE_AA)
    return out


def write_image(path: Path, image: _U8) -> None:
    """Write ``image`` atomically in the format of ``path``'s suffix (PNG, JPEG...).

    Raises:
        OutputError: OpenCV cannot encode that format, or the file cannot be written.
    """
    from softarm.files import atomic_path

    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        ok, buf = cv2.imencode(path.suffix or ".png", image)
    except cv2.error:
        ok = False
    if not ok:
        raise OutputError(f"{path}: OpenCV cannot write a {path.suffix or 'suffix-less'} image")
    with atomic_path(path, "annotated picture") as tmp:
        Path(tmp).write_bytes(buf.tobytes())
