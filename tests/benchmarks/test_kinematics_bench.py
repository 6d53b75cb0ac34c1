"""pytest-benchmark: kinematics from Python against a numpy implementation of the same
equations (eq. 1-3), run side by side. Targets (docs/architecture.md): one forward/jacobian call
<= 2 us; batch >= 5 million poses per second per core.

Run with ``make bench`` (benchmarks are skipped in ``make test``)."""

from __future__ import annotations

import numpy as np
import pytest

import softarm
from oracle import fd_jacobian, soft_arm_forward

ARM = softarm.SoftArm.blackberry()
SECTIONS = [(s.radius, s.rest_length, s.offset, s.twist) for s in ARM.sections]
Q = np.array([0.010, 0.002, 0.025, 0.030, 0.012, 0.001, 0.005, 0.020, 0.015])
BATCH = np.random.default_rng(0).uniform(ARM.lower, ARM.upper, size=(100_000, 9))


def numpy_forward_batch(qs: np.ndarray) -> np.ndarray:
    """Vectorised numpy eq. (1)-(3) over a batch: the fair baseline for batches."""
    n = qs.shape[0]
    t = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
    for i, (r, l0, b, beta) in enumerate(SECTIONS):
        l1, l2, l3 = qs[:, 3 * i], qs[:, 3 * i + 1], qs[:, 3 * i + 2]
        ux = (l2 + l3 - 2 * l1) / (3 * r)
        uy = np.sqrt(3) * (l3 - l2) / (3 * r)
        length = l0 + (l1 + l2 + l3) / 3
        th = np.hypot(ux, uy)
        c = np.where(th > 0, ux / np.where(th > 0, th, 1), 1.0)
        s = np.where(th > 0, uy / np.where(th > 0, th, 1), 0.0)
        ct, st_ = np.cos(th), np.sin(th)
        rad = np.where(th > 0, length / np.where(th > 0, th, 1), 0.0)
        a = np.zeros((n, 4, 4))
        # Rz(theta) Ry(Theta) Rz(-theta) and the arc's tip (eq. 2).
        a[:, 0, 0] = c * c * ct + s * s
        a[:, 0, 1] = c * s * (ct - 1)
        a[:, 0, 2] = c * st_
        a[:, 1, 0] = c * s * (ct - 1)
        a[:, 1, 1] = s * s * ct + c * c
        a[:, 1, 2] = s * st_
        a[:, 2, 0] = -c * st_
        a[:, 2, 1] = -s * st_
        a[:, 2, 2] = ct
        a[:, 0, 3] = np.where(th > 0, rad * (1 - ct) * c, 0.0)
        a[:, 1, 3] = np.where(th > 0, rad * (1 - ct) * s, 0.0)
        a[:, 2, 3] = np.where(th > 0, rad * st_, length)
        a[:, 3, 3] = 1
        tail = np.eye(4)
        tail[:3, :3] = [
            [np.cos(beta), -np.sin(beta), 0],
            [np.sin(beta), np.cos(beta), 0],
            [0, 0, 1],
        ]
        tail[2, 3] = b
        t = t @ a @ tail
    return t


def test_numpy_batch_baseline_is_correct() -> None:
    np.testing.assert_allclose(
        numpy_forward_batch(BATCH[:100]), ARM.forward_batch(BATCH[:100]), atol=1e-12
    )


@pytest.mark.benchmark(group="forward (one call)")
def test_forward_rust(benchmark) -> None:  # type: ignore[no-untyped-def]
    benchmark(ARM.forward, Q)


@pytest.mark.benchmark(group="forward (one call)")
def test_forward_numpy_baseline(benchmark) -> None:  # type: ignore[no-untyped-def]
    benchmark(soft_arm_forward, SECTIONS, Q)


@pytest.mark.benchmark(group="jacobian (one call)")
def test_jacobian_rust(benchmark) -> None:  # type: ignore[no-untyped-def]
    benchmark(ARM.jacobian, Q)


@pytest.mark.benchmark(group="jacobian (one call)")
def test_jacobian_numpy_fd_baseline(benchmark) -> None:  # type: ignore[no-untyped-def]
    benchmark(fd_jacobian, lambda q: soft_arm_forward(SECTIONS, q), Q)


@pytest.mark.benchmark(group="forward batch (100k poses)")
def test_forward_batch_rust(benchmark) -> None:  # type: ignore[no-untyped-def]
    benchmark(ARM.forward_batch, BATCH)


@pytest.mark.benchmark(group="forward batch (100k poses)")
def test_forward_batch_numpy_baseline(benchmark) -> None:  # type: ignore[no-untyped-def]
    benchmark(numpy_forward_batch, BATCH)


@pytest.mark.benchmark(group="jacobian batch (100k)")
def test_jacobian_batch_rust(benchmark) -> None:  # type: ignore[no-untyped-def]
    benchmark(ARM.jacobian_batch, BATCH)
