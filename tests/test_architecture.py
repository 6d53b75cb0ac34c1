"""The structural rules of docs/architecture.md, checked on the source: each unit constant
is defined once, and ``softarm.sim`` imports nothing above it."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import softarm

PACKAGE = Path(softarm.__file__).parent


def _modules(root: Path) -> list[Path]:
    return sorted(p for p in root.rglob("*.py") if "__pycache__" not in p.parts)


def _numbers(tree: ast.AST) -> list[float]:
    """Every numeric literal in the code, with ``1.0 / 2100.0`` folded to its value."""
    out: list[float] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, int | float):
            out.append(float(node.value))
        if (
            isinstance(node, ast.BinOp)
            and isinstance(node.op, ast.Div)
            and isinstance(node.left, ast.Constant)
            and isinstance(node.right, ast.Constant)
            and isinstance(node.right.value, int | float)
            and node.right.value != 0
        ):
            out.append(float(node.left.value) / float(node.right.value))
    return out


def test_the_pressure_map_constant_is_written_once() -> None:
    """Only softarm/units.py spells the 1/2100 m per psi map (docstrings may mention it)."""
    offenders = [
        str(path.relative_to(PACKAGE))
        for path in _modules(PACKAGE)
        if path.name != "units.py"
        and any(v in (2100.0, 1.0 / 2100.0) for v in _numbers(ast.parse(path.read_text())))
    ]
    assert offenders == []


def test_every_module_uses_the_same_unit_objects() -> None:
    from softarm import units
    from softarm.config import ChannelsConfig
    from softarm.hardware import pressure_map
    from softarm.sim import pressure

    assert pressure_map.METRES_PER_PSI is units.METRES_PER_PSI
    assert pressure.METRES_PER_PSI is units.METRES_PER_PSI
    assert pressure.MAX_PSI is units.MAX_PSI
    assert pressure_map.ElongationMap().max_psi == units.MAX_PSI
    assert ChannelsConfig().metres_per_psi == units.METRES_PER_PSI == 1.0 / 2100.0
    assert ChannelsConfig().p_max == units.MAX_PSI == 70.0


#: What ``softarm.sim`` may not import: the layers above it, and private vision modules.
FORBIDDEN = ("softarm.harvest", "softarm.commands", "softarm.cli")


def _imports(tree: ast.AST) -> list[str]:
    names: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.extend(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.append(node.module)
            names.extend(f"{node.module}.{alias.name}" for alias in node.names)
    return names


def _violations(name: str) -> bool:
    if any(name == f or name.startswith(f + ".") for f in FORBIDDEN):
        return True
    parts = name.split(".")
    return len(parts) >= 3 and parts[:2] == ["softarm", "vision"] and parts[2].startswith("_")


@pytest.mark.parametrize(
    "path", _modules(PACKAGE / "sim"), ids=lambda p: str(p.relative_to(PACKAGE))
)
def test_sim_imports_nothing_above_it(path: Path) -> None:
    bad = [n for n in _imports(ast.parse(path.read_text())) if _violations(n)]
    assert bad == [], f"{path.relative_to(PACKAGE)} imports {bad}"


def test_the_layer_check_can_fail() -> None:
    tree = ast.parse(
        "from softarm.harvest.control.ik import cone_axes\n"
        "from softarm.vision._checks import finite\n"
        "import softarm.cli\n"
        "from softarm.vision import detector\n"
    )
    assert [n for n in _imports(tree) if _violations(n)] == [
        "softarm.harvest.control.ik",
        "softarm.harvest.control.ik.cone_axes",
        "softarm.vision._checks",
        "softarm.vision._checks.finite",
        "softarm.cli",
    ]


#: The layers of docs/architecture.md, bottom up, and what each may not import: nothing
#: above it. ``softarm.viz``'s drawing geometry (``viz.arm``, ``viz.gripper``) sits below
#: the harvest and the planning that plot with it; its rerun views of a harvest above.
_TOP = ("softarm.commands", "softarm.cli", "softarm.sweep", "softarm.experiments")
_HARVEST_UP = (*_TOP, "softarm.harvest", "softarm.planning", "softarm.viz")
_FIT_UP = (*_HARVEST_UP, "softarm.calibration", "softarm.identification")
_SIM_UP = (*_FIT_UP, "softarm.sim")
#: What the harvest may not import: the top, the planning, and the viz above its drawing
#: geometry (``viz.arm``, ``viz.gripper``); the viz's harvest views import the harvest.
_VIZ_ABOVE_HARVEST = tuple(
    f"softarm.viz.{p.stem}"
    for p in sorted((PACKAGE / "viz").iterdir())
    if p.stem not in ("arm", "gripper", "__init__", "__pycache__")
)
_HARVEST_ABOVE = (*_TOP, "softarm.planning", *_VIZ_ABOVE_HARVEST)
LAYERS: dict[str, tuple[str, ...]] = {
    "units.py": ("softarm.",),
    "so3.py": ("softarm.",),
    "geometry.py": ("softarm.",),
    "checks.py": ("softarm.",),
    "errors.py": ("softarm.",),
    "uninterrupted.py": ("softarm.",),
    "files": ("softarm.",),
    "hardware": (*_SIM_UP, "softarm.vision", "softarm.config"),
    "config.py": (*_SIM_UP, "softarm.vision"),
    "harvest_config.py": (*_SIM_UP, "softarm.vision", "softarm.config"),
    "identified_plant.py": (*_SIM_UP, "softarm.vision"),
    "vision": _SIM_UP,
    "perception": _SIM_UP,
    "sim": _FIT_UP,
    "calibration": _HARVEST_UP,
    "identification": _HARVEST_UP,
    "viz/arm.py": _HARVEST_UP,
    "viz/gripper.py": _HARVEST_UP,
    # harvest's rooms, bottom up: the machine, its control stack and its records; the runs
    # over them; the rigs (the only place the simulator and the arm differ) on top.
    "harvest/machine": (*_HARVEST_ABOVE, "softarm.harvest.runs", "softarm.harvest.rigs"),
    "harvest/control": (*_HARVEST_ABOVE, "softarm.harvest.runs", "softarm.harvest.rigs"),
    "harvest/records": (*_HARVEST_ABOVE, "softarm.harvest.runs", "softarm.harvest.rigs"),
    "harvest/runs": (*_HARVEST_ABOVE, "softarm.harvest.rigs"),
    "harvest": _HARVEST_ABOVE,
    "config_table.py": ("softarm.",),
    "formatting.py": ("softarm.",),
    "stops.py": _SIM_UP,  # over softarm.uninterrupted, a leaf
    "perception_config.py": (*_SIM_UP, "softarm.config", "softarm.harvest_config",
                             "softarm.perception"),
    "_arm_config.py": _HARVEST_UP,
    "planning": (*_TOP, "softarm.harvest"),
    "viz": _TOP,
    "sweep": ("softarm.commands", "softarm.cli", "softarm.experiments"),
    "experiments": ("softarm.commands", "softarm.cli", "softarm.sweep"),
    # The top: the command line and the package's own entry points may import anything.
    "commands": (),
    "cli.py": (),
    "__init__.py": (),
    "__main__.py": (),
    "_stubdocs.py": (),
}  # fmt: skip
#: What a leaf module may import of softarm (softarm.files is itself a leaf over errors).
LEAF_MAY = ("softarm.errors", "softarm._core", "softarm.files")


def _layer_violations(rel: str, source: str) -> list[str]:
    """The imports of module ``rel`` (path under softarm/) that its layer forbids."""
    key = _layer_of(rel)
    forbidden = () if key is None else LAYERS[key]
    return [
        n
        for n in _imports(ast.parse(source))
        if any(n == f or n.startswith(f if f.endswith(".") else f + ".") for f in forbidden)
        and not any(n == m or n.startswith(m + ".") for m in LEAF_MAY)
    ]


@pytest.mark.parametrize("path", _modules(PACKAGE), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_every_layer_imports_nothing_above_it(path: Path) -> None:
    rel = path.relative_to(PACKAGE).as_posix()
    bad = _layer_violations(rel, path.read_text())
    assert bad == [], f"{rel} imports {bad} (see the layers of docs/architecture.md)"


def _layer_of(rel: str) -> str | None:
    """The LAYERS key that holds module ``rel`` (path under softarm/), if any."""
    return next((k for k in LAYERS if rel == k or rel.startswith(k + "/")), None)


def test_every_module_has_a_layer() -> None:
    """A module no LAYERS entry covers could import anything unnoticed."""
    missing = [
        p.relative_to(PACKAGE).as_posix()
        for p in _modules(PACKAGE)
        if _layer_of(p.relative_to(PACKAGE).as_posix()) is None
    ]
    assert missing == [], f"{missing}: add them to LAYERS (docs/architecture.md, Layers)"


def test_the_layer_table_can_fail() -> None:
    up = "from softarm.harvest.machine.interfaces import Observation\nimport softarm.cli\n"
    assert _layer_violations("vision/two_cameras.py", up) == [
        "softarm.harvest.machine.interfaces",
        "softarm.harvest.machine.interfaces.Observation",
        "softarm.cli",
    ]
    assert _layer_violations("config.py", "from softarm.identification.estimate import X\n")
    assert _layer_violations("units.py", "from softarm.so3 import exp\n")
    assert not _layer_violations("units.py", "from softarm.errors import InputError\n")
    assert _layer_violations("harvest/rigs/sim/plots.py", "from softarm.viz.replay import replay\n")
    assert not _layer_violations("harvest/rigs/sim/plots.py", "from softarm.viz.arm import X\n")
    assert _layer_violations(
        "harvest/machine/stages/servo.py", "from softarm.harvest.rigs import sim_rig\n"
    )
    assert _layer_violations(
        "harvest/runs/policy.py", "from softarm.harvest.rigs.hardware.rig import X\n"
    )
    assert not _layer_violations(
        "harvest/runs/policy.py", "from softarm.harvest.machine import X\n"
    )


def _only_reexports(tree: ast.Module) -> bool:
    """A module whose body is a docstring, imports and ``__all__``: a shim for an old path."""
    body = [
        n for n in tree.body if not (isinstance(n, ast.Expr) and isinstance(n.value, ast.Constant))
    ]
    imports = [n for n in body if isinstance(n, ast.Import | ast.ImportFrom)]
    rest = [n for n in body if n not in imports]
    all_only = all(
        isinstance(n, ast.Assign) and [getattr(t, "id", None) for t in n.targets] == ["__all__"]
        for n in rest
    )
    return bool(imports) and all_only


def test_the_package_keeps_no_reexport_shims() -> None:
    """Old paths are not kept alive by shims (docs/architecture.md, "Layers"): each name
    has one module; a package's ``__init__`` may gather its public surface."""
    shims = [
        path.relative_to(PACKAGE).as_posix()
        for path in _modules(PACKAGE)
        if path.name != "__init__.py" and _only_reexports(ast.parse(path.read_text()))
    ]
    assert shims == []


