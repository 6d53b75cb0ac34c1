"""The checks of a frames folder's index (``frames.json``, :mod:`softarm.harvest.
frame_files`), made where it is read and before anything is replayed: every frame entry
and every stream the dry run reads must have the types the recorder writes, or the
replay could fail half-way (a string where a time belongs), or compare NaN with NaN and
call the result "the same" (``max(0.0, nan)`` is 0.0), or read a file outside the folder.

Each failure is one :class:`~softarm.errors.ConfigError` line naming the index, the
entry or stream, and the field.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from softarm.errors import ConfigError

__all__ = [
    "BERRY_STATES",
    "COMMANDS",
    "RIPENESS",
    "SEED",
    "check_entry",
    "check_streams",
    "is_number",
]

#: The stream of pressure commands: ``["set", t, [psi, ...]]`` or ``["vent", t]``.
COMMANDS = "commands"
#: The stream of the ripeness sensor's readings.
RIPENESS = "ripeness"
#: The stream of how each berry ended: ``[final state, fault or null, harvested,
#: skipped unripe]`` (:func:`softarm.harvest.rigs.replay.dry_run.berry_outcome`).
BERRY_STATES = "berry_states"
#: The stream holding the recorded run's seed (one non-negative integer).
SEED = "seed"


def is_number(value: Any) -> bool:
    """Whether ``value`` is a finite JSON number (not a bool, not an integer too large
    for a float)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _is_int(value: Any, least: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= least


def _plain_name(value: Any) -> bool:
    """A file name inside the folder itself: no separator, not ``.`` or ``..``, not
    hidden (the recorder writes ``c1_000003.png``)."""
    return (
        isinstance(value, str)
        and value != ""
        and "/" not in value
        and "\\" not in value
        and "\x00" not in value
        and not value.startswith(".")
    )


def check_entry(where: str, entry: Any) -> dict[str, Any]:
    """One frame entry: ``camera`` a name, ``n`` a count, ``t`` a finite time, ``file``
    null or a plain file name in the folder, and a crop's ``origin`` and ``full_size``
    two integers each. Returns the entry.

    Raises:
        ConfigError: the field and what it must be, named with ``where``.
    """
    if not isinstance(entry, dict) or not {"camera", "n", "t", "file"} <= set(entry):
        raise ConfigError(f"{where} must have camera, n, t and file")
    fields = (
        ("camera", isinstance(entry["camera"], str) and entry["camera"] != "", "a camera name"),
        ("n", _is_int(entry["n"], 0), "a frame count (an integer >= 0)"),
        ("t", is_number(entry["t"]), "a finite number of seconds"),
        (
            "file",
            entry["file"] is None or _plain_name(entry["file"]),
            "null or the name of a file in the folder itself (no '/', '..' or absolute path)",
        ),
    )
    for name, ok, what in fields:
        if not ok:
            raise ConfigError(f"{where}: {name} must be {what}, got {entry[name]!r:.60}")
    if "origin" in entry or "full_size" in entry:
        _check_window(where, entry)
    return entry


def _check_window(where: str, entry: Mapping[str, Any]) -> None:
    """A crop's place in its full frame: ``origin`` two integers >= 0, ``full_size``
    two integers >= 1."""
    for name, least in (("origin", 0), ("full_size", 1)):
        value = entry.get(name)
        if not (
            isinstance(value, list) and len(value) == 2 and all(_is_int(v, least) for v in value)
        ):
            raise ConfigError(
                f"{where}: a crop needs {name} as two integers >= {least}, got {value!r:.60}"
            )


def check_streams(source: str, streams: Any) -> dict[str, list[Any]]:
    """The index's streams: a table of lists; those the dry run reads (commands,
    ripeness readings, the seed, the berries' outcomes) with their recorded types.

    Raises:
        ConfigError: the stream, the reading's index and what it must be.
    """
    if not isinstance(streams, dict) or not all(isinstance(v, list) for v in streams.values()):
        raise ConfigError(f"{source}: streams must be a table of lists")
    for name, check in _STREAMS.items():
        for i, value in enumerate(streams.get(name, [])):
            what = check(value)
            if what is not None:
                raise ConfigError(f"{source}: {name}[{i}] must be {what}, got {value!r:.60}")
    seeds = streams.get(SEED)
    if seeds is not None and len(seeds) != 1:
        raise ConfigError(f"{source}: {SEED} must hold one integer, got {len(seeds)} values")
    return streams


def _command(value: Any) -> str | None:
    what = '["set", t, [psi, ...]] or ["vent", t] with finite numbers'
    if not isinstance(value, list) or not value or value[0] not in ("set", "vent"):
        return what
    if value[0] == "vent":
        return None if len(value) == 2 and is_number(value[1]) else what
    ok = len(value) == 3 and is_number(value[1]) and isinstance(value[2], list)
    return None if ok and value[2] and all(is_number(p) for p in value[2]) else what


def _reading(value: Any) -> str | None:
    return None if is_number(value) else "a finite number"


def _seed(value: Any) -> str | None:
    return None if _is_int(value, 0) else "an integer >= 0"


def _outcome(value: Any) -> str | None:
    ok = (
        isinstance(value, list)
        and len(value) == 4
        and isinstance(value[0], str)
        and (value[1] is None or isinstance(value[1], str))
        and isinstance(value[2], bool)
        and isinstance(value[3], bool)
    )
    return None if ok else "[state, fault or null, harvested, skipped unripe]"


_STREAMS = {COMMANDS: _command, RIPENESS: _reading, SEED: _seed, BERRY_STATES: _outcome}
