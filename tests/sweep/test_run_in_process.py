"""softarm.sweep.run: a sweep in this process without Ray (issue 25 item 5), and the
README's tune example sized to finish in a few minutes, its cost stated (item 6)."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path

import softarm
from softarm.sweep import load_spec
from softarm.sweep.trial import BERRY_COLUMNS

ROOT = Path(__file__).resolve().parents[2]


def test_run_sweeps_in_process_without_ray(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    for name in ("ray", "pyarrow", "tqdm.auto"):
        monkeypatch.setitem(sys.modules, name, None)  # an import of any would fail
    seen = []
    spec = {"sweep": {"seeds": [0], "berries": 1, "plant": {"pressure_tau": [0.08, 0.3]}}}
    rows = softarm.sweep.run(spec, on_trial=lambda t, r: seen.append((t.plant, len(r))))
    assert [p for p, _ in seen] == [{"pressure_tau": 0.08}, {"pressure_tau": 0.3}]
    assert len(rows) == 2 and all(r["error"] is None for r in rows), rows
    assert set(BERRY_COLUMNS) | {"trial_id", "seed", "pressure_tau"} == set(rows[0])
    assert all(r["harvested"] for r in rows)


def test_readme_tune_example_is_a_few_minutes_and_says_so() -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    lines = [ln for ln in readme.splitlines() if ln.startswith("softarm tune ")]
    assert lines
    for line in lines:
        words = shlex.split(line, comments=True)
        spec = load_spec(ROOT / words[2])
        samples = int(words[words.index("--samples") + 1]) if "--samples" in words else None
        harvests = (samples or spec.tune.samples) * len(spec.trials()) * spec.berries
        assert harvests <= 20, (line, harvests)  # ~1 min on 2 cores, not 24 x 2 min
        assert f"{harvests} harvests" in line and "min" in line, line
