"""Stops that arrived where no handler could act on them (issue 42, items 15 and 19):
a SIGTERM while a finalizer runs (a bush harvest's renderers freed at its very end)
was printed as "Exception ignored in ... __del__" and the command exited 0; a SIGTERM
while ``harvest --bag`` wrote the bag after the run exited 143 with no ``interrupted``
record in the log."""

from __future__ import annotations

import json
import os
import signal
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from bag_stops import sigterm_while_writing_bag
from softarm.cli import main
from softarm.stops import drives_arm


@pytest.fixture(autouse=True)
def _unhandled_sigterm_fails_the_test() -> Any:
    """Without the handling under test, SIGTERM would end the test runner itself."""

    def fail(signum: int, frame: object) -> None:
        raise AssertionError(f"{signal.Signals(signum).name} reached no handler")

    previous = signal.signal(signal.SIGTERM, fail)
    yield
    signal.signal(signal.SIGTERM, previous)


class _StopsWhenFreed:
    """An object whose finalizer is running when SIGTERM arrives (as mujoco's renderers
    are when a finished harvest frees them)."""

    def __del__(self) -> None:
        os.kill(os.getpid(), signal.SIGTERM)


def test_a_stop_that_arrives_in_a_finalizer_still_stops_the_command(
    capsys: pytest.CaptureFixture[str],
) -> None:
    @drives_arm("test")
    def finishes(args: Any) -> int:
        freed = _StopsWhenFreed()
        del freed  # the handler runs inside __del__: Python swallows what it raises
        return 0

    assert finishes(None) == 143
    err = capsys.readouterr().err
    assert "softarm test: interrupted by SIGTERM" in err
    assert "Exception ignored" not in err


def test_a_stop_swallowed_mid_run_stops_the_run_soon(capsys: pytest.CaptureFixture[str]) -> None:
    """The swallowed stop is signalled again once the finalizer has returned: the run
    does not go on to its end with the stop ignored."""
    reached: list[int] = []

    @drives_arm("test")
    def long_run(args: Any) -> int:
        freed = _StopsWhenFreed()
        del freed
        for step in range(1000):  # up to 10 s of "driving the arm"
            reached.append(step)
            time.sleep(0.01)
        return 0

    assert long_run(None) == 143
    assert len(reached) < 1000
    assert "Exception ignored" not in capsys.readouterr().err


def test_other_unraisable_errors_are_still_reported(monkeypatch: pytest.MonkeyPatch) -> None:
    reported: list[Any] = []
    monkeypatch.setattr(sys, "unraisablehook", reported.append)

    class Broken:
        def __del__(self) -> None:
            raise RuntimeError("a finalizer's own bug")

    @drives_arm("test")
    def run(args: Any) -> int:
        broken = Broken()
        del broken
        return 0

    assert run(None) == 0
    assert [str(u.exc_value) for u in reported] == ["a finalizer's own bug"]


def test_a_stop_while_the_bag_is_written_is_recorded_in_the_log(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Item 19: the run had closed its log; the stop during the bag left it without an
    ``interrupted`` record (exit 143, the report written, no bag)."""
    pytest.importorskip("rosbags")
    sigterm_while_writing_bag(monkeypatch, after=20)
    log, bag = tmp_path / "run.jsonl", tmp_path / "run.mcap"
    argv = ["harvest", "--sim", "--berries", "1", "--seed", "3", "--log", str(log)]
    assert main([*argv, "--bag", str(bag), "-q"]) == 143
    records = [json.loads(line) for line in log.read_text().splitlines()]
    kinds = [r["kind"] for r in records]
    assert kinds[-1] == "interrupted" and kinds.count("interrupted") == 1
    assert "berry_result" in kinds  # the run itself had ended
    assert records[-1]["signal"] == "SIGTERM" and records[-1]["exit_status"] == 143
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.jsonl"]  # no bag, no temp
    assert "softarm harvest: interrupted by SIGTERM" in capsys.readouterr().err


def test_a_dry_run_stopped_while_it_reads_the_recording_says_so_in_its_log(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Item 16: a dry run stopped before its rig was built (reading the recording) left
    an empty log; the stop is recorded from the moment the log exists."""
    from softarm.commands import harvest

    def stopped(args: Any) -> Any:
        os.kill(os.getpid(), signal.SIGTERM)
        raise AssertionError("the signal did not arrive")

    monkeypatch.setattr(harvest, "replay_devices", stopped)
    (tmp_path / "hw.toml").write_text("")
    log = tmp_path / "dry.jsonl"
    argv = ["harvest", "--config", str(tmp_path / "hw.toml"), "--frames", str(tmp_path)]
    assert main([*argv, "--dry-run", "--log", str(log), "-q"]) == 143
    records = [json.loads(line) for line in log.read_text().splitlines()]
    assert [r["kind"] for r in records] == ["interrupted"]
    assert records[0]["signal"] == "SIGTERM"


def test_a_stop_waits_for_a_section_that_must_not_be_cut() -> None:
    from softarm.uninterrupted import uninterrupted

    done: list[str] = []

    @drives_arm("test")
    def run(args: Any) -> int:
        with uninterrupted():
            os.kill(os.getpid(), signal.SIGTERM)
            done.append("section complete")
        done.append("after the section")
        return 0

    assert run(None) == 143
    assert done == ["section complete"]


def test_the_renderers_are_all_freed_before_a_stop_is_raised() -> None:
    """Item 15: a SIGTERM while the bush harvest freed its renderers cut an EGL context's
    free in half; the outer close then failed on it (EGL_BAD_CONTEXT, a traceback, exit
    1). Every renderer is freed, once, and then the stop is raised."""
    from softarm.sim.render.renderer import BushRenderer
    from softarm.stops import Interrupted, raise_on_signals

    freed: list[int] = []

    class Renderer:
        def __init__(self, n: int) -> None:
            self.n = n

        def close(self) -> None:
            if self.n == 1:  # the stop arrives half-way through
                os.kill(os.getpid(), signal.SIGTERM)
            freed.append(self.n)

    renderer = BushRenderer.__new__(BushRenderer)
    renderer._renderers = {n: Renderer(n) for n in range(3)}  # type: ignore[assignment]
    with pytest.raises(Interrupted), raise_on_signals():
        renderer.close()
    assert sorted(freed) == [0, 1, 2]
    renderer.close()  # nothing left to free twice
    assert sorted(freed) == [0, 1, 2]
