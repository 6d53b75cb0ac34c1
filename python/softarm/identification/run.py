"""``identify(rig)``: run the excitation on a rig, vent, and estimate."""

from __future__ import annotations

from typing import Any

from softarm._core import SoftArm
from softarm.identification.estimate import estimate
from softarm.identification.protocol import Design
from softarm.identification.record import Progress, run_experiment
from softarm.identification.rig import IdentificationRig
from softarm.identified_plant import IdentifiedPlant

__all__ = ["identify"]


def identify(
    rig: IdentificationRig,
    nominal: SoftArm | None = None,
    design: Design | None = None,
    progress: Progress | None = None,
    metadata: dict[str, Any] | None = None,
) -> IdentifiedPlant:
    """Identify ``rig``'s plant within ``design.budget_s`` seconds of arm time (default
    120 s) and the rig's safety limits; the rig is vented when this returns or raises."""
    nominal = nominal if nominal is not None else SoftArm.blackberry()
    design = design if design is not None else Design(n=rig.bank.channels)
    rec = run_experiment(rig, design.segments(), design.budget_s, design.settle_psi, progress)
    meta = {"budget_s": design.budget_s, "excitation_seed": design.seed}
    meta.update(metadata or {})
    return estimate(rec, nominal, meta)
