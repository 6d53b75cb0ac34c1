"""The calibration's analytic Jacobian (chain rule through the core's eq. 4-6) against
central differences, for every parameter."""

import numpy as np
import pytest

import softarm
from softarm.calibration.metrics import rotation_residuals
from softarm.calibration.model import ParameterMap


@pytest.mark.parametrize(("seed", "bias"), [(0, False), (1, False), (2, True)])
def test_pose_jacobian_matches_central_differences(seed: int, bias: bool) -> None:
    pm = ParameterMap(softarm.SoftArm.blackberry(), bias=bias)
    rng = np.random.default_rng(seed)
    x = rng.uniform(-0.05, 0.05, pm.size)
    c = rng.uniform(0.0, 0.033, (6, pm.n_actuators))
    c[0] = 0.0  # the straight arm, where eq. (1) alone would divide by zero
    _, jac = pm.pose_jacobian(x, c)
    h = 1e-6
    for k in range(pm.size):
        d = np.zeros(pm.size)
        d[k] = h
        plus = pm.arm(x + d).forward_batch(pm.elongations(x + d, c))
        minus = pm.arm(x - d).forward_batch(pm.elongations(x - d, c))
        v = (plus[:, :3, 3] - minus[:, :3, 3]) / (2 * h)
        w = rotation_residuals(plus, minus) / (2 * h)
        np.testing.assert_allclose(jac[:, :3, k], v, atol=1e-7, err_msg=pm.names()[k])
        np.testing.assert_allclose(jac[:, 3:, k], w, atol=1e-7, err_msg=pm.names()[k])


def test_zero_parameters_give_the_nominal_arm() -> None:
    arm = softarm.SoftArm.blackberry()
    pm = ParameterMap(arm)
    fitted = pm.arm(np.zeros(pm.size))
    assert fitted.sections == arm.sections
    np.testing.assert_array_equal(pm.gains(np.zeros(pm.size)), np.ones(9))


def test_bias_offsets_have_zero_mean_per_section() -> None:
    pm = ParameterMap(softarm.SoftArm.blackberry(), bias=True)
    x = np.random.default_rng(3).uniform(-0.1, 0.1, pm.size)
    assert pm.size == 27
    np.testing.assert_allclose(pm.offsets(x).reshape(3, 3).sum(axis=1), 0.0, atol=1e-15)
