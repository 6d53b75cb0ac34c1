"""The README cannot drift from the code: every ```python block runs as pasted, every
`softarm ...` line of a ```sh block parses with the real command-line parser, every
`make X` names a Makefile target, and every optional extra of pyproject.toml is
documented. The `softarm` and `make` lines of docs/getting-started.md are checked the
same way."""

from __future__ import annotations

import re
import shlex
import tomllib
from pathlib import Path
from typing import Any

import pytest

from softarm import cli

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
BLOCK = re.compile(r"^```(\w+)\n(.*?)^```", re.DOTALL | re.MULTILINE)


GETTING_STARTED = (ROOT / "docs" / "getting-started.md").read_text(encoding="utf-8")


def blocks(language: str, text: str = README) -> list[str]:
    return [body for lang, body in BLOCK.findall(text) if lang == language]


def commands(program: str, text: str = README) -> list[str]:
    """Lines of the sh blocks that run ``program``, without their comments."""
    found = []
    for body in blocks("sh", text):
        for line in body.splitlines():
            words = shlex.split(line, comments=True)
            if words[:1] == [program]:
                found.append(words)
    return found


def written_by_readme() -> set[str]:
    """Files that a README (or getting-started) line writes: the argument of an output
    option or `config init`."""
    out: set[str] = set()
    for words in commands("softarm") + commands("softarm", GETTING_STARTED):
        for i, word in enumerate(words[:-1]):
            if word in ("--out", "--log", "--record", "--report", "init"):
                out.add(words[i + 1])
            if word == "--record-frames":  # the recording's folder and its hw.toml
                out.add(words[i + 1].rstrip("/") + "/hw.toml")
    return out


def test_there_is_something_to_check() -> None:
    assert blocks("python") and commands("softarm") and commands("make")


@pytest.mark.parametrize("index", range(len(blocks("python"))))
def test_python_block_runs(index: int, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)  # whatever a block writes stays out of the repository
    code = blocks("python")[index]
    exec(compile(code, f"README.md python block {index}", "exec"), {"__name__": "__readme__"})


@pytest.mark.parametrize(
    "words", commands("softarm") + commands("softarm", GETTING_STARTED), ids=" ".join
)
def test_softarm_line_parses(
    words: list[str],
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.chdir(tmp_path)  # relative output paths resolve in a scratch folder
    parser = cli.build_parser()
    args = words[1:]
    if any(a in ("--help", "-h", "--version") for a in args):
        with pytest.raises(SystemExit) as exit_:
            parser.parse_args(args)
        assert exit_.value.code == 0
        return
    try:
        parsed = parser.parse_args(args)
    except SystemExit:
        err = capsys.readouterr().err
        # The only acceptable failure is an input file that an earlier line of the README
        # writes (`softarm config init hw.toml`, `--log run.jsonl`, `--out id.json`, ...)
        # or one of the repository's own files (the test runs in a scratch folder).
        missing = re.search(r"'([^']+)'(?: does not exist|: no such file)", err)
        assert missing is not None, err
        name = missing.group(1)
        assert name in written_by_readme() or (ROOT / name).is_file(), err
        return
    assert callable(parsed.run)


def test_make_targets_exist() -> None:
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    targets = set(re.findall(r"(?m)^([\w-]+):", makefile))
    for words in commands("make") + commands("make", GETTING_STARTED):
        assert words[1] in targets, f"make {words[1]}: no such target"


def test_every_extra_is_documented() -> None:
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"][
        "optional-dependencies"
    ]
    for name in extras:
        assert f"| `{name}` |" in README, f"extra {name!r} is not in the README's table"


def test_license_and_citation() -> None:
    assert (ROOT / "LICENSE").read_text(encoding="utf-8").startswith("MIT License")
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert meta["license"] == {"text": "MIT"}
    yaml = pytest.importorskip("yaml")
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert cff["cff-version"] == "1.2.0" and cff["license"] == "MIT"
    assert cff["version"] == meta["version"]
    titles = [r["title"] for r in cff["references"]]
    assert any("Redundancy Resolution" in t for t in titles)
    assert any("Path Planning of Soft Robotic Arms" in t for t in titles)
    assert all(r["authors"] and r["year"] for r in cff["references"])


def test_the_tune_example_is_quick_and_states_its_cost() -> None:
    """Issue 25 item 6: the README's `softarm tune` line finishes in a few minutes and
    says what it costs; the stated number of harvests (berries) is the spec's."""
    from softarm.sweep import load_spec

    (line,) = [ln for ln in README.splitlines() if ln.startswith("softarm tune ")]
    cost = re.search(r"(\d+) harvests, ~(\d+) min", line)
    assert cost is not None, line
    spec = load_spec(ROOT / shlex.split(line, comments=True)[2])
    berries = spec.tune.samples * sum(t.berries for t in spec.trials())
    assert int(cost.group(1)) == berries and berries <= 40
    assert int(cost.group(2)) <= 5


def _pyproject_extras() -> set[str]:
    doc = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    return set(doc["project"]["optional-dependencies"])


def test_one_documented_way_to_add_extras_to_the_dev_environment() -> None:
    """Issue 25 item 6: `pip install ".[extra]"` in the dev .venv replaced the editable
    install. The README and getting-started give `maturin develop --extras` (editable),
    naming extras that exist, and the Makefile's dev targets install extras that way."""
    maturin = re.compile(r"^\.venv/bin/maturin develop --release --extras ([\w,]+)", re.M)
    for name, text in (("README.md", README), ("getting-started.md", GETTING_STARTED)):
        lines = [m for body in blocks("sh", text) for m in maturin.findall(body)]
        assert lines, f"{name} shows no `maturin develop --extras` line"
        for extras in lines:
            assert set(extras.split(",")) <= _pyproject_extras(), (name, extras)
        assert "editable" in text
    makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
    extras = re.search(r"(?m)^TEST_EXTRAS := ([\w,]+)$", makefile)
    assert extras is not None and set(extras.group(1).split(",")) <= _pyproject_extras()
    assert re.search(r"(?m)^dev-all:.*\n\t.*maturin develop --release --extras \$\(TEST_EXTRAS\)",
                     makefile)  # fmt: skip
    assert "make dev-all" in GETTING_STARTED


def test_the_resolver_snippet_solves_for_another_pose(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Issue 25 item 6: the README's Resolver.solve snippet once solved for the pose it
    started from (0 steps). Its goal lies centimetres away and the solve takes steps."""
    import numpy as np

    monkeypatch.chdir(tmp_path)
    (code,) = [b for b in blocks("python") if "res.solve(" in b]
    scope: dict[str, Any] = {"__name__": "__readme__"}
    exec(compile(code, "README.md resolver block", "exec"), scope)
    arm, q, goal, sol = scope["arm"], scope["q"], scope["goal"], scope["sol"]
    start = arm.forward(q)
    assert np.linalg.norm(np.asarray(goal)[:3, 3] - start[:3, 3]) > 0.01
    assert sol.steps > 0 and sol.converged
