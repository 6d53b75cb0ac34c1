"""``SoftArm.from_config``: the arm described by the ``[arm]`` section of a configuration.

Attached to the native class by ``softarm/__init__.py``: building an arm from a file is
Python's business (TOML, paths, error messages naming the key), the kinematics Rust's.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from softarm.errors import ConfigError

if TYPE_CHECKING:
    from softarm._core import SoftArm
    from softarm.config import ArmConfig, Config

__all__ = ["from_config"]


def from_config(cls: type[SoftArm], config: str | Path | Config | ArmConfig) -> SoftArm:
    """The arm of a configuration: a TOML file path (see :mod:`softarm.config`), a loaded
    :class:`~softarm.config.Config`, or its :class:`~softarm.config.ArmConfig`.

    >>> import softarm
    >>> from softarm.config import default_config
    >>> softarm.SoftArm.from_config(default_config()).n_actuators
    9

    Raises:
        ConfigError: the file is missing or invalid (the message names the key).
    """
    from softarm._core import Section
    from softarm.config import ArmConfig, Config, load_config

    if isinstance(config, str | Path):
        config = load_config(config)
    if isinstance(config, Config):
        config = config.arm
    if not isinstance(config, ArmConfig):
        raise ConfigError(
            f"config must be a path, a softarm.config.Config or an ArmConfig, "
            f"got {type(config).__name__}"
        )
    return cls([Section(**vars(s)) for s in config.sections])
