"""One check, before any work, that the rendered world can draw here: MuJoCo imports and an
offscreen OpenGL context can be made with the chosen ``MUJOCO_GL``.

MuJoCo reports a missing context only when the first renderer is made, as
``mujoco.FatalError`` after a page of GLFW warnings (``MUJOCO_GL=glfw`` on a machine with no
display; a set but empty ``MUJOCO_GL`` means glfw to MuJoCo). The commands call
:func:`require_offscreen_gl` before their banner and before they create an output folder,
so that such a machine gets one line naming the fix, not a traceback and an empty folder.
"""

from __future__ import annotations

import os
import warnings
from typing import Any

from softarm.sim.render.renderer import HOW_TO_ENABLE, RenderUnavailableError, require_mujoco

__all__ = ["require_offscreen_gl"]

#: The backends already proven to draw in this process (a context is made once per backend).
_WORKS: set[str] = set()


def require_offscreen_gl() -> Any:
    """The ``mujoco`` module once a tiny offscreen renderer was made with it, or
    :class:`RenderUnavailableError` whose message says how to enable one."""
    if not os.environ.get("MUJOCO_GL", "").strip():
        # Empty is glfw to MuJoCo, which needs a display; unset is EGL here.
        os.environ["MUJOCO_GL"] = "egl"
    mujoco = require_mujoco()
    backend = os.environ.get("MUJOCO_GL", "")
    if backend in _WORKS:
        return mujoco
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # GLFW's warnings before the error itself
        try:
            renderer = mujoco.Renderer(mujoco.MjModel.from_xml_string("<mujoco/>"), 8, 8)
        except Exception as exc:  # mujoco.FatalError, or OSError/RuntimeError of the GL loader
            raise RenderUnavailableError(
                f"{HOW_TO_ENABLE} (MUJOCO_GL={backend!r}: {_first_line(exc)})"
            ) from exc
        renderer.close()
    _WORKS.add(backend)
    return mujoco


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__
