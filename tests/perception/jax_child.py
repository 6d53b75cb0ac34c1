"""The detector training's tests run JAX in a child process: JAX starts thread pools when
imported, and the suite's own later forks (Ray, subprocess) must never happen beside them."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

HAS_JAX = all(importlib.util.find_spec(m) is not None for m in ("jax", "optax", "onnx"))
NEEDS_JAX = pytest.mark.skipif(not HAS_JAX, reason="needs the train extra (jax, optax, onnx)")
TESTS = Path(__file__).parent


def in_child(code: str, *args: str) -> subprocess.CompletedProcess[str]:
    """Run ``code`` (with the tests' helpers importable) in a fresh interpreter."""
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(TESTS), os.environ.get("PYTHONPATH", "")]),
    }
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code), *args],
        capture_output=True, text=True, env=env, timeout=600, check=False,
    )  # fmt: skip
