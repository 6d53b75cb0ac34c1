"""Rate-independent hysteresis: a play (backlash) operator per actuator.

The output follows the input only once the input has moved more than half the band
width ``w`` away from it, ``y = clip(y_prev, x - w/2, x + w/2)``; it depends on the
path of the input, not on its speed. A pneumatic muscle's braid friction gives this
kind of loop between pressure and length. The law is the core's (``softarm._core.play``),
which the controller's model of the plant (``softarm.harvest.control.plant_model``) applies too."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm._core import play
from softarm.errors import ParameterError


class PlayHysteresis:
    """A vector of play operators of band widths ``width`` (input units)."""

    def __init__(self, width: npt.ArrayLike, initial: npt.ArrayLike | None = None) -> None:
        self.width = np.asarray(width, dtype=np.float64)
        if self.width.ndim != 1 or not np.all(np.isfinite(self.width)) or np.any(self.width < 0):
            raise ParameterError("width: must be a 1-D array of finite values >= 0")
        self.output = (
            np.zeros_like(self.width)
            if initial is None
            else np.asarray(initial, dtype=np.float64).copy()
        )

    def __call__(self, x: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Feeds input ``x``; returns the operator outputs."""
        self.output = play(self.output, np.asarray(x, dtype=np.float64), self.width)
        return self.output.copy()
