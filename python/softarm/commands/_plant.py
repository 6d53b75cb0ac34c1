"""``--plant FILE``, ``--identified id.json`` and ``--model model.toml``, shared by every
command that builds the simulated rig (``harvest --sim``, ``demo``): the simulated plant's
``[plant]`` table (:mod:`softarm.sim.plant_file`), the plant ``softarm identify`` measured
(:mod:`softarm.identified_plant`) and the model ``softarm calibrate`` fitted
(:mod:`softarm.calibration.result`). Both files are read and checked before the run
starts; a bad one is a one-line error naming the key (exit status 2)."""

from __future__ import annotations

import argparse
from typing import Any

from softarm.commands._args import config_file
from softarm.errors import ParameterError

__all__ = ["add_plant_options", "plant_options"]


def add_plant_options(p: argparse.ArgumentParser, *, sim_only_flag: bool = True) -> None:
    """Add ``--plant``, ``--identified`` and ``--model`` to ``p``."""
    p.add_argument(
        "--plant",
        type=config_file,
        help="simulated plant parameters: a TOML [plant] table (docs/identification.md)"
        + (" (--sim only)" if sim_only_flag else ""),
    )
    p.add_argument(
        "--identified",
        type=config_file,
        help="the plant `softarm identify` measured (id.json): the actuators' lag the "
        "lag-aware loop predicts (on hardware it replaces the config's [plant_model])",
    )
    p.add_argument(
        "--model",
        type=config_file,
        help="a fitted arm model (`softarm calibrate` writes model.toml): the controller's "
        "arm and the actuators' gains (on hardware it replaces the config's arm and "
        "channel gains)",
    )


def plant_options(args: argparse.Namespace) -> dict[str, Any]:
    """``SimRigOptions`` keywords from the parsed options (files read and validated).

    Raises:
        ParameterError: ``--plant`` without ``--sim``.
        ConfigError: a file is unreadable or holds a bad key or value.
    """
    from softarm.identified_plant import load_identified
    from softarm.sim.plant_file import load_plant_file

    out: dict[str, Any] = {}
    if getattr(args, "plant", None) is not None:
        if not getattr(args, "sim", True):
            raise ParameterError("--plant: works with --sim only (the hardware is its own plant)")
        out["plant"] = load_plant_file(args.plant)
    if getattr(args, "identified", None) is not None:
        out["identified"] = load_identified(args.identified)
    if getattr(args, "model", None) is not None:
        from softarm.calibration import load_calibration

        out["calibration"] = load_calibration(args.model)
    return out
