"""Fine positioning's end rules side by side: simulated harvests of one world on the same
seeds, each seed run under every ``[harvest] fine_end_rule`` in one process (the same
code for both), one JSON line per bush appended to --out; --summary prints the table
docs/harvest.md quotes (seconds per berry, fine positioning's share, the true error at
the grasp, berries harvested, unripe picked, cane contacts).

    MUJOCO_GL=egl python examples/fine_end_rule.py --world bush --seeds 1260 1261 \
        --berries 3 --out out/fine_rule.jsonl
    python examples/fine_end_rule.py --summary out/fine_rule.jsonl
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from softarm.commands._args import Parser, int_range, non_negative_int

RULES = ("steps", "confidence")


def one_bush(world: str, seed: int, berries: int, rule: str, body: str) -> dict[str, Any]:
    """One simulated harvest under ``rule`` with the marker ``body`` on the gripper: its
    report's figures this table needs."""
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig
    from softarm.harvest_config import HarvestConfig
    from softarm.sim.world import WorldName

    config = HarvestConfig(fine_end_rule=rule)
    options = SimRigOptions(
        n_berries=berries,
        seed=seed,
        world=WorldName.parse(world),
        config=config,
        marker_body=body,
    )
    rig = build_sim_rig(options)
    try:
        report = rig.run().to_dict()
    finally:
        rig.close()
    rate = report["rate"]
    tried = [b for b in report["berries"] if not b["skipped_unripe"] and b.get("ripe") is not False]
    return {
        "world": world,
        "seed": seed,
        "rule": rule,
        "body": body,
        "ripe": report.get("ripe_in_reach", report["attempted"]),
        "harvested": rate["harvested"],
        "unripe_picked": report.get("unripe_picked", 0),
        "contact_steps": report["branch_contact_steps"],
        "total_s": rate["total_s"],
        "survey_s": rate["stage_s"]["survey"],
        "fine_s": rate["stage_s"]["fine_positioning"],
        "berry_s": [b["duration_s"] for b in tried if b["harvested"]],
        "true_mm": [b["true_position_error_mm"] for b in tried if b["harvested"]],
        "fine_budget": [b["tag_id"] for b in tried if b["duration_s"] > 12.0],
    }


def summary(rows: list[dict[str, Any]]) -> str:
    """A markdown table: one line per world and rule."""
    out = [
        "| world | rule | bushes | s/berry mean | s/berry p90 | fine s/berry | true mm median "
        "| true <= 0.5 mm | harvested | unripe | contacts | berries > 12 s |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    worlds = sorted({(r["world"], r.get("body", "cube")) for r in rows})
    for world, body in worlds:
        for rule in RULES:
            group = [
                r for r in rows
                if (r["world"], r.get("body", "cube"), r["rule"]) == (world, body, rule)
            ]  # fmt: skip
            if group:
                out.append(_line(f"{world} ({body})", rule, group))
    return "\n".join(out)


def _line(world: str, rule: str, group: list[dict[str, Any]]) -> str:
    harvested = sum(r["harvested"] for r in group)
    # Each berry's own time plus its share of its bush's survey (the survey is per bush).
    per_berry = [s + r["survey_s"] / max(r["harvested"], 1) for r in group for s in r["berry_s"]]
    true = np.array([e for r in group for e in r["true_mm"]])
    ripe = sum(r["ripe"] for r in group)
    slow = sum(len(r["fine_budget"]) for r in group)
    return (
        f"| {world} | {rule} | {len(group)} | "
        f"{sum(r['total_s'] for r in group) / harvested:.2f} | "
        f"{np.percentile(per_berry, 90):.2f} | "
        f"{sum(r['fine_s'] for r in group) / harvested:.2f} | {np.median(true):.2f} | "
        f"{np.sum(true <= 0.5)}/{true.size} | {harvested}/{ripe} | "
        f"{sum(r['unripe_picked'] for r in group)} | "
        f"{sum(r['contact_steps'] for r in group)} | {slow} |"
    )


def main() -> None:
    parser = Parser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", choices=("tags", "bush"), default="tags")
    parser.add_argument("--seeds", type=non_negative_int, nargs="+", default=[1260])
    parser.add_argument("--berries", type=int_range(1, 20), default=3)
    parser.add_argument("--rules", choices=RULES, nargs="+", default=list(RULES))
    parser.add_argument("--marker-body", choices=("cube", "frustum"), default="cube")
    parser.add_argument("--out", type=Path, default=Path("out/fine_rule.jsonl"))
    parser.add_argument("--summary", type=Path, nargs="+", help="print the table of these")
    args = parser.parse_args()
    if args.summary:
        rows = [json.loads(line) for path in args.summary for line in path.open()]
        print(summary(rows))
        return
    args.out.parent.mkdir(parents=True, exist_ok=True)
    for seed in args.seeds:
        for rule in args.rules:
            row = one_bush(args.world, seed, args.berries, rule, args.marker_body)
            with args.out.open("a") as f:
                f.write(json.dumps(row) + "\n")
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
