"""The SO(3) toolkit of the Python side: rotation vector ↔ rotation matrix, on scipy's
:class:`~scipy.spatial.transform.Rotation`.

One place for the exponential and logarithm maps (the rotation vector of
``R_target R_currentᵀ`` is the resolver's orientation error e_ζ, redundancy paper
eq. 10-11; the core computes that error itself and returns it as
``StepResult.orientation_error`` / ``Solution.orientation_error``). Used by the simulated
tracker's filter on SO(3), the vision pose filter and the harvest approach targets. The
camera's rvec ↔ pose conversion stays on ``cv2.Rodrigues`` in
:mod:`softarm.vision.poses` (the same map, OpenCV's convention, cheaper per call).
This module imports only numpy and scipy, so every layer may use it.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt
from scipy.spatial.transform import Rotation

__all__ = ["exp", "log", "rotation_between"]

F64 = npt.NDArray[np.float64]


def exp(w: npt.ArrayLike) -> F64:
    """Rotation matrix (3, 3) of the rotation vector ``w`` (3,): exp([w]×) (Rodrigues)."""
    return np.asarray(Rotation.from_rotvec(np.asarray(w, dtype=np.float64)).as_matrix())


def log(r: npt.ArrayLike) -> F64:
    """Rotation vector (3,) of the rotation matrix ``r`` (3, 3), angle in [0, π]."""
    return np.asarray(Rotation.from_matrix(np.asarray(r, dtype=np.float64)).as_rotvec())


def rotation_between(a: npt.ArrayLike, b: npt.ArrayLike) -> F64 | None:
    """The smallest rotation (3, 3) taking the unit vector ``a`` onto the unit vector
    ``b``: about ``a × b`` by the angle between them. None when they are antiparallel
    (every axis normal to ``a`` is then as small; the caller picks one)."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    v = np.cross(a, b)
    s = float(np.linalg.norm(v))
    c = float(np.clip(a @ b, -1.0, 1.0))
    if s < 1e-12:
        return np.eye(3) if c > 0 else None
    return exp(v / s * math.atan2(s, c))
