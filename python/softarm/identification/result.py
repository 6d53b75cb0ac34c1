"""The identified plant (``id.json``): :mod:`softarm.identified_plant`, re-exported."""

from softarm.identified_plant import (
    PER_CHANNEL_KEYS,
    IdentifiedPlant,
    identified_from_config,
    load_identified,
)

__all__ = ["PER_CHANNEL_KEYS", "IdentifiedPlant", "identified_from_config", "load_identified"]
