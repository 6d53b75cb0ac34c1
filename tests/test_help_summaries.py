"""``help()`` of the native classes: each member's summary is a whole sentence, not the
first line of its stub docstring cut mid-sentence (issue 39 item 7)."""

from __future__ import annotations

import re

import pytest

import softarm
from softarm import _core


def _members(doc: str) -> list[str]:
    """The member summaries of a class docstring built from the stub, one string each."""
    block = doc.split("Members:\n", 1)[1]
    entries: list[str] = []
    for line in block.splitlines():
        if re.match(r"    \w+: ", line):
            entries.append(line.strip())
        elif line.startswith("        ") and entries:
            entries[-1] += " " + line.strip()
    return entries


def _doc(name: str) -> str:
    return getattr(softarm, name, getattr(_core, name)).__doc__ or ""


#: The native classes whose stub documents members.
DOCUMENTED = [
    name
    for name in dir(_core)
    if isinstance(getattr(_core, name), type) and "Members:" in _doc(name)
]


def test_the_stub_documents_members() -> None:
    assert {"SoftArm", "Gains"} <= set(DOCUMENTED)


@pytest.mark.parametrize("name", DOCUMENTED)
def test_member_summaries_are_whole_sentences(name: str) -> None:
    for entry in _members(_doc(name)):
        assert entry.endswith((".", ")", "`")), f"{name}: summary cut mid-sentence: {entry!r}"


def test_the_soft_arm_summary_spans_its_lines() -> None:
    entries = _members(softarm.SoftArm.__doc__ or "")
    from_config = next(e for e in entries if e.startswith("from_config:"))
    assert from_config.endswith("(``softarm._arm_config``).")
