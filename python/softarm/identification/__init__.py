"""Plant identification: safe step, ramp and random-pose tests through the safety layer,
then the regulators' lag and dead time, the actuators' elongation per psi and their
hysteresis, per channel (``softarm identify``; docs/identification.md).

    >>> from softarm.identification import SimIdentificationRig, identify
    >>> plant = identify(SimIdentificationRig(seed=0))          # doctest: +SKIP
    >>> plant.tau_s, plant.metres_per_psi                        # doctest: +SKIP
"""

from softarm.identification.estimate import estimate
from softarm.identification.protocol import Design, Segment
from softarm.identification.record import Recording, run_experiment
from softarm.identification.rig import IdentificationRig, SimIdentificationRig, sim_plant_seed
from softarm.identification.run import identify
from softarm.identified_plant import IdentifiedPlant, identified_from_config, load_identified

__all__ = [
    "Design",
    "IdentificationRig",
    "IdentifiedPlant",
    "Recording",
    "Segment",
    "SimIdentificationRig",
    "estimate",
    "identified_from_config",
    "identify",
    "load_identified",
    "run_experiment",
    "sim_plant_seed",
]