def test_the_shim_check_can_fail() -> None:
    shim = ast.parse('"""Old path."""\nfrom softarm.sim.plant import ArmPlant\n__all__ = ["A"]\n')
    real = ast.parse("from softarm.sim.plant import ArmPlant\nX = ArmPlant\n")
    assert _only_reexports(shim)
    assert not _only_reexports(real)


def test_moved_helpers_are_the_same_objects_or_give_the_same_results() -> None:
    import numpy as np

    from softarm import checks, geometry
    from softarm.harvest.control import clearance, ik
    from softarm.sim import plant
    from softarm.vision import _checks

    assert plant.ArmPlant.__module__ == "softarm.sim.plant"
    assert (_checks.as_pose, _checks.as_array, _checks.positive) == (
        checks.as_pose,
        checks.as_array,
        checks.positive,
    )
    assert clearance.ACTUATOR_RADIUS is geometry.ACTUATOR_RADIUS
    for axis in ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.3, -0.2, 0.9]):
        a = np.array(axis)
        np.testing.assert_array_equal(geometry.cone_axes(a, 35.0), ik.cone_axes(a, 35.0))


def test_plant_step_advances_like_apply_without_measuring() -> None:
    import numpy as np

    from softarm.sim.arm import SimulatedArm

    a, b = SimulatedArm(seed=3), SimulatedArm(seed=3)
    q = np.full(9, 0.02)
    for _ in range(5):
        measured = a.apply(q, 0.05)
        b.step(q, 0.05)
    np.testing.assert_array_equal(a.pressure, b.pressure)
    np.testing.assert_array_equal(a.true_pose(), b.true_pose())
    assert measured.shape == (4, 4)
    assert a.time == b.time


