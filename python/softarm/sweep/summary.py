"""Summaries of a sweep's results table: per-key and per-plant-point Markdown tables and
``summary.png`` (success, error and cycle time against each swept key)."""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from softarm.formatting import plural

__all__ = ["GroupStats", "axis_label", "group_stats", "markdown_summary", "plot_summary"]


@dataclass(frozen=True)
class GroupStats:
    """The figures of a set of berries (rows that ran; failed trials counted apart)."""

    berries: int
    harvested: float  # fraction
    mean_error_mm: float  # true fine-positioning error of the harvested berries
    std_error_mm: float
    median_duration_s: float  # simulated seconds per berry, all berries
    contact_steps: int  # cane-contact steps, summed over the trials (bushes)
    min_gap_mm: float  # smallest arm-to-cane gap over the trials
    failed_trials: int
    #: Berries harvested per hour of simulated time over the trials (their harvested
    #: berries over their simulated time: survey, moves and way home included).
    berries_per_hour: float = math.nan


def _stats(rows: list[dict[str, Any]]) -> GroupStats:
    ran = [r for r in rows if r["error"] is None]
    failed = len({r["trial_id"] for r in rows if r["error"] is not None})
    harvested = [r for r in ran if r["harvested"]]
    errs = np.array([r["true_position_error_mm"] for r in harvested
                     if r["true_position_error_mm"] is not None], dtype=float)  # fmt: skip
    durs = np.array([r["duration_s"] for r in ran if r["duration_s"] is not None], dtype=float)
    per_trial = {r["trial_id"]: r for r in ran}
    gaps = [r["min_branch_gap_m"] for r in per_trial.values() if r["min_branch_gap_m"] is not None]
    return GroupStats(
        berries=len(ran),
        harvested=len(harvested) / len(ran) if ran else math.nan,
        mean_error_mm=float(errs.mean()) if errs.size else math.nan,
        std_error_mm=float(errs.std()) if errs.size else math.nan,
        median_duration_s=float(np.median(durs)) if durs.size else math.nan,
        contact_steps=int(sum(r["branch_contact_steps"] or 0 for r in per_trial.values())),
        min_gap_mm=1e3 * min(gaps) if gaps else math.nan,
        failed_trials=failed,
        berries_per_hour=_rate(per_trial.values(), len(harvested)),
    )


def _rate(trials: Iterable[dict[str, Any]], harvested: int) -> float:
    """Harvested berries per hour of the trials' simulated time (NaN without it)."""
    seconds = [t["sim_s"] for t in trials if t.get("sim_s") is not None]
    return 3600.0 * harvested / sum(seconds) if seconds and sum(seconds) > 0 else math.nan


def group_stats(
    rows: list[dict[str, Any]], keys: Sequence[str]
) -> dict[tuple[Any, ...], GroupStats]:
    """Stats per distinct value of ``keys`` (sorted)."""
    groups: dict[tuple[Any, ...], list[dict[str, Any]]] = defaultdict(list)
    for r in rows:
        groups[tuple(r[k] for k in keys)].append(r)
    return {k: _stats(groups[k]) for k in sorted(groups)}


def _fmt(v: float, spec: str) -> str:
    return "–" if isinstance(v, float) and math.isnan(v) else format(v, spec)


def _table(keys: Sequence[str], stats: dict[tuple[Any, ...], GroupStats]) -> list[str]:
    head = [*keys, "berries", "harvested", "mean error (mm)", "median s / berry",
            "contact steps", "min gap (mm)", "berries / h", "failed trials"]  # fmt: skip
    out = ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
    for k, s in stats.items():
        cells = [*map(str, k), str(s.berries), _fmt(100 * s.harvested, ".1f") + " %",
                 _fmt(s.mean_error_mm, ".2f"), _fmt(s.median_duration_s, ".1f"),
                 str(s.contact_steps), _fmt(s.min_gap_mm, ".1f"),
                 _fmt(s.berries_per_hour, ".0f"), str(s.failed_trials)]  # fmt: skip
        out.append("| " + " | ".join(cells) + " |")
    return out


def markdown_summary(rows: list[dict[str, Any]], keys: Sequence[str]) -> str:
    """Markdown: overall, one table per swept key (the others pooled), and every point."""
    lines = ["## All trials", "", *_table([], group_stats(rows, [])), ""]
    for key in keys:
        lines += [f"## By {key}", "", *_table([key], group_stats(rows, [key])), ""]
    if len(keys) > 1:
        lines += ["## By plant point", "", *_table(list(keys), group_stats(rows, keys)), ""]
    return "\n".join(lines)


def axis_label(key: str) -> str:
    """A swept key as an axis label, with its unit (the plant file's): ``pressure_tau
    (s)``, ``twist_spread (rad)``, a relative spread ``gain_spread (relative)``; a key
    that names its unit (``hysteresis_psi``), the model and the seed stay as they are."""
    from softarm.sim.plant_file import PLANT_KEYS

    spec = PLANT_KEYS.get(key)
    if spec is None or spec.kind == "model" or key.endswith(f"_{spec.unit}"):
        return key
    return f"{key} ({spec.unit or 'relative'})"


def plot_summary(rows: list[dict[str, Any]], keys: Sequence[str], path: str | Path) -> None:
    """``path`` (PNG): harvested %, mean error and median cycle time (rows) against each
    swept key (columns; the other keys pooled), or against the seed if none is swept."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cols = list(keys) or ["seed"]
    fig, axes = plt.subplots(3, len(cols), figsize=(3.6 * len(cols) + 0.6, 7.5), squeeze=False)
    for j, key in enumerate(cols):
        stats = group_stats(rows, [key])
        numeric = all(isinstance(k[0], int | float) for k in stats)
        xs = [k[0] for k in stats] if numeric else list(range(len(stats)))
        st = list(stats.values())
        ax_s, ax_e, ax_t = axes[0, j], axes[1, j], axes[2, j]
        ax_s.plot(xs, [100 * s.harvested for s in st], "o-", color="tab:green")
        ax_e.errorbar(xs, [s.mean_error_mm for s in st], yerr=[s.std_error_mm for s in st],
                      fmt="o-", color="tab:blue", capsize=3)  # fmt: skip
        ax_t.plot(xs, [s.median_duration_s for s in st], "o-", color="tab:orange")
        ax_s.set_ylim(0, 105)
        ax_t.set_xlabel(axis_label(key))
        if not numeric:
            for ax in (ax_s, ax_e, ax_t):
                ax.set_xticks(xs, [str(k[0]) for k in stats])
        for ax in (ax_s, ax_e, ax_t):
            ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("harvested (%)")
    axes[1, 0].set_ylabel("mean true error (mm)")
    axes[2, 0].set_ylabel("median s / berry (sim.)")
    n = sum(r["error"] is None for r in rows)
    fig.suptitle(f"softarm sweep: {plural(n, 'berry')}, other keys pooled")
    fig.tight_layout()
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
