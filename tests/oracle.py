"""A slow numpy transcription of the papers' equations, used only as a test oracle and
as the benchmark baseline (never by the package: the kinematics live once, in Rust)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]


def rot_z(a: float) -> F64:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def rot_y(a: float) -> F64:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1.0]])


def trans(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> F64:
    t = np.eye(4)
    t[:3, 3] = (x, y, z)
    return t


def soft_arm_forward(sections: list[tuple[float, float, float, float]], q: F64) -> F64:
    """Redundancy paper eq. (1)-(3) literally; sections are (radius, L0, b, beta).
    Valid away from straight sections (eq. 1 divides by s_i)."""
    t = np.eye(4)
    for i, (r, l0, b, beta) in enumerate(sections):
        l1, l2, l3 = q[3 * i : 3 * i + 3]
        s = np.sqrt(l1**2 + l2**2 + l3**2 - l1 * l2 - l2 * l3 - l1 * l3)
        phi = 2 * s / (3 * r)
        lam = (3 * l0 + l1 + l2 + l3) * r / (2 * s)
        theta = np.arctan2(np.sqrt(3) * (l3 - l2), l2 + l3 - 2 * l1)
        ti = rot_z(theta) @ trans(lam) @ rot_y(phi) @ trans(-lam) @ rot_z(-theta)
        t = t @ ti @ trans(z=b) @ rot_z(beta)
    return t


def fd_jacobian(forward: object, q: F64, h: float = 1e-7) -> F64:
    """Central finite differences of a pose function; angular part (dR R^T)^vee."""
    fwd = forward  # callable q -> (4, 4)
    t0 = fwd(q)  # type: ignore[operator]
    jac = np.zeros((6, q.size))
    for k in range(q.size):
        dq = np.zeros(q.size)
        dq[k] = h
        dt = (fwd(q + dq) - fwd(q - dq)) / (2 * h)  # type: ignore[operator]
        w = dt[:3, :3] @ t0[:3, :3].T
        jac[:3, k] = dt[:3, 3]
        jac[3:, k] = 0.5 * np.array([w[2, 1] - w[1, 2], w[0, 2] - w[2, 0], w[1, 0] - w[0, 1]])
    return jac
