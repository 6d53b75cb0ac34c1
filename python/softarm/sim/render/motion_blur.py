"""Motion blur from real motion: how fast each pixel of a frame moves during the
exposure, and the frame smeared along that motion.

Two sources. A camera that moves (C2 on the end effector) sees every static point
move: :func:`camera_twist` takes the camera's velocity from two of its poses, and
:func:`twist_flow` the image velocity of each pixel from it and the scene's inverse
depth there (the standard image Jacobian of a point: translation scales with 1/Z,
rotation does not depend on depth). A fixed camera (C1) sees only what moves in front
of it: :func:`swept_flow` paints each moving part's image velocity over the pixels it
sweeps during the exposure, zero elsewhere.

:func:`flow_blur` then averages each pixel's light along the segment it moved over
(a gather: each pixel takes the mean of the image sampled along its own motion, which
for a moving object over a still background also gives the background it slides over
its share of the object's colour). Every pixel's weights sum to 1: blur moves light,
it makes none. Motions under a pixel during the exposure are no blur at all, as
:func:`~softarm.sim.render.camera_effects.blur_kernel` has it.
"""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray
from softarm.errors import ParameterError

__all__ = [
    "MIN_DEPTH",
    "camera_twist",
    "check_flow",
    "flow_blur",
    "plane_inverse_depth",
    "swept_flow",
    "twist_flow",
]

#: The nearest depth (m) a scene point is taken at: nothing C2 sees in focus is nearer
#: (the fingers' tips reach 4 cm in front of it), and 1/Z stays bounded.
MIN_DEPTH = 0.04
#: At most this many samples along a pixel's motion: a longer smear is sampled sparser.
MAX_SAMPLES = 48

Flow = npt.NDArray[np.float32]


def camera_twist(
    T_before: FloatArray, T_now: FloatArray, dt: float
) -> tuple[FloatArray, FloatArray]:
    """The camera's linear (m/s) and angular (rad/s) velocity, both in its own frame
    now, from its poses ``T_before`` and ``T_now`` (base frame) ``dt`` s apart.

    Raises:
        ParameterError: ``dt`` not positive, or a pose not finite.
    """
    if not (np.isfinite(dt) and dt > 0):
        raise ParameterError(f"dt must be a positive time, got {dt}")
    if not (np.all(np.isfinite(T_before)) and np.all(np.isfinite(T_now))):
        raise ParameterError("T_before and T_now must be finite poses")
    R_now = T_now[:3, :3]
    v = R_now.T @ (T_now[:3, 3] - T_before[:3, 3]) / dt
    # The rotation vector of R_before^T R_now is its own axis in either frame.
    rotvec, _ = cv2.Rodrigues(np.ascontiguousarray(T_before[:3, :3].T @ R_now))
    w: FloatArray = np.asarray(rotvec, np.float64).ravel() / dt
    return v, w


def _grid(
    focal: float, principal: tuple[float, float], size: tuple[int, int]
) -> tuple[FloatArray, FloatArray]:
    """The normalised image coordinates (x/z, y/z) of every pixel (pinhole)."""
    w, h = size
    x = (np.arange(w, dtype=np.float64) - principal[0]) / focal
    y = (np.arange(h, dtype=np.float64) - principal[1]) / focal
    return np.meshgrid(x, y)


def twist_flow(
    v: FloatArray,
    w: FloatArray,
    focal: float,
    principal: tuple[float, float],
    size: tuple[int, int],
    inverse_depth: float | FloatArray,
) -> Flow:
    """(H, W, 2) image velocity (px/s) of the static scene seen by a pinhole camera
    (``focal`` px, ``principal`` point, ``size`` (W, H)) moving at ``v`` (m/s), ``w``
    (rad/s) in its own frame; ``inverse_depth``: 1/Z (1/m) of the scene at each pixel
    (0: at infinity, the sky), or one value for all."""
    x, y = _grid(focal, principal, size)
    iz = np.broadcast_to(np.asarray(inverse_depth, np.float64), x.shape)
    vx, vy, vz = (float(c) for c in v)
    wx, wy, wz = (float(c) for c in w)
    du = focal * ((-vx + x * vz) * iz + x * y * wx - (1 + x * x) * wy + y * wz)
    dv = focal * ((-vy + y * vz) * iz + (1 + y * y) * wx - x * y * wy - x * wz)
    return np.stack([du, dv], axis=-1).astype(np.float32)


def plane_inverse_depth(
    T_base_camera: FloatArray,
    point: FloatArray,
    normal: FloatArray,
    focal: float,
    principal: tuple[float, float],
    size: tuple[int, int],
) -> FloatArray:
    """(H, W) 1/Z (1/m) at each pixel of a scene that is the plane through ``point``
    with ``normal`` (base frame): a hedge's face to first order. A pixel whose ray
    misses the plane sees the sky (0); none is nearer than :data:`MIN_DEPTH`."""
    R, p = T_base_camera[:3, :3], T_base_camera[:3, 3]
    n = R.T @ np.asarray(normal, float)
    h = float(n @ (R.T @ (np.asarray(point, float) - p)))  # the plane's offset, camera frame
    x, y = _grid(focal, principal, size)
    facing = n[0] * x + n[1] * y + n[2]  # n . (x, y, 1): the ray's approach to the plane
    if abs(h) < 1e-9:
        inverse = np.where(facing != 0, np.inf, 0.0)
    else:
        inverse = facing / h
    result: FloatArray = np.clip(inverse, 0.0, 1.0 / MIN_DEPTH)
    return result


