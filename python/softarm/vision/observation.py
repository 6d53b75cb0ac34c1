"""What the two-camera vision reports (section III-D, fig. 4): the berry looked for, its
position fix and where it came from, one observation of a control period, and the
protocol of a vision that gives them (:class:`Vision`).

Defined in the vision layer so that vision and identification use them without the
harvest; :mod:`softarm.harvest.machine.interfaces` re-exports them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, Protocol

from softarm.checks import FloatArray

__all__ = ["BerryFix", "BerryTarget", "CameraName", "Observation", "Vision"]

#: Which camera the berry position came from; ``held`` = the most recent one, kept while
#: the berry is hidden (section III-D). (A name, not a device: the device protocol is
#: :class:`softarm.hardware.protocols.Camera`.)
CameraName = Literal["eye_to_hand", "eye_in_hand", "held"]


@dataclass(frozen=True)
class BerryTarget:
    """A berry to harvest: the id of the ArUco tag that marks it (section IV-E) and an
    optional label for the logs."""

    tag_id: int
    label: str = ""


@dataclass(frozen=True)
class BerryFix:
    """A berry position ``position`` (3,) in the base frame, the ``camera`` it came from
    and its ``age`` (s since it was measured; 0 for a fresh measurement)."""

    position: FloatArray
    camera: CameraName
    age: float = 0.0


@dataclass(frozen=True)
class Observation:
    """What the cameras give at time ``t``: ``T_base_ee`` (4, 4) from the marker cube
    (eq. 22), None when the cube is not seen, and the berry ``fix``, None when there is
    none (not seen and no fix held)."""

    t: float
    pose: FloatArray | None
    fix: BerryFix | None


class Vision(Protocol):
    """Both cameras: eye-to-hand tracking of the end-effector cube (eq. 22), and the berry
    from eye-to-hand far away, eye-in-hand (eq. 21) within the 6 cm hand-over distance,
    the most recent fix held while the berry is hidden, up to an age limit (section
    III-D, fig. 4). How long the harvest tolerates a lost marker is not the vision's
    business (:class:`softarm.harvest.machine.observe.BerryWatch` owns that)."""

    def select(self, berry: BerryTarget) -> None:
        """Track ``berry`` from now on, forgetting any held fix."""
        ...

    def observe(self, time: float, need_fix: bool = True) -> Observation:
        """The end-effector pose and the berry at ``time``. Without ``need_fix`` the
        caller throws the berry fix away (the back-out holds the berry frozen, the moves
        between berries need none): the vision then spends nothing on finding the berry
        up close (C2 is neither rendered nor read for it); the fix it still gives (C1's,
        or the held one) is what it has without that."""
        ...
