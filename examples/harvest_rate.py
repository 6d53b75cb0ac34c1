"""The harvest rate and where its time goes: simulated harvests of the tag world and the
rendered bush on the same seeds, each bush's ``rate`` (softarm.harvest.records.rate) summed per
world into seconds per harvested berry by stage, drawn as one stacked bar per world.

    MUJOCO_GL=egl python examples/harvest_rate.py --seeds 90050 90051 90052 --berries 6 \
        --out out/rate

writes ``rate.json`` (per world: berries harvested, simulated seconds, berries per hour,
seconds per berry by stage) and ``rate.png`` to --out; docs/harvest.md shows the picture.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from softarm.commands._args import Parser, int_range, non_negative_int, output_dir

WORLDS = ("tags", "bush")


def one_bush(world: str, seed: int, berries: int) -> dict[str, Any]:
    """One simulated harvest's ``rate`` record (its harvested berries, time and stages)."""
    from softarm.harvest.rigs.sim.options import SimRigOptions
    from softarm.harvest.rigs.sim.rig import build_sim_rig

    rig = build_sim_rig(SimRigOptions(n_berries=berries, seed=seed, world=world))
    try:
        rate: dict[str, Any] = rig.run().to_dict()["rate"]
    finally:
        rig.close()
    return rate


def pooled(rates: list[dict[str, Any]]) -> dict[str, Any]:
    """The bushes of one world together: harvested over simulated time, and each stage's
    seconds per harvested berry."""
    harvested = sum(r["harvested"] for r in rates)
    total = sum(r["total_s"] for r in rates)
    stages = {k: sum(r["stage_s"][k] for r in rates) for k in rates[0]["stage_s"]}
    per_berry = {k: v / harvested if harvested else float("nan") for k, v in stages.items()}
    return {
        "bushes": len(rates),
        "harvested": harvested,
        "sim_s": total,
        "berries_per_hour": 3600.0 * harvested / total if total > 0 else 0.0,
        "s_per_berry_by_stage": per_berry,
    }


def plot(by_world: dict[str, dict[str, Any]], path: Path) -> None:
    """One stacked horizontal bar per world: seconds per harvested berry by stage."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 1.6 + 0.5 * len(by_world)))
    stages = list(next(iter(by_world.values()))["s_per_berry_by_stage"])
    for row, figures in enumerate(by_world.values()):
        left = 0.0
        for k, stage in enumerate(stages):
            width = figures["s_per_berry_by_stage"][stage]
            ax.barh(row, width, left=left, color=f"C{k}", label=stage if row == 0 else None)
            left += width
        ax.text(left + 0.05, row, f"{figures['berries_per_hour']:.0f} berries/h", va="center")
    ax.set_yticks(
        range(len(by_world)), [f"{w} ({f['bushes']} bushes)" for w, f in by_world.items()]
    )
    longest = max(sum(f["s_per_berry_by_stage"].values()) for f in by_world.values())
    ax.set_xlim(0.0, 1.3 * longest)  # room for the rate beside the longest bar
    ax.set_xlabel("simulated seconds per harvested berry")
    ax.legend(ncol=len(stages), loc="upper center", bbox_to_anchor=(0.5, -0.35), frameon=False)
    ax.set_title("Where a berry's time goes (nominal plant)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = Parser(prog="harvest_rate.py", description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--seeds", type=non_negative_int, nargs="+", default=[90050, 90051, 90052],
        help="one bush per seed, the same in every world",
    )  # fmt: skip
    ap.add_argument("--berries", type=int_range(1, 40), default=6, help="berries per bush")
    ap.add_argument("--worlds", nargs="+", choices=WORLDS, default=list(WORLDS), help="worlds")
    ap.add_argument("--out", type=output_dir, default="out/rate", help="output folder")
    args = ap.parse_args(argv)
    by_world = {w: pooled([one_bush(w, s, args.berries) for s in args.seeds]) for w in args.worlds}
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "rate.json").write_text(json.dumps(by_world, indent=1) + "\n")
    plot(by_world, args.out / "rate.png")
    for world, f in by_world.items():
        stages = ", ".join(f"{k} {v:.2f}" for k, v in f["s_per_berry_by_stage"].items())
        print(f"{world}: {f['berries_per_hour']:.0f} berries/h simulated ({stages} s a berry)")
    print(f"wrote {args.out}/rate.json, rate.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
