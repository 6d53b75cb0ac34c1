"""Edge-based sub-pixel refinement of marker corners.

``cornerSubPix`` (OpenCV's ``CORNER_REFINE_SUBPIX``) is built for saddle corners; on the
convex corner of a marker's black square it leaves a bias of about 0.1–0.2 px. Here each
side of the square is located instead: along the side, the intensity profile across it is
sampled (bilinear) and the edge is the centroid of the (signed) gradient, which for a
blurred, anti-aliased step is the step's position. The edge points are undistorted to
normalised coordinates, where the sides are straight lines (pinhole projection of a
straight edge), a line is fitted to each side (total least squares), and adjacent lines
intersect at the corners, which are then distorted back to pixels. Dozens of edge points
per side average the pixel noise down, which the four-point corner fit cannot do.
"""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt

from softarm.vision._checks import FloatArray
from softarm.vision.camera_model import CameraModel

_STEP = 0.25  # px between profile samples across an edge
_MAX_SHIFT = 2.0  # px: a refined corner further than this from the detection is refused


def refine_marker_corners(
    gray: npt.NDArray[np.float32], corners: FloatArray, camera: CameraModel, cells: int
) -> FloatArray:
    """Refined (4, 2) pixel corners of one marker (``cells`` = bits + 2 border cells);
    returns ``corners`` unchanged if the edges cannot be measured."""
    quad = np.asarray(corners, dtype=np.float64).reshape(4, 2)
    h, w = gray.shape
    lines = []
    samples, normals, counts = [], [], []
    # Half-width of the profile: well inside the black border cell, whatever the view.
    widths = [np.linalg.norm(quad[k] - quad[(k + 1) % 4]) for k in range(4)]
    reach = float(np.clip(0.4 * min(widths) / cells, 1.0, 4.0))
    offsets = np.arange(-reach, reach + 1e-9, _STEP)
    for k in range(4):
        a, b = quad[k], quad[(k + 1) % 4]
        length = float(np.linalg.norm(b - a))
        if length < 8:
            return quad
        tangent = (b - a) / length
        normal = np.array([tangent[1], -tangent[0]])
        margin = max(3.0, 0.08 * length) / length
        fractions = np.linspace(margin, 1 - margin, max(int(length), 8))
        base = a + fractions[:, None] * (b - a)  # (n, 2)
        samples.append(base[:, None, :] + offsets[None, :, None] * normal)  # (n, m, 2)
        normals.append(normal)
        counts.append(len(fractions))
    pts = np.concatenate(samples).astype(np.float32)  # (N, m, 2)
    if (
        pts[..., 0].min() < 0
        or pts[..., 1].min() < 0
        or pts[..., 0].max() > w - 1
        or pts[..., 1].max() > h - 1
    ):
        return quad
    prof = cv2.remap(gray, pts[..., 0], pts[..., 1], cv2.INTER_LINEAR)  # (N, m)
    # Signed gradient: for a box-filtered step sampled bilinearly its centroid is exactly the
    # step position (a squared or absolute gradient is biased by the sub-pixel phase or by
    # noise), and pixel noise adds zero-mean terms only.
    grad = np.diff(prof, axis=1)
    mid = 0.5 * (offsets[1:] + offsets[:-1])
    wsum = grad.sum(axis=1)
    contrast = np.abs(wsum)
    ok_edge = contrast > 0.25 * np.median(contrast)
    shift = (grad @ mid) / np.where(ok_edge, wsum, 1.0)  # edge offset along the normal
    start = 0
    for k in range(4):
        n = counts[k]
        base = pts[start : start + n, 0].astype(np.float64) + reach * normals[k]
        edge = base + shift[start : start + n, None] * normals[k]
        good = ok_edge[start : start + n] & (np.abs(shift[start : start + n]) < reach)
        start += n
        if good.sum() < 4:
            return quad
        norm_pts = camera.normalize(edge[good])
        centre = norm_pts.mean(axis=0)
        _, _, vt = np.linalg.svd(norm_pts - centre)
        lines.append((centre, vt[0]))  # point and direction of side k
    out = np.empty((4, 2))
    for k in range(4):
        # Corner k joins side k-1 (ending at k) and side k (starting at k).
        (p1, d1), (p2, d2) = lines[k - 1], lines[k]
        mat = np.column_stack([d1, -d2])
        if abs(np.linalg.det(mat)) < 1e-9:
            return quad
        s = np.linalg.solve(mat, p2 - p1)
        out[k] = p1 + s[0] * d1
    pix = camera.project(np.column_stack([out, np.ones(4)]))
    if np.max(np.linalg.norm(pix - quad, axis=1)) > _MAX_SHIFT:
        return quad
    return pix
