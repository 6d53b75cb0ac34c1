"""The cube tracking experiment's ``--edge-fit``: the markers' edges located by the
blurred-step fit for that run only (softarm.vision.refine.EDGE_FIT), and said so."""

from __future__ import annotations

from typing import Any

import pytest

import softarm.experiments.cube_tracking as cube_tracking
from softarm.vision import refine


@pytest.mark.parametrize(("flags", "fitted"), [(["--edge-fit"], True), ([], False)])
def test_edge_fit_holds_for_the_run_only(
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    flags: list[str],
    fitted: bool,
) -> None:
    seen: list[bool] = []

    def tracked(*_: Any) -> tuple[list[Any], float, list[int]]:
        seen.append(refine.EDGE_FIT)
        return [], 0.0, []

    monkeypatch.setattr(cube_tracking, "_tracked", tracked)
    assert cube_tracking.main(["1", *flags]) == 0
    assert seen == [fitted]
    assert refine.EDGE_FIT is False  # the default again after the run
    assert f"edge={'fit' if fitted else 'centroid'}" in capsys.readouterr().out
