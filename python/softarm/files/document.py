"""Structural bounds of a parsed document, checked once for every file read.

A parser hands back whatever the text spelled: integers of any length (``10**400``
overflows the first ``float()`` a loader calls) and nesting as deep as the interpreter's
stack allows (a later recursive walk, ``repr`` or ``json.dumps``, then dies with a
``RecursionError``). Bounding both here, where every document passes, means no loader
has to remember to.
"""

from __future__ import annotations

from typing import Any

from softarm.errors import ConfigError

__all__ = ["MAX_DEPTH", "MAX_INT", "check_document"]

#: Deepest nesting of tables and arrays in any softarm file (a 4x4 pose inside a table
#: inside a table is 4); far beyond any real file, far below the recursion limit.
MAX_DEPTH = 32
#: Largest integer magnitude: TOML's own 64-bit range (TOML 1.0 says an integer that
#: cannot be held losslessly in 64 bits is an error), used for JSON too.
MAX_INT = 2**63 - 1


def _child_key(key: str, name: object) -> str:
    if isinstance(name, int):
        return f"{key}[{name}]"
    return f"{key}.{name}" if key else str(name)


def check_document(data: Any, source: str) -> None:
    """Raise :class:`ConfigError` (naming ``source`` and the key path) when ``data`` nests
    deeper than :data:`MAX_DEPTH` or holds an integer outside ±:data:`MAX_INT`."""
    # Iterative, so that the check itself cannot exhaust the stack it protects.
    stack: list[tuple[Any, str, int]] = [(data, "", 0)]
    while stack:
        value, key, depth = stack.pop()
        if isinstance(value, dict | list):
            if depth >= MAX_DEPTH:
                where = key or "the top level"
                raise ConfigError(f"{source}: {where} nests deeper than {MAX_DEPTH} levels")
            items = value.items() if isinstance(value, dict) else enumerate(value)
            stack.extend((v, _child_key(key, k), depth + 1) for k, v in items)
        elif isinstance(value, int) and not isinstance(value, bool):
            if not -MAX_INT - 1 <= value <= MAX_INT:
                digits = len(str(abs(value)))
                raise ConfigError(
                    f"{source}: {key or 'value'} is an integer of {digits} digits, "
                    f"outside the 64-bit range"
                )
