"""One trial of the perception map: one cell of the daylight row's conditions on one
seed, measured on a single stereo frame pair from C1 (the arm out of view).

The bush is :meth:`~softarm.sim.bush.Bush.generate`'s for the seed (``berries``,
``unripe_fraction``), inside the row of :meth:`RowLook.named(look, seed, lookalikes,
fruit) <softarm.sim.render.row_look.RowLook.named>`; its frames through the look's camera
model (``effects = "on"``), an ideal camera that only exposes (``"off"``) or none
(``"raw"``: as rendered, lens distortion only).
Every detector runs on the left eye and, by stereo
(:func:`~softarm.perception.stereo.locate_berries`), on the pair; the canes are fitted
on the pair. Scores: :mod:`.perception_score`. This is perception per frame, not the
harvest: nothing moves, nothing is picked.

Plain Python, no Ray: :func:`run_perception_trial` never raises; a trial that fails is a
row with its ``error``, so one bad cell never stops the map.
"""

from __future__ import annotations

import socket
import time
import traceback
from dataclasses import replace
from typing import Any

import numpy as np

from softarm.sweep.perception_score import is_counted, stereo_counts, tally_counts
from softarm.sweep.perception_spec import CELL_KEYS, PerceptionTrial

__all__ = ["run_perception_trial", "trial_look"]

#: Fruit with fewer visible pixels than this in the left eye are not labelled (as in
#: ``softarm dataset``).
MIN_PIXELS = 4


def run_perception_trial(trial: PerceptionTrial) -> dict[str, Any]:
    """The trial's row: its id, cell, seed, figures (see :func:`measure`), ``error``
    (None, or one line) and its wall and CPU seconds."""
    import cv2

    cv2.setNumThreads(1)  # one core per task: Ray runs one task per core
    start, cpu = time.perf_counter(), time.process_time()
    row: dict[str, Any] = {
        "trial_id": trial.trial_id,
        **dict(zip(CELL_KEYS, trial.cell, strict=True)),
        "seed": trial.seed,
    }
    try:
        row.update(measure(trial))
        row["error"] = None
    except Exception as exc:  # a trial never raises: its row says what went wrong
        last = traceback.extract_tb(exc.__traceback__)[-1:]
        where = f" ({last[0].filename.rsplit('/', 1)[-1]}:{last[0].lineno})" if last else ""
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        row["error"] = f"{type(exc).__name__}: {first}{where}"
    row["wall_s"] = round(time.perf_counter() - start, 2)
    row["cpu_s"] = round(time.process_time() - cpu, 2)
    row["node"] = socket.gethostname()
    return row


def trial_look(trial: PerceptionTrial) -> Any:
    """The trial's :class:`~softarm.sim.render.row_look.RowLook`; with ``effects = "off"``
    its cameras ideal (auto-exposure, nothing else)."""
    from softarm.sim.render.camera_effects import CameraEffects, StereoEffects
    from softarm.sim.render.row_look import RowLook

    look = RowLook.named(trial.look, trial.seed, trial.lookalikes, trial.fruit)
    if trial.effects == "off":
        ideal = CameraEffects()
        look = replace(look, stereo=StereoEffects(ideal), c2=ideal, blur_px_s=0.0)
    return look


def _world(trial: PerceptionTrial) -> Any:
    import softarm
    from softarm.harvest.rigs.sim.options import default_cameras
    from softarm.sim.bush import Bush
    from softarm.sim.render.world import RenderedBush, scaled
    from softarm.sim.rig_cameras import BASE_TAG_ID

    cams = default_cameras()
    bush = Bush.generate(
        softarm.SoftArm.blackberry(),
        trial.berries,
        trial.seed,
        view_point=cams.T_base_c1[:3, 3],
        unripe_fraction=trial.unripe_fraction,
    )
    world = RenderedBush(
        bush,
        cams.T_base_c1,
        scaled(cams.model(1), trial.scale),
        scaled(cams.model(2), trial.scale),
        cams.T_ee_c2,
        cams.T_ee_cube,
        cams.T_base_tag,
        BASE_TAG_ID,
        cams.base_tag,
        cams.cube_marker,
        trial_look(trial),
        shadows=trial.shadows,
    )
    if trial.effects == "raw":
        world.effects = None  # the frames as rendered: no camera model
    return world


