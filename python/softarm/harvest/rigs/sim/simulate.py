"""``softarm.harvest.simulate`` (defined here): the simulated harvest as a Python call,
what ``softarm harvest --sim`` runs; re-exported as ``softarm.simulate_harvest``. It lives
in the harvest layer, not in ``softarm.sim``: the simulation sits below the harvest state
machine and may not import it (docs/architecture.md).

>>> import softarm
>>> report = softarm.simulate_harvest(berries=1, seed=0)   # doctest: +SKIP
>>> report.success_rate, report.berries[0].true_position_error_mm   # doctest: +SKIP
"""

from __future__ import annotations

import dataclasses
import difflib
from collections.abc import Callable
from pathlib import Path
from typing import Any

from softarm.harvest.records.report import BerryResult, HarvestReport

__all__ = ["simulate"]


def simulate(
    berries: int = 5,
    seed: int = 0,
    *,
    log: str | Path | None = None,
    on_berry: Callable[[int, BerryResult], None] | None = None,
    **options: Any,
) -> HarvestReport:
    """Harvest ``berries`` berries of the simulated bush of ``seed``, and return the
    report (one :class:`~softarm.harvest.records.report.BerryResult` per berry: outcome, errors in
    mm and deg, time; ``report.to_dict()`` is the JSON of ``softarm harvest --report``).

    A thin wrapper over ``build_sim_rig(SimRigOptions(...)).run(on_berry)``
    (:mod:`softarm.harvest.rigs.sim.rig`): the same bush, plant, cameras and control stack as
    ``softarm harvest --sim --berries N --seed S``, with no output on the console.

    Args:
        berries: berries to harvest (at least 1).
        seed: seed of the bush, the plant's noise and the cameras.
        log: write the JSON-lines step log here, opened by the run's header record (the
            one ``softarm replay`` reads), as ``--log`` does.
        on_berry: called as ``on_berry(i, result)`` after each berry (a retried berry
            calls it again).
        **options: any other field of ``SimRigOptions``: ``plant`` (a ``PlantConfig``),
            ``gains`` (resolver gain keywords, as ``--gains``), ``world`` ("tags",
            "bush", the rendered bush: render extra, or "row", the bush in the daylight
            row, with ``look``: "sun", "overcast", "backlight", "dusk" or "random"),
            ``calibration``, ``identified``,
            ``config`` (a ``HarvestConfig``), ``unripe_fraction``, ...

    Raises:
        TypeError: an unknown option (named, with the nearest known one).
        softarm.sim.render.RenderUnavailableError: ``world="bush"`` where MuJoCo or an
            offscreen OpenGL context is missing.
        softarm.errors.SoftarmError: a bad value (as the command line reports it).
    """
    from softarm.harvest.records.header import HEADER, header_record
    from softarm.harvest.rigs.sim.header import sim_settings
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig

    _check_options(options, SimRigOptions)
    if options.get("world") in ("bush", "row"):  # before the log: a typed error, not MuJoCo's
        from softarm.sim.render.gl_check import require_offscreen_gl

        require_offscreen_gl()
    rig_options = SimRigOptions(n_berries=berries, seed=seed, log_path=log, **options)
    rig = build_sim_rig(rig_options)
    header = header_record(
        command="softarm.simulate_harvest",
        argv=[],
        options={"berries": berries, "seed": seed, **{k: repr(v) for k, v in options.items()}},
        **sim_settings(rig, rig_options),
    )
    rig.machine.log.event(HEADER, **header)
    report = rig.run(on_berry)
    report.header = rig.machine.log.records[0]
    rig.machine.log.close()
    return report


def _check_options(options: dict[str, Any], fields_of: type) -> None:
    """An unknown keyword is a TypeError naming ``simulate_harvest`` (the function the
    user called, not the dataclass behind it), with the nearest option's name."""
    known = [f.name for f in dataclasses.fields(fields_of) if f.name not in _SET_HERE]
    for name in options:
        if name not in known:
            near = difflib.get_close_matches(name, known, n=1)
            hint = f"; did you mean {near[0]!r}?" if near else f"; options: {', '.join(known)}"
            raise TypeError(
                f"softarm.simulate_harvest() got an unexpected keyword argument {name!r}{hint}"
            )


#: SimRigOptions fields that simulate() sets from its own arguments.
_SET_HERE = frozenset({"n_berries", "seed", "log_path"})
