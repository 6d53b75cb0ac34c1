"""A renderer that cannot draw here (``MUJOCO_GL=glfw`` with no display, no MuJoCo at all)
is one line naming the fix and exit status 2, before the banner and before any output
folder; from Python, a typed :class:`RenderUnavailableError` (issue 39, item 1)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

NO_MUJOCO = "import sys; sys.modules['mujoco'] = None; "
CLI = "from softarm.cli import main; sys.exit(main(sys.argv[1:]))"


def _run(
    argv: list[str], gl: str, cwd: Path, prelude: str = ""
) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    env["MUJOCO_GL"] = gl
    code = f"import sys; {prelude}{CLI}"
    return subprocess.run(
        [sys.executable, "-c", code, *argv],
        capture_output=True, text=True, env=env, cwd=cwd, timeout=300,
    )  # fmt: skip


def _one_clean_line(done: subprocess.CompletedProcess[str]) -> None:
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr and "GLFWError" not in done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "MUJOCO_GL=egl" in lines[0], done.stderr
    assert done.stdout == ""  # no banner


@pytest.mark.parametrize(
    ("argv", "folder"),
    [
        (
            ["harvest", "--sim", "--world", "bush", "--berries", "1", "--record-frames", "rec/a"],
            "rec",
        ),
        (["demo", "--world", "bush", "--berries", "1", "--out", "out/demo"], "out"),
        (["dataset", "--out", "ds/x", "--images", "1"], "ds"),
    ],
)
def test_glfw_without_a_display_is_one_line_and_no_folder(
    tmp_path: Path, argv: list[str], folder: str
) -> None:
    done = _run(argv, "glfw", tmp_path)
    _one_clean_line(done)
    assert "MUJOCO_GL='glfw'" in done.stderr
    assert not (tmp_path / folder).exists()


def test_without_mujoco_the_line_names_the_render_extra_before_the_banner(tmp_path: Path) -> None:
    done = _run(
        ["harvest", "--sim", "--world", "bush", "--berries", "1"], "egl", tmp_path, NO_MUJOCO
    )
    _one_clean_line(done)
    assert "pip install 'softarm[render]'" in done.stderr


def test_simulate_harvest_in_the_bush_raises_the_typed_error(tmp_path: Path) -> None:
    code = (
        "import softarm\n"
        "from softarm.sim.render import RenderUnavailableError\n"
        "try:\n"
        "    softarm.simulate_harvest(1, world='bush', log='run.jsonl')\n"
        "except RenderUnavailableError as exc:\n"
        "    print('typed:', exc)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "DISPLAY"}
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
        env={**env, "MUJOCO_GL": "glfw"}, cwd=tmp_path,
    )  # fmt: skip
    assert done.stdout.startswith("typed:"), done.stdout + done.stderr
    assert "GLFWError" not in done.stderr
    assert not (tmp_path / "run.jsonl").exists()


def test_an_empty_mujoco_gl_is_the_default_egl_not_glfw(tmp_path: Path) -> None:
    code = (
        "import os\n"
        "from softarm.sim.render import RenderUnavailableError\n"
        "from softarm.sim.render.gl_check import require_offscreen_gl\n"
        "try:\n"
        "    require_offscreen_gl()\n"
        "    print('drew with', os.environ['MUJOCO_GL'])\n"
        "except RenderUnavailableError as exc:\n"
        "    print('typed:', exc)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "DISPLAY"}
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
        env={**env, "MUJOCO_GL": ""}, cwd=tmp_path,
    )  # fmt: skip
    assert "Traceback" not in done.stderr and "GLFWError" not in done.stderr
    assert done.stdout.startswith("drew with egl") or "MUJOCO_GL='egl'" in done.stdout
