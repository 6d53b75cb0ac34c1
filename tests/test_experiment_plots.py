"""The experiments' pressure plots name their channels (issue 25: a channel legend)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from softarm.experiments.common import Trace
from softarm.experiments.output import channel_labels, plot_comparison


def test_channels_are_named_as_the_papers_number_them() -> None:
    assert channel_labels(9) == ["l11", "l12", "l13", "l21", "l22", "l23", "l31", "l32", "l33"]


def test_the_pressure_panels_carry_a_channel_legend(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import matplotlib.pyplot as plt

    legends: list[list[str]] = []
    close = plt.close

    def keep(fig: object = None) -> None:
        for ax in plt.gcf().axes:
            legend = ax.get_legend()
            if legend is not None:
                legends.append([t.get_text() for t in legend.get_texts()])
        close(fig)  # type: ignore[arg-type]

    monkeypatch.setattr(plt, "close", keep)
    t = np.linspace(0.0, 1.0, 5)
    trace = Trace(list(t), list(t), list(t), [np.full(9, 10.0 * k) for k in range(5)])
    plot_comparison(tmp_path / "p.png", "test", {"proposed": trace})
    assert (tmp_path / "p.png").stat().st_size > 0
    assert channel_labels(9) in legends
