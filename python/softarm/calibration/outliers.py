"""Samples that do not belong to the fit (issue 26, item 12): a pose mismeasured by a
metre among sixty good ones made a "converged" fit four times worse than none.

Each sample's residual is its six weighted residuals (position over its noise, rotation
over its noise) after a *robust* fit (soft-L1 loss, which lets a far sample pull with a
bounded force), reduced to one norm. A sample is an outlier when its norm exceeds
:data:`OUTLIER_FACTOR` times the median norm and :data:`MIN_OUTLIER_SIGMA` noise levels.
Good fits have max/median 1.6 to 2.7 (pcc and Cosserat plants, 22 to 80 poses), so
nothing of theirs is dropped; more than :data:`MAX_OUTLIER_SHARE` of the samples flagged
is a model that does not fit, not outliers, and nothing is dropped.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray as F64

__all__ = ["outlier_indices"]

I64 = npt.NDArray[np.int64]

OUTLIER_FACTOR = 6.0
MIN_OUTLIER_SIGMA = 5.0
MAX_OUTLIER_SHARE = 0.2


def outlier_indices(sample_residuals: F64) -> I64:
    """Indices of the outlying samples, from their weighted residuals (N, k)."""
    norms = np.linalg.norm(sample_residuals, axis=1)
    limit = max(OUTLIER_FACTOR * float(np.median(norms)), MIN_OUTLIER_SIGMA)
    out = np.flatnonzero(norms > limit)
    if len(out) > MAX_OUTLIER_SHARE * len(norms):
        return np.zeros(0, dtype=np.int64)
    return out.astype(np.int64)
