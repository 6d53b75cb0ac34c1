"""pytest-benchmark: one hybrid resolver step (eq. 20) from Python against a numpy
implementation of the same equations, run side by side. The numpy baseline gets its
pose and Jacobian from the Rust kinematics (one call) and does eq. (14), (17), (20)
with numpy pseudo-inverses: it lives here, never in the package.

Run with ``make bench`` (benchmarks are skipped in ``make test``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import softarm

ARM = softarm.SoftArm.blackberry()
GAINS = softarm.Gains()
RES = softarm.Resolver(ARM, "hybrid", GAINS)
Q = np.array([0.016, 0.012, 0.020, 0.018, 0.015, 0.014, 0.017, 0.019, 0.013])
TARGET = ARM.forward([0.017, 0.013, 0.019, 0.019, 0.014, 0.015, 0.016, 0.020, 0.012])
LO, HI = ARM.lower, ARM.upper


def _rotvec(r: np.ndarray) -> np.ndarray:
    th = math.acos(max(-1.0, min(1.0, (np.trace(r) - 1) / 2)))
    v = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    return 0.5 * v if th < 1e-9 else th / (2 * math.sin(th)) * v


def numpy_hybrid_step(q: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Eq. (20) in numpy with the x/z axis mask and the smooth schedule."""
    pose, j = ARM.forward_jacobian(q)
    jv, jw = j[:3], j[[3, 5]]
    ep = target[:3, 3] - pose[:3, 3]
    ew = _rotvec(target[:3, :3] @ pose[:3, :3].T)[[0, 2]]
    r = HI - LO
    d = GAINS.limit_margin * r
    x = np.clip(q, LO + d, HI - d)
    eta = 0.25 * r**2 * (2 * x - HI - LO) / ((HI - x) * (x - LO)) ** 2
    e = np.linalg.norm(ep)
    gamma = GAINS.hybrid_gamma * e**2 / (e**2 + GAINS.hybrid_switch**2)
    jvp = np.linalg.pinv(jv)
    n1 = np.eye(9) - jvp @ jv
    jt = jw @ n1
    jtp = np.linalg.pinv(jt)
    dq = GAINS.hybrid_alpha * (
        GAINS.hybrid_position * jvp @ ep
        + GAINS.hybrid_orientation * jtp @ (ew - jw @ jvp @ ep)
        + gamma * (n1 - jtp @ jt) @ eta
    )
    return np.clip(q + dq, LO, HI)


def test_baseline_agrees_with_rust() -> None:
    np.testing.assert_allclose(numpy_hybrid_step(Q, TARGET), RES.step(Q, TARGET).q, atol=1e-9)


@pytest.mark.benchmark(group="resolver-step")
def test_bench_rust_hybrid_step(benchmark) -> None:
    benchmark(RES.step, Q, TARGET)


@pytest.mark.benchmark(group="resolver-step")
def test_bench_numpy_hybrid_step(benchmark) -> None:
    benchmark(numpy_hybrid_step, Q, TARGET)


@pytest.mark.benchmark(group="resolver-solve")
def test_bench_rust_solve(benchmark) -> None:
    benchmark(RES.solve, np.full(9, 0.0166), TARGET)
