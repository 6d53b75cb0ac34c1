"""The simulated harvest's world, one protocol for all of them: what the cameras see of
it (:class:`~softarm.vision.observation.Vision`), the gripper that closes on its true
berries and reports the true errors (:class:`WorldGripper`), the canes the control
stack is told of, and what the world adds to the report. The tag world, the rendered
bush and the daylight row implement it (:mod:`softarm.harvest.rigs.worlds`); the
simulated rig asks the world, never its name."""

from __future__ import annotations

from collections.abc import Sequence
from enum import StrEnum
from typing import Protocol

from softarm._core import PolynomialCurve
from softarm.checks import FloatArray
from softarm.errors import ParameterError
from softarm.hardware.protocols import Gripper, RipenessSensor
from softarm.sim.bush import Berry
from softarm.vision.observation import BerryTarget, Vision

__all__ = ["GroundTruth", "World", "WorldGripper", "WorldName"]


class WorldName(StrEnum):
    """The simulated worlds: ``tags`` (every berry wears an ArUco tag, the canes are
    mapped: fast, for controller sweeps), ``bush`` (the rendered bush: berries and canes
    found by perception) and ``row`` (the rendered bush in the daylight row)."""

    TAGS = "tags"
    BUSH = "bush"
    ROW = "row"

    @property
    def rendered(self) -> bool:
        """Whether the renderer draws it (perception finds the berries and canes)."""
        return self is not WorldName.TAGS

    @classmethod
    def parse(cls, value: object, name: str = "world") -> WorldName:
        """``value`` as a world.

        Raises:
            ParameterError: not one of the worlds (``name`` and the choices named).
        """
        if isinstance(value, str) and value in cls._value2member_map_:
            return cls(value)
        choices = ", ".join(repr(w.value) for w in cls)
        raise ParameterError(f"{name} = {value!r}: must be one of {choices}")


class GroundTruth(Protocol):
    """Simulation only: true errors, to report what vision cannot see."""

    def grasp_errors(self, berry: BerryTarget, axis: FloatArray) -> tuple[float, float]:
        """True (grasp point to ``berry`` in m, gripper axis to ``axis`` in rad) now."""
        ...


class WorldGripper(Gripper, RipenessSensor, GroundTruth, Protocol):
    """The simulated gripper: the device, its ripeness sensor and the ground truth."""

    @property
    def delivered(self) -> list[int]:
        """The true berries (tag ids) it has delivered, in order."""
        ...


class World(Protocol):
    """What the simulated rig needs of its world."""

    @property
    def name(self) -> WorldName:
        """Which world this is (for the report and the header)."""
        ...

    @property
    def vision(self) -> Vision:
        """Both cameras as the harvest sees them."""
        ...

    @property
    def gripper(self) -> WorldGripper:
        """The gripper closing on the world's true berries."""
        ...

    def known_canes(self) -> Sequence[PolynomialCurve]:
        """The canes the planner, the resolver and the clearance checks are told of:
        the true ones where they are mapped (tags), those fitted from C1 where they are
        perceived."""
        ...

    def truth_of(self, berry_id: int) -> Berry | None:
        """The true berry the run's ``berry_id`` stands for (its tag, or the bush-map
        entry's nearest true berry), None where none does."""
        ...

    def report_extra(self) -> dict[str, object]:
        """What the world adds to the report (nothing for the tag world)."""
        ...

    def close(self) -> None:
        """Free what the world holds (the renderer's contexts); harmless twice."""
        ...
