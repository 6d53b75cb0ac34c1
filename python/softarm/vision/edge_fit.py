"""An edge's position across its profile by least squares on a blurred-step model.

:mod:`softarm.vision.refine` locates a marker's edge on each profile across it as the
centroid of the signed gradient over the whole profile (up to +-4 px). That centroid is
a weighted sum of every sample, each with the same weight (the telescoped sum: the
edge is the profile's far end less the area under its normalised ramp), so a sample
several pixels from the edge, which says nothing about where the edge is, adds as much
noise as one on the ramp. Its variance is about ``W sigma**2 / b**2`` (``W`` the
profile's width in px, ``sigma`` the pixel noise, ``b`` the step's contrast).

Here the profile is fitted instead by a blurred step,

    f(x) = a + b * Phi((x - c) / s),

(``Phi`` the standard normal CDF: a step blurred by a Gaussian of ``s`` px; a camera's
PSF, the pixel's box and the bilinear sampling together are close to one), with ``c``,
``s``, ``a`` and ``b`` free per profile, by Gauss-Newton. The samples far from the edge
fix the levels and the ramp's fix ``c``: its Cramer-Rao bound, for pixel-spaced samples
of independent noise, is ``var(c) >= 2 sqrt(pi) s sigma**2 / b**2`` (the Fisher
information ``sum (b phi(z) / s)**2 / sigma**2 ~ b**2 / (2 sqrt(pi) s sigma**2)``),
under the centroid's by ``W / (2 sqrt(pi) s)``: about 2-3x in variance for an 8 px
profile and a 1-1.5 px ramp; on a synthetic edge through the row camera's noise and
JPEG the fit reaches it. The price is the model: the centroid (the gradient's first
moment) finds the middle of any ramp symmetric about the edge, the fit only of one
shaped like its model. The bush's rendered tags (clean kinked ramps about 3 px wide, the
ink at 0) are not, and the fit moves stretches of a side by 0.01-0.04 px there
(docs/perception.md, "The edge by a blurred-step fit"): hence an option.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy.special import ndtr

from softarm.vision._checks import FloatArray

__all__ = ["fit_edges"]

#: Gauss-Newton iterations: from the centroid's position the 4th moves c by ~1e-5 px.
ITERATIONS = 4
#: The ramp's blur (px) a fit may end with: narrower is a single noisy sample, wider no
#: edge the profile can fix; a profile fitted outside is refused.
BLUR_RANGE = (0.15, 3.0)
#: The fitted ramp, ``COVER`` blurs to either side of the edge, must lie within the
#: profile: where one level is not seen (a detection's line off the edge by half a
#: pixel on a +-2 px profile) the fit extrapolates it and trades it for the edge's
#: position (on the bush's small tags 0.3 px off the centroid, either way).
COVER = 2.5
#: A fitted step under this many times the fit's rms residual is noise, not an edge.
MIN_STEP = 4.0
_SQRT_2PI = float(np.sqrt(2.0 * np.pi))


def fit_edges(
    profiles: npt.NDArray[np.floating],
    offsets: FloatArray,
    start: FloatArray,
) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
    """The edge's offset on each of the (N, m) ``profiles`` sampled at ``offsets`` (m,
    px), fitted by a blurred step from ``start`` (N, px: the centroid's), and which fits
    converged to an edge whose ramp lies within the profile (``|c| + COVER * s`` within
    its reach, blur within :data:`BLUR_RANGE`, a step over :data:`MIN_STEP` times the
    residual); a refused profile keeps ``start``."""
    y = np.asarray(profiles, dtype=np.float64)
    x = np.asarray(offsets, dtype=np.float64)[None, :]
    reach = float(np.max(np.abs(offsets)))
    begin = np.asarray(start, dtype=np.float64)
    c = begin.copy()
    # A first blur from the gradient's spread about the start (its second moment), then
    # the levels by linear least squares for that ramp.
    g = np.diff(y, axis=1)
    mid = 0.5 * (x[:, 1:] + x[:, :-1])
    total = g.sum(axis=1)
    spread = np.sum(g * (mid - c[:, None]) ** 2, axis=1) / np.where(total != 0, total, 1.0)
    s = np.sqrt(np.clip(spread, BLUR_RANGE[0] ** 2, 4.0))
    a, b = _levels(y, x, c, s)
    for _ in range(ITERATIONS):
        z = (x - c[:, None]) / s[:, None]
        cdf = ndtr(z)
        residual = y - (a[:, None] + b[:, None] * cdf)
        slope = (-b / (_SQRT_2PI * s))[:, None] * np.exp(-0.5 * z * z)  # d f / d c
        # The Jacobian (N, m, 4) in (c, s, a, b): d f / d s = slope z, d f / d a = 1,
        # d f / d b = the ramp; the normal equations J^T J step = J^T r, batched.
        jac = np.stack((slope, slope * z, np.ones_like(cdf), cdf), axis=2)
        normal = np.matmul(jac.transpose(0, 2, 1), jac)
        rhs = np.matmul(jac.transpose(0, 2, 1), residual[:, :, None])[:, :, 0]
        # A little Levenberg damping keeps a flat profile's singular system solvable.
        normal += 1e-6 * np.einsum("nii->ni", normal)[:, :, None] * np.eye(4) + 1e-9 * np.eye(4)
        step = np.linalg.solve(normal, rhs[:, :, None])[:, :, 0]
        # At most half a pixel in c and a fifth of the blur in s at a time.
        c = c + np.clip(step[:, 0], -0.5, 0.5)
        s = np.clip(s + np.clip(step[:, 1], -0.2 * s, 0.2 * s), 0.5 * BLUR_RANGE[0], 4.0)
        a, b = a + step[:, 2], b + step[:, 3]
    residual = y - (a[:, None] + b[:, None] * ndtr((x - c[:, None]) / s[:, None]))
    rms = np.sqrt(np.mean(residual * residual, axis=1))
    ok = (np.abs(c) + COVER * s <= reach) & (s >= BLUR_RANGE[0]) & (s <= BLUR_RANGE[1])
    ok &= np.abs(b) > MIN_STEP * rms
    return np.where(ok, c, begin), ok


def _levels(
    y: FloatArray, x: FloatArray, c: FloatArray, s: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The levels ``a`` and ``b`` (N,) that fit ``y`` best for the ramps ``c``, ``s``."""
    cdf = ndtr((x - c[:, None]) / s[:, None])
    m = y.shape[1]
    sp, spp = cdf.sum(axis=1), np.sum(cdf * cdf, axis=1)
    sy, spy = y.sum(axis=1), np.sum(cdf * y, axis=1)
    det = m * spp - sp * sp
    det = np.where(np.abs(det) > 1e-12, det, 1.0)
    b = (m * spy - sp * sy) / det
    a = (sy - b * sp) / m
    return a, b
