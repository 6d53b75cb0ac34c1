"""Textures for the synthetic camera: ArUco markers with a white quiet zone, and scene items.

A :class:`TexturedPlane` is a flat rectangle carrying a gray texture; a :class:`SceneMarker`
is an ArUco marker (the cube's faces, the base tag, the berry tag) that converts itself to
one. Plane frames follow OpenCV's ArUco convention: origin at the centre, x right, y up,
z out of the visible face.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import cv2
import numpy as np
import numpy.typing as npt

from softarm.checks import FloatArray, as_pose, positive
from softarm.errors import ParameterError
from softarm.vision.dictionaries import check_marker_id, get_dictionary

# Texture resolution is chosen per frame (texels per marker cell) so that one texel is
# about one sub-sample; the cap bounds the memory of a marker seen from very close.
MAX_TEXELS_PER_CELL = 96


@dataclass(frozen=True)
class TexturedPlane:
    """A ``width`` x ``height`` (m) rectangle at ``T_camera_plane`` showing ``texture``.

    ``texture`` is a 2-D array of reflectance in [0, 1]; row 0 is the top edge (+y).
    """

    texture: npt.NDArray[np.float32]
    width: float
    height: float
    T_camera_plane: FloatArray

    def __post_init__(self) -> None:
        tex = np.asarray(self.texture, dtype=np.float32)
        if tex.ndim != 2 or min(tex.shape) == 0:
            raise ParameterError(f"texture must be a non-empty 2-D array, got shape {tex.shape}")
        object.__setattr__(self, "texture", tex)
        object.__setattr__(self, "width", positive(self.width, "width"))
        object.__setattr__(self, "height", positive(self.height, "height"))
        object.__setattr__(self, "T_camera_plane", as_pose(self.T_camera_plane, "T_camera_plane"))


@dataclass(frozen=True)
class SceneMarker:
    """ArUco ``marker_id`` of ``dictionary``, side ``marker_length`` (m), at ``T_camera_marker``.

    ``border`` is the width (m) of the white quiet zone printed around the marker; None
    means ``marker_length / 8`` (an 80 mm marker on a 100 mm cube face).
    """

    marker_id: int
    dictionary: str
    marker_length: float
    T_camera_marker: FloatArray
    border: float | None = None

    def __post_init__(self) -> None:
        check_marker_id(self.dictionary, self.marker_id)
        object.__setattr__(self, "marker_length", positive(self.marker_length, "marker_length"))
        object.__setattr__(
            self, "T_camera_marker", as_pose(self.T_camera_marker, "T_camera_marker")
        )
        if self.border is not None and (not np.isfinite(self.border) or self.border < 0):
            raise ParameterError(f"border must be >= 0, got {self.border!r}")

    def to_plane(self, texels_per_cell: int) -> TexturedPlane:
        """The marker as a textured plane with ``texels_per_cell`` texels per marker cell."""
        cells = get_dictionary(self.dictionary).markerSize + 2
        cell = self.marker_length / cells
        border = self.marker_length / 8 if self.border is None else float(self.border)
        k = int(np.clip(texels_per_cell, 1, MAX_TEXELS_PER_CELL))
        pad = round(border / cell * k)
        tex = marker_texture(self.dictionary, self.marker_id, k, pad)
        side = self.marker_length + 2 * pad * cell / k
        return TexturedPlane(tex, side, side, self.T_camera_marker)


@lru_cache(maxsize=256)
def marker_texture(
    dictionary: str, marker_id: int, texels_per_cell: int, pad: int
) -> npt.NDArray[np.float32]:
    """Reflectance texture (0 black, 1 white) of a marker with ``pad`` white texels around."""
    cells = get_dictionary(dictionary).markerSize + 2
    bits = cv2.aruco.generateImageMarker(get_dictionary(dictionary), int(marker_id), cells)
    # Each cell repeated texels_per_cell times along both axes (a Kronecker product with a
    # block of ones, without multiplying), then the white quiet zone.
    big = np.repeat(
        np.repeat(bits.astype(np.float32) / 255.0, texels_per_cell, 0), texels_per_cell, 1
    )
    out = np.pad(big, pad, constant_values=1.0)
    out.setflags(write=False)
    return out


def cube_scene_markers(
    markers: dict[int, FloatArray],
    marker_length: float,
    dictionary: str,
    T_camera_cube: npt.ArrayLike,
    border: float | None = None,
) -> list[SceneMarker]:
    """Scene markers of a marker cube (``MarkerCube.markers``) posed at ``T_camera_cube``."""
    pose = as_pose(T_camera_cube, "T_camera_cube")
    return [SceneMarker(i, dictionary, marker_length, pose @ m, border) for i, m in markers.items()]
