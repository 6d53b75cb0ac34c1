"""``softarm dataset`` hardened (issue 42, items 17, 18 and 23): a set is written into a
fresh folder and moved into place (a stop leaves an earlier set as it was, a complete
run replaces it whole, a folder of other files is refused); on Ray, task submission is
bounded and Ray's own SIGTERM handler is replaced by the command's again. Nothing is
rendered: ``render_sample`` and Ray are stand-ins that record what they were asked."""

from __future__ import annotations

import json
import os
import signal
import sys
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from softarm.errors import OutputError
from softarm.sim.render import dataset
from softarm.sim.render.dataset_ray import IN_FLIGHT_PER_WORKER, on_ray
from softarm.stops import Interrupted

#: What write_dataset reads of its rig once the images are rendered (the bush world).
RIG = SimpleNamespace(world_kind="bush")


def _fake_render(stop_at: int | None = None) -> Any:
    """A render_sample that writes one small file per image, and is stopped (as by
    SIGTERM) at image ``stop_at``."""

    def render(out_dir: str | Path, seed: int, index: int, rig: Any) -> dict[str, Any]:
        if index == stop_at:
            raise Interrupted(signal.SIGTERM)
        name = f"images/{index:06d}.png"
        (Path(out_dir) / "images").mkdir(exist_ok=True)
        (Path(out_dir) / name).write_bytes(f"seed {seed}".encode())
        return {"image": {"id": index + 1, "file_name": name}, "annotations": []}

    return render


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def test_a_stopped_set_leaves_the_earlier_one_as_it_was(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Item 18: stopped over an existing set, the old annotations.json described the
    new images."""
    out = tmp_path / "set"
    monkeypatch.setattr(dataset, "render_sample", _fake_render())
    dataset.write_dataset(out, 3, 1, RIG, workers=1)  # type: ignore[arg-type]
    before = _files(out)
    monkeypatch.setattr(dataset, "render_sample", _fake_render(stop_at=2))
    with pytest.raises(Interrupted):
        dataset.write_dataset(out, 5, 2, RIG, workers=1)  # type: ignore[arg-type]
    assert _files(out) == before
    assert [p.name for p in tmp_path.iterdir()] == ["set"]  # no fresh folder left


def test_a_complete_set_replaces_the_earlier_one_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "set"
    monkeypatch.setattr(dataset, "render_sample", _fake_render())
    dataset.write_dataset(out, 4, 1, RIG, workers=1)  # type: ignore[arg-type]
    coco = dataset.write_dataset(out, 2, 2, RIG, workers=1)  # type: ignore[arg-type]
    assert sorted(_files(out)) == ["annotations.json", "images/000000.png", "images/000001.png"]
    assert json.loads((out / "annotations.json").read_text()) == coco
    assert (out / "images/000001.png").read_bytes() == b"seed 2"
    assert [p.name for p in tmp_path.iterdir()] == ["set"]


def test_a_folder_of_other_files_is_refused_and_kept(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "home"
    out.mkdir()
    (out / "thesis.tex").write_text("keep me")
    monkeypatch.setattr(dataset, "render_sample", _fake_render())
    with pytest.raises(OutputError, match="other files than an earlier dataset"):
        dataset.write_dataset(out, 2, 1, RIG, workers=1)  # type: ignore[arg-type]
    assert _files(out) == {"thesis.tex": b"keep me"}


class _FakeRay:
    """What on_ray uses of Ray: tasks run when waited for; it records the most tasks
    submitted and not yet collected, and, as ray.init does, installs a SIGTERM handler
    that calls sys.exit."""

    class exceptions:  # Ray's name
        class RayTaskError(Exception):
            cause: BaseException | None = None

    def __init__(self) -> None:
        self.initialized = False
        self.in_flight: list[Any] = []
        self.most_in_flight = 0
        self.handlers_seen: list[Any] = []
        self.waits = 0
        self.kill_at: int | None = None
        self.raised_inside_wait = False
        self.kill_in_init = False
        self._private = SimpleNamespace(
            utils=SimpleNamespace(set_sigterm_handler=lambda h: signal.signal(signal.SIGTERM, h))
        )

    def is_initialized(self) -> bool:
        return self.initialized

    def init(self, **kwargs: Any) -> None:
        self.initialized = True
        # As ray.init does (through this function), and a stop while it starts.
        self._private.utils.set_sigterm_handler(lambda signum, frame: sys.exit(signum))
        if self.kill_in_init:
            os.kill(os.getpid(), signal.SIGTERM)

    def shutdown(self) -> None:
        self.initialized = False

    def put(self, value: Any) -> Any:
        return value

    def remote(self, **kwargs: Any) -> Any:
        ray = self

        def wrap(function: Any) -> Any:
            class Task:
                @staticmethod
                def remote(*args: Any) -> Any:
                    ref = (function, args)
                    ray.in_flight.append(ref)
                    ray.most_in_flight = max(ray.most_in_flight, len(ray.in_flight))
                    return ref

            return Task

        return wrap

    def wait(
        self, refs: list[Any], num_returns: int, timeout: float | None = None
    ) -> tuple[list[Any], list[Any]]:
        self.waits += 1
        self.handlers_seen.append(signal.getsignal(signal.SIGTERM))
        try:
            if self.waits == self.kill_at:  # Ray runs the handlers inside its wait
                os.kill(os.getpid(), signal.SIGTERM)
            return [refs[0]], refs[1:]
        except BaseException:
            self.raised_inside_wait = True
            raise

    def get(self, ref: Any) -> Any:
        self.in_flight.remove(ref)
        function, args = ref
        return function(*args)


def test_ray_tasks_are_submitted_a_few_at_a_time(tmp_path: Path) -> None:
    """Item 23: every task was submitted up front (the driver grew by 60 MB/s for
    --images 1000000); now at most IN_FLIGHT_PER_WORKER per worker are out at once."""
    ray = _FakeRay()
    done: list[int] = []
    results = on_ray(
        ray, _fake_render(), tmp_path, 3, range(1, 200), None, 4, lambda: done.append(1)
    )
    assert [r["image"]["id"] for r in results] == list(range(2, 201))  # in index order
    assert len(done) == 199 and not ray.in_flight
    assert ray.most_in_flight == IN_FLIGHT_PER_WORKER * 4


def test_a_sigterm_while_ray_runs_is_the_commands_stop(tmp_path: Path) -> None:
    """Item 17: ray.init installs a SIGTERM handler that calls sys.exit, and Ray runs
    handlers inside its C++ wait, where an exception came out as a SystemError (exit
    134, a C++ stack dump). The stop is now the command's own (``Interrupted``), raised
    between two waits, and Ray is shut down."""

    def ours(signum: int, frame: Any) -> None:
        raise Interrupted(signum)

    previous = signal.signal(signal.SIGTERM, ours)
    try:
        ray = _FakeRay()
        ray.kill_at = 3
        with pytest.raises(Interrupted):
            on_ray(ray, _fake_render(), tmp_path, 3, range(1, 50), None, 2, lambda: None)
        assert not ray.raised_inside_wait and ray.waits == 3
        assert not ray.initialized  # shut down on the way out
        assert signal.getsignal(signal.SIGTERM) is ours
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_a_sigterm_while_ray_starts_is_the_commands_stop(tmp_path: Path) -> None:
    """Item 17: Ray's own SIGTERM handler (sys.exit) is not installed; a stop while Ray
    starts is raised once it has started, and Ray is shut down."""

    def ours(signum: int, frame: Any) -> None:
        raise Interrupted(signum)

    previous = signal.signal(signal.SIGTERM, ours)
    try:
        ray = _FakeRay()
        ray.kill_in_init = True
        with pytest.raises(Interrupted):
            on_ray(ray, _fake_render(), tmp_path, 3, range(1, 50), None, 2, lambda: None)
        assert ray.waits == 0 and not ray.initialized
        assert signal.getsignal(signal.SIGTERM) is ours
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_the_dataset_command_takes_signals(tmp_path: Path) -> None:
    """Item 17 without Ray: SIGTERM ended the command at once, without a word and with
    its folder half-written; it now unwinds (``softarm.cli.main`` says why, 143)."""
    from softarm.commands import dataset as command

    assert getattr(command.run, "__wrapped__", None) is not None
