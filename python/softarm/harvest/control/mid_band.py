"""A planned configuration moved, in the null space of its pose task, towards the middle
of every actuator's range.

The arm is redundant (nine elongations for a pose with its roll free: five rows), so the
pose a plan ends on is reached by a four-dimensional family of configurations, and the
planner's resolver stops on the first it converges to. Its joint-limit term (eq. 14,
γ₅ of eq. 20) is scheduled off near the target (the blackberry gains' smooth schedule
weighs it by e²/(e² + d²), under 1e-3 of itself within a millimetre), so a solution may
keep a channel a few psi from 0 or 70. On a slow plant (τ = 0.8 s) such a channel sets
the time of the whole move: a first-order regulator driven at its 70 psi limit needs
τ ln(35 / (70 − p)) to reach p from mid-range (1.3 s to 63 psi, 0.45 s to 50 psi), and
the lead's boost, one vector, is cut for every channel by the one nearest its limit
(docs/harvest.md, "Where the slow plant waits").

:func:`toward_mid` descends the band cost

    C(q) = ½ Σ_m (max(0, l_m + b − q_m)² + max(0, q_m − u_m + b)²),   b = band (u − l),

zero inside the band ``[l + b, u − b]``, along N = I − J⁺J, the exact projector onto the
null space of the task's Jacobian J (position rows and the resolver's masked orientation
rows, the same task as eq. 20), with a damped Newton correction J⁺e of the task's error
at each step to undo the drift of a finite null-space step.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from softarm import so3
from softarm._core import SoftArm
from softarm.checks import FloatArray

__all__ = ["band_gradient", "null_projector", "task_error", "toward_mid"]

#: Singular values of the task Jacobian below this fraction of the largest count as zero
#: in the projector (its rank): an arm near a singular pose keeps more directions.
RANK_TOLERANCE = 1e-6
#: Damping (m) of the task correction's pseudo-inverse: a Newton step of a few mm at most.
CORRECTION_DAMPING = 1e-3
#: How far (a fraction of the range) past the least room of the moment each step's band
#: lies: the channels within it of the nearest limit are the ones pushed in.
LIFT = 0.02
#: Newton corrections of the task alone after the last null-space step.
CORRECTIONS = 3


def band_gradient(q: FloatArray, lower: FloatArray, upper: FloatArray, band: float) -> FloatArray:
    """∇C of the band cost (module docs) at ``q``: −(l + b − q) below the band,
    q − (u − b) above it, 0 inside."""
    b = band * (upper - lower)
    return np.asarray(
        np.maximum(0.0, q - (upper - b)) - np.maximum(0.0, (lower + b) - q), dtype=np.float64
    )


def null_projector(jac: FloatArray) -> FloatArray:
    """N = I − V_r V_rᵀ, with V_r the right singular vectors of ``jac`` (rows × n) whose
    singular values are above :data:`RANK_TOLERANCE` of the largest: symmetric,
    idempotent, and ``jac @ N`` is zero up to the dropped singular values."""
    _, s, vt = np.linalg.svd(jac, full_matrices=True)
    rank = int(np.sum(s > RANK_TOLERANCE * (s[0] if s.size else 0.0)))
    v = vt[:rank].T
    return np.asarray(np.eye(jac.shape[1]) - v @ v.T, dtype=np.float64)


def task_error(
    arm: SoftArm, q: FloatArray, target: FloatArray, mask: Sequence[bool]
) -> tuple[FloatArray, FloatArray]:
    """The task's error (position, then the masked rotation vector of R_t Rᵀ as the
    resolver's eq. 20 controls it) and its Jacobian's rows, at ``q``."""
    pose, jac = arm.forward_jacobian(q)
    e_p = target[:3, 3] - pose[:3, 3]
    e_w = so3.log(target[:3, :3] @ pose[:3, :3].T)
    rows = [0, 1, 2] + [3 + i for i in range(3) if mask[i]]
    err = np.concatenate([e_p, e_w])[rows]
    return np.asarray(err, dtype=np.float64), np.asarray(jac[rows], dtype=np.float64)


def toward_mid(
    arm: SoftArm,
    q: FloatArray,
    target: FloatArray,
    mask: Sequence[bool],
    band: float,
    *,
    iterations: int = 60,
    position_tolerance: float = 1e-3,
    orientation_tolerance: float = 0.02,
) -> FloatArray:
    """``q`` (a solution of ``target`` on ``arm``) moved along the task's null space
    towards the band ``[l + b, u − b]`` of every actuator (``band`` a fraction of its
    range): the result reaches ``target`` within the tolerances (as ``Resolver.solve``
    counts them) and its band cost is no higher; else ``q`` itself. The arm stays
    inside its limits."""
    lower, upper = np.asarray(arm.lower), np.asarray(arm.upper)
    start = np.asarray(q, dtype=np.float64)
    if not np.any(band_gradient(start, lower, upper, band)):
        return start  # in the band already
    x = start.copy()
    for _ in range(iterations):
        # The band of this step: the nearest channel's room lifted by LIFT (never past
        # ``band``), so that only the channels nearest their limits are pushed in and the
        # others are free to give way (the least room raised, not the sum of squares).
        step_band = min(band, _room(x, lower, upper) + LIFT)
        grad = band_gradient(x, lower, upper, step_band)
        if not np.any(grad):
            break
        err, jac = task_error(arm, x, target, mask)
        step = -null_projector(jac) @ grad
        if float(np.max(np.abs(step))) < 1e-7:
            break  # what is left of the cost is the task's: the band cannot be reached
        gram = jac @ jac.T + CORRECTION_DAMPING**2 * np.eye(jac.shape[0])
        x = np.clip(x + step + jac.T @ np.linalg.solve(gram, err), lower, upper)
    for _ in range(CORRECTIONS):  # the last null-space step's drift, taken out
        err, jac = task_error(arm, x, target, mask)
        gram = jac @ jac.T + CORRECTION_DAMPING**2 * np.eye(jac.shape[0])
        x = np.clip(x + jac.T @ np.linalg.solve(gram, err), lower, upper)
    err, _ = task_error(arm, x, target, mask)
    reached = (
        float(np.linalg.norm(err[:3])) <= position_tolerance
        and float(np.linalg.norm(err[3:])) <= orientation_tolerance
    )
    if reached and _room(x, lower, upper) > _room(start, lower, upper):
        return x
    return start


def _room(q: FloatArray, lower: FloatArray, upper: FloatArray) -> float:
    """The least distance of ``q`` to a limit, as a fraction of each range."""
    return float(np.min(np.minimum(q - lower, upper - q) / (upper - lower)))
