"""The marker bodies ``--marker-body`` accepts (``softarm harvest --sim``): those of
:data:`softarm.vision.marker_body.MARKER_BODIES`, spelt here so that the command line
starts without loading OpenCV (a test checks the two agree)."""

from __future__ import annotations

__all__ = ["MARKER_BODIES"]

MARKER_BODIES = ("cube", "frustum")
