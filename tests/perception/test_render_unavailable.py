"""Without an offscreen OpenGL the rendered world says how to enable it, in one line,
from the library and from the command line."""

from __future__ import annotations

import os
import subprocess
import sys

SCRIPT = """
from softarm.sim.render import RenderUnavailableError, require_mujoco
try:
    require_mujoco()
    import mujoco
    mujoco.Renderer(mujoco.MjModel.from_xml_string('<mujoco/>'), 8, 8)
except RenderUnavailableError as exc:
    print('typed:', exc)
except Exception as exc:
    print('untyped:', type(exc).__name__, exc)
"""


def _run(code: list[str], gl: str) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "MUJOCO_GL": gl}
    return subprocess.run(code, capture_output=True, text=True, env=env, timeout=120)


def test_a_bad_gl_backend_is_a_typed_error_naming_the_fix() -> None:
    out = _run([sys.executable, "-c", SCRIPT], "no-such-backend").stdout
    assert out.startswith("typed:") and "MUJOCO_GL=egl" in out


def test_the_bush_harvest_exits_2_with_the_fix_in_one_line() -> None:
    cmd = [sys.executable, "-m", "softarm", "harvest", "--sim", "--world", "bush",
           "--berries", "2", "-q"]  # fmt: skip
    done = _run(cmd, "no-such-backend")
    assert done.returncode == 2
    assert "MUJOCO_GL=egl" in done.stderr and "Traceback" not in done.stderr
