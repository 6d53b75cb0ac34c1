"""Path planning among curve obstacles: the planning paper's three simulations, the
comparison with point-set obstacle models, and snapshot plots (figures 3-5).

The planner itself (eq. 9) and the exact arc-to-curve distance (eq. 10-18) run in the
Rust core; this package only sets up scenarios, measures and draws.
"""

from softarm.planning.scenarios import (
    COLLISION_DISTANCE,
    PAPER_TABLES,
    POINT_MODELS,
    SCENARIOS,
    Result,
    Scenario,
    compare,
    load,
    run_method,
)

__all__ = [
    "COLLISION_DISTANCE",
    "PAPER_TABLES",
    "POINT_MODELS",
    "SCENARIOS",
    "Result",
    "Scenario",
    "compare",
    "load",
    "run_method",
]
