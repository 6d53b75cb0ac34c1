"""The hardware rig: the same state machine on the real devices, from a TOML config; its
device boundary and its stereo source."""
