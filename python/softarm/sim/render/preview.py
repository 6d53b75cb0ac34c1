"""8-bit previews of a dataset's 16-bit PNGs, for an image viewer: millimetres of depth and
instance numbers up to a few dozen are all near black in 16 bits, so ``depth/`` and
``instances/`` look empty. ``preview/depth/NNNNNN.png`` colours the depth from near
(yellow) to far (dark blue) with the turbo map, black where nothing was drawn;
``preview/instances/NNNNNN.png`` gives each instance a colour of its own, black for 0.
The training data stays the 16-bit files; the previews are for eyes only."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import numpy.typing as npt

from softarm.errors import InputError
from softarm.files.write import atomic_path

__all__ = ["depth_preview", "instance_preview", "write_previews"]

#: The folders previewed, under the dataset's folder.
FOLDERS = ("depth", "instances")


def depth_preview(depth_mm: npt.NDArray[np.uint16]) -> npt.NDArray[np.uint8]:
    """(H, W, 3) BGR: the turbo colour map over this image's range of depth, near
    bright and far dark; black where the depth is 0 (nothing drawn)."""
    import cv2

    drawn = depth_mm > 0
    out = np.zeros((*depth_mm.shape, 3), np.uint8)
    if not drawn.any():
        return out
    near, far = float(depth_mm[drawn].min()), float(depth_mm[drawn].max())
    scale = 255.0 / max(far - near, 1.0)
    level = np.clip(255.0 - (depth_mm.astype(np.float64) - near) * scale, 0, 255)
    coloured = cv2.applyColorMap(level.astype(np.uint8), cv2.COLORMAP_TURBO)
    out[drawn] = coloured[drawn]
    return out


def instance_preview(instances: npt.NDArray[np.uint16]) -> npt.NDArray[np.uint8]:
    """(H, W, 3) BGR: each instance value its own bright colour (the same colour for a
    value in every image), black for 0."""
    import cv2

    ids = instances.astype(np.uint64)
    # A multiplicative hash spreads neighbouring ids over the hues; 0 stays black.
    hue = ((ids * np.uint64(2654435761)) % np.uint64(180)).astype(np.uint8)
    hsv = np.stack([hue, np.full_like(hue, 200), np.full_like(hue, 255)], axis=-1)
    out = np.asarray(cv2.cvtColor(hsv, cv2.COLOR_HSV2BGR), np.uint8)
    out[instances == 0] = 0
    return out


def write_previews(out: str | Path) -> int:
    """Write ``out/preview/depth`` and ``out/preview/instances`` from a dataset's
    ``depth/`` and ``instances/``; the number of previews written."""
    import cv2

    from softarm.files.images import read_image

    root = Path(out)
    written = 0
    for folder, draw in zip(FOLDERS, (depth_preview, instance_preview), strict=True):
        for source in sorted((root / folder).glob("*.png")):
            image = read_image(source, "dataset image")  # bytes to OpenCV, not the path
            if image is None or image.dtype != np.uint16 or image.ndim != 2:
                raise InputError(f"{source}: not a 16-bit single-channel PNG")
            ok, png = cv2.imencode(".png", draw(np.asarray(image, np.uint16)))
            if not ok:
                raise InputError(f"{source}: OpenCV could not encode its preview")
            with atomic_path(root / "preview" / folder / source.name, "preview") as tmp:
                tmp.write_bytes(png.tobytes())
            written += 1
    return written
