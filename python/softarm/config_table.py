"""A TOML table read with its key path, so that every error of a configuration file names
``a.b[2].c``: the reader behind ``softarm.config`` and ``softarm.perception_config``, below
both (each table of hw.toml is parsed by the module that owns it)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Protocol

from softarm.errors import ConfigError

__all__ = ["RangeLimit", "TomlTable", "resolve"]


class RangeLimit(Protocol):
    """A safety setting's range (``softarm.hardware.limits.Limit``)."""

    def contains(self, value: Any) -> bool: ...

    def describe(self) -> str: ...


def resolve(path: str, folder: str | Path | None) -> str:
    """``path`` as written in a config file, resolved against the file's ``folder`` (an
    absolute path, or no folder, leaves it as it is)."""
    return path if folder is None else str(Path(folder) / path)


class TomlTable:
    """A TOML table plus its key path, so every error can name ``a.b[2].c``."""

    def __init__(self, data: dict[str, Any], path: str, source: str) -> None:
        self.data, self.path, self.source = data, path, source
        self.used: set[str] = set()
        self.folder: str | None = None

    def key(self, name: str) -> str:
        return f"{self.path}.{name}" if self.path else name

    def error(self, name: str, message: str) -> ConfigError:
        value = self.data.get(name, "<missing>")
        return ConfigError(f"{self.source}: {self.key(name)} {message}, got {value!r}")

    def get(self, name: str, default: Any = ...) -> Any:
        self.used.add(name)
        if name not in self.data:
            if default is ...:
                raise ConfigError(f"{self.source}: {self.key(name)} is required but missing")
            return default
        return self.data[name]

    def number(
        self, name: str, default: Any = ..., *, lo: float = -math.inf, positive: bool = False
    ) -> float:
        value = self.get(name, default)
        if not (
            isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
        ):
            raise self.error(name, "must be a finite number")
        if value < lo or (positive and value <= 0.0):
            raise self.error(name, "must be > 0" if positive else f"must be >= {lo}")
        return float(value)

    def within(self, name: str, value: Any, limit: RangeLimit) -> Any:
        """``value`` if it lies in a safety setting's range (``softarm.hardware.limits``,
        the same check the drivers make), else a ConfigError saying the range and why."""
        if not limit.contains(value):
            raise self.error(name, limit.describe())
        return value

    def table(self, name: str, required: bool = False) -> TomlTable:
        value = self.get(name, ... if required else {})
        if not isinstance(value, dict):
            raise self.error(name, "must be a table")
        child = TomlTable(value, self.key(name), self.source)
        child.folder = self.folder
        return child

    def done(self) -> None:
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise ConfigError(f"{self.source}: unknown key {self.key(unknown[0])!r}")
