"""What a camera calibration says about its own data, before anyone uses its result.

``cv2.calibrateCamera`` fits whatever it is given: twelve copies of one view of a board
give an RMS of 0.07 px and fx = 1211 px for a true 1000, views of the board all facing
the camera give any focal length, and a stereo pair whose images are off by one give a
baseline of 438 mm for 120. The checks here are the ones such data fails:

* **distinct views** (:func:`distinct_views`): a view whose corners lie where an earlier
  view's do (within :data:`SAME_VIEW` of the image diagonal) adds nothing but weight, and
  makes the fit look surer than it is; it is dropped, and at least 3 must remain;
* **tilted views** (:data:`MIN_TILT_DEG`): the focal length is pinned down only by boards
  seen at different angles; two views' board normals must differ by that much;
* **uncertainty** (:data:`MAX_RELATIVE_STD`): OpenCV's standard deviations of fx, fy, cx
  and cy, relative to the focal length and the image size;
* **reprojection** (:data:`MAX_RMS_PX`): an RMS above it is no calibration (a stereo pair
  whose images do not pair up, a board of the wrong size);
* **the pair** (:func:`pair_problems`): a baseline of plausible length
  (:data:`BASELINE_RANGE`), the right eye mostly along the left eye's +x.

A calibration that fails one after fitting raises :class:`CalibrationNotConverged`,
which carries the model and the problems, so that ``softarm camera calibrate`` can show
them and say "not converged" (exit status 1) as ``softarm calibrate`` does.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from softarm.errors import VisionError

__all__ = [
    "BASELINE_RANGE",
    "MAX_RELATIVE_STD",
    "MAX_RMS_PX",
    "MIN_TILT_DEG",
    "SAME_VIEW",
    "CalibrationNotConverged",
    "distinct_views",
    "intrinsics_problems",
    "pair_problems",
    "same_view",
]

#: Two views are the same when their common corners lie within this fraction of the
#: image diagonal of each other (RMS): 1 % is 15 px on a 1280 x 720 image, far more than
#: sensor noise, far less than a board moved on purpose.
SAME_VIEW = 0.01
#: Least angle (degrees) between two views' board normals: boards all facing the camera
#: leave the focal length free (measured: 3-5 degrees of spread gave fx 2730 for 900).
MIN_TILT_DEG = 10.0
#: Largest standard deviation of fx, fy (relative to them) and of cx, cy (relative to the
#: image width and height): 2 % is 18 px of a 900 px focal length.
MAX_RELATIVE_STD = 0.02
#: Largest RMS reprojection error (px) of a calibration: a good one is 0.1-0.5 px.
MAX_RMS_PX = 2.0
#: Plausible stereo baselines (m): from a 5 mm module pair to a 2 m rig.
BASELINE_RANGE = (0.005, 2.0)

#: A view's corners: ids (N,) and pixels (N, 2).
Corners = tuple[npt.NDArray[np.int32], npt.NDArray[np.float32]]


class CalibrationNotConverged(VisionError):
    """A calibration was fitted, but its own data says the result is not to be used:
    ``problems`` says why; ``model`` and ``rms`` are what the fit gave."""

    def __init__(self, model: Any, rms: float, problems: list[str]) -> None:
        super().__init__("calibration not converged: " + "; ".join(problems))
        self.model, self.rms, self.problems = model, rms, list(problems)

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.model, self.rms, self.problems))


def same_view(a: Corners, b: Corners, tolerance_px: float) -> bool:
    """Whether ``a`` and ``b`` show the board at the same place: at least 6 common
    corners, within ``tolerance_px`` of each other (RMS)."""
    common, ia, ib = np.intersect1d(a[0], b[0], return_indices=True)
    if len(common) < 6:
        return False
    diff = a[1][ia].astype(np.float64) - b[1][ib]
    return bool(np.sqrt(np.mean(np.sum(diff**2, axis=1))) <= tolerance_px)


def tolerance(size: tuple[int, int]) -> float:
    """:data:`SAME_VIEW` of the diagonal of an image of ``size`` = (w, h), in pixels."""
    return SAME_VIEW * float(np.hypot(*size))


def distinct_views(views: list[Corners], size: tuple[int, int]) -> list[int]:
    """The indices of the views that repeat no earlier kept view (see :func:`same_view`)."""
    tol = tolerance(size)
    kept: list[int] = []
    for k, view in enumerate(views):
        if not any(same_view(views[j], view, tol) for j in kept):
            kept.append(k)
    return kept


def intrinsics_problems(
    name: str,
    matrix: npt.NDArray[Any],
    std: npt.NDArray[Any],
    rvecs: Any,
    size: tuple[int, int],
) -> list[str]:
    """What the fitted ``matrix``, its standard deviations ``std`` (OpenCV's order: fx,
    fy, cx, cy, ...) and the views' board rotations ``rvecs`` say is wrong, one line
    each naming ``name``."""
    import cv2

    problems = []
    normals = np.array([cv2.Rodrigues(np.asarray(r, np.float64))[0][:, 2] for r in rvecs])
    tilt = float(np.degrees(np.arccos(np.clip(np.min(normals @ normals.T), -1.0, 1.0))))
    if tilt < MIN_TILT_DEG:
        problems.append(
            f"{name}: the board's views differ by {tilt:.1f} degrees at most: tilt it by "
            f">= {MIN_TILT_DEG:g} degrees between views, or the focal length is not pinned down"
        )
    sd = np.ravel(std)[:4]
    scale = np.array([matrix[0, 0], matrix[1, 1], size[0], size[1]], dtype=np.float64)
    worst = int(np.argmax(sd / scale))
    if not np.all(np.isfinite(sd)) or sd[worst] > MAX_RELATIVE_STD * scale[worst]:
        label = ("fx", "fy", "cx", "cy")[worst]
        problems.append(
            f"{name}: {label} is uncertain by {sd[worst]:.1f} px (more than "
            f"{100 * MAX_RELATIVE_STD:g} %): add views, tilted and reaching the image corners"
        )
    return problems


def rms_problem(name: str, rms: float) -> list[str]:
    """A line when the RMS reprojection error is above :data:`MAX_RMS_PX`."""
    if rms <= MAX_RMS_PX:
        return []
    return [
        f"{name}: rms {rms:.2f} px is above {MAX_RMS_PX:g} px (images that do not pair up, "
        "or a board of another size?)"
    ]


def pair_problems(T_left_right: npt.NDArray[Any]) -> list[str]:
    """What is implausible in the right eye's pose ``T_left_right`` (4x4, m, in the left
    eye's frame): a baseline outside :data:`BASELINE_RANGE`, or the right eye not mostly
    along the left eye's +x (swapped eyes, or a pair that is not side by side)."""
    T = np.asarray(T_left_right, dtype=np.float64)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        return ["T_left_right must be a finite 4x4 pose"]
    t = T[:3, 3]
    largest = float(np.max(np.abs(t)))  # scaled first: the norm of 1e308 would overflow
    baseline = largest * float(np.linalg.norm(t / largest)) if largest > 0 else 0.0
    lo, hi = BASELINE_RANGE
    if not lo <= baseline <= hi:
        return [f"the baseline is {1e3 * baseline:.4g} mm: a stereo pair's is {1e3 * lo:g} mm "
                f"to {hi:g} m"]  # fmt: skip
    # As StereoCamera requires: mostly along +x (a vertical pair is not side by side).
    if t[0] <= max(abs(t[1]), abs(t[2])):
        at = ", ".join(f"{1e3 * v:.1f}" for v in t)
        return [
            f"the right eye is at ({at}) mm of the left: it must lie mostly along the left "
            "eye's +x (eyes swapped?)"
        ]
    return []
