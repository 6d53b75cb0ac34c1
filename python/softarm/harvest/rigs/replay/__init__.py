"""The dry run: a simulated harvest recorded, and replayed through the hardware rig with
the recorded frames and readings in the devices' place."""
