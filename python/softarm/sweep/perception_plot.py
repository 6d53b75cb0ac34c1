"""The perception map's picture: one heat map per detector and figure (ripe precision,
ripe recall, ripe berries located by stereo within 10 mm) and, in the last column, the
cane map's (coverage, precision, median distance); a map's rows are the light and the
camera model, its columns the look-alikes and the fruit density; each square is a cell
pooled over its seeds, its value written in it (blank: nothing to score)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["plot_map"]

_DETECTOR_ROWS = (
    ("ripe_precision", "ripe precision"),
    ("recall_ripe", "ripe recall"),
    ("located", "located ≤ 10 mm"),
)
_CANE_ROWS = (
    ("coverage", "cane coverage"),
    ("precision", "cane precision"),
    ("median_mm", "cane median (mm)"),
)


def _grid(doc: dict[str, Any], value: Any) -> np.ndarray[Any, Any]:
    spec = doc["spec"]
    rows = [(lk, e) for lk in spec["looks"] for e in spec["effects"]]
    cols = [(a, f) for a in spec["lookalikes"] for f in spec["fruit"]]
    grid = np.full((len(rows), len(cols)), np.nan)
    for c in doc["cells"]:
        v = value(c)
        if v is not None:
            grid[
                rows.index((c["look"], c["effects"])), cols.index((c["lookalikes"], c["fruit"]))
            ] = v
    return grid


def _panel(
    ax: Any, grid: np.ndarray[Any, Any], doc: dict[str, Any], title: str, vmax: float, cmap: str
) -> None:
    spec = doc["spec"]
    ax.imshow(grid, vmin=0.0, vmax=vmax, cmap=cmap, aspect="auto")
    for (i, j), v in np.ndenumerate(grid):
        if np.isfinite(v):
            ax.text(
                j, i, f"{v:.2f}" if vmax <= 1 else f"{v:.1f}", ha="center", va="center", fontsize=8
            )
    ax.set_title(title, fontsize=10)
    ax.set_xticks(range(grid.shape[1]))
    ax.set_xticklabels([f"{a}\n{f}" for a in spec["lookalikes"] for f in spec["fruit"]], fontsize=7)
    ax.set_yticks(range(grid.shape[0]))
    ax.set_yticklabels([f"{lk} / {e}" for lk in spec["looks"] for e in spec["effects"]], fontsize=7)


def plot_map(doc: dict[str, Any], path: str | Path) -> None:
    """Draw the map of ``doc`` (:func:`~softarm.sweep.perception_map.summarise`) to the
    PNG ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    detectors = doc["spec"]["detectors"]
    canes = any(c.get("canes") for c in doc["cells"])
    ncols = len(detectors) + int(canes)
    fig, axes = plt.subplots(3, ncols, figsize=(3.4 * ncols + 1.0, 10.5), squeeze=False)
    for j, name in enumerate(detectors):
        for i, (key, label) in enumerate(_DETECTOR_ROWS):
            grid = _grid(doc, lambda c, n=name, k=key: c["detectors"][n].get(k))
            _panel(axes[i, j], grid, doc, f"{name}: {label}", 1.0, "RdYlGn")
    if canes:
        worst = max(
            (c["canes"]["median_mm"] or 0.0 for c in doc["cells"] if c.get("canes")), default=0.0
        )
        for i, (key, label) in enumerate(_CANE_ROWS):
            grid = _grid(doc, lambda c, k=key: (c.get("canes") or {}).get(k))
            mm = key == "median_mm"
            _panel(
                axes[i, -1],
                grid,
                doc,
                label,
                max(worst, 5.0) if mm else 1.0,
                "RdYlGn_r" if mm else "RdYlGn",
            )
    trials = doc["trials"]
    seeds = doc["spec"]["seeds"]
    fig.suptitle(
        f"Perception per frame on the daylight row: {len(doc['cells'])} cells × "
        f"{len(seeds)} seed(s) ({trials} frame pairs, seeds {seeds[0]}–{seeds[-1]})\n"
        "rows: light / camera model; columns: look-alikes / fruit",
        fontsize=11,
    )
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(path, dpi=80)
    plt.close(fig)
