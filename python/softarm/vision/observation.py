"""What the two-camera vision reports (section III-D, fig. 4): the berry looked for, its
position fix and where it came from, and one observation of a control period.

Defined in the vision layer so that vision and identification use them without the
harvest; :mod:`softarm.harvest.machine.interfaces` re-exports them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from softarm.checks import FloatArray

__all__ = ["BerryFix", "BerryTarget", "CameraName", "Observation"]

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
