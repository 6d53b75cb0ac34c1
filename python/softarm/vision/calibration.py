"""Intrinsic calibration from chessboard or ChArUco images (``cv2.calibrateCamera``).

The views are judged before and after the fit (:mod:`softarm.vision.calibration_checks`):
repeated views are dropped and at least 3 distinct ones must remain (else a
:class:`VisionError`); a fit whose views are not tilted enough, whose intrinsics are
uncertain or whose RMS is too large raises :class:`CalibrationNotConverged`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import InputError, ParameterError, VisionError
from softarm.vision._checks import as_gray, positive
from softarm.vision._opencv import opencv_errors
from softarm.vision.calibration_checks import (
    CalibrationNotConverged,
    Corners,
    distinct_views,
    intrinsics_problems,
    rms_problem,
)
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
    views: list[Corners] = []
    shape = None
    ids = np.arange(cols * rows, dtype=np.int32)
    for k, image in enumerate(images):
        gray = as_gray(image, f"images[{k}]")
        shape = _same_shape(shape, gray, k)
        with opencv_errors(f"chessboard in images[{k}]"):
            found, corners = cv2.findChessboardCorners(gray, (cols, rows))
            if not found:
                continue
            corners = cv2.cornerSubPix(gray, corners, (5, 5), (-1, -1), _SUBPIX)
        views.append((ids, np.asarray(corners, np.float32).reshape(-1, 2)))
    return _calibrate(grid, views, shape, flags)


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
    board = charuco_board(squares, square_length, marker_length, dictionary)
    detector = cv2.aruco.CharucoDetector(board)
    views: list[Corners] = []
    shape = None
    for k, image in enumerate(images):
        gray = as_gray(image, f"images[{k}]")
        shape = _same_shape(shape, gray, k)
        ch_corners, ch_ids, _, _ = detector.detectBoard(gray)
        if ch_ids is None or len(ch_ids) < 6:
            continue
        views.append(
            (
                np.asarray(ch_ids, np.int32).ravel(),
                np.asarray(ch_corners, np.float32).reshape(-1, 2),
            )
        )
    return _calibrate(board.getChessboardCorners(), views, shape, flags)


def charuco_board(squares: Any, square_length: float, marker_length: float, dictionary: str) -> Any:
    """The ``cv2.aruco.CharucoBoard``, its arguments checked: ``squares`` (columns, rows)
    in [2, :data:`MAX_GRID`], both lengths positive, the marker smaller than the square.

    Raises:
        InputError: an argument is invalid (``ParameterError`` for the two lengths).
    """
    square = positive(square_length, "square_length")
    marker = positive(marker_length, "marker_length")
    if marker >= square:
        raise ParameterError(
            f"marker_length = {marker!r} must be smaller than square_length = {square!r}"
        )
    grid = grid_size(squares, "squares", least=2)
    # OpenCV reports some impossible boards as SystemError, not cv2.error.
    try:
        with opencv_errors("ChArUco board"):
            return cv2.aruco.CharucoBoard(grid, square, marker, get_dictionary(dictionary))
    except SystemError as exc:
        raise VisionError(f"ChArUco board: OpenCV could not build it ({exc})") from None


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
    points: npt.NDArray[Any],
    views: list[Corners],
    shape: tuple[int, int] | None,
    flags: int,
) -> tuple[CameraModel, float]:
    """Fit the distinct ``views`` (corner ids index the board's ``points``) and judge it."""
    if shape is None:
        raise VisionError(f"calibration needs >= {_MIN_VIEWS} usable views, got 0")
    h, w = shape
    model, rms, _ = fit_views(points, views, (w, h), flags, "images")
    return model, rms


def fit_views(
    points: npt.NDArray[Any],
    views: list[Corners],
    size: tuple[int, int],
    flags: int,
    name: str,
) -> tuple[CameraModel, float, list[int]]:
    """The camera of the distinct ``views`` of an image ``size`` = (w, h), its RMS (px)
    and which views it used; ``name`` names the images in errors.

    Raises:
        VisionError: fewer than 3 usable views, or fewer than 3 distinct ones.
        CalibrationNotConverged: the fit is not to be trusted (the problems named).
    """
    kept = distinct_views(views, size)
    if len(views) < _MIN_VIEWS or len(kept) < _MIN_VIEWS:
        repeats = (
            f" ({len(views) - len(kept)} repeat an earlier view)" if len(kept) < len(views) else ""
        )
        raise VisionError(
            f"{name}: calibration needs >= {_MIN_VIEWS} usable views, got {len(kept)}{repeats}"
        )
    obj = [np.asarray(points, np.float32)[views[k][0]].reshape(-1, 1, 3) for k in kept]
    img = [views[k][1].reshape(-1, 1, 2) for k in kept]
    with opencv_errors(f"calibrateCamera ({name}): views or flags"):
        # The stubs want initial matrices; None lets OpenCV start from its own.
        rms, mat, dist, rvecs, _, std, _, _ = cv2.calibrateCameraExtended(  # type: ignore[call-overload]
            obj, img, size, None, None, flags=flags
        )
    model = CameraModel(np.asarray(mat, dtype=np.float64), np.ravel(dist), size)
    problems = rms_problem(name, float(rms))
    problems += intrinsics_problems(name, model.matrix, std, rvecs, size)
    if problems:
        raise CalibrationNotConverged(model, float(rms), problems)
    return model, float(rms), kept
