"""Perception without tags: ripe and unripe berries in colour images, their 3D positions
from C1's stereo pair or C2's view, and the canes fitted as curves from C1's depth.

At the level of :mod:`softarm.vision` (it imports vision and the leaf modules, never the
simulation), so that the simulated and the real rig run the same code."""

from softarm.perception.stereo_camera import Rectification, StereoCamera

__all__ = ["Rectification", "StereoCamera"]
