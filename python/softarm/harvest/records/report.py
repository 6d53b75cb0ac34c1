"""Per-berry results and the harvest report written as JSON."""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from softarm.files import write_text
from softarm.harvest.machine.states import FaultReason, HarvestState
from softarm.harvest.records.log import _plain

__all__ = ["BerryResult", "HarvestReport"]


@dataclass
class BerryResult:
    """What happened to one berry.

    Attributes:
        tag_id: the berry's tag.
        target: last berry position measured (base frame, m), or None if never seen.
        harvested: grasped, ripe, and brought home.
        final_state: DONE, or FAULT.
        fault: why it faulted, if it did.
        skipped_unripe: grasped but found unripe, released.
        position_error_mm: at the end of fine positioning, grasp point to berry, as
            measured by the cameras (what the controller sees).
        orientation_error_deg: angle between the gripper's approach axis and the desired one.
        true_position_error_mm: the same against ground truth (simulation only).
        true_orientation_error_deg: the same against ground truth (simulation only).
        duration_s: clock time from IDLE to the end.
        steps: control steps.
        cameras: control steps per berry source (eye_to_hand, eye_in_hand, held).
        ripe: the berry's true ripeness, where the berries are found without tags
            (simulation only; None in the tag world).
        localisation_error_mm: the perceived position against the true one, likewise.
    """

    tag_id: int
    target: list[float] | None = None
    harvested: bool = False
    final_state: HarvestState = HarvestState.IDLE
    fault: FaultReason | None = None
    skipped_unripe: bool = False
    position_error_mm: float = math.nan
    orientation_error_deg: float = math.nan
    true_position_error_mm: float | None = None
    true_orientation_error_deg: float | None = None
    duration_s: float = 0.0
    steps: int = 0
    cameras: dict[str, int] = field(default_factory=dict)
    ripe: bool | None = None
    localisation_error_mm: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (NaN → null, enums → their values)."""
        return dict(_plain(asdict(self)))


@dataclass
class HarvestReport:
    """The results of a run, in berry order, and anything the rig adds in ``extra``
    (seed, minimum branch clearance, ...); ``header``: the run's header record
    (:mod:`softarm.harvest.records.header`), which then opens the report."""

    berries: list[BerryResult] = field(default_factory=list)
    stopped: FaultReason | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    header: dict[str, Any] | None = None

    @property
    def success_rate(self) -> float:
        """Harvested berries over berries attempted or pending (0 when there are none)."""
        return self.harvested / self.attempted if self.berries else 0.0

    @property
    def harvested(self) -> int:
        """Berries grasped, ripe, and brought home (``to_dict()["harvested"]``)."""
        return sum(b.harvested for b in self.berries)

    @property
    def attempted(self) -> int:
        """Berries attempted or pending: one result each (``to_dict()["attempted"]``)."""
        return len(self.berries)

    @property
    def cane_map(self) -> dict[str, float] | None:
        """How well the rendered bush's canes were mapped (median and p95 error mm,
        coverage, precision, length m; docs/perception.md), None in the tag world."""
        value = self.extra.get("cane_map")
        return dict(value) if isinstance(value, dict) else None

    def to_dict(self) -> dict[str, Any]:
        """The report as a JSON-ready dict."""
        return dict(
            _plain(
                {
                    **({} if self.header is None else {"header": self.header}),
                    "success_rate": self.success_rate,
                    "harvested": self.harvested,
                    "attempted": self.attempted,
                    "stopped": self.stopped,
                    "berries": [b.to_dict() for b in self.berries],
                    **self.extra,
                }
            )
        )

    def save(self, path: str | Path) -> None:
        """Write the report as indented JSON."""
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        write_text(path, json.dumps(self.to_dict(), indent=2, allow_nan=False) + "\n", "report")
