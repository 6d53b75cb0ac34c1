"""Perception measured on rendered bushes it was not tuned on: the berry detector and
the stereo localisation on C1 (docs/perception.md's tables come from here)."""

from __future__ import annotations

import time
from collections.abc import Iterable

import softarm
from softarm.harvest.sim_rig import default_cameras
from softarm.harvest.sim_vision import BASE_TAG_ID
from softarm.perception.stereo import locate_berries
from softarm.sim.bush import Bush
from softarm.sim.render.scoring import BerryScore, score_berries
from softarm.sim.render.world import world_for

__all__ = ["evaluate_berries"]


def evaluate_berries(
    seeds: Iterable[int], n_berries: int = 10, unripe_fraction: float = 0.4
) -> list[tuple[int, BerryScore]]:
    """Render one bush per seed (no arm in view), run the stereo berry perception on C1,
    and score it; the time is that of :func:`locate_berries` alone."""
    arm = softarm.SoftArm.blackberry()
    cams = default_cameras()
    out = []
    for seed in seeds:
        bush = Bush.generate(
            arm, n_berries, seed, view_point=cams.T_base_c1[:3, 3], unripe_fraction=unripe_fraction
        )
        world = world_for(bush, cams, BASE_TAG_ID)
        left, right = world.c1()
        t0 = time.perf_counter()
        dets = locate_berries(left.colour, right.colour, world.stereo)
        elapsed = time.perf_counter() - t0
        score = score_berries(world, dets)
        score.seconds.append(elapsed)
        world.close()
        out.append((seed, score))
    return out


def table(seeds: Iterable[int]) -> str:
    """A Markdown table of :func:`evaluate_berries` over ``seeds``, one row per bush and
    the pooled figures last."""
    header = "| bush | precision | recall | ripe/unripe right | ripe ≥ ½ visible | localised "
    rows = [header + "| median mm | p95 mm |", "|" + " --- |" * 8]
    pooled = BerryScore()
    for seed, score in evaluate_berries(seeds):
        pooled.add(score)
        rows.append(_row(str(seed), score.summary()))
    rows.append(_row("**all**", pooled.summary()))
    return "\n".join(rows)


def _row(name: str, s: dict[str, float | tuple[float, float]]) -> str:
    return (
        f"| {name} | {s['precision']:.3f} | {s['recall']:.3f} | {s['ripeness_accuracy']:.3f} "
        f"| {s['ripe_in_view']} | {s['localised']} | {s['median_mm']:.2f} | {s['p95_mm']:.2f} |"
    )


if __name__ == "__main__":  # python -m softarm.experiments.perception FIRST LAST
    import sys

    print(table(range(int(sys.argv[1]), int(sys.argv[2]) + 1)))
