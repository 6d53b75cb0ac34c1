"""Pinhole camera intrinsics with OpenCV lens distortion, saved as JSON, OpenCV FileStorage
or ROS camera_info (:mod:`softarm.vision.camera_files`).

softarm's own file format (JSON, UTF-8), version ``softarm.camera/1``::

    {
      "format": "softarm.camera/1",
      "image_size": [1280, 720],            # [width, height] in pixels, or null
      "camera_matrix": [[fx, 0, cx], [0, fy, cy], [0, 0, 1]],   # pixels
      "distortion": [k1, k2, p1, p2, k3]    # OpenCV order; 0, 4, 5, 8, 12 or 14 values
    }

Pixel coordinates follow OpenCV: origin at the centre of the top-left pixel, x right,
y down; the camera frame has z along the optical axis, x right, y down.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import cv2
import numpy as np
import numpy.typing as npt

from softarm.errors import ConfigError, ParameterError, ShapeError
from softarm.files import read_text, write_text
from softarm.vision._checks import FloatArray, as_array


class CameraIntrinsicsSource(Protocol):
    """Where a configuration keeps one camera's intrinsics (``softarm.config.CameraConfig``,
    which sits above vision): a file's resolved path, or an inline matrix and distortion."""

    @property
    def path(self) -> str | None: ...

    @property
    def matrix(self) -> Sequence[Sequence[float]] | None: ...

    @property
    def distortion(self) -> Sequence[float] | None: ...


FORMAT = "softarm.camera/1"
_DIST_LENGTHS = (0, 4, 5, 8, 12, 14)
#: Focal lengths in pixels: below 1 px the whole field of view falls inside one pixel
#: (fx = 1e-300 made ``normalize`` return inf); above 1e7 px a lens would see less than
#: a thousandth of a degree.
FOCAL_PX = (1.0, 1e7)
#: Largest principal point, skew and image side (pixels).
MAX_PIXELS = 1e7


def _check_intrinsics(mat: FloatArray) -> None:
    """fx, fy within :data:`FOCAL_PX`; cx, cy and the skew within :data:`MAX_PIXELS`."""
    lo, hi = FOCAL_PX
    for name, value in (("fx", mat[0, 0]), ("fy", mat[1, 1])):
        if not lo <= value <= hi:
            raise ParameterError(f"matrix {name} = {value!r}: must be in [{lo:g}, {hi:g}] px")
    for name, value in (("skew", mat[0, 1]), ("cx", mat[0, 2]), ("cy", mat[1, 2])):
        if not abs(value) <= MAX_PIXELS:
            raise ParameterError(f"matrix {name} = {value!r}: must be within +-{MAX_PIXELS:g} px")


def _image_size(size: Any) -> tuple[int, int]:
    """``(width, height)`` as two whole numbers in [1, MAX_PIXELS]; 1.9 is refused, not
    truncated to 1."""
    ok = isinstance(size, list | tuple | np.ndarray) and len(size) == 2
    values = list(size) if ok else []
    if not ok or not all(
        isinstance(v, int | float | np.integer | np.floating)
        and not isinstance(v, bool)
        and float(v).is_integer()
        and 1 <= v <= MAX_PIXELS
        for v in values
    ):
        raise ParameterError(
            f"image_size must be (width, height), whole numbers in [1, {MAX_PIXELS:g}], "
            f"got {size!r}"
        )
    return int(values[0]), int(values[1])


