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

# A rendered world that cannot run is a skip on a developer's machine, a failure in CI
# (CI=true or SOFTARM_REQUIRE_RENDER=1): the hook applies to every test.
from render_required import pytest_runtest_makereport  # noqa: F401


def pytest_configure(config: pytest.Config) -> None:
    """The benchmarks' bodies (tests/benchmarks) run once each, untimed, in every plain
    test run, their asserts with them (pytest-benchmark's --benchmark-disable), so that CI
    runs them; --benchmark-only (make bench) or --benchmark-enable times them, and
    --benchmark-skip leaves them out."""
    opt = config.option
    if not hasattr(opt, "benchmark_disable"):
        return  # pytest-benchmark is not installed
    if not (opt.benchmark_only or opt.benchmark_enable or opt.benchmark_skip):
        opt.benchmark_disable = True


@pytest.fixture
def arm() -> softarm.SoftArm:
    return softarm.SoftArm.blackberry()


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)
