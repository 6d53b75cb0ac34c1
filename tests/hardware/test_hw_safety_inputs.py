"""What :meth:`SafePressureBank.set_pressures` takes (issue 26, item 16): numbers only.
Text, complex, dicts and integers beyond the float range raised a plain TypeError,
ValueError or OverflowError, and ``["1"] * 9`` was parsed as numbers and sent. Every one
is now a typed one-line error naming ``psi``, and nothing reaches the backend."""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from softarm.checks import numeric_array
from softarm.errors import InputError, NonFiniteError, ShapeError
from softarm.hardware.safety import SafePressureBank
from softarm.hardware.simulated import IdealPlant, SimulatedPressureBank

N = SimulatedPressureBank(IdealPlant()).channels
EXAMPLES = int(os.environ.get("SOFTARM_FUZZ_EXAMPLES", "50"))


class RecordingBackend(SimulatedPressureBank):
    def __init__(self) -> None:
        super().__init__(IdealPlant())
        self.sent: list[np.ndarray] = []

    def set_pressures(self, psi: np.ndarray) -> None:
        self.sent.append(np.array(psi))
        super().set_pressures(psi)


def _bank() -> tuple[SafePressureBank, RecordingBackend]:
    backend = RecordingBackend()
    bank = SafePressureBank(backend, 60.0, 100.0, 0.5, watchdog_thread=False)
    backend.sent.clear()  # the startup vent
    return bank, backend


BAD = {
    "text": ("abc", ShapeError),
    "numeric text": (["1"] * N, ShapeError),
    "bytes": ([b"1"] * N, ShapeError),
    "complex": ([1j] * N, ShapeError),
    "complex array": (np.full(N, 1 + 0j), ShapeError),
    "dict": ({"a": 1}, ShapeError),
    "None": ([None] * N, ShapeError),
    "bool": ([True] * N, ShapeError),
    "ragged": ([[1.0], [1.0, 2.0]], ShapeError),
    "400 digits": (10**400, NonFiniteError),
    "400 digits per channel": ([10**400] * N, NonFiniteError),
    "wrong length": ([1.0] * (N + 1), ShapeError),
    "NaN": ([float("nan")] * N, NonFiniteError),
}


@pytest.mark.parametrize("case", list(BAD))
def test_a_bad_command_is_a_typed_one_line_error_and_sends_nothing(case: str) -> None:
    value, error = BAD[case]
    bank, backend = _bank()
    with pytest.raises(error) as info:
        bank.set_pressures(value)
    message = str(info.value)
    assert "psi" in message and "\n" not in message and len(message) < 200
    assert backend.sent == []


def test_numbers_of_every_kind_are_still_commands() -> None:
    bank, backend = _bank()
    for value in ([1] * N, np.arange(N, dtype=np.int8), np.ones(N, np.float32), [2**70] * N):
        sent = bank.set_pressures(value).sent
        assert np.all((sent >= 0.0) & (sent <= 60.0))
    assert len(backend.sent) == 4


def test_numeric_array_names_the_argument() -> None:
    with pytest.raises(ShapeError, match=r"^T_base_ee must be numeric"):
        numeric_array("x", "T_base_ee")


#: Anything a caller might pass: numbers of every size, text, complex, containers.
ANYTHING = st.recursive(
    st.none()
    | st.booleans()
    | st.integers()
    | st.floats()
    | st.complex_numbers()
    | st.text(max_size=5)
    | st.binary(max_size=5),
    lambda inner: st.lists(inner, max_size=N + 1) | st.dictionaries(st.text(max_size=3), inner),
    max_leaves=20,
)


@settings(
    max_examples=EXAMPLES,
    derandomize=os.environ.get("SOFTARM_FUZZ_RANDOM") != "1",
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(value=ANYTHING)
def test_fuzz_set_pressures_sends_in_range_or_raises_typed(value: object) -> None:
    bank, backend = _bank()
    try:
        result = bank.set_pressures(value)
    except InputError:
        assert backend.sent == []
        return
    assert np.all((result.sent >= 0.0) & (result.sent <= 60.0))
    assert not isinstance(value, str)