def swept_flow(
    size: tuple[int, int],
    centres: FloatArray,
    velocities: FloatArray,
    radii: FloatArray,
    exposure_s: float,
    origin: tuple[int, int] = (0, 0),
) -> Flow:
    """(H, W, 2) image velocity (px/s) of a frame of ``size`` (W, H) whose top-left
    pixel is ``origin`` of the whole image: each moving part, a disc at ``centres``
    (N, 2) px of ``radii`` (N,) px moving at ``velocities`` (N, 2) px/s, paints its
    velocity over the band it sweeps during ``exposure_s``; the rest is still (0).
    Later parts paint over earlier ones (list the fast end last)."""
    w, h = size
    flow = np.zeros((h, w, 2), np.float32)
    c = np.asarray(centres, float).reshape(-1, 2)
    vel = np.asarray(velocities, float).reshape(-1, 2)
    half = 0.5 * exposure_s * vel
    ok = np.isfinite(c).all(axis=1) & np.isfinite(half).all(axis=1)
    ok &= np.hypot(half[:, 0], half[:, 1]) >= 0.5  # else not drawn, or under a pixel
    with np.errstate(invalid="ignore"):
        # Clipped far outside the frame: cv2.line takes 32-bit coordinates.
        a = np.clip(np.round(c - half - origin), -1e6, 1e6)
        b = np.clip(np.round(c + half - origin), -1e6, 1e6)
    thick = np.maximum(1, np.round(2 * np.asarray(radii, float)) + 1)
    # A band wholly off the frame paints nothing: skipped (a window sees few parts).
    reach = thick / 2 + 2
    ok &= np.isfinite(thick)
    ok &= (np.minimum(a[:, 0], b[:, 0]) - reach < w) & (np.maximum(a[:, 0], b[:, 0]) + reach >= 0)
    ok &= (np.minimum(a[:, 1], b[:, 1]) - reach < h) & (np.maximum(a[:, 1], b[:, 1]) + reach >= 0)
    for i in np.flatnonzero(ok):
        cv2.line(flow, (int(a[i, 0]), int(a[i, 1])), (int(b[i, 0]), int(b[i, 1])),
                 (float(vel[i, 0]), float(vel[i, 1])), int(thick[i]))  # fmt: skip
    return flow


def flow_blur(
    light: npt.NDArray[np.float32], shift: Flow, still: npt.NDArray[np.bool_] | None = None
) -> npt.NDArray[np.float32]:
    """``light`` (H, W, C) float with each pixel averaged along its ``shift`` (H, W, 2):
    its motion (px) during the exposure, centred on where it is drawn. ``still``: pixels
    of a part that moves with the camera (C2's fingers): they stay sharp, and the scene
    sliding behind them takes none of their light (their samples are left out). Only
    the box around the pixels that move a pixel or more is touched; ``light`` back as
    it was when none does."""
    length = np.hypot(shift[..., 0], shift[..., 1])
    moving = length >= 1.0
    if still is not None:
        moving &= ~still
    if not moving.any():
        return light
    rows, cols = np.flatnonzero(moving.any(axis=1)), np.flatnonzero(moving.any(axis=0))
    y0, y1, x0, x1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
    box = np.where(moving[y0:y1, x0:x1, None], shift[y0:y1, x0:x1], np.float32(0.0))
    n = int(min(MAX_SAMPLES, max(2, np.ceil(float(length[y0:y1, x0:x1].max())) + 1)))
    grid = np.empty((y1 - y0, x1 - x0, 2), np.float32)
    grid[..., 0] = np.arange(x0, x1, dtype=np.float32)
    grid[..., 1] = np.arange(y0, y1, dtype=np.float32)[:, None]
    source = light
    if still is not None:
        # The light is sampled with its weight (1 off the still part, 0 on it) as a
        # last channel: one remap a sample gives both.
        source = np.empty((*light.shape[:2], light.shape[2] + 1), np.float32)
        source[..., -1] = ~still
        np.multiply(light, source[..., -1:], out=source[..., :-1])
    total = np.zeros((y1 - y0, x1 - x0, source.shape[2]), np.float32)
    shifted = np.empty_like(grid)
    for s in np.linspace(-0.5, 0.5, n, dtype=np.float32):
        np.multiply(box, s, out=shifted)
        shifted += grid
        # One (H, W, 2) map, no second one: the stubs want an array where None works.
        sample = cv2.remap(source, shifted, None, cv2.INTER_LINEAR,  # type: ignore[call-overload]
                           borderMode=cv2.BORDER_REPLICATE)  # fmt: skip
        total += sample.reshape(total.shape)
    out = light.copy()
    inner = out[y0:y1, x0:x1]
    if still is None:
        np.copyto(inner, total / np.float32(n), where=moving[y0:y1, x0:x1, None])
        return out
    count = total[..., -1:]
    # A pixel whose every sample fell on the still part keeps its light.
    blurred = moving[y0:y1, x0:x1, None] & (count > 1e-3)
    np.copyto(inner, total[..., :-1] / np.maximum(count, np.float32(1e-3)), where=blurred)
    return out


def check_flow(flow: object, shape: tuple[int, ...]) -> Flow:
    """``flow`` as an (H, W, 2) float32 array of the image's ``shape[:2]``.

    Raises:
        ParameterError: another shape, or a value not finite.
    """
    array = np.asarray(flow, np.float32)
    if array.shape != (*shape[:2], 2):
        raise ParameterError(f"flow_px_s must be {(*shape[:2], 2)}, got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ParameterError("flow_px_s must be finite")
    return array
