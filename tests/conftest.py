"""Shared fixtures. ``tests/`` is on sys.path so tests can import the numpy oracle."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
# The rendered bush draws offscreen through EGL (Mesa's software rasteriser without a
# GPU), set before anything imports MuJoCo; `make test` exports the same.
os.environ.setdefault("MUJOCO_GL", "egl")

import softarm


@pytest.fixture
def arm() -> softarm.SoftArm:
    return softarm.SoftArm.blackberry()


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)
