"""The unit constants of the pressure boundary, defined once for the Python side.

Every Python module that converts actuator elongation (m) to pressure (psi) takes its
numbers from here: :mod:`softarm.hardware.pressure_map` (the rig's maps, which also own
psi ↔ volts), :mod:`softarm.sim.pressure` (the simulated regulators) and the
configuration defaults. This module imports nothing, so every layer may import it (see
``docs/architecture.md``, "Units"). The Rust core has its own single copy in
``crates/softarm-core/src/soft_arm.rs``.
"""

from __future__ import annotations

__all__ = ["MAX_PSI", "METRES_PER_PSI", "PA_PER_PSI"]

#: Actuator elongation per psi (m / psi): the length/pressure ratio measured in the
#: redundancy paper, section IV-A (linear guide + optical encoder, 10 → 50 psi ramp).
METRES_PER_PSI = 1.0 / 2100.0
#: Largest regulator pressure (psi) the arm is driven to; 70 psi x 1/2100 m/psi = 0.0333 m,
#: the blackberry arm's elongation limit (paper, section IV-A).
MAX_PSI = 70.0
#: Pascals per psi (exact by definition of the pound-force and the inch).
PA_PER_PSI = 6894.757293168361
