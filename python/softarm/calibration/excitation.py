"""A safe excitation set: the commands a calibration drives the arm through.

Latin-hypercube samples of every actuator's command inside ``[lo, hi]`` of its limits
(a margin from both ends: below ~5 psi a real muscle barely elongates, section IV-A, and
the top stays clear of the regulators' saturation), starting from the vented arm, ordered
by a greedy nearest-neighbour tour so that consecutive poses are close (short, slow moves
of the arm). A Latin hypercube puts every actuator at N distinct levels, which separates
the gains from each other and from the geometry better than random draws.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import qmc

from softarm._core import SoftArm
from softarm.checks import FloatArray as F64
from softarm.errors import ParameterError

__all__ = ["MAX_POSES", "excitation_set"]


#: The most poses a calibration run drives the arm through.
MAX_POSES = 100


def excitation_set(
    arm: SoftArm, n: int = 80, seed: int = 0, lo: float = 0.1, hi: float = 0.95
) -> F64:
    """``n`` commands (n, n_actuators) inside the fractions ``[lo, hi]`` of ``arm``'s
    limits, in visiting order.

    Raises:
        ParameterError: ``n`` outside 1..MAX_POSES or ``0 <= lo < hi <= 1`` violated.
    """
    if not (isinstance(n, int) and 1 <= n <= MAX_POSES):
        raise ParameterError(f"n = {n!r}: must be an integer in 1..{MAX_POSES}")
    if not (0.0 <= lo < hi <= 1.0):
        raise ParameterError(f"(lo, hi) = ({lo!r}, {hi!r}): need 0 <= lo < hi <= 1")
    low, up = np.asarray(arm.lower), np.asarray(arm.upper)
    u = qmc.LatinHypercube(d=arm.n_actuators, seed=np.random.default_rng(seed)).random(n)
    pts = low + (up - low) * (lo + (hi - lo) * u)
    # Greedy nearest-neighbour tour from the vented arm.
    order, here, left = [], low, list(range(n))
    while left:
        k = min(left, key=lambda j: float(np.abs(pts[j] - here).max()))
        order.append(k)
        left.remove(k)
        here = pts[k]
    result: F64 = pts[order]
    return result
