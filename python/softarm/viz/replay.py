"""A harvest run log (``softarm harvest --log run.jsonl``) turned into a rerun recording:
whatever the log holds (states, commands drawn on the model arm, measured poses, berry
estimates, errors, faults), on the run's own timeline. See :mod:`softarm.viz.records`."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from softarm.errors import InputError
from softarm.harvest.records.header import find_header
from softarm.harvest.records.log import read_log
from softarm.sim.bush import Bush
from softarm.viz.bag.scene import RunScene
from softarm.viz.layout import harvest_blueprint
from softarm.viz.records import RecordLogger
from softarm.viz.rerun_sdk import close_recording, open_recording, require_rerun
from softarm.viz.scene import log_berries, log_canes

__all__ = ["replay"]


#: How far (m) a berry the log estimated may lie from the rebuilt bush's berry of the same
#: tag: a few mm of vision error, far below the spacing of two berries.
SCENE_MATCH = 0.02


def replay(
    log: str | Path,
    record: str | Path | None = None,
    spawn: bool = False,
    model: Any | None = None,
    grasp_offset: float = 0.03,
    scene: tuple[int, int] | None = None,
) -> int:
    """Log every record of ``log`` to ``record`` (.rrd), a spawned viewer, or both;
    returns the number of records. ``model``: the arm the run controlled (default the
    header's arm, else the nominal blackberry arm), on which the commanded elongations
    are drawn. The bush of a simulated run is drawn (the canes and the true berries at
    ``world/bush``) from the log's header record (:mod:`softarm.harvest.records.header`); for an
    older log without one, ``scene`` = (seed, berries) of its ``harvest --sim`` run
    rebuilds it, after checking that the log's berries are that bush's.

    Raises:
        InputError: a line is not JSON, a record is malformed (the message names the
            record's number and the field), or the log's berries are not the scene's.
        MissingDependencyError: rerun-sdk (the ``viz`` extra) is not installed.
    """
    rr = require_rerun()  # before reading a large log
    path = Path(log)
    records = _read(path)
    bush = None if scene is None else _bush(path, records, *scene)
    header = _header_scene(path, records)
    if model is None:
        model = header.arm
    stream = open_recording(f"replay {path.name}", record, spawn, harvest_blueprint(False))
    try:
        if bush is not None:
            log_canes(stream, rr, bush.branches)
            log_berries(stream, rr, "world/bush/berries", bush.berries, static=True)
        elif header.berries:
            log_canes(stream, rr, header.branches)
            log_berries(stream, rr, "world/bush/berries", header.berries, static=True)
        logger = RecordLogger(stream, rr, model, grasp_offset, berries_from_results=True)
        for n, rec in enumerate(records, start=1):
            try:
                logger.log(rec)
            except InputError as exc:
                raise type(exc)(f"{path}: record {n}: {exc}") from None
    finally:
        close_recording(stream, viewer=spawn)
    return len(records)


def _read(path: Path) -> list[Any]:
    """Every record of the log (read_log names a malformed line in an InputError)."""
    return list(read_log(path))


def _header_scene(path: Path, records: list[Any]) -> RunScene:
    """The arm and the bush the log's header describes (the defaults without one)."""
    try:
        return RunScene.from_header(find_header(records))
    except InputError as exc:
        raise type(exc)(f"{path}: {exc}") from None


def _bush(path: Path, records: list[Any], seed: int, berries: int) -> Bush:
    """The bush of ``harvest --sim --seed seed --berries berries``, checked against the
    berries the log estimated (a log of another run would draw a wrong scene)."""
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import sim_bush

    bush = sim_bush(SimRigOptions(n_berries=berries, seed=seed))
    true = {b.tag_id: np.asarray(b.position) for b in bush.berries}
    for r in records:
        if not isinstance(r, dict) or r.get("kind") != "berry_result" or r.get("target") is None:
            continue
        tag = r.get("tag_id")
        off = (
            np.inf
            if tag not in true
            else float(np.linalg.norm(np.subtract(r["target"], true[tag])))
        )
        if not off <= SCENE_MATCH:
            raise InputError(
                f"{path}: berry tag {tag} is not a berry of the simulated bush of seed {seed} "
                f"with {berries} berries (--sim-seed/--berries must be the run's --seed/--berries)"
            )
    return bush
