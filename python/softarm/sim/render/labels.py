"""Ground truth of a rendered frame: which object each geom belongs to, read from the
geom names the scene was built with (:mod:`softarm.sim.render.mjcf`)."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = ["KINDS", "GeomLabels"]

#: Object kinds, in the order of their codes.
KINDS = ("background", "berry", "cane", "leaf", "clutter", "arm")
_PATTERN = re.compile(r"^(berry|cane|leaf|clutter|arm|bg)_?([a-z]*)(\d*)")


@dataclass(frozen=True)
class GeomLabels:
    """``kind`` (ngeom,) codes into :data:`KINDS` and ``instance`` (ngeom,): the berry's
    tag id, the cane's index, else -1."""

    kind: npt.NDArray[np.int8]
    instance: npt.NDArray[np.int32]

    @classmethod
    def from_model(cls, model: Any, mujoco: Any) -> GeomLabels:
        """Labels of every geom of ``model``."""
        kind = np.zeros(model.ngeom, np.int8)
        instance = np.full(model.ngeom, -1, np.int32)
        for g in range(model.ngeom):
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or ""
            m = _PATTERN.match(name)
            if m is None or m.group(1) == "bg":
                continue
            kind[g] = KINDS.index(m.group(1))
            if m.group(1) in ("berry", "cane") and m.group(3):
                instance[g] = int(m.group(3))
        return cls(kind, instance)

    def kinds(self, geoms: npt.NDArray[np.int32]) -> npt.NDArray[np.int8]:
        """Per-pixel kind codes of a geom-id image (-1 → background)."""
        return np.where(geoms >= 0, self.kind[np.maximum(geoms, 0)], 0).astype(np.int8)

    def mask(self, geoms: npt.NDArray[np.int32], kind: str, instance: int) -> npt.NDArray[np.bool_]:
        """Pixels of one object (a berry by tag id, a cane by index)."""
        g = np.maximum(geoms, 0)
        code = KINDS.index(kind)
        result: npt.NDArray[np.bool_] = (
            (geoms >= 0) & (self.kind[g] == code) & (self.instance[g] == instance)
        )
        return result
