"""ArUco dictionaries by name (``"DICT_4X4_50"``), resolved through ``cv2.aruco`` constants.

Names are looked up with ``getattr`` because OpenCV 5 renumbered several enums: a name is
stable across versions, an integer is not.
"""

from __future__ import annotations

from functools import cache

import cv2

from softarm.errors import ParameterError


@cache
def get_dictionary(name: str) -> cv2.aruco.Dictionary:
    """The predefined ArUco dictionary called ``name`` (e.g. ``"DICT_4X4_50"``)."""
    if not isinstance(name, str) or not name.startswith("DICT_"):
        raise ParameterError(f"dictionary must be a name like 'DICT_4X4_50', got {name!r}")
    const = getattr(cv2.aruco, name, None)
    if not isinstance(const, int):
        raise ParameterError(f"dictionary {name!r} is not a cv2.aruco predefined dictionary")
    return cv2.aruco.getPredefinedDictionary(const)


def dictionary_size(name: str) -> int:
    """Number of marker ids in dictionary ``name``."""
    return int(get_dictionary(name).bytesList.shape[0])


def check_marker_id(name: str, marker_id: int) -> int:
    """Return ``marker_id`` as int if it is valid in dictionary ``name``."""
    size = dictionary_size(name)
    if isinstance(marker_id, bool) or not 0 <= int(marker_id) < size or marker_id != int(marker_id):
        raise ParameterError(
            f"marker id must be an integer in [0, {size}) for {name}, got {marker_id!r}"
        )
    return int(marker_id)