@dataclass(frozen=True)
class CameraModel:
    """Intrinsics ``matrix`` (3x3, pixels) and OpenCV ``distortion`` coefficients.

    ``distortion`` None means no distortion, as in OpenCV (stored as five zeros, the
    default). ``image_size`` is ``(width, height)`` in pixels when known. Arrays are
    validated and stored as read-only float64.
    """

    matrix: FloatArray
    distortion: FloatArray = field(default_factory=lambda: np.zeros(5))
    image_size: tuple[int, int] | None = None

    def __post_init__(self) -> None:
        mat = as_array(self.matrix, (3, 3), "matrix")
        if not (mat[0, 0] > 0 and mat[1, 1] > 0) or not np.allclose(mat[2], [0, 0, 1]):
            raise ParameterError(
                f"matrix must be [[fx, s, cx], [0, fy, cy], [0, 0, 1]] with fx, fy > 0, "
                f"got {mat.tolist()}"
            )
        if abs(mat[1, 0]) > 0:
            raise ParameterError(f"matrix[1, 0] must be 0, got {mat[1, 0]}")
        _check_intrinsics(mat)
        raw = np.zeros(5) if self.distortion is None else self.distortion
        dist = as_array(np.ravel(np.asarray(raw, dtype=object)), (None,), "distortion")
        if dist.size not in _DIST_LENGTHS:
            raise ShapeError(
                f"distortion must have one of {_DIST_LENGTHS} coefficients, got {dist.size}"
            )
        if self.image_size is not None:
            object.__setattr__(self, "image_size", _image_size(self.image_size))
        mat.setflags(write=False)
        dist.setflags(write=False)
        object.__setattr__(self, "matrix", mat)
        object.__setattr__(self, "distortion", dist)

    @classmethod
    def ideal(
        cls, focal: float, width: int, height: int, distortion: npt.ArrayLike | None = None
    ) -> CameraModel:
        """A camera with square pixels of focal length ``focal`` (px), centred principal point."""
        mat = np.array([[focal, 0.0, (width - 1) / 2], [0.0, focal, (height - 1) / 2], [0, 0, 1]])
        dist = np.zeros(5) if distortion is None else np.asarray(distortion, dtype=np.float64)
        return cls(mat, dist, (width, height))

    @property
    def focal(self) -> float:
        """Mean focal length in pixels."""
        return float(0.5 * (self.matrix[0, 0] + self.matrix[1, 1]))

    def project(self, points: npt.ArrayLike) -> FloatArray:
        """Project (N, 3) points in the camera frame to (N, 2) distorted pixel coordinates."""
        pts = as_array(points, (None, 3), "points")
        if pts.shape[0] == 0:
            return np.zeros((0, 2))
        if np.any(pts[:, 2] <= 0.0):
            raise ParameterError("points must lie in front of the camera (z > 0)")
        pix, _ = cv2.projectPoints(pts, np.zeros(3), np.zeros(3), self.matrix, self.distortion)
        return np.asarray(pix, dtype=np.float64).reshape(-1, 2)

    def normalize(self, pixels: npt.ArrayLike) -> FloatArray:
        """Undistort (N, 2) pixel coordinates to normalised image coordinates (x/z, y/z)."""
        pix = as_array(pixels, (None, 2), "pixels")
        if pix.shape[0] == 0:
            return np.zeros((0, 2))
        criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-12)
        out = cv2.undistortPoints(
            pix.reshape(-1, 1, 2), self.matrix, self.distortion, R=None, P=None, criteria=criteria
        )
        return np.asarray(out, dtype=np.float64).reshape(-1, 2)

    def to_dict(self) -> dict[str, Any]:
        """The JSON-ready dictionary of the documented file format."""
        return {
            "format": FORMAT,
            "image_size": list(self.image_size) if self.image_size else None,
            "camera_matrix": self.matrix.tolist(),
            "distortion": self.distortion.tolist(),
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any], source: str = "camera file") -> CameraModel:
        """Build from the dictionary of the documented file format; ``source`` names the
        file in errors."""
        if not isinstance(data, dict) or data.get("format") != FORMAT:
            fmt = data.get("format") if isinstance(data, dict) else data
            raise ConfigError(f"{source}: format must be {FORMAT!r}, got {fmt!r}")
        if "camera_matrix" not in data:
            raise ConfigError(f"{source}: camera_matrix is required")
        try:
            return cls(data["camera_matrix"], data.get("distortion", []), data.get("image_size"))
        except (TypeError, ValueError) as exc:  # the model's own InputErrors are ValueErrors
            raise ConfigError(f"{source}: {exc}") from None

    def save(
        self, path: str | Path, format: str | None = None, *, camera_name: str = "camera"
    ) -> None:
        """Write the model to ``path``. ``format``: ``"json"`` (softarm's, see the module
        docstring), ``"opencv"`` (``cv2.FileStorage``, as OpenCV's calibration sample
        writes) or ``"ros"`` (a ROS camera_info YAML named ``camera_name``); None picks
        by extension (``.json``; ``.yml``/``.xml`` OpenCV; ``.yaml`` ROS).

        Raises:
            ConfigError: unknown format or extension, a model the format cannot hold
                (ROS needs the image size), or the file cannot be written.
        """
        from softarm.vision import camera_files

        fmt = camera_files.format_for_path(path) if format is None else format
        if fmt == "json":
            write_text(path, json.dumps(self.to_dict(), indent=2) + "\n", "camera file")
        elif fmt == "opencv":
            camera_files.write_opencv(self, path)
        elif fmt == "ros":
            camera_files.write_ros(self, path, camera_name)
        else:
            raise ConfigError(f"format must be one of {camera_files.FORMATS} or None, got {fmt!r}")

    @classmethod
    def load(cls, path: str | Path) -> CameraModel:
        """Read a camera file: softarm JSON, OpenCV FileStorage (YAML, XML or JSON) or ROS
        camera_info YAML, told apart by their contents.

        Raises:
            ConfigError: the file cannot be read, is in none of these formats, or holds
                an invalid model (the message names the file and the field).
        """
        from softarm.vision import camera_files

        text = read_text(path, "camera file")
        fmt, fields = camera_files.read_camera_file(path, text)
        if fmt == "json":
            return cls.from_dict(fields, f"camera file {str(path)!r}")
        try:
            return cls(fields["matrix"], fields["distortion"], fields["image_size"])
        except (ValueError, TypeError) as exc:
            raise ConfigError(f"camera file {str(path)!r} ({fmt}): {exc}") from exc

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, CameraModel):
            return NotImplemented
        return (
            np.array_equal(self.matrix, other.matrix)
            and np.array_equal(self.distortion, other.distortion)
            and self.image_size == other.image_size
        )

    __hash__ = None  # type: ignore[assignment]


def camera_from_config(cam: CameraIntrinsicsSource, name: str) -> CameraModel:
    """The intrinsics of camera ``name`` (``c1``, ``c2``) of a configuration: its
    ``file`` (resolved against the config file's folder), else its inline ``matrix``
    and ``distortion``.

    Raises:
        ConfigError: neither is given, the file is missing or unparsable, or the inline
            values are not a camera (the message names the key).
    """
    if cam.path is not None:
        try:
            return CameraModel.load(cam.path)
        except ConfigError as exc:
            raise ConfigError(f"calibration.{name}.file: {exc}") from None
    if cam.matrix is None:
        raise ConfigError(f"calibration.{name}: no intrinsics (matrix or file) in the config")
    try:
        return CameraModel(np.array(cam.matrix), np.array(cam.distortion or [0.0] * 5))
    except ValueError as exc:  # the model's InputErrors
        raise ConfigError(f"calibration.{name}: {exc}") from None
