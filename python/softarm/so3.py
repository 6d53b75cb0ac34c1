"""The SO(3) toolkit of the Python side: rotation vector ↔ rotation matrix, on scipy's
:class:`~scipy.spatial.transform.Rotation`, and a matrix's quaternion in plain floats
(:func:`quaternion_xyzw`, for the live view's every step).

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

__all__ = ["exp", "log", "quaternion_xyzw", "rotation_between"]

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


def quaternion_xyzw(r: npt.ArrayLike) -> tuple[float, float, float, float]:
    """The unit quaternion (x, y, z, w), w ≥ 0, of the rotation matrix ``r`` (3, 3).

    Shepperd's method: the largest of w², x², y², z² (from the trace and the diagonal)
    is taken by its square root and the others from the off-diagonal sums, so no
    division is by a small number. In plain floats, because the live view converts every
    control step's poses and scipy's ``Rotation.from_matrix`` (which also checks and
    orthogonalises) costs about ten times the rest of a step's messages."""
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = np.asarray(r, dtype=np.float64).tolist()
    trace = m00 + m11 + m22
    if trace >= max(m00, m11, m22):
        s = 2.0 * math.sqrt(max(1.0 + trace, 0.0))
        q = ((m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, 0.25 * s)
    elif m00 >= m11 and m00 >= m22:
        s = 2.0 * math.sqrt(max(1.0 + m00 - m11 - m22, 0.0))
        q = (0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s)
    elif m11 >= m22:
        s = 2.0 * math.sqrt(max(1.0 + m11 - m00 - m22, 0.0))
        q = ((m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s)
    else:
        s = 2.0 * math.sqrt(max(1.0 + m22 - m00 - m11, 0.0))
        q = ((m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s)
    norm = math.sqrt(sum(c * c for c in q))
    sign = -1.0 if q[3] < 0.0 else 1.0
    x, y, z, w = (sign * c / norm for c in q)
    return x, y, z, w
