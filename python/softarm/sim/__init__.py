"""Simulation: a simulated pneumatic arm (a plant that is not the controller's model) and
synthetic cameras, so that everything runs with no hardware attached."""

from softarm.sim.camera import Lighting, Scene, SyntheticCamera
from softarm.sim.markers import SceneMarker, TexturedPlane, cube_scene_markers

__all__ = [
    "Lighting",
    "Scene",
    "SceneMarker",
    "SyntheticCamera",
    "TexturedPlane",
    "cube_scene_markers",
]
