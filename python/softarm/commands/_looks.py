"""The daylight families ``--look`` accepts (``softarm harvest --sim --world row``,
``softarm dataset --world row``): those of :data:`softarm.sim.render.row_look.LOOKS`,
spelt here so that the command line starts without loading the renderer (a test
checks the two agree)."""

from __future__ import annotations

import argparse

__all__ = ["LOOKS", "add_look"]

LOOKS = ("sun", "overcast", "backlight", "dusk", "random")


def add_look(p: argparse.ArgumentParser) -> None:
    """``--look``, the daylight family of ``--world row`` (``harvest --sim``, ``demo``)."""
    p.add_argument(
        "--look", choices=LOOKS, default=None,
        help="--world row: the daylight family (default random: one of the four drawn "
        "from the seed; docs/perception.md, 'The daylight row')",
    )  # fmt: skip
