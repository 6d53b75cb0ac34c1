"""The ``[harvest]`` keys of fine positioning's end rule: defaults, and a bad value one
typed error naming the key (in code and in a configuration file)."""

from __future__ import annotations

from importlib import resources

import pytest

from softarm.config import parse_config
from softarm.errors import ConfigError, ParameterError
from softarm.harvest_config import FINE_END_RULES, HarvestConfig

#: The shipped template, whose [harvest] block the tests add keys to.
TEMPLATE = resources.files("softarm.data").joinpath("blackberry.toml").read_text("utf-8")


def _with_harvest(lines: str) -> str:
    assert TEMPLATE.count("\n[harvest]") == 1
    return TEMPLATE.replace("\n[harvest]", f"\n[harvest]\n{lines}\n#", 1)


def test_defaults() -> None:
    c = HarvestConfig()
    assert (c.fine_end_rule, c.fine_window, c.fine_confidence) == ("steps", 20, 0.95)
    assert FINE_END_RULES == ("confidence", "steps")
    assert HarvestConfig(fine_end_rule="confidence").fine_end_rule == "confidence"


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"fine_end_rule": "mean"}, "fine_end_rule must be one of confidence, steps, got 'mean'"),
        ({"fine_end_rule": 1}, "fine_end_rule must be one of"),
        ({"fine_window": 1}, "fine_window must be an integer >= 2, got 1"),
        ({"fine_window": 2.5}, "fine_window must be an integer >= 2"),
        ({"fine_confidence": 1.0}, "fine_confidence must be in (0, 1), got 1.0"),
        ({"fine_confidence": 0.0}, "fine_confidence must be in (0, 1)"),
        ({"fine_confidence": float("nan")}, "fine_confidence must be a finite number"),
    ],
)
def test_bad_values_name_the_key(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(ParameterError) as info:
        HarvestConfig(**kwargs)  # type: ignore[arg-type]
    assert message in str(info.value)


def test_config_file_names_the_key() -> None:
    with pytest.raises(ConfigError) as info:
        parse_config(_with_harvest('fine_end_rule = "fast"'), source="hw.toml")
    assert "harvest.fine_end_rule must be one of confidence, steps, got 'fast'" in str(info.value)
    harvest = parse_config(_with_harvest('fine_end_rule = "steps"\nfine_window = 8')).harvest
    assert (harvest.fine_end_rule, harvest.fine_window) == ("steps", 8)
