"""The ``--world`` option: its value parsed into a :class:`~softarm.sim.world.WorldName`
once, at the command line, so that no command compares world names as strings."""

from __future__ import annotations

import argparse
from collections.abc import Callable

from softarm.sim.world import WorldName

__all__ = ["world_metavar", "world_type"]


def world_type(*allowed: WorldName) -> Callable[[str], WorldName]:
    """An argparse ``type`` taking one of ``allowed`` by its name."""

    def world(value: str) -> WorldName:
        if value in allowed:
            return WorldName(value)
        names = ", ".join(repr(w.value) for w in allowed)
        raise argparse.ArgumentTypeError(f"invalid choice: {value!r} (choose from {names})")

    return world


def world_metavar(*allowed: WorldName) -> str:
    """``{tags,bush,row}`` for the help, as argparse writes choices."""
    return "{" + ",".join(w.value for w in allowed) + "}"
