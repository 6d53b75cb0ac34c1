"""A 4x4 marker rendered analytically, its corners known to a sixteenth of a pixel, as a
camera delivers it (black level, read noise, clipping): shared by the corner
refinement's tests and its benchmark."""

from __future__ import annotations

import cv2
import numpy as np

from softarm.vision.dictionaries import get_dictionary

SS = 16  # supersampling: the marker's corners sit on this grid of a pixel
CELL_PX = 7  # px per cell (a 6-cell marker, 42 px: the cube's tags near C1)
CELLS = 6
SIZE = 80  # px: the image
ORIGIN = (17 + 5 / SS, 19 + 11 / SS)  # the marker's top-left corner (px, pixel edges)


def render_marker(
    ink: float,
    paper: float,
    black_level: float = 0.0,
    blur_px: float = 0.7,
    noise: float = 0.0,
    seed: int = 0,
) -> np.ndarray:
    """A 4x4 marker (id 3) with its quiet zone, blurred by a Gaussian PSF of ``blur_px``,
    area-sampled, then as a camera delivers it: ``black_level`` DN subtracted, read
    ``noise`` (DN) added, clipped to 0-255 and rounded."""
    bits = cv2.aruco.generateImageMarker(get_dictionary("DICT_4X4_50"), 3, CELLS)
    level = np.where(bits > 0, paper, ink).astype(np.float32)
    big = np.repeat(np.repeat(level, CELL_PX * SS, 0), CELL_PX * SS, 1)
    canvas = np.full((SIZE * SS, SIZE * SS), paper, np.float32)
    x0, y0 = round(ORIGIN[0] * SS), round(ORIGIN[1] * SS)
    canvas[y0 : y0 + big.shape[0], x0 : x0 + big.shape[1]] = big
    blurred = np.asarray(cv2.GaussianBlur(canvas, (0, 0), blur_px * SS), np.float64)
    light = blurred.reshape(SIZE, SS, SIZE, SS).mean(axis=(1, 3))
    rng = np.random.default_rng(seed)
    signal = light - black_level + noise * rng.standard_normal(light.shape)
    image: np.ndarray = np.clip(np.round(signal), 0, 255).astype(np.uint8)
    return image


def marker_truth() -> np.ndarray:
    """The marker's corners in OpenCV's pixel coordinates (a pixel's centre is integer)."""
    side = CELLS * CELL_PX
    x, y = ORIGIN[0] - 0.5, ORIGIN[1] - 0.5
    return np.array([[x, y], [x + side, y], [x + side, y + side], [x, y + side]])
