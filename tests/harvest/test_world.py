"""One World for the simulator (docs/architecture.md, "The rooms of softarm.harvest"):
the rig asks its world, never its name; a world's name is parsed once, into an enum."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

import softarm
from softarm.errors import ParameterError
from softarm.harvest.rigs.sim.options import SimRigOptions
from softarm.harvest.rigs.sim.rig import build_sim_rig, sim_bush
from softarm.harvest.rigs.sim.tag_world import TagWorld
from softarm.harvest.rigs.sim.worlds import WORLDS
from softarm.sim.world import WorldName

PACKAGE = Path(softarm.__file__).parent


def test_a_world_name_is_parsed_once_with_a_clear_error() -> None:
    assert WorldName.parse("row") is WorldName.ROW
    assert SimRigOptions(world="bush").world is WorldName.BUSH  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match=r"world = 'nope': must be one of 'tags'"):
        SimRigOptions(world="nope")  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match="world = 3"):
        WorldName.parse(3)
    assert [w.rendered for w in WorldName] == [False, True, True]


def test_every_world_has_a_builder() -> None:
    assert set(WORLDS) == set(WorldName)


def test_the_tag_world_knows_the_true_canes_and_adds_nothing() -> None:
    rig = build_sim_rig(SimRigOptions(n_berries=2, seed=11))
    assert isinstance(rig.world, TagWorld) and rig.world.name is WorldName.TAGS
    assert len(rig.world.known_canes()) == len(rig.bush.branches)
    assert rig.world.report_extra() == {}
    assert rig.scene is None and rig.survey is None
    first = rig.bush.berries[0]
    assert rig.world.truth_of(first.tag_id) is first
    assert rig.world.truth_of(-1) is None


def test_the_replays_bush_is_the_rigs_without_building_the_rig() -> None:
    options = SimRigOptions(n_berries=3, seed=12)
    drawn, built = sim_bush(options), build_sim_rig(options).bush
    assert [b.tag_id for b in drawn.berries] == [b.tag_id for b in built.berries]
    for a, b in zip(drawn.berries, built.berries, strict=True):
        assert np.array_equal(a.position, b.position)


def _name_switches(source: str) -> list[int]:
    """Lines comparing something with a world's name written as a string."""
    names = {w.value for w in WorldName}
    lines = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare):
            parts = [node.left, *node.comparators]
            if any(isinstance(p, ast.Constant) and p.value in names for p in parts):
                if any("world" in ast.unparse(p) for p in parts):
                    lines.append(node.lineno)
    return lines


def test_no_module_switches_on_a_world_name_string() -> None:
    found = {
        str(p.relative_to(PACKAGE)): lines
        for p in sorted(PACKAGE.rglob("*.py"))
        if (lines := _name_switches(p.read_text()))
    }
    assert found == {}


def test_the_switch_check_can_fail() -> None:
    assert _name_switches('if o.world == "bush":\n    pass\n') == [1]
    assert _name_switches('if args.world in ("bush", "row"):\n    pass\n') == []  # a tuple
    assert _name_switches("if o.world is WorldName.ROW:\n    pass\n") == []


def test_the_lag_control_mode_is_an_enum_checked_where_it_is_made() -> None:
    from softarm.harvest.control.stack import ControlInputs, LagControl

    arm = softarm.SoftArm.blackberry()
    assert ControlInputs(arm, lag_control="bound").lag_control is LagControl.BOUND  # type: ignore[arg-type]
    assert ControlInputs(arm).lag_control is LagControl.PREDICTOR
    with pytest.raises(ParameterError, match="lag_control = 'fast'"):
        ControlInputs(arm, lag_control="fast")  # type: ignore[arg-type]
