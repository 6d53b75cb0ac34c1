"""Stereo calibration from ChArUco views (``cv2.stereoCalibrate``): both eyes' intrinsics
and the right eye's pose in the left eye's frame.

Each eye is first calibrated on its own views (as :func:`calibrate_charuco`); the pair is
then refined together on the views where both eyes see at least 6 common corners, each
eye's intrinsics kept as the start. The data is judged as a mono calibration's is
(:mod:`softarm.vision.calibration_checks`), and the pair besides: a pair of images that
show the board at the same place (one image given for both eyes) is refused, and a pair
whose RMS is too large (images that do not pair up), whose baseline is implausible or
whose right eye is not on the left eye's +x raises :class:`CalibrationNotConverged`
with every problem found. ``T_left_right`` follows
:class:`softarm.vision.stereo_camera.StereoCamera`: ``x_left = T_left_right @ x_right``,
metres.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import InputError, VisionError
from softarm.vision._checks import FloatArray, as_gray
from softarm.vision._opencv import opencv_errors
from softarm.vision.calibration import DEFAULT_FLAGS, charuco_board, fit_views
from softarm.vision.calibration_checks import (
    CalibrationNotConverged,
    Corners,
    pair_problems,
    rms_problem,
    same_view,
    tolerance,
)
from softarm.vision.camera_model import CameraModel
from softarm.vision.poses import invert
from softarm.vision.stereo_camera import StereoCamera

__all__ = ["calibrate_stereo_charuco", "split_side_by_side"]

#: Fewest ChArUco corners a view needs (as calibrate_charuco), and fewest usable views.
MIN_CORNERS = 6
MIN_VIEWS = 3
_TERM = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-9)


class UnjudgedFit(NamedTuple):
    """What a stereo fit gave when its data says not to use it (the payload of
    :class:`CalibrationNotConverged`): maybe not a pair a StereoCamera accepts."""

    left: CameraModel
    right: CameraModel
    T_left_right: FloatArray


#: Each view's corners (None: fewer than 6), and the images' common (w, h).
Detected = tuple[list[Corners | None], tuple[int, int]]


def split_side_by_side(frame: npt.NDArray[Any], name: str = "frame") -> tuple[Any, Any]:
    """The (left, right) halves of a side-by-side stereo frame (the ZED2 over USB video:
    one image, the left eye in the left half)."""
    if not isinstance(frame, np.ndarray) or frame.ndim < 2:
        raise VisionError(f"{name} must be an image array, got {type(frame).__name__}")
    width = frame.shape[1]
    if width < 2 or width % 2:
        raise VisionError(f"{name} is {width} px wide: a side-by-side frame has an even width")
    return frame[:, : width // 2], frame[:, width // 2 :]


def calibrate_stereo_charuco(
    left_images: Sequence[npt.NDArray[Any]],
    right_images: Sequence[npt.NDArray[Any]],
    squares: tuple[int, int],
    square_length: float,
    marker_length: float,
    dictionary: str = "DICT_4X4_50",
    flags: int = DEFAULT_FLAGS,
) -> tuple[StereoCamera, float]:
    """Calibrate a stereo pair from simultaneous views of a ChArUco board of ``squares``
    = (columns, rows) squares: ``left_images[k]`` and ``right_images[k]`` were taken at
    the same moment. Returns the model and the RMS reprojection error (px) of the joint
    refinement. ``flags`` are ``cv2.calibrateCamera`` flags (default: k3 fixed at 0).

    Raises:
        InputError: the two lists differ in length, or a board argument is invalid.
        VisionError: an image is unusable, fewer than 3 distinct views show the board to
            both eyes with at least 6 common corners, or a pair shows it at the same
            place to both eyes.
        CalibrationNotConverged: the fit is not to be trusted (every problem named).
    """
    if len(left_images) != len(right_images):
        raise InputError(
            f"left_images and right_images must pair up, got {len(left_images)} and "
            f"{len(right_images)} images"
        )
    board = charuco_board(squares, square_length, marker_length, dictionary)
    left, right = _detect_pairs(board, left_images, right_images)
    problems: list[str] = []
    model_l = _mono(board, left, "left_images", flags, problems)
    model_r = _mono(board, right, "right_images", flags, problems)
    eyes, T_left_right, rms = _stereo(board, left, right, model_l, model_r, flags)
    problems += rms_problem("stereo", rms) + pair_problems(T_left_right)
    if problems:
        raise CalibrationNotConverged(UnjudgedFit(*eyes, T_left_right), rms, problems)
    return StereoCamera.pair(*eyes, T_left_right), rms


def _detect_pairs(
    board: Any, left_images: Sequence[npt.NDArray[Any]], right_images: Sequence[npt.NDArray[Any]]
) -> tuple[Detected, Detected]:
    """Both eyes' ChArUco corners, a pair at a time (so that images read on demand are
    read once and not kept)."""
    detector = cv2.aruco.CharucoDetector(board)
    found: tuple[list[Corners | None], list[Corners | None]] = ([], [])
    shapes: list[tuple[int, ...] | None] = [None, None]
    for k in range(len(left_images)):
        for eye, (images, name) in enumerate(
            ((left_images, "left_images"), (right_images, "right_images"))
        ):
            gray = as_gray(images[k], f"{name}[{k}]")
            if shapes[eye] is not None and gray.shape != shapes[eye]:
                raise VisionError(
                    f"{name}[{k}] has shape {gray.shape}, the first image {shapes[eye]}"
                )
            shapes[eye] = gray.shape
            corners, ids, _, _ = detector.detectBoard(gray)
            ok = ids is not None and len(ids) >= MIN_CORNERS
            found[eye].append(_corners(ids, corners) if ok else None)
    left, right = shapes
    if left is None or right is None:
        raise VisionError(f"left_images is empty: calibration needs >= {MIN_VIEWS} views")
    return (found[0], (int(left[1]), int(left[0]))), (found[1], (int(right[1]), int(right[0])))


def _corners(ids: Any, corners: Any) -> Corners:
    """A detection as (ids (N,) int32, pixels (N, 2) float32)."""
    return np.asarray(ids, np.int32).ravel(), np.asarray(corners, np.float32).reshape(-1, 2)


def _points(board: Any, corners: Corners) -> tuple[npt.NDArray[Any], npt.NDArray[Any]]:
    """The board points (N, 1, 3) and image points (N, 1, 2) of detected corners."""
    ids, pixels = corners
    obj = board.getChessboardCorners()[ids].reshape(-1, 1, 3)
    return obj.astype(np.float32), pixels.reshape(-1, 1, 2).astype(np.float32)


def _mono(
    board: Any, detected: Detected, name: str, flags: int, problems: list[str]
) -> CameraModel:
    """One eye's camera from its own distinct views; what is wrong with it is added to
    ``problems`` (the pair is still fitted, so that every problem is told at once)."""
    views, size = detected
    usable = [c for c in views if c is not None]
    try:
        model, _, _ = fit_views(board.getChessboardCorners(), usable, size, flags, name)
    except CalibrationNotConverged as exc:
        problems += exc.problems
        return exc.model  # type: ignore[no-any-return]
    return model


def _common(a: Corners, b: Corners) -> tuple[Corners, Corners] | None:
    """The corners both eyes saw, in the same order (None: fewer than 6)."""
    ids = np.intersect1d(a[0], b[0])
    if len(ids) < MIN_CORNERS:
        return None
    return (ids, _at(a, ids)), (ids, _at(b, ids))


def _at(corners: Corners, ids: npt.NDArray[np.int32]) -> npt.NDArray[np.float32]:
    """The pixels of the corners ``ids`` (each one detected in ``corners``)."""
    where = {int(i): k for k, i in enumerate(corners[0])}
    return corners[1][[where[int(i)] for i in ids]]


def _stereo(
    board: Any,
    left: Detected,
    right: Detected,
    model_l: CameraModel,
    model_r: CameraModel,
    flags: int,
) -> tuple[tuple[CameraModel, CameraModel], FloatArray, float]:
    """Both eyes refined together, the right eye's pose in the left's, and the RMS."""
    if right[1] != left[1]:
        raise VisionError(f"left images are {left[1]} px, right images {right[1]} px")
    usable = _distinct_pairs(left, right)
    if len(usable) < MIN_VIEWS:
        raise VisionError(
            f"stereo calibration needs >= {MIN_VIEWS} distinct views with >= {MIN_CORNERS} "
            f"corners seen by both eyes, got {len(usable)}"
        )
    obj = [_points(board, a)[0] for a, _ in usable]
    img_l = [_points(board, a)[1] for a, _ in usable]
    img_r = [_points(board, b)[1] for _, b in usable]
    with opencv_errors("stereoCalibrate"):
        rms, k1, d1, k2, d2, R, T, _, _ = cv2.stereoCalibrate(
            obj, img_l, img_r, model_l.matrix.copy(), model_l.distortion.copy(),
            model_r.matrix.copy(), model_r.distortion.copy(), left[1],
            flags=flags | cv2.CALIB_USE_INTRINSIC_GUESS, criteria=_TERM,
        )  # fmt: skip
    T_right_left = np.eye(4)
    T_right_left[:3, :3], T_right_left[:3, 3] = R, np.ravel(T)
    eyes = (
        CameraModel(np.asarray(k1, dtype=np.float64), np.ravel(d1), left[1]),
        CameraModel(np.asarray(k2, dtype=np.float64), np.ravel(d2), right[1]),
    )
    return eyes, invert(T_right_left), float(rms)


def _distinct_pairs(left: Detected, right: Detected) -> list[tuple[Corners, Corners]]:
    """The common corners of each pair both eyes saw, repeated pairs dropped.

    Raises:
        VisionError: a pair shows the board at the same place to both eyes.
    """
    tol = tolerance(left[1])
    kept: list[tuple[Corners, Corners]] = []
    for k, (a, b) in enumerate(zip(left[0], right[0], strict=True)):
        pair = None if a is None or b is None else _common(a, b)
        if pair is None:
            continue
        if same_view(pair[0], pair[1], tol):
            raise VisionError(
                f"pair {k}: the left and the right image show the board at the same place "
                "(one image given for both eyes?)"
            )
        if not any(same_view(p[0], pair[0], tol) and same_view(p[1], pair[1], tol) for p in kept):
            kept.append(pair)
    return kept
