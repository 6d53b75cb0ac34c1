"""Writing experiment results: CSV tables, JSON summaries and PNG plots like the
paper's figures 6-9."""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from softarm.experiments.common import Trace
from softarm.units import MAX_PSI


def mean_std(values: Sequence[float], scale: float = 1.0) -> dict[str, float]:
    """Mean, standard deviation and maximum of ``values`` times ``scale``."""
    a = np.asarray(values, dtype=np.float64) * scale
    return {"mean": float(a.mean()), "std": float(a.std()), "max": float(a.max())}


def write_csv(path: Path, header: Sequence[str], rows: Sequence[Sequence[Any]]) -> None:
    """A CSV file with a header row."""
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


def write_json(path: Path, data: dict[str, Any]) -> None:
    """A JSON file (infinities written as null)."""

    def clean(x: Any) -> Any:
        if isinstance(x, float) and not math.isfinite(x):
            return None
        if isinstance(x, dict):
            return {k: clean(v) for k, v in x.items()}
        if isinstance(x, list | tuple):
            return [clean(v) for v in x]
        return x

    path.write_text(json.dumps(clean(data), indent=2) + "\n")


def channel_labels(n: int) -> list[str]:
    """The actuators' names in the papers' numbering, ``l11`` ... ``l33``: section then
    actuator, from 1 (docs/architecture.md; the API's q[3i + j] is l(i+1)(j+1))."""
    return [f"l{i // 3 + 1}{i % 3 + 1}" for i in range(n)]


def plot_comparison(
    path: Path,
    title: str,
    traces: dict[str, Trace],
    *,
    orientation: bool = False,
    max_psi: float = MAX_PSI,
) -> None:
    """Error vs time for each controller (A), then the commanded pressures of each (B, C...),
    like Fig. 7-9. Pressures outside [0, max_psi] are infeasible."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = len(traces)
    rows = 1 + n + int(orientation)
    fig, axes = plt.subplots(rows, 1, figsize=(7, 2.2 * rows), sharex=True)
    ax = axes[0]
    for name, tr in traces.items():
        ax.semilogy(tr.time, np.asarray(tr.position_error) * 1e3 + 1e-6, label=name)
    ax.set_ylabel("position error (mm)")
    ax.legend()
    ax.set_title(title)
    k = 1
    if orientation:
        ax = axes[1]
        for name, tr in traces.items():
            ax.semilogy(tr.time, np.degrees(tr.orientation_error) + 1e-6, label=name)
        ax.set_ylabel("orientation error (deg)")
        k = 2
    for name, tr in traces.items():
        ax = axes[k]
        psi = np.asarray(tr.command_psi)
        for j, label in enumerate(channel_labels(psi.shape[1])):
            ax.plot(tr.time, psi[:, j], label=label, lw=1.0)
        ax.legend(ncol=3, fontsize=6, title="channel", title_fontsize=6, loc="upper right")
        ax.axhline(0.0, color="k", lw=0.8)
        ax.axhline(max_psi, color="k", lw=0.8, ls="--")
        ax.set_ylabel("command (psi)")
        ax.set_title(f"{name}: commanded pressures", fontsize=9)
        k += 1
    axes[-1].set_xlabel("time (s)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_final_errors(
    path: Path, title: str, labels: Sequence[str], errors: Mapping[str, Sequence[float]], unit: str
) -> None:
    """Final error per set-point for each controller (like Fig. 6)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 3))
    x = np.arange(len(labels))
    width = 0.8 / max(1, len(errors))
    for i, (name, e) in enumerate(errors.items()):
        ax.bar(x + i * width, e, width, label=name)
    ax.set_yscale("log")
    ax.set_xlabel("set-point")
    ax.set_ylabel(f"final error ({unit})")
    ax.set_title(title)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