def measure(trial: PerceptionTrial) -> dict[str, Any]:
    """The frame's figures: fruit in view, ripe targets, per detector its tally and
    stereo counts, and the cane map's scores."""
    world = _world(trial)
    try:
        left, right = world.c1(truth=True)
        fruit = _truth(world, left)
        out: dict[str, Any] = {
            "fruit_in_view": len(fruit),
            "ripe_targets": sum(
                1 for _, o in fruit if o.stage == "ripe" and is_counted(o.visible or 0.0)
            ),
            "detectors": {
                name: _detector_counts(name, world, left, right, fruit, trial.stereo)
                for name in trial.detectors
            },
        }
        out["canes"] = _canes(world, left, right) if trial.canes else None
        return out
    finally:
        world.close()


def _truth(world: Any, frame: Any) -> list[tuple[int, Any]]:
    """(fruit id, labelled object) of every fruit with MIN_PIXELS visible in ``frame``:
    its stage (green and red fruit are unripe), mask and visible share."""
    from softarm.perception.detector.labels import LabelledObject

    shares = world.berry_shares(frame)
    out = []
    for fid in world.fruit_ids():
        mask = world.labels.mask(frame.geoms, "berry", fid)
        if np.count_nonzero(mask) < MIN_PIXELS:
            continue
        stage = world.stage(fid)
        stage = stage if stage in ("ripe", "turning") else "unripe"
        out.append((fid, LabelledObject(stage, mask, visible=shares[fid])))
    return out


def _detector_counts(
    name: str, world: Any, left: Any, right: Any, fruit: list[tuple[int, Any]], stereo: bool
) -> dict[str, Any]:
    from softarm.perception.detector.choice import current_detector, detector, use_detector
    from softarm.perception.detector.scoring import Tally

    det = detector(name)
    tally = Tally()
    dets = list(det.detect_berries(left.colour, world.stereo.left))
    pairs = tally.add(dets, [o for _, o in fruit])
    out: dict[str, Any] = {
        "tally": tally_counts(tally),
        "wrong_ripe_on": _wrong_ripe_on(dets, pairs, fruit, world, left.geoms),
        "stereo": None,
    }
    if stereo:
        from softarm.perception.stereo import locate_berries

        before = current_detector()
        use_detector(name)  # the stereo detects with the process's detector
        try:
            found = locate_berries(left.colour, right.colour, world.stereo)
        finally:
            use_detector(before)
        targets = {
            fid: world.row.find(fid).position
            for fid, o in fruit
            if o.stage == "ripe" and is_counted(o.visible or 0.0)
        }
        placed = [d.position for d in found if d.ripeness == "ripe" and d.position is not None]
        out["stereo"] = stereo_counts(targets, placed)
    return out


def _wrong_ripe_on(
    dets: list[Any], pairs: dict[int, int], fruit: list[tuple[int, Any]], world: Any, geoms: Any
) -> dict[str, int]:
    """The ripe calls that match no ripe fruit, by what they are: the stage of the fruit
    they match (turning, unripe), else what lies under their centre (a look-alike is
    ``clutter``; ``berry`` a fruit they overlap too little or one under MIN_PIXELS)."""
    from softarm.sim.render.labels import KINDS

    out: dict[str, int] = {}
    h, w = geoms.shape
    for i, d in enumerate(dets):
        if d.ripeness != "ripe":
            continue
        j = pairs.get(i)
        if j is not None:
            what = fruit[j][1].stage
        else:
            u, v = (min(max(round(c), 0), n - 1) for c, n in zip(d.center, (w, h), strict=True))
            g = int(geoms[v, u])
            what = KINDS[world.labels.kind[g]] if g >= 0 else "background"
        if what != "ripe":
            out[what] = out.get(what, 0) + 1
    return out


def _canes(world: Any, left: Any, right: Any) -> dict[str, float | int | None]:
    from softarm.perception.cane_metrics import cane_map_error
    from softarm.perception.canes import fit_canes

    fits = fit_canes(left.colour, right.colour, world.stereo)
    scores = cane_map_error(fits, world.canes())
    # A map with no fit has no distances (NaN, inf): None in the JSON.
    out = {k: round(float(v), 4) if np.isfinite(v) else None for k, v in scores.items()}
    out["fits"] = len(fits)
    return out
