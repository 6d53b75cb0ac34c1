"""Shared fixtures for the hardware tests."""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from fake_arduino import FakeArduino


class FakeClock:
    """A manual monotonic clock: tests advance it explicitly."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now

    def advance(self, dt: float) -> None:
        self.now += dt


@pytest.fixture
def clock() -> FakeClock:
    return FakeClock()


@pytest.fixture
def arduino() -> Iterator[FakeArduino]:
    fake = FakeArduino()
    yield fake
    fake.close()
