"""`make demo` builds the extension with its progress shown: a first build takes minutes,
and a silent one looked hung to a new user (issue 25, item 6)."""

from __future__ import annotations

import re
from pathlib import Path

MAKEFILE = Path(__file__).parent.parent / "Makefile"


def _recipe(target: str) -> list[str]:
    lines = MAKEFILE.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if re.match(rf"^{target}:", line))
    body = []
    for line in lines[start + 1 :]:
        if not line.startswith("\t"):
            break
        body.append(line.strip())
    return body


def test_the_demo_build_shows_its_progress() -> None:
    builds = [line for line in _recipe("install") if "maturin develop" in line]
    assert builds and all(" -q" not in line for line in builds)
    assert any("building the Rust extension" in line for line in _recipe("install"))


def test_make_demo_builds_through_that_recipe() -> None:
    demo = next(ln for ln in MAKEFILE.read_text().splitlines() if ln.startswith("demo:"))
    assert demo.split(":", 1)[1].split() == ["install"]
