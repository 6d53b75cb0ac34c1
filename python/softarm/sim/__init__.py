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

from softarm.sim.arm import PlantConfig, SimulatedArm, perturbed_arm
from softarm.sim.hysteresis import PlayHysteresis
from softarm.sim.pressure import PressureDynamics
from softarm.sim.tracker import PoseTracker

__all__ += [
    "PlantConfig",
    "PlayHysteresis",
    "PoseTracker",
    "PressureDynamics",
    "SimulatedArm",
    "perturbed_arm",
]
