"""The harvest's perception: :class:`softarm.vision.two_cameras.CameraVision` and
:func:`~softarm.vision.two_cameras.register_c1`, re-exported where the rigs import them."""

from softarm.vision.two_cameras import CameraVision, register_c1

__all__ = ["CameraVision", "register_c1"]
