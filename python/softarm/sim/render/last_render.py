"""The last render of each kind, kept with the scene state it was drawn from: the
harvest often draws a camera again with nothing moved (a C2 frame and a C1 window each
control step while the arm holds still: about one render in seven of a row harvest),
and the same scene draws the same pixels, so such a render is handed back, copied,
instead of drawn again. The camera model is applied afterwards, each frame anew."""

from __future__ import annotations

from collections.abc import Hashable
from dataclasses import fields, replace
from typing import Any, TypeVar

import numpy as np

__all__ = ["LastRender", "scene_state"]

T = TypeVar("T")


def scene_state(model: Any, data: Any) -> bytes:
    """What a render of ``model`` and ``data`` is drawn from and the harvest changes:
    the arm's bodies (mocap poses) and sizes, the leaves pushed aside, the geoms
    taken away (their groups), the lights' strength (C1's marker window is drawn with
    them dimmed: softarm.sim.render.headroom). The cameras and materials stay as built."""
    return b"".join(
        np.ascontiguousarray(a).tobytes()
        for a in (data.mocap_pos, data.mocap_quat, model.geom_pos, model.geom_size,
                  model.geom_group, model.light_diffuse)
    )  # fmt: skip


def _copied(value: T) -> T:
    if isinstance(value, np.ndarray):
        return value.copy()
    if hasattr(value, "__dataclass_fields__"):
        changes = {f.name: _copied(getattr(value, f.name)) for f in fields(value)}  # type: ignore[arg-type]
        return replace(value, **changes)  # type: ignore[type-var]
    return value


class LastRender:
    """One render kept per ``slot`` (a camera and what was asked of it)."""

    def __init__(self) -> None:
        self._last: dict[Hashable, tuple[bytes, Any]] = {}

    def get(self, slot: Hashable, state: bytes) -> Any | None:
        """A copy of the render kept for ``slot`` if it was drawn from ``state``."""
        kept = self._last.get(slot)
        return _copied(kept[1]) if kept is not None and kept[0] == state else None

    def put(self, slot: Hashable, state: bytes, value: T) -> T:
        """Keep ``value`` (a copy) as ``slot``'s render of ``state``; ``value`` back."""
        self._last[slot] = (state, _copied(value))
        return value
