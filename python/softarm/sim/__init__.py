"""Simulation: a simulated pneumatic arm (a plant that is not the controller's model) and
synthetic cameras, so that everything runs with no hardware attached."""