#: The longest a function of the package may be (issue 27: functions short enough to
#: read whole; split where the parts have names).
MAX_FUNCTION_LINES = 80


def test_no_function_of_the_package_is_over_80_lines() -> None:
    long = [
        f"{path.relative_to(PACKAGE).as_posix()}:{node.lineno} {node.name} "
        f"({node.end_lineno - node.lineno + 1} lines)"
        for path in _modules(PACKAGE)
        for node in ast.walk(ast.parse(path.read_text()))
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
        and node.end_lineno is not None
        and node.end_lineno - node.lineno + 1 > MAX_FUNCTION_LINES
    ]
    assert not long, f"functions over {MAX_FUNCTION_LINES} lines: {long}"


MAX_CLASS_LINES = 300


def test_no_class_of_the_package_is_over_300_lines() -> None:
    """Small objects (issue 38 item 5): a class over 300 lines holds more than one job."""
    long = [
        f"{path.relative_to(PACKAGE).as_posix()}:{node.lineno} {node.name} "
        f"({node.end_lineno - node.lineno + 1} lines)"
        for path in _modules(PACKAGE)
        for node in ast.walk(ast.parse(path.read_text()))
        if isinstance(node, ast.ClassDef)
        and node.end_lineno is not None
        and node.end_lineno - node.lineno + 1 > MAX_CLASS_LINES
    ]
    assert not long, f"classes over {MAX_CLASS_LINES} lines: {long}"


def test_the_names_a_config_lists_are_the_modules_own() -> None:
    """The config layer lists the names of what sits above it (so that reading a config
    imports no perception or vision); each list must equal its module's."""
    from softarm import config, perception_config
    from softarm.perception.cane_source import CANE_SOURCES
    from softarm.perception.detector.choice import DETECTORS
    from softarm.vision.marker_body import MARKER_BODIES

    assert tuple(config.MARKER_BODY_NAMES) == tuple(MARKER_BODIES)
    assert tuple(perception_config.DETECTORS) == tuple(DETECTORS)
    assert tuple(perception_config.CANE_SOURCES) == tuple(CANE_SOURCES)
