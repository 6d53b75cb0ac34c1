"""The backlash inverse against the play operator it inverts (softarm.sim.hysteresis)."""

import numpy as np
import pytest

from softarm.errors import ParameterError, ShapeError
from softarm.hardware.play_inverse import PlayInverse
from softarm.sim.hysteresis import PlayHysteresis


def _through_play(widths: np.ndarray, path: np.ndarray, inverse: PlayInverse | None) -> np.ndarray:
    play = PlayHysteresis(widths)
    out = []
    for p in path:
        out.append(play(p if inverse is None else inverse.command(p)))
    return np.array(out)


def test_settles_at_the_wanted_pressure_after_every_reversal() -> None:
    widths = np.array([5.0, 2.0, 0.0])
    rng = np.random.default_rng(3)
    # A random walk of wanted pressures with reversals, every step larger than the deadband.
    steps = rng.choice([-1.0, 1.0], size=(200, 3)) * rng.uniform(0.2, 3.0, size=(200, 3))
    path = 30.0 + np.cumsum(steps, axis=0)
    with_inverse = _through_play(widths, path, PlayInverse(widths, deadband=0.05))
    without = _through_play(widths, path, None)
    assert np.allclose(with_inverse[1:], path[1:], atol=1e-12)
    # Without it the output lags the reversals by up to half the band.
    assert np.max(np.abs(without[:, 0] - path[:, 0])) == pytest.approx(2.5, abs=1e-9)


def test_reversals_inside_the_deadband_do_not_flip() -> None:
    inv = PlayInverse([4.0], deadband=0.5)
    assert inv.command([10.0])[0] == pytest.approx(12.0)
    assert inv.command([9.7])[0] == pytest.approx(11.7)  # 0.3 back: still upwards
    assert inv.command([9.4])[0] == pytest.approx(7.4)  # 0.6 back from 10: flips
    assert inv.command([9.6])[0] == pytest.approx(7.6)  # 0.2 up from 9.4: still downwards
    inv.reset()
    assert inv.command([1.0])[0] == pytest.approx(3.0)


@pytest.mark.parametrize(
    ("width", "deadband", "arg"),
    [([-1.0], 0.0, "width_psi"), ([np.nan], 0.0, "width_psi"), ([], 0.0, "width_psi"),
     ([1.0], -0.1, "deadband"), ([1.0], np.inf, "deadband")],
)  # fmt: skip
def test_bad_arguments_name_themselves(width: list[float], deadband: float, arg: str) -> None:
    with pytest.raises(ParameterError, match=arg):
        PlayInverse(width, deadband)


def test_wrong_shape_is_a_typed_error() -> None:
    with pytest.raises(ShapeError, match="wanted_psi"):
        PlayInverse([1.0, 1.0]).command([1.0])
