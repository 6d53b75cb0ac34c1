"""The optional dependencies of ``softarm sweep`` / ``softarm tune`` (the ``sweep`` extra),
imported only when used, with a one-line error that says how to install them."""

from __future__ import annotations

import importlib
from typing import Any

from softarm.errors import MissingDependencyError

__all__ = ["require"]

INSTALL = "pip install 'softarm[sweep]'"


def require(module: str) -> Any:
    """Import ``module`` or raise :class:`MissingDependencyError` naming the extra."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise MissingDependencyError(
            f"{module} is not installed ({exc.name} missing): {INSTALL}", "sweep"
        ) from None
