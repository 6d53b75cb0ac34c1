"""The simulated rig: its options, its worlds (the tag world, the rendered bush and row),
its devices, the header and plots of a simulated run, and the simulated harvest as a
Python call."""
