"""The viewer's default layout (a rerun blueprint): the 3-D scene large on the left, both
cameras beside it, and the errors, the state and the state machine's log on the right."""

from __future__ import annotations

from typing import Any

from softarm.viz.rerun_sdk import require_rerun

__all__ = ["harvest_blueprint"]


def harvest_blueprint(cameras: bool = True) -> Any:
    """The layout of a harvest recording; ``cameras=False`` (a replayed log has no
    images) leaves out the camera column."""
    rrb = require_rerun().blueprint
    scene = rrb.Spatial3DView(origin="world", name="arm, canes and berries")
    plots = rrb.Vertical(
        rrb.TimeSeriesView(
            origin="errors",
            contents=["errors/position_mm", "errors/true_grasp_mm", "errors/true_position_mm"],
            name="position error (mm)",
        ),
        rrb.TimeSeriesView(
            origin="errors",
            contents=["errors/pointing_deg", "errors/target_age_s", "errors/true_gap_mm"],
            name="pointing (deg), fix age (s), cane gap (mm)",
        ),
        rrb.TimeSeriesView(origin="harvest/state_index", name="state (0 idle ... 6 fault)"),
        rrb.TextLogView(origin="harvest", name="state machine"),
    )
    columns: list[Any] = [scene]
    if cameras:
        columns.append(
            rrb.Vertical(
                rrb.Spatial2DView(origin="world/c1/image", name="C1 eye-to-hand"),
                rrb.Spatial2DView(origin="world/c2/image", name="C2 eye-in-hand"),
            )
        )
    columns.append(plots)
    shares = [2.0, 1.2, 1.2] if cameras else [2.0, 1.2]
    return rrb.Blueprint(rrb.Horizontal(*columns, column_shares=shares), collapse_panels=False)
