"""The row's frames are recorded as the bush's (``--record-frames`` with ``--world row``):
the option is accepted for both rendered worlds and refused, naming them, elsewhere;
a recorded row harvest replays on the hardware path with the same commands (slow)."""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

import pytest

from render_required import need_mujoco, unavailable
from softarm.cli import main
from softarm.commands._dry_run import check_dry_run
from softarm.errors import ParameterError
from softarm.harvest.records.frame_files import INDEX, FrameFolder
from softarm.sim.world import WorldName

os.environ.setdefault("MUJOCO_GL", "egl")

#: The dry run's bush (tests/harvest/test_dry_run.py), here in the row: a test seed,
#: not a reported one.
SEED = 902


def _args(world: WorldName, sim: bool = True) -> argparse.Namespace:
    return argparse.Namespace(sim=sim, world=world, record_frames="rec", dry_run=False, frames=None)


@pytest.mark.parametrize("world", [WorldName.BUSH, WorldName.ROW])
def test_record_frames_takes_both_rendered_worlds(world: WorldName) -> None:
    check_dry_run(_args(world))


@pytest.mark.parametrize(("world", "sim"), [(WorldName.TAGS, True), (WorldName.ROW, False)])
def test_record_frames_elsewhere_names_the_rendered_worlds(world: WorldName, sim: bool) -> None:
    with pytest.raises(ParameterError, match="--world bush or row"):
        check_dry_run(_args(world, sim))


@pytest.mark.slow
def test_a_recorded_row_harvest_replays_with_the_same_commands(tmp_path: Path) -> None:
    need_mujoco()
    folder = tmp_path / "rec"
    args = ["harvest", "--sim", "--world", "row", "--look", "sun", "--berries", "1"]
    status = main([*args, "--seed", str(SEED), "--record-frames", str(folder), "-q"])
    if not (folder / INDEX).is_file():
        unavailable("the rendered row is unavailable here (EGL)")
    assert status in (0, 1)
    cameras = FrameFolder(folder).entries
    assert {"c1_left", "c1_right", "c1", "c2"} <= set(cameras)
    report = tmp_path / "replay.json"
    replayed = main(
        ["harvest", "--config", str(folder / "hw.toml"), "--frames", str(folder),
         "--dry-run", "--report", str(report), "-q"]
    )  # fmt: skip
    dry = json.loads(report.read_text())["dry_run"]
    assert replayed == status and dry["same"]
    assert dry["count"][0] == dry["count"][1] > 10
