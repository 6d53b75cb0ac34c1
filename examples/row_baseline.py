"""Today's colour-and-shape detector (``softarm.perception.detect_berries``) on the
daylight row, per look: C1's left eye as delivered (the camera model applied) on fresh
bushes, scored against the ground truth.

* A target is a ripe fruit at least half visible (its visible share >= 0.5).
* Recall: the targets whose mask holds the centre of a detection called ripe.
* Precision: the detections called ripe whose centre lies on a ripe fruit (any share;
  one partly hidden is not a false alarm).
* Ripeness: of the detections whose centre lies on a fruit, the share whose ripe/unripe
  call matches the fruit's stage (turning fruit is not ripe).
* False alarms are counted by what lies under their centre (leaf, look-alike, cane,
  background, unripe fruit).

No threshold of the detector is changed. The table in docs/perception.md comes from::

    MUJOCO_GL=egl python examples/row_baseline.py --out docs/data
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from pathlib import Path
from typing import Any

import softarm
from softarm.harvest.rigs.sim.options import default_cameras
from softarm.perception import detect_berries
from softarm.sim.bush import Bush
from softarm.sim.render.labels import KINDS
from softarm.sim.render.row_look import FAMILIES, RowLook
from softarm.sim.render.world import world_for
from softarm.sim.rig_cameras import BASE_TAG_ID


def _frame_counts(world: Any) -> dict[str, Any]:
    """One C1 left frame of ``world`` scored (see the module docstring)."""
    frame = world.c1_left(truth=True)
    shares = world.berry_shares(frame)
    geoms = frame.geoms
    labels = world.labels
    detections = detect_berries(frame.colour, world.stereo.left)
    ripe_ids = [i for i in world.fruit_ids() if world.stage(i) == "ripe"]
    targets = {i for i in ripe_ids if shares[i] >= 0.5}
    hit: set[int] = set()
    c: Counter[str] = Counter()
    for d in detections:
        u, v = (round(x) for x in d.center)
        g = int(geoms[min(max(v, 0), geoms.shape[0] - 1), min(max(u, 0), geoms.shape[1] - 1)])
        kind = KINDS[labels.kind[g]] if g >= 0 else "background"
        fruit = int(labels.instance[g]) if kind == "berry" else None
        stage = world.stage(fruit) if fruit is not None else None
        if stage is not None:
            c["on_fruit"] += 1
            c["ripeness_right"] += (d.ripeness == "ripe") == (stage == "ripe")
        if d.ripeness != "ripe":
            continue
        c["called_ripe"] += 1
        if stage == "ripe":
            c["true_ripe"] += 1
            hit.add(fruit)  # type: ignore[arg-type]
        else:
            c[f"false_on_{stage or kind}"] += 1
    c["targets"] = len(targets)
    c["targets_found"] = len(targets & hit)
    c["fruit_in_view"] = sum(1 for s in shares.values() if s > 0)
    return dict(c)


def _summary(counts: list[dict[str, Any]]) -> dict[str, Any]:
    total: Counter[str] = Counter()
    for c in counts:
        total.update(c)

    def ratio(a: str, b: str) -> float | None:
        return None if not total[b] else round(total[a] / total[b], 3)

    return {
        "frames": len(counts),
        "precision": ratio("true_ripe", "called_ripe"),
        "recall": ratio("targets_found", "targets"),
        "ripeness": ratio("ripeness_right", "on_fruit"),
        "counts": dict(total),
    }


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    parser.add_argument("--out", type=Path, default=Path("out/row_baseline"), help="folder")
    parser.add_argument("--seeds", type=int, nargs=2, default=(600, 606), help="[from, to)")
    args = parser.parse_args(argv)
    cams = default_cameras()
    arm = softarm.SoftArm.blackberry()
    result: dict[str, Any] = {"seeds": list(args.seeds), "looks": {}}
    for name in FAMILIES:
        counts = []
        for seed in range(*args.seeds):
            bush = Bush.generate(
                arm, 8, seed, view_point=cams.T_base_c1[:3, 3], unripe_fraction=0.3
            )
            world = world_for(bush, cams, BASE_TAG_ID, look=RowLook.named(name, seed))
            try:
                counts.append(_frame_counts(world))
            finally:
                world.close()
        result["looks"][name] = _summary(counts)
        print(name, result["looks"][name], flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "row_baseline.json"
    path.write_text(json.dumps(result, indent=1) + "\n")
    print(f"baseline: {path}")
    print("| look | precision | recall | ripeness | frames |\n| --- | --- | --- | --- | --- |")
    for name, s in result["looks"].items():
        print(f"| {name} | {s['precision']} | {s['recall']} | {s['ripeness']} | {s['frames']} |")


if __name__ == "__main__":
    main()
