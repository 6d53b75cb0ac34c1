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
    gray: npt.NDArray[np.uint8], corners: FloatArray, camera: CameraModel, cells: int
) -> FloatArray:
    """Refined (4, 2) pixel corners of one marker in the 2-D ``gray`` image (``cells`` =
    bits + 2 border cells); returns ``corners`` unchanged if the edges cannot be measured."""
    quad = np.asarray(corners, dtype=np.float64).reshape(4, 2)
    h, w = gray.shape
    samples, normals, counts = [], [], []
    # Half-width of the profile: well inside the black border cell, whatever the view.
    widths = [np.linalg.norm(quad[k] - quad[(k + 1) % 4]) for k in range(4)]
    reach = float(np.clip(0.4 * min(widths) / cells, 1.0, 4.0))
    reach = _STEP * round(reach / _STEP)  # so that the offsets are symmetric about 0
    offsets = _STEP * np.arange(-round(reach / _STEP), round(reach / _STEP) + 1)
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
    pts64 = np.concatenate(samples)  # (N, m, 2) pixel positions of the profile samples
    # Every sample lies within ``reach`` of the quad's sides.
    lo = np.floor(quad.min(axis=0) - reach - 1).astype(int)
    hi = np.ceil(quad.max(axis=0) + reach + 1).astype(int)
    if lo.min() < 0 or hi[0] > w - 1 or hi[1] > h - 1:
        return quad
    # Work on a float copy of the marker's neighbourhood only (a full-frame copy costs ~1 ms).
    crop = gray[lo[1] : hi[1] + 1, lo[0] : hi[0] + 1].astype(np.float32)
    pts = (pts64 - lo).astype(np.float32)
    prof = cv2.remap(crop, pts[..., 0], pts[..., 1], cv2.INTER_LINEAR)  # (N, m)
    # Signed gradient: for a box-filtered step sampled bilinearly its centroid is exactly the
    # step position (a squared or absolute gradient is biased by the sub-pixel phase or by
    # noise), and pixel noise adds zero-mean terms only.
    grad = np.diff(prof, axis=1)
    mid = 0.5 * (offsets[1:] + offsets[:-1])
    wsum = grad.sum(axis=1)
    contrast = np.abs(wsum)
    ok_edge = contrast > 0.25 * np.median(contrast)
    shift = (grad @ mid) / np.where(ok_edge, wsum, 1.0)  # edge offset along the normal
    good = ok_edge & (np.abs(shift) < reach)
    side = np.repeat(np.arange(4), counts)
    centre_px = pts64[:, len(offsets) // 2]  # offsets is symmetric: its middle is 0
    edge = centre_px + shift[:, None] * np.stack(normals)[side]
    if np.any(np.bincount(side[good], minlength=4) < 4):
        return quad
    norm_pts = camera.normalize(edge[good])  # one call for all four sides
    side = side[good]
    lines = []
    for k in range(4):
        pts_k = norm_pts[side == k]
        centre = pts_k.mean(axis=0)
        _, _, vt = np.linalg.svd(pts_k - centre, full_matrices=False)
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
