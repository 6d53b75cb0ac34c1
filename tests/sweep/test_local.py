"""A tiny real sweep on a local Ray started by the command: 2 trials, 1 berry each."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("ray")
pytest.importorskip("pyarrow")
import pyarrow.parquet as pq

from softarm.cli import main

SPEC = """\
[sweep]
seeds = [0]
berries = 1

[sweep.plant]
pressure_tau = [0.08, 0.3]
"""


def test_tiny_sweep_on_local_ray(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "tiny.toml"
    spec.write_text(SPEC)
    out = tmp_path / "out"
    args = ["sweep", str(spec), "--out", str(out), "--cpus", "2", "--no-progress"]
    assert main(args) == 0
    table = pq.read_table(out / "results.parquet").to_pylist()
    assert len(table) == 2
    assert sorted(r["pressure_tau"] for r in table) == [0.08, 0.3]
    for r in table:
        assert r["error"] is None, r["error"]
        assert r["seed"] == 0 and r["berry"] == 0
        assert isinstance(r["harvested"], bool)
        assert r["duration_s"] > 0 and r["branch_contact_steps"] >= 0
    assert (out / "summary.png").stat().st_size > 10_000
    assert "By pressure_tau" in (out / "summary.md").read_text()
    capsys.readouterr()

    # The same command again is refused (it would mix two sweeps) ...
    assert main(args) == 2
    assert "--resume" in capsys.readouterr().err
    # ... and with --resume there is nothing left to run (Ray is not even started).
    assert main([*args, "--resume"]) == 0
    assert "0 trials run (0 failed), 2 already done" in capsys.readouterr().out
    assert len(pq.read_table(out / "results.parquet")) == 2
