"""What a test does when the rendered world (MuJoCo, offscreen OpenGL) cannot run here.

On a developer's machine without EGL such a test is skipped with the renderer's own
reason. Where the render is required it FAILS instead, so that the rendered-world tests
cannot vanish silently: in CI (``CI=true``, as CI services set it) and wherever
``SOFTARM_REQUIRE_RENDER=1`` (``.ci/run`` sets it).

The rendered-world tests build their worlds inside :func:`rendering` (or call
:func:`unavailable` / :func:`need_mujoco`); the hook :func:`pytest_runtest_makereport`
(registered by tests/conftest.py) catches the rest: a skip raised while handling a
``RenderUnavailableError`` or a failed ``import mujoco`` becomes a failure where the
render is required, whichever test raised it.
"""

from __future__ import annotations

import os
from collections.abc import Generator, Iterator
from contextlib import contextmanager
from types import ModuleType
from typing import Any, NoReturn

import pytest

#: Set to 1 to make a rendered world that cannot run a failure, not a skip.
REQUIRE = "SOFTARM_REQUIRE_RENDER"


def render_required() -> bool:
    """Whether this run must render: in CI or with ``SOFTARM_REQUIRE_RENDER=1``."""
    ci = os.environ.get("CI", "").strip().lower() in {"1", "true", "yes"}
    return ci or os.environ.get(REQUIRE, "").strip() == "1"


def _required_message(reason: str) -> str:
    return f"the rendered world is required here (CI or {REQUIRE}=1) but cannot run: {reason}"


def unavailable(reason: str) -> NoReturn:
    """Skip the test for ``reason`` (the rendered world cannot run here), or fail it where
    the render is required."""
    if render_required():
        pytest.fail(_required_message(reason), pytrace=False)
    pytest.skip(reason)


@contextmanager
def rendering() -> Iterator[None]:
    """Around the code that builds a rendered world: a ``RenderUnavailableError`` inside
    becomes :func:`unavailable`."""
    from softarm.sim.render import RenderUnavailableError

    try:
        yield
    except RenderUnavailableError as exc:
        unavailable(str(exc))


def need_mujoco() -> ModuleType:
    """The ``mujoco`` module with its offscreen backend (``pytest.importorskip``, but a
    failure where the render is required)."""
    from softarm.sim.render import require_mujoco

    with rendering():
        return require_mujoco()  # type: ignore[no-any-return]
    raise AssertionError("unreachable: rendering() skips or fails")  # for the type checker


def from_render(exc: BaseException | None) -> bool:
    """Whether ``exc`` (a skip) is for a render that cannot run: ``importorskip("mujoco")``
    (it keeps no context: its reason says so) or raised while handling a
    ``RenderUnavailableError`` or a failed import of mujoco (its context or cause)."""
    from softarm.sim.render import RenderUnavailableError

    if isinstance(exc, pytest.skip.Exception) and str(exc.msg).startswith(
        "could not import 'mujoco"
    ):
        return True
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        if isinstance(exc, RenderUnavailableError):
            return True
        if isinstance(exc, ImportError) and (exc.name or "").split(".")[0] == "mujoco":
            return True
        exc = exc.__cause__ or exc.__context__
    return False


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(
    item: pytest.Item, call: pytest.CallInfo[None]
) -> Generator[None, Any, None]:
    """A skip for a render that cannot run is a failure where the render is required."""
    outcome = yield
    report = outcome.get_result()
    if not (report.skipped and call.excinfo is not None and render_required()):
        return
    if isinstance(call.excinfo.value, pytest.skip.Exception) and from_render(call.excinfo.value):
        report.outcome = "failed"
        report.longrepr = _required_message(str(call.excinfo.value))
