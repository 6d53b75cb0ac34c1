"""The planning figures: every line inside its axes, and the colliding point models drawn
at their first contact."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

from softarm import _core
from softarm.planning.plot import first_contact, plot_plan
from softarm.planning.scenarios import COLLISION_DISTANCE, compare, load


@pytest.fixture(scope="module")
def curve_results():
    return compare("curve", repeats=1)


def _drawn_figure(monkeypatch, *args, **kwargs):
    """Run plot_plan and keep the figure it closes."""
    kept = []
    monkeypatch.setattr(plt, "close", kept.append)
    plot_plan(*args, **kwargs)
    (fig,) = kept
    return fig


def test_every_line_stays_inside_the_axes(curve_results, tmp_path, monkeypatch) -> None:
    # The curve scenario's parabola climbs to z = 20 m, far above the arm's 3 m.
    scenario = load("curve")
    fig = _drawn_figure(
        monkeypatch, scenario, curve_results[0].plan, tmp_path / "p.png", "t", curve_results[1:]
    )
    assert (tmp_path / "p.png").stat().st_size > 0
    for ax in fig.axes:
        limits = np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()])
        for line in ax.get_lines():
            pts = np.column_stack(line.get_data_3d())
            pts = pts[np.all(np.isfinite(pts), axis=1)]
            assert np.all(pts >= limits[:, 0] - 1e-9) and np.all(pts <= limits[:, 1] + 1e-9)
    plt.close(fig)


def test_colliding_baselines_get_their_own_panel(curve_results, tmp_path, monkeypatch) -> None:
    colliding = [r for r in curve_results[1:] if r.collision]
    assert colliding  # the point models pass through the gaps between their points
    scenario = load("curve")
    fig = _drawn_figure(
        monkeypatch, scenario, curve_results[0].plan, tmp_path / "p.png", "", curve_results[1:]
    )
    assert len(fig.axes) == 4
    labels = fig.axes[3].get_legend_handles_labels()[1]
    for r in colliding:
        assert any(label.startswith(f"{r.method}: contact") for label in labels)
    plt.close(fig)


def test_first_contact_matches_the_judged_collision(curve_results) -> None:
    scenario = load("curve")
    assert first_contact(scenario, curve_results[0].plan) is None  # the proposed plan
    for r in curve_results[1:]:
        contact = first_contact(scenario, r.plan)
        assert (contact is not None) == r.collision
        if contact is not None:
            at, q, point = contact
            assert 0.0 <= at <= r.plan.iterations
            near = min(
                (_core.closest(scenario.chain, q, c) for c in scenario.curves),
                key=lambda c: c.distance,
            )
            assert near.distance < COLLISION_DISTANCE
            assert np.allclose(near.obstacle_point, point)
