"""The daylight families ``--look`` accepts (``softarm harvest --sim --world row``,
``softarm dataset --world row``): those of :data:`softarm.sim.render.row_look.LOOKS`,
spelt here so that the command line starts without loading the renderer (a test
checks the two agree)."""

from __future__ import annotations

__all__ = ["LOOKS"]

LOOKS = ("sun", "overcast", "backlight", "dusk", "random")
