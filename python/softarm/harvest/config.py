"""Tuning of the harvesting state machine: :class:`softarm.harvest_config.HarvestConfig`,
defined below the harvest layer so that :mod:`softarm.config` can read it from a file."""

from softarm.harvest_config import HarvestConfig

__all__ = ["HarvestConfig"]
