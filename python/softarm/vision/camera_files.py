"""Camera calibration files in the formats other tools write: OpenCV ``FileStorage`` and
ROS ``camera_info`` YAML (besides softarm's own JSON, :mod:`softarm.vision.camera_model`).

**OpenCV** (``cv2.FileStorage``, YAML, XML or JSON), as OpenCV's calibration sample
(``samples/cpp/calibration.cpp``) writes it: ``image_width``, ``image_height``,
``camera_matrix`` (3x3 ``opencv-matrix``) and ``distortion_coefficients`` (N x 1); other
keys (``calibration_time``, ``avg_reprojection_error``, per-view extrinsics) are ignored.
``cameraMatrix`` / ``distCoeffs`` are accepted as the two matrices' names too.

**ROS** ``sensor_msgs/CameraInfo`` YAML, as ``camera_calibration`` (``ost.yaml``) and
``camera_calibration_parsers`` write it: ``image_width``, ``image_height``,
``camera_name``, ``camera_matrix``, ``distortion_model``, ``distortion_coefficients``,
``rectification_matrix`` and ``projection_matrix``, each matrix as ``{rows, cols, data}``.
``plumb_bob`` (k1 k2 p1 p2 k3) and ``rational_polynomial`` (k1 k2 p1 p2 k3 k4 k5 k6) are
OpenCV's own models and are read as they are; ``equidistant`` (fisheye) is a different
lens model and is refused. A monocular camera has the identity rectification; the
projection matrix is written as ``[K | 0]`` and ignored when read (it describes the
rectified image, which softarm does not use).

Both are parsed with ``cv2.FileStorage`` (OpenCV reads YAML with or without the
``%YAML`` line), so no YAML library is needed.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import cv2
import numpy as np

from softarm.errors import ConfigError
from softarm.files import parse_json, write_text

if TYPE_CHECKING:
    from softarm.vision.camera_model import CameraModel

__all__ = ["FORMATS", "format_for_path", "read_camera_file", "write_opencv", "write_ros"]

#: ``CameraModel.save`` formats: softarm JSON, OpenCV FileStorage, ROS camera_info.
FORMATS = ("json", "opencv", "ros")
# The ROS names of OpenCV's distortion models, by number of coefficients.
_ROS_MODELS = {5: "plumb_bob", 8: "rational_polynomial"}
_ROS_LENGTHS = {"plumb_bob": (4, 5), "rational_polynomial": (8,)}


def format_for_path(path: str | Path) -> str:
    """The format :meth:`CameraModel.save` writes for ``path``'s extension: ``.json`` →
    softarm JSON, ``.yml`` / ``.xml`` → OpenCV FileStorage, ``.yaml`` → ROS camera_info
    (the name ROS' ``camera_calibration`` gives its ``ost.yaml``)."""
    suffix = Path(path).suffix.lower()
    by_suffix = {".json": "json", ".yml": "opencv", ".xml": "opencv", ".yaml": "ros"}
    if suffix not in by_suffix:
        raise ConfigError(
            f"cannot tell the camera file format from the extension of {str(path)!r}: use "
            f".json, .yml/.xml (OpenCV) or .yaml (ROS), or pass format= one of {FORMATS}"
        )
    return by_suffix[suffix]


def read_camera_file(path: str | Path, text: str) -> tuple[str, dict[str, Any]]:
    """(format, fields) of a camera file whose contents are ``text``; ``fields`` has
    ``matrix``, ``distortion`` and ``image_size`` for the OpenCV and ROS formats and is
    the parsed JSON object for softarm's own format."""
    body = text.lstrip("\ufeff \t\r\n")
    if body.startswith("{"):
        data = parse_json(body, f"camera file {str(path)!r}")
        if isinstance(data, dict) and "format" in data:
            return "json", data
        # OpenCV FileStorage writes JSON too: {"camera_matrix": {"type_id": "opencv-matrix"...
    fs = _open(path, body)
    try:
        return _read_fields(fs, path)
    except cv2.error as exc:  # a node of the wrong kind (a scalar where a matrix goes)
        raise ConfigError(f"camera file {str(path)!r}: {_cv_reason(exc)}") from None
    finally:
        fs.release()


def _cv_reason(exc: BaseException) -> str:
    """The last line of an OpenCV error: the reason, without the source location."""
    text = str(exc).strip()
    last = text.splitlines()[-1] if text else type(exc).__name__
    return last.split(" error: ", 1)[-1]


def _read_fields(fs: Any, path: str | Path) -> tuple[str, dict[str, Any]]:
    """(format, fields) of an opened OpenCV or ROS camera file."""
    if not fs.root().isMap():
        raise ConfigError(f"camera file {str(path)!r} is not a map of named fields")
    node = _first(fs, ("camera_matrix", "cameraMatrix"))
    if node is None:
        raise ConfigError(
            f"camera file {str(path)!r} has no camera_matrix: not a softarm JSON, "
            "OpenCV FileStorage or ROS camera_info file"
        )
    if node.isMap() and node.getNode("dt").isNone():
        return "ros", _read_ros(fs, path)
    return "opencv", _read_opencv(fs, path)


def write_opencv(model: CameraModel, path: str | Path) -> None:
    """Write ``model`` as OpenCV's calibration sample does (YAML for .yml/.yaml, XML for
    .xml, JSON for .json: FileStorage picks by extension)."""
    fs = memory_storage(path, "camera file")
    if model.image_size is not None:
        fs.write("image_width", int(model.image_size[0]))
        fs.write("image_height", int(model.image_size[1]))
    fs.write("camera_matrix", np.asarray(model.matrix, dtype=np.float64))
    fs.write("distortion_coefficients", model.distortion.reshape(-1, 1).astype(np.float64))
    write_text(path, fs.releaseAndGetString(), "camera file")


def memory_storage(path: str | Path, what: str) -> Any:
    """A ``cv2.FileStorage`` writing into memory in the format of ``path``'s suffix: the
    text is then written by :func:`~softarm.files.write_text`, so OpenCV never sees the
    path (a name that is not UTF-8 crashes it)."""
    try:
        fs = cv2.FileStorage(Path(path).suffix, cv2.FILE_STORAGE_WRITE | cv2.FILE_STORAGE_MEMORY)
    except cv2.error as exc:
        raise ConfigError(f"cannot write {what} {str(path)!r}: {_cv_reason(exc)}") from None
    if not fs.isOpened():
        raise ConfigError(f"cannot write {what} {str(path)!r}")
    return fs


def write_ros(model: CameraModel, path: str | Path, camera_name: str = "camera") -> None:
    """Write ``model`` as a ROS camera_info YAML (see the module docstring)."""
    if model.image_size is None:
        raise ConfigError("a ROS camera_info file needs the image size: model.image_size is None")
    dist = np.asarray(model.distortion, dtype=np.float64)
    if dist.size in (0, 4):
        dist = np.concatenate([dist, np.zeros(5 - dist.size)])  # plumb_bob has k3
    if dist.size not in _ROS_MODELS:
        raise ConfigError(
            f"ROS camera_info has no distortion model with {dist.size} coefficients "
            "(plumb_bob: 5, rational_polynomial: 8)"
        )
    name = str(camera_name)
    if not name or any(c in name for c in ":#{}[],&*!|>'\"%@`\n"):
        raise ConfigError(f"camera_name must be a plain word for YAML, got {camera_name!r}")
    k = np.asarray(model.matrix, dtype=np.float64)
    proj = np.hstack([k, np.zeros((3, 1))])
    width, height = model.image_size
    lines = [
        f"image_width: {int(width)}",
        f"image_height: {int(height)}",
        f"camera_name: {name}",
        *_ros_matrix("camera_matrix", k),
        f"distortion_model: {_ROS_MODELS[dist.size]}",
        *_ros_matrix("distortion_coefficients", dist.reshape(1, -1)),
        *_ros_matrix("rectification_matrix", np.eye(3)),
        *_ros_matrix("projection_matrix", proj),
    ]
    write_text(path, "\n".join(lines) + "\n", "camera file")


def _ros_matrix(name: str, mat: np.ndarray) -> list[str]:
    # repr() of a float is the shortest string that reads back to the same double.
    data = ", ".join(repr(float(v)) for v in mat.ravel())
    rows, cols = mat.shape
    return [f"{name}:", f"  rows: {rows}", f"  cols: {cols}", f"  data: [{data}]"]


def _open(path: str | Path, body: str, what: str = "camera file") -> Any:
    # OpenCV's own errors for these are opaque (a SystemError, an assertion on "buf").
    if not body.strip():
        raise ConfigError(f"{what} {str(path)!r} is empty")
    if "\0" in body:
        raise ConfigError(f"{what} {str(path)!r} holds a NUL byte: it is not a text file")
    try:  # the text itself, never a path: OpenCV takes a path as a C string
        fs = cv2.FileStorage(body, cv2.FILE_STORAGE_READ | cv2.FILE_STORAGE_MEMORY)
    except (cv2.error, SystemError) as exc:
        # A parse error surfaces as a SystemError whose cause is the cv2.error.
        cause = exc.__cause__ if isinstance(exc.__cause__, cv2.error) else exc
        text = " ".join(str(cause).split()).partition(" error: ")[2].partition(") ")[2]
        why = text.replace(" in function ", ": ")[:200] or type(exc).__name__
        raise ConfigError(f"cannot parse {what} {str(path)!r}: {why}") from None
    if not fs.isOpened():
        raise ConfigError(f"cannot parse {what} {str(path)!r}")
    return fs


def _first(fs: Any, names: tuple[str, ...]) -> Any:
    for name in names:
        node = fs.getNode(name)
        if not node.isNone():
            return node
    return None


#: Largest image side and matrix dimension read from a camera file (pixels, rows).
MAX_PIXELS = 100_000


def _whole(node: Any, name: str, path: str | Path, lo: int, hi: int) -> int:
    """A node holding a whole number in [lo, hi] (an integral real is accepted: some
    writers put 640.0). NaN, 1.5, a string or a map are one ConfigError naming it."""
    value = node.real() if (node.isInt() or node.isReal()) else None
    if value is None or not (value == value and float(value).is_integer() and lo <= value <= hi):
        raise ConfigError(
            f"camera file {str(path)!r}: {name} must be a whole number in [{lo}, {hi}]"
        )
    return int(value)


def _size(fs: Any, path: str | Path) -> tuple[int, int] | None:
    w, h = fs.getNode("image_width"), fs.getNode("image_height")
    if w.isNone() and h.isNone():
        return None
    return (
        _whole(w, "image_width", path, 1, MAX_PIXELS),
        _whole(h, "image_height", path, 1, MAX_PIXELS),
    )


def _mat(node: Any, name: str, path: str | Path) -> Any:
    """The matrix of an ``opencv-matrix`` node (None when empty); a node that is not one
    (a scalar, wrong rows, an unknown dt) is a ConfigError naming ``name``."""
    try:
        return node.mat()
    except cv2.error as exc:
        raise ConfigError(
            f"camera file {str(path)!r}: {name} is not a valid opencv-matrix ({_cv_reason(exc)})"
        ) from None


def _read_opencv(fs: Any, path: str | Path) -> dict[str, Any]:
    mat = _mat(_first(fs, ("camera_matrix", "cameraMatrix")), "camera_matrix", path)
    if mat is None:
        raise ConfigError(f"camera file {str(path)!r}: camera_matrix is not an opencv-matrix")
    node = _first(fs, ("distortion_coefficients", "distCoeffs"))
    dist = None if node is None else _mat(node, "distortion_coefficients", path)
    return {
        "matrix": np.asarray(mat, dtype=np.float64),
        # An empty matrix reads back as None: no distortion.
        "distortion": np.zeros(0) if dist is None else np.asarray(dist, dtype=np.float64).ravel(),
        "image_size": _size(fs, path),
    }


def _read_ros(fs: Any, path: str | Path) -> dict[str, Any]:
    mat = _ros_data(fs, "camera_matrix", path, (3, 3))
    model = fs.getNode("distortion_model")
    name = "plumb_bob" if model.isNone() else model.string()
    dist = np.zeros(0)
    if not fs.getNode("distortion_coefficients").isNone():
        dist = _ros_data(fs, "distortion_coefficients", path, None).ravel()
    if name not in _ROS_LENGTHS:
        raise ConfigError(
            f"camera file {str(path)!r}: distortion_model {name!r} is not supported "
            f"(supported: {', '.join(_ROS_LENGTHS)}; a fisheye lens needs another model)"
        )
    if dist.size not in (0, *_ROS_LENGTHS[name]):
        raise ConfigError(
            f"camera file {str(path)!r}: distortion_model {name!r} takes "
            f"{' or '.join(map(str, _ROS_LENGTHS[name]))} coefficients, got {dist.size}"
        )
    return {"matrix": mat, "distortion": dist, "image_size": _size(fs, path)}


def _ros_data(fs: Any, name: str, path: str | Path, shape: tuple[int, int] | None) -> np.ndarray:
    node = fs.getNode(name)
    data = node.getNode("data")
    if not node.isMap() or not data.isSeq():
        raise ConfigError(f"camera file {str(path)!r}: {name} must be a map with a data list")
    items = [data.at(i) for i in range(data.size())]
    # A string element reads as real() = DBL_MAX: check each element's kind first.
    bad = next((i for i, item in enumerate(items) if not (item.isInt() or item.isReal())), None)
    if bad is not None:
        raise ConfigError(f"camera file {str(path)!r}: {name}.data[{bad}] must be a number")
    values = np.array([float(item.real()) for item in items])
    rows, cols = node.getNode("rows"), node.getNode("cols")
    r = _whole(rows, f"{name}.rows", path, 1, MAX_PIXELS) if not rows.isNone() else None
    c = _whole(cols, f"{name}.cols", path, 1, MAX_PIXELS) if not cols.isNone() else None
    r = r if r is not None else (shape[0] if shape else 1)
    c = c if c is not None else (shape[1] if shape else values.size)
    if r * c != values.size or (shape is not None and (r, c) != shape):
        want = f"{shape[0]}x{shape[1]}" if shape else f"{r}x{c}"
        raise ConfigError(
            f"camera file {str(path)!r}: {name} must be {want} ({r} rows x {c} cols), "
            f"got {values.size} values"
        )
    return values.reshape(r, c)
