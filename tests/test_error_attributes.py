"""Errors a program can read (issue 27 item 6): every error of the native core reaches
Python with its argument, value and expected range as attributes, kept through pickling;
the Cosserat rod's divergence is a typed error."""

from __future__ import annotations

import math
import pickle
from collections.abc import Callable

import numpy as np
import pytest

import softarm
from softarm import errors
from softarm.errors import (
    DivergenceError,
    InputError,
    NonFiniteError,
    OutOfRangeError,
    ParameterError,
    PoseError,
    ShapeError,
    SoftarmError,
)

ARM = softarm.SoftArm.blackberry()
Q = np.array([0.010, 0.022, 0.015, 0.020, 0.012, 0.008, 0.015, 0.020, 0.012])


def _shape() -> None:
    # A point target in hybrid mode: the core's Error::Shape.
    softarm.Resolver(ARM, "hybrid").step(Q, np.array([0.1, 0.0, 0.2]))


def _binding_shape() -> None:
    ARM.forward(np.zeros(8))


def _binding_type() -> None:
    ARM.forward("nine numbers")


def _non_finite() -> None:
    q = Q.copy()
    q[4] = math.nan
    ARM.forward(q)


def _out_of_range() -> None:
    ARM.point(Q, 7, 0.5)


def _parameter() -> None:
    cane = softarm.Segment([0.1, -0.1, 0.1], [0.1, 0.1, 0.1])
    softarm.Resolver(ARM, "conventional").step(Q, ARM.forward(Q)[:3, 3], obstacles=[cane])


def _choice() -> None:
    softarm.Resolver(ARM, "sideways")


def _pose() -> None:
    softarm.Resolver(ARM, "hybrid").step(Q, 2.0 * np.eye(4))


# (the call, its class, argument, value (None: not compared), words of `expected`): one
# per variant of the core's Error enum, then errors the binding raises itself.
CASES: list[tuple[Callable[[], None], type[InputError], str, object, str]] = [
    (_shape, ShapeError, "target", "a 3-vector", "4×4 pose"),
    (_non_finite, NonFiniteError, "q", None, "finite"),
    (_out_of_range, OutOfRangeError, "section", 7.0, "["),
    (_parameter, ParameterError, "obstacles", 1.0, "null space"),
    (_choice, ParameterError, "mode", "sideways", "hybrid"),
    (_pose, PoseError, "target", None, ""),
    (_binding_shape, ShapeError, "q", "(8,)", "shape (9,)"),
    (_binding_type, InputError, "q", "dtype <U12", "real numbers"),
]


@pytest.mark.parametrize(("call", "cls", "argument", "value", "expected"), CASES)
def test_every_core_error_carries_its_fields(
    call: Callable[[], None], cls: type[InputError], argument: str, value: object, expected: str
) -> None:
    with pytest.raises(cls) as info:
        call()
    err = info.value
    assert isinstance(err, InputError) and isinstance(err, SoftarmError)
    assert isinstance(err, ValueError), "except ValueError keeps working"
    assert err.argument == argument
    assert isinstance(err.expected, str) and expected in err.expected
    if value is not None:
        assert err.value == value
    # The message names the same things.
    assert argument in str(err)
    # Pickling (multiprocessing, Ray) keeps the class and every attribute.
    back = pickle.loads(pickle.dumps(err))
    assert type(back) is type(err)
    for name in ("argument", "expected", "bounds", "index"):
        assert getattr(back, name, None) == getattr(err, name, None)


def test_the_extra_fields_of_a_range_and_of_a_non_finite_value() -> None:
    with pytest.raises(OutOfRangeError) as rng:
        _out_of_range()
    assert rng.value.bounds is not None
    low, high = rng.value.bounds
    assert low <= high < 7.0
    with pytest.raises(NonFiniteError) as nf:
        _non_finite()
    assert nf.value.index == 4
    assert isinstance(nf.value.value, float) and math.isnan(nf.value.value)
    with pytest.raises(PoseError) as pose:
        _pose()
    assert pose.value.value is None


def test_python_raised_input_errors_default_their_fields_to_none() -> None:
    err = ShapeError("x: expected length 3, got length 2")
    assert (err.argument, err.value, err.expected) == (None, None, None)
    assert OutOfRangeError("y").bounds is None
    assert NonFiniteError("z").index is None


def test_a_diverged_simulation_is_a_typed_error() -> None:
    assert issubclass(DivergenceError, SoftarmError)
    assert issubclass(DivergenceError, FloatingPointError), "except FloatingPointError still works"
    assert "DivergenceError" in errors.__all__
