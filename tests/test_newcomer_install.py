"""After `make demo` a new user is told how to run softarm, the install commands of
getting-started hold on a fresh clone, and pip's "Ignoring X: markers" lines are gone
(issue 39, item 2)."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent
GETTING_STARTED = (ROOT / "docs" / "getting-started.md").read_text(encoding="utf-8")

needs_make = pytest.mark.skipif(shutil.which("make") is None, reason="no make")


def _make(*args: str) -> str:
    done = subprocess.run(
        ["make", "-s", *args], cwd=ROOT, capture_output=True, text=True, timeout=120
    )
    return done.stdout + done.stderr


@needs_make
def test_make_demo_ends_by_saying_how_to_run_softarm() -> None:
    tail = _make("-n", "demo").strip().splitlines()[-3:]
    text = "\n".join(tail)
    assert ".venv/bin/softarm" in text and "source .venv/bin/activate" in text


@needs_make
def test_pip_under_make_does_not_list_the_extras_it_ignores() -> None:
    if not (ROOT / ".venv" / "bin" / "pip").exists():
        pytest.skip("no .venv with pip")
    recipe = '_pq: ; @$(PIP) install --no-index --dry-run "shtab>=1.7; extra == \\"test\\""'
    out = _make("--eval", recipe, "_pq")
    assert "Ignoring" not in out, out


def _section(title: str) -> str:
    return GETTING_STARTED.split(f"## {title}", 1)[1].split("\n## ", 1)[0]


def test_getting_started_activates_the_venv_before_any_softarm_line() -> None:
    install = _section("1. Install")
    assert "source .venv/bin/activate" in install and ".venv/bin/softarm" in install


def test_the_wheel_is_built_before_pip_installs_it() -> None:
    block = next(
        b for b in re.findall(r"```sh\n(.*?)```", GETTING_STARTED, re.S) if "--find-links" in b
    )
    commands = [line.split("#", 1)[0].strip() for line in block.splitlines()]
    assert "make wheel" in commands
    assert commands.index("make wheel") < next(
        i for i, c in enumerate(commands) if "--find-links target/wheels" in c
    )
