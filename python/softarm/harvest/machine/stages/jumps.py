"""Jumps of the measurement in fine positioning (:class:`JumpCounter`), by which the
machine gives up an approach axis from which C1 cannot see the marker cube well.

In the rendered bush, at some approaches C1's pose of the cube flips between two or more
solutions 5-25 mm apart while the arm moves by a fraction of a millimetre (no tag faces
C1 well: docs/perception.md); the berry, placed through that pose (eq. 21), moves with
it only in part, so the measured grasp error jumps by 2-6 mm. Which solution comes back
depends on the view, not on chance (the same still arm gives the same frames), so
neither holding the arm nor waiting averages it out: such a berry ran to its 12 s
budget, and then along another axis of the cone took 0.7 s (diagnosis seeds 1410-1419,
docs/harvest.md "Where the bush's time goes").
"""

from __future__ import annotations

import numpy as np

from softarm.harvest.machine.interfaces import FloatArray

__all__ = ["JUMP", "JumpCounter"]

#: The least (m) a measured grasp error differs from the one expected to be a jump: the
#: noise of a measurement that does not jump is a few tenths of a millimetre; a jump of
#: the cube's pose moves it by 2-6 mm.
JUMP = 0.0015


class JumpCounter:
    """Counts the jumps of the measured offset of the grasp point from its goal.

    The offset expected now is the last one measured, carried by the model's motion of
    the grasp point since (from where the lag model had the arm then to where it has it
    now). An offset farther from it than ``jump`` (m) and than the expected offset's own
    length is a jump: in a period the loop moves the arm by a part of the error it was
    told, never by more than the whole of it. Every offset is taken as the next one's
    reference, a jump too: a flip of the pose away from the goal is a jump, the flip
    back onto it is not (the loop could have brought the arm there).
    """

    def __init__(self, jump: float = JUMP) -> None:
        self.jump = jump
        #: Jumps seen so far.
        self.jumps = 0
        self._last: tuple[FloatArray, FloatArray] | None = None

    def see(self, offset: FloatArray, point: FloatArray) -> float:
        """Take ``offset`` (m, base frame), measured with the model's grasp point at
        ``point``; its distance (m) from the offset expected (0 for the first). Counts
        it in :attr:`jumps` when it is a jump."""
        offset = np.asarray(offset, dtype=np.float64)
        point = np.asarray(point, dtype=np.float64)
        residual = 0.0
        if self._last is not None:
            expected = self._last[0] + (point - self._last[1])
            residual = float(np.linalg.norm(offset - expected))
            if residual > max(self.jump, float(np.linalg.norm(expected))):
                self.jumps += 1
        self._last = (offset, point)
        return residual
