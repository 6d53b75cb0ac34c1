"""The control stack of a harvest rig, built once for the simulator and the arm: the
resolver closed on the cameras, the placement IK, the clearance to the canes, the model
of the measurement chain and the actuator behind the safety layer."""
