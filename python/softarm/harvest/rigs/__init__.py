"""The rigs: the only place where the simulator and the arm differ. The simulated rig and
its devices, the hardware rig and its devices, the dry run's replayed devices, the
rendered bush's world."""
