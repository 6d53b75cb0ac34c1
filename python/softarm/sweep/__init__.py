"""Sweeps of the simulated harvest over plants and seeds on Ray, and gain tuning with
Ray Tune (``softarm sweep``, ``softarm tune``).

Only the spec and gains-file modules import at ``import softarm.sweep``; Ray, pyarrow,
tqdm and Optuna (the ``sweep`` extra: ``pip install 'softarm[sweep]'``) are imported when
a sweep or a tuning run starts. :func:`run` sweeps in this process without any of them.
"""

from __future__ import annotations

from softarm.sweep.gains_file import gains_from, load_gains, write_gains
from softarm.sweep.local import run
from softarm.sweep.spec import SweepSpec, TrialSpec, load_spec, parse_spec

__all__ = [
    "SweepSpec",
    "TrialSpec",
    "gains_from",
    "load_gains",
    "load_spec",
    "parse_spec",
    "run",
    "write_gains",
]
