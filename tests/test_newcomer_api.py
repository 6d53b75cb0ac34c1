"""The Python API as a newcomer meets it (issue 39, item 7): a report's counts as
attributes, reprs that read as Python and fit on a screen, ``dir(softarm)`` without the
command line's modules, and dataset previews an image viewer shows."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest

import softarm
from softarm import cli
from softarm.harvest.records.report import BerryResult, HarvestReport
from softarm.perception.berries import BerryDetection
from softarm.sim.render.preview import write_previews

ROOT = Path(__file__).resolve().parents[1]


def test_a_report_has_its_counts_and_cane_map_as_attributes() -> None:
    report = HarvestReport([BerryResult(0, harvested=True), BerryResult(1)])
    assert (report.harvested, report.attempted, report.cane_map) == (1, 2, None)
    report.extra["cane_map"] = {"median_mm": 1.0, "coverage": 0.9}
    assert report.cane_map == {"median_mm": 1.0, "coverage": 0.9}
    d = report.to_dict()
    assert (d["harvested"], d["attempted"], d["success_rate"]) == (1, 2, 0.5)


def _stale_core() -> bool:
    """The compiled core is older than its Rust source (not rebuilt since the repr change)."""
    built = Path(softarm._core.__file__ or "").stat().st_mtime
    source = ROOT / "crates" / "softarm-py" / "src" / "resolver.rs"
    return source.exists() and source.stat().st_mtime > built


def test_a_solution_repr_writes_its_bools_as_python() -> None:
    if _stale_core():
        pytest.skip("softarm._core predates crates/softarm-py/src/resolver.rs: rebuild it")
    arm = softarm.SoftArm.blackberry()
    solution = softarm.Resolver(arm).solve([0.0] * 9, arm.forward([0.01] * 9))
    text = repr(solution)
    assert "converged=True" in text or "converged=False" in text, text
    assert "true" not in text and "false" not in text


def test_a_detection_repr_leaves_out_its_mask() -> None:
    mask = np.ones((40, 40), bool)
    d = BerryDetection((20.0, 20.0), 20.0, (0, 0, 40, 40), mask, 0.9, "ripe", 0.95)
    text = repr(d)
    assert "mask=" not in text and "True, True" not in text and len(text) < 400
    assert "score=0.9" in text


def test_dir_shows_the_api_not_the_command_line() -> None:
    names = dir(softarm)
    for internal in ("cli", "commands", "checks", "files"):
        assert internal not in names
    assert {"SoftArm", "simulate_harvest", "vision", "harvest"} <= set(names)
    assert softarm.cli.__name__ == "softarm.cli"  # still importable


def _fake_dataset(out: Path) -> None:
    for folder in ("depth", "instances"):
        (out / folder).mkdir(parents=True)
    depth = np.zeros((8, 8), np.uint16)
    depth[2:6, 2:6] = np.arange(300, 316, dtype=np.uint16).reshape(4, 4)
    instances = np.zeros((8, 8), np.uint16)
    instances[1:3, 1:3], instances[5:7, 5:7] = 1, 2
    cv2.imwrite(str(out / "depth" / "000000.png"), depth)
    cv2.imwrite(str(out / "instances" / "000000.png"), instances)


def test_previews_are_8_bit_and_visible(tmp_path: Path) -> None:
    _fake_dataset(tmp_path)
    assert write_previews(tmp_path) == 2
    depth = cv2.imread(str(tmp_path / "preview" / "depth" / "000000.png"), cv2.IMREAD_UNCHANGED)
    inst = cv2.imread(str(tmp_path / "preview" / "instances" / "000000.png"), cv2.IMREAD_UNCHANGED)
    assert depth.dtype == inst.dtype == np.uint8 and depth.shape == inst.shape == (8, 8, 3)
    assert depth[0, 0].max() == 0 and depth[3, 3].max() > 100  # drawn pixels are bright
    assert inst[0, 0].max() == 0 and inst[1, 1].max() > 100
    assert not np.array_equal(inst[1, 1], inst[5, 5])  # two instances, two colours


def test_softarm_dataset_writes_the_previews(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import softarm.sim.render.dataset as dataset
    import softarm.sim.render.gl_check as gl_check

    def fake(out: Path, images: int, seed: int, rig: Any, **kw: Any) -> dict[str, Any]:
        _fake_dataset(Path(out))
        return {"images": [{}], "annotations": [], "categories": []}

    monkeypatch.setattr(dataset, "write_dataset", fake)
    monkeypatch.setattr(gl_check, "require_offscreen_gl", lambda: None)
    out = tmp_path / "set"
    assert cli.main(["dataset", "--out", str(out), "--images", "1", "--workers", "1", "-q"]) == 0
    assert (out / "preview" / "depth" / "000000.png").is_file()
    assert (out / "preview" / "instances" / "000000.png").is_file()
