"""The elongation ↔ psi and psi ↔ volt maps: values, inverses, clamping, rejection."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from softarm.errors import NonFiniteError, OutOfRangeError, ParameterError
from softarm.hardware.pressure_map import (
    ITV1031_FULL_SCALE_PSI,
    ElongationMap,
    VoltageMap,
)


def test_paper_ratio_and_arm_limit() -> None:
    m = ElongationMap()
    assert m.to_psi(1.0 / 2100.0) == pytest.approx(1.0)
    assert m.to_elongation(70.0) == pytest.approx(0.0333333, abs=1e-6)
    assert m.max_elongation == pytest.approx(70.0 / 2100.0)


def test_itv1031_full_scale_is_half_a_megapascal() -> None:
    assert pytest.approx(72.5189, abs=1e-3) == ITV1031_FULL_SCALE_PSI
    v = VoltageMap()
    assert v.to_volts(0.0) == 0.0
    assert v.to_volts(ITV1031_FULL_SCALE_PSI) == pytest.approx(5.0)
    assert v.to_volts(70.0) == pytest.approx(5.0 * 70.0 / 72.5189, rel=1e-5)


def test_clamping_and_strict_mode() -> None:
    m, v = ElongationMap(), VoltageMap()
    np.testing.assert_allclose(m.to_psi([-0.01, 0.1]), [0.0, 70.0])
    np.testing.assert_allclose(v.to_volts([-5.0, 1e3]), [0.0, 5.0])
    np.testing.assert_allclose(v.to_psi([-1.0, 6.0]), [0.0, ITV1031_FULL_SCALE_PSI])
    with pytest.raises(OutOfRangeError, match="elongation"):
        m.to_psi(0.1, clamp=False)
    with pytest.raises(OutOfRangeError, match="psi"):
        v.to_volts(-1.0, clamp=False)


def test_offset_voltage_range() -> None:
    v = VoltageMap(full_scale_psi=100.0, v_min=1.0, v_max=5.0)
    assert v.to_volts(50.0) == pytest.approx(3.0)
    assert v.to_psi(3.0) == pytest.approx(50.0)


@pytest.mark.parametrize("bad", [np.nan, np.inf, [1.0, np.nan]])
def test_non_finite_rejected(bad: object) -> None:
    with pytest.raises(NonFiniteError):
        ElongationMap().to_psi(bad)  # type: ignore[arg-type]
    with pytest.raises(NonFiniteError):
        VoltageMap().to_volts(bad)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("factory", "name"),
    [
        (lambda: ElongationMap(max_psi=0.0), "max_psi"),
        (lambda: ElongationMap(metres_per_psi=-1.0), "metres_per_psi"),
        (lambda: VoltageMap(full_scale_psi=np.nan), "full_scale_psi"),
        (lambda: VoltageMap(v_min=5.0, v_max=0.0), "voltage range"),
    ],
)
def test_bad_parameters(factory: object, name: str) -> None:
    with pytest.raises(ParameterError, match=name):
        factory()  # type: ignore[operator]


@given(st.floats(0.0, 70.0))
def test_round_trips(psi: float) -> None:
    m, v = ElongationMap(), VoltageMap()
    assert m.to_psi(m.to_elongation(psi)) == pytest.approx(psi, abs=1e-9)
    volts = v.to_volts(psi)
    assert 0.0 <= volts <= 5.0
    assert v.to_psi(volts) == pytest.approx(psi, abs=1e-9)
