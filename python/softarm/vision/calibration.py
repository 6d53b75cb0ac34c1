"""Intrinsic calibration from chessboard or ChArUco images (``cv2.calibrateCamera``)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import InputError, VisionError
from softarm.vision._checks import as_gray, positive
from softarm.vision._opencv import opencv_errors
from softarm.vision.camera_model import CameraModel
from softarm.vision.dictionaries import get_dictionary

_SUBPIX = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 50, 1e-4)
_MIN_VIEWS = 3
# k3 fixed at 0: with views that do not reach the image corners, a free k3 fits the
# covered area and extrapolates wildly outside it (the usual advice for mild lenses).
DEFAULT_FLAGS = cv2.CALIB_FIX_K3


def calibrate_chessboard(
    images: Sequence[npt.NDArray[Any]],
    pattern: tuple[int, int],
    square: float,
    flags: int = DEFAULT_FLAGS,
) -> tuple[CameraModel, float]:
    """Calibrate from views of a chessboard with ``pattern`` = (columns, rows) inner
    corners and ``square`` side (m). Returns the model and the RMS reprojection error (px).
    Views where the board is not found are skipped; at least 3 must remain. ``flags`` are
    ``cv2.calibrateCamera`` flags (default: k3 fixed at 0, see :data:`DEFAULT_FLAGS`)."""
    size = positive(square, "square")
    # findChessboardCorners needs more than 2 inner corners each way.
    cols, rows = grid_size(pattern, "pattern", least=3)
    grid = np.zeros((cols * rows, 3), np.float32)
    grid[:, :2] = np.mgrid[0:cols, 0:rows].T.reshape(-1, 2) * size
    obj, img, shape = [], [], None
    for k, image in enumerate(images):
        gray = as_gray(image, f"images[{k}]")
        shape = _same_shape(shape, gray, k)
        with opencv_errors(f"chessboard in images[{k}]"):
            found, corners = cv2.findChessboardCorners(gray, (cols, rows))
            if not found:
                continue
            corners = cv2.cornerSubPix(gray, corners, (5, 5), (-1, -1), _SUBPIX)
        obj.append(grid)
        img.append(corners)
    return _calibrate(obj, img, shape, flags)


def calibrate_charuco(
    images: Sequence[npt.NDArray[Any]],
    squares: tuple[int, int],
    square_length: float,
    marker_length: float,
    dictionary: str = "DICT_4X4_50",
    flags: int = DEFAULT_FLAGS,
) -> tuple[CameraModel, float]:
    """Calibrate from views of a ChArUco board of ``squares`` = (columns, rows) squares.
    Views with fewer than 6 ChArUco corners are skipped; at least 3 must remain."""
    with opencv_errors("ChArUco board"):
        board = cv2.aruco.CharucoBoard(
            grid_size(squares, "squares", least=2),
            positive(square_length, "square_length"),
            positive(marker_length, "marker_length"),
            get_dictionary(dictionary),
        )
    detector = cv2.aruco.CharucoDetector(board)
    obj, img, shape = [], [], None
    for k, image in enumerate(images):
        gray = as_gray(image, f"images[{k}]")
        shape = _same_shape(shape, gray, k)
        ch_corners, ch_ids, _, _ = detector.detectBoard(gray)
        if ch_ids is None or len(ch_ids) < 6:
            continue
        # ChArUco corners are one (N, 1, 2) array; the stubs only know the marker form.
        o, i = board.matchImagePoints(ch_corners, ch_ids)  # type: ignore[call-overload]
        obj.append(np.asarray(o, dtype=np.float32))
        img.append(np.asarray(i, dtype=np.float32))
    return _calibrate(obj, img, shape, flags)


#: The largest board side (corners or squares) accepted: far beyond any printed board,
#: small enough that the object grid stays a few MB.
MAX_GRID = 200


def grid_size(value: Any, name: str, least: int) -> tuple[int, int]:
    """``value`` as (columns, rows): two integers in [``least``, :data:`MAX_GRID`]."""
    ok = (
        isinstance(value, tuple | list)
        and len(value) == 2
        and all(isinstance(v, int | np.integer) and not isinstance(v, bool) for v in value)
        and all(least <= v <= MAX_GRID for v in value)
    )
    if not ok:
        raise InputError(
            f"{name} must be two integers (columns, rows) in [{least}, {MAX_GRID}], got {value!r}"[
                :200
            ]
        )
    return int(value[0]), int(value[1])


def _same_shape(shape: tuple[int, int] | None, gray: npt.NDArray[Any], k: int) -> tuple[int, int]:
    if shape is not None and gray.shape != shape:
        raise VisionError(f"images[{k}] has shape {gray.shape}, the first image {shape}")
    return (int(gray.shape[0]), int(gray.shape[1]))


def _calibrate(
    obj: list[npt.NDArray[Any]],
    img: list[npt.NDArray[Any]],
    shape: tuple[int, int] | None,
    flags: int,
) -> tuple[CameraModel, float]:
    if shape is None or len(obj) < _MIN_VIEWS:
        raise VisionError(f"calibration needs >= {_MIN_VIEWS} usable views, got {len(obj)}")
    h, w = shape
    with opencv_errors("calibrateCamera: views or flags"):
        rms, mat, dist, _, _ = cv2.calibrateCamera(obj, img, (w, h), None, None, flags=flags)
    return CameraModel(np.asarray(mat, dtype=np.float64), np.ravel(dist), (w, h)), float(rms)
