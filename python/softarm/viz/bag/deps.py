"""The optional rosbags package (the ``ros`` extra): checked before a run starts, with a
one-line error that says how to install it."""

from __future__ import annotations

import importlib
from typing import Any

from softarm.errors import MissingDependencyError

__all__ = ["DISTRO", "INSTALL", "require_rosbags", "typestore"]

INSTALL = 'pip install "softarm[ros]" (or pip install rosbags)'
#: The ROS 2 distribution whose message definitions the bags carry (an LTS release).
DISTRO = "ROS2_JAZZY"


def require_rosbags() -> Any:
    """The ``rosbags.rosbag2`` module, or :class:`MissingDependencyError` naming the extra."""
    try:
        importlib.import_module("rosbags.typesys")
        return importlib.import_module("rosbags.rosbag2")
    except ImportError as exc:
        raise MissingDependencyError(
            f"--bag needs rosbags, the optional extra 'ros' ({exc.name} missing): {INSTALL}",
            "ros",
        ) from None


def typestore() -> Any:
    """The message types of :data:`DISTRO` (rosbags' standard definitions)."""
    require_rosbags()
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(getattr(Stores, DISTRO))
