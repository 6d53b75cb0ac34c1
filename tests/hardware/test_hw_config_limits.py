"""The safety settings' ranges (issue 12 item 12) in the configuration and in the
constructors: one table (softarm.hardware.limits), so both accept exactly the same."""

from __future__ import annotations

import pytest

from softarm.config import default_config, dump_config, parse_config
from softarm.errors import ConfigError, ParameterError
from softarm.hardware import limits
from softarm.hardware.safety import SafePressureBank
from softarm.hardware.simulated import IdealPlant, SimulatedPressureBank

TEXT = dump_config(default_config())


def with_value(section: str, key: str, value: str) -> str:
    lines = TEXT.splitlines()
    start = lines.index(f"[{section}]")
    i = next(i for i in range(start, len(lines)) if lines[i].startswith(f"{key} = "))
    lines[i] = f"{key} = {value}"
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(
    ("section", "key", "value"),
    [
        ("channels", "watchdog_timeout_s", "1e308"),
        ("channels", "watchdog_timeout_s", "1e-300"),
        ("channels", "max_rate_psi_per_s", "1e308"),
        ("channels", "max_rate_psi_per_s", "1e-3"),
        ("channels", "full_scale_psi", "1e300"),
        ("serial", "timeout_s", "1e308"),
        ("serial", "timeout_s", "1e-6"),
        ("serial", "startup_delay_s", "1e308"),
        ("serial", "retries", "1000000"),
        ("serial", "baud", "1000000000000"),
    ],
)
def test_out_of_range_safety_settings_are_config_errors(section: str, key: str, value: str) -> None:
    with pytest.raises(ConfigError, match=rf"{section}\.{key} must be .* in \[.*\(.*\), got"):
        parse_config(with_value(section, key, value), source="arm.toml")


LIMITS = [
    limits.WATCHDOG_TIMEOUT_S,
    limits.MAX_RATE_PSI_PER_S,
    limits.FULL_SCALE_PSI,
    limits.SERIAL_TIMEOUT_S,
    limits.STARTUP_DELAY_S,
    limits.RETRIES,
    limits.BAUD,
]
WHERE = {
    "watchdog_timeout_s": "channels",
    "max_rate_psi_per_s": "channels",
    "full_scale_psi": "channels",
    "timeout_s": "serial",
    "startup_delay_s": "serial",
    "retries": "serial",
    "baud": "serial",
}


@pytest.mark.parametrize("limit", LIMITS, ids=lambda lim: lim.name)
def test_the_config_accepts_each_range_end(limit: limits.Limit) -> None:
    for end in (limit.lo, limit.hi):
        if end == 0:
            continue  # a zero delay is covered by the shipped tests
        value = repr(int(end)) if limit.integer else repr(float(end))
        if limit.name == "full_scale_psi" and end < 70.0:
            continue  # p_max = 70 must not exceed full scale
        parse_config(with_value(WHERE[limit.name], limit.name, value))


@pytest.mark.parametrize("limit", LIMITS, ids=lambda lim: lim.name)
def test_every_range_is_documented_with_its_reason(limit: limits.Limit) -> None:
    text = limit.describe()
    assert f"[{limit.lo:g}, {limit.hi:g}]" in text and len(limit.why) > 30


def test_constructors_accept_the_range_ends_and_reject_beyond() -> None:
    backend = SimulatedPressureBank(IdealPlant())
    for rate in (0.1, 1000.0):
        for timeout in (0.02, 10.0):
            SafePressureBank(backend, 70.0, rate, timeout, watchdog_thread=False).close()
            backend = SimulatedPressureBank(IdealPlant())
    for rate, timeout in ((0.0999, 0.5), (1000.1, 0.5), (100.0, 0.0199), (100.0, 10.01)):
        with pytest.raises(ParameterError):
            SafePressureBank(backend, 70.0, rate, timeout, watchdog_thread=False)


@pytest.mark.parametrize("bad", [True, "1", 1j, float("nan"), float("inf"), None])
def test_limits_reject_non_numbers(bad: object) -> None:
    for limit in LIMITS:
        assert not limit.contains(bad)
        with pytest.raises(ParameterError, match=limit.name):
            limit.check(bad)


def test_the_config_loader_imports_the_limits_without_the_drivers() -> None:
    """softarm.hardware is lazy: the config loader gets the table without pyserial."""
    import subprocess
    import sys

    code = "import sys, softarm.config; print('serial' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_the_lazy_package_exports_every_name() -> None:
    import softarm.hardware as hw

    assert set(hw.__all__) == set(hw._WHERE)
    for name in hw.__all__:
        value = getattr(hw, name)
        assert name.isupper() or value.__module__ == f"softarm.hardware.{hw._WHERE[name]}"
    with pytest.raises(AttributeError, match="no attribute 'Nope'"):
        _ = hw.Nope
