"""One ``MissingDependencyError`` (softarm.errors) for every optional part that is absent,
naming its extra; the rendered world's ``RenderUnavailableError`` is one of them."""

from __future__ import annotations

import ast
import importlib
import pickle
import sys
from pathlib import Path

import pytest

import softarm
from softarm.errors import MissingDependencyError, SoftarmError
from softarm.sim.render import RenderUnavailableError

PACKAGE = Path(softarm.__file__).parent


def test_one_class_and_it_names_the_extra() -> None:
    err = MissingDependencyError("x needs y: pip install 'softarm[sweep]'", "sweep")
    assert isinstance(err, SoftarmError) and isinstance(err, ImportError)
    assert err.extra == "sweep" and str(err) == "x needs y: pip install 'softarm[sweep]'"
    back = pickle.loads(pickle.dumps(err))  # Ray and multiprocessing carry it whole
    assert type(back) is MissingDependencyError and back.extra == "sweep"
    assert str(back) == str(err)


def test_no_module_defines_its_own() -> None:
    defined = [
        str(path.relative_to(PACKAGE))
        for path in PACKAGE.rglob("*.py")
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
        if isinstance(node, ast.ClassDef) and node.name == "MissingDependencyError"
    ]
    assert defined == ["errors.py"]


def test_the_rendered_world_unavailable_is_a_missing_render_extra() -> None:
    err = RenderUnavailableError("no EGL")
    assert isinstance(err, MissingDependencyError) and err.extra == "render"
    back = pickle.loads(pickle.dumps(err))
    assert type(back) is RenderUnavailableError and back.extra == "render"


@pytest.mark.parametrize(
    ("absent", "module", "call", "extra"),
    [
        ("optuna", "softarm.sweep._deps", "require", "sweep"),
        ("rerun", "softarm.viz.rerun_sdk", "require_rerun", "viz"),
        ("rosbags", "softarm.viz.bag.deps", "require_rosbags", "ros"),
        ("elastica", "softarm.sim.cosserat", "require_elastica", "cosserat"),
    ],
)
def test_each_extra_says_its_name(
    monkeypatch: pytest.MonkeyPatch, absent: str, module: str, call: str, extra: str
) -> None:
    require = getattr(importlib.import_module(module), call)
    # A None entry makes `import NAME` raise ImportError, as when it is not installed.
    for name in [m for m in sys.modules if m == absent or m.startswith(absent + ".")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, absent, None)
    with pytest.raises(MissingDependencyError) as info:
        require(absent) if call == "require" else require()
    assert info.value.extra == extra and f"softarm[{extra}]" in str(info.value)
    assert "\n" not in str(info.value)
