"""A synthetic calibration problem on a constant-curvature plant, for tests and the
fidelity evaluation (``examples/fidelity.py``): a true arm whose geometry and actuator
gains differ from the nominal one, measured with tracker-like noise."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from softarm._core import SoftArm
from softarm.calibration.excitation import excitation_set
from softarm.checks import FloatArray as F64
from softarm.sim.arm import PlantConfig, perturbed_arm

__all__ = ["SyntheticProblem", "noisy", "synthetic_problem"]


def noisy(poses: F64, rng: np.random.Generator, position: float, angle: float) -> F64:
    """``poses`` with Gaussian noise per axis on the position (m) and on the rotation
    (rad, applied in the base frame), as :class:`softarm.sim.tracker.PoseTracker`."""
    out = poses.copy()
    out[:, :3, 3] += rng.normal(0.0, position, (len(poses), 3))
    rot = Rotation.from_rotvec(rng.normal(0.0, angle, (len(poses), 3))).as_matrix()
    out[:, :3, :3] = rot @ poses[:, :3, :3]
    return out


@dataclass(frozen=True)
class SyntheticProblem:
    """Fit data (noisy), held-out data (noise-free truth) and the truth itself."""

    nominal: SoftArm
    true_arm: SoftArm
    true_gain: F64
    fit_commands: F64
    fit_poses: F64
    test_commands: F64
    test_poses: F64


def synthetic_problem(
    seed: int,
    n_fit: int = 80,
    n_test: int = 200,
    spread: float = 0.06,
    position_noise: float = 1e-4,
    angle_noise: float = math.radians(0.1),
) -> SyntheticProblem:
    """A true arm with radii, rest lengths, offsets and gains within +-``spread``
    (relative) and twists within +-``spread`` rad of the blackberry arm; ``n_fit``
    excitation poses measured with noise, ``n_test`` uniformly drawn held-out commands
    with their true poses."""
    nominal = SoftArm.blackberry()
    rng = np.random.default_rng(seed)
    cfg = PlantConfig(geometry_spread=spread, twist_spread=spread, gain_spread=spread)
    true_arm = perturbed_arm(nominal, rng, cfg)
    gain = 1.0 + rng.uniform(-spread, spread, nominal.n_actuators)
    fit_c = excitation_set(nominal, n_fit, seed=int(rng.integers(2**31)), lo=0.0, hi=1.0)
    fit_p = noisy(true_arm.forward_batch(fit_c * gain), rng, position_noise, angle_noise)
    lo, up = np.asarray(nominal.lower), np.asarray(nominal.upper)
    test_c = rng.uniform(lo, up, (n_test, nominal.n_actuators))
    test_p = true_arm.forward_batch(test_c * gain)
    return SyntheticProblem(nominal, true_arm, gain, fit_c, fit_p, test_c, test_p)
