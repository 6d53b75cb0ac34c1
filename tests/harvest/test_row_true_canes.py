"""The simulated row's truth holds the row's own canes, not only the bush's: contacts
and the cane map's scores are measured against every cane drawn (the row's canes stand
clear of the berries' approach corridors, not of the arm's sections)."""

from __future__ import annotations

import numpy as np

from softarm.harvest.rigs.sim.options import SimRigOptions
from softarm.harvest.rigs.sim.rig import sim_bush
from softarm.harvest.rigs.sim.worlds import true_canes
from softarm.sim.render.row import Row, row_canes
from softarm.sim.render.row_look import RowLook
from softarm.sim.world import WorldName


def _coeffs(curves: list) -> list[np.ndarray]:
    return [np.asarray(c.coeffs) for c in curves]


def test_row_canes_are_the_whole_rows_canes() -> None:
    bush = sim_bush(SimRigOptions(world=WorldName.ROW, look="sun", seed=90011, n_berries=4))
    look = RowLook.named("sun", bush.seed)
    alone, whole = row_canes(bush, look), Row.generate(bush, look).canes
    assert len(alone) == len(whole) > 0
    for a, b in zip(_coeffs(alone), _coeffs(whole), strict=True):
        np.testing.assert_array_equal(a, b)


def test_the_rows_truth_holds_the_row_canes_and_the_bushs() -> None:
    o = SimRigOptions(world=WorldName.ROW, look="overcast", seed=90012, n_berries=4)
    bush = sim_bush(o)
    truth = true_canes(o, bush)
    row = row_canes(bush, RowLook.named("overcast", bush.seed))
    assert len(truth) == len(bush.branches) + len(row)
    drawn = [*bush.branches, *row]
    for curve, branch in zip(truth, drawn, strict=True):
        np.testing.assert_allclose(
            np.asarray(curve.sample(9)), np.asarray(branch.curve().sample(9))
        )


def test_the_bush_truth_is_the_bushs_canes_alone() -> None:
    for world in (WorldName.BUSH, WorldName.TAGS):
        o = SimRigOptions(world=world, seed=90013, n_berries=4)
        bush = sim_bush(o)
        assert len(true_canes(o, bush)) == len(bush.branches)


def test_the_log_header_records_every_cane_drawn() -> None:
    # The header's world.canes (plots, bags, the Foxglove scene) are the truth's too.
    from softarm.harvest.rigs.sim.header import sim_settings
    from softarm.harvest.rigs.sim.rig import build_sim_rig

    o = SimRigOptions(world=WorldName.ROW, look="sun", seed=90014, n_berries=2)
    rig = build_sim_rig(o)
    recorded = sim_settings(rig, o)["world"]["canes"]
    truth = true_canes(o, rig.bush)
    assert len(recorded) == len(truth) > len(rig.bush.branches)
    for coeffs, curve in zip(recorded, truth, strict=True):
        np.testing.assert_array_equal(coeffs, np.asarray(curve.coeffs))
