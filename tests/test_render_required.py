"""A rendered world that cannot run skips its tests on a developer's machine and fails
them in CI (``CI=true`` or ``SOFTARM_REQUIRE_RENDER=1``): tests/render_required.py."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from render_required import REQUIRE, from_render, unavailable
from softarm.sim.render import RenderUnavailableError

TESTS = Path(__file__).parent

#: Three ways a rendered-world test meets a machine that cannot render.
PROBE = """
import pytest
from render_required import rendering
from softarm.sim.render import RenderUnavailableError

def test_own_skip():
    try:
        raise RenderUnavailableError("no EGL here")
    except RenderUnavailableError as exc:
        pytest.skip(str(exc))

def test_helper():
    with rendering():
        raise RenderUnavailableError("no EGL here")

def test_no_mujoco(monkeypatch):
    import sys
    monkeypatch.setitem(sys.modules, "mujoco", None)
    pytest.importorskip("mujoco")

def test_other_skip():
    pytest.skip("not a render")
"""


@pytest.fixture
def not_required(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("CI", raising=False)
    monkeypatch.delenv(REQUIRE, raising=False)


@pytest.mark.usefixtures("not_required")
@pytest.mark.parametrize(("name", "value"), [(None, None), ("CI", "true"), (REQUIRE, "1")])
def test_unavailable_skips_or_fails(
    monkeypatch: pytest.MonkeyPatch, name: str | None, value: str | None
) -> None:
    if name is not None:
        monkeypatch.setenv(name, value or "")
    expected = pytest.skip.Exception if name is None else pytest.fail.Exception
    with pytest.raises(expected, match="no EGL"):
        unavailable("no EGL")


def _skip_while_handling(exc: BaseException) -> BaseException:
    try:
        try:
            raise exc
        except type(exc):
            pytest.skip("x")
    except pytest.skip.Exception as skip:
        return skip
    raise AssertionError("no skip")


def test_a_skip_is_from_the_render_when_raised_handling_its_error(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    assert from_render(_skip_while_handling(RenderUnavailableError("no EGL")))
    assert not from_render(_skip_while_handling(KeyError("other")))
    monkeypatch.setitem(sys.modules, "mujoco", None)
    with pytest.raises(pytest.skip.Exception) as info:
        pytest.importorskip("mujoco")
    assert from_render(info.value)
    monkeypatch.setitem(sys.modules, "rerun", None)
    with pytest.raises(pytest.skip.Exception) as other:
        pytest.importorskip("rerun")
    assert not from_render(other.value)


@pytest.mark.parametrize("required", [False, True])
def test_every_render_skip_fails_where_required(tmp_path: Path, required: bool) -> None:
    (tmp_path / "test_probe.py").write_text(PROBE, encoding="utf-8")
    (tmp_path / "pytest.ini").write_text("[pytest]\n", encoding="utf-8")
    env = {k: v for k, v in os.environ.items() if k not in ("CI", REQUIRE)}
    env["PYTHONPATH"] = os.pathsep.join([str(TESTS), env.get("PYTHONPATH", "")])
    if required:
        env["CI"] = "true"
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "render_required", "-p", "no:cacheprovider",
         "-p", "no:randomly", "test_probe.py"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    summary = done.stdout.strip().splitlines()[-1]
    if required:
        assert done.returncode == 1 and "3 failed, 1 skipped" in summary, done.stdout
        assert "the rendered world is required here" in done.stdout
    else:
        assert done.returncode == 0 and "4 skipped" in summary, done.stdout
