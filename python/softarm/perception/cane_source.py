"""Where the cane pixels come from: ``colour`` (the colour, texture and width thresholds of
:func:`softarm.perception.cane_pixels.cane_mask`, the default), ``net`` (the shipped
network's cane class, :meth:`softarm.perception.detector.learned.LearnedDetector.
cane_mask`) or ``net+colour`` (the network's cane pixels that the colour mask also
calls cane: their intersection). Whatever the source, the stereo,
the push to the centre line and the curve fit that follow are the same
(:mod:`softarm.perception.canes`).

The choice is one per process, as the berry detector's is
(:mod:`softarm.perception.detector.choice`): set from ``[perception] canes`` of hw.toml
or the simulator's ``--cane-source``; a :class:`~softarm.perception.canes.CaneSettings`
whose ``source`` is given overrides it for its own calls.

The network's mask is its cane probability over ½, as it is: no width band-pass as the
colour mask has (the 3×3 opening there is what drops a cane under 3 px wide). Taking
out its parts 11 px wide or more, as the colour mask does, was tried on the tuning
seeds 311000–311003 (sun, dusk and the bush): it cost 0.08 of the coverage in sun
(0.51 → 0.44) for 0.04 of precision (0.96 → 1.00), and changed nothing elsewhere; a
threshold of 0.3 lost half the coverage in the row.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softarm.errors import ParameterError
from softarm.perception.cane_pixels import CaneLook, cane_mask

__all__ = [
    "CANE_SOURCES",
    "DEFAULT_CANE_SOURCE",
    "candidate_masks",
    "check_cane_source",
    "current_cane_source",
    "source_mask",
    "use_cane_source",
]

#: The cane-pixel sources to choose from.
CANE_SOURCES = ("colour", "net", "net+colour")
#: The harvest's cane source unless told otherwise (docs/perception.md, "Which cane
#: pixels").
DEFAULT_CANE_SOURCE = "colour"

BoolImage = npt.NDArray[np.bool_]
_chosen = DEFAULT_CANE_SOURCE


def check_cane_source(name: object, argument: str = "cane_source") -> str:
    """``name`` when it is one of CANE_SOURCES.

    Raises:
        ParameterError: it is not, named as ``argument``.
    """
    if not isinstance(name, str) or name not in CANE_SOURCES:
        raise ParameterError(f"{argument} must be one of {', '.join(CANE_SOURCES)}, got {name!r}")
    return name


def use_cane_source(name: str) -> None:
    """Make ``name`` the cane source of this process (the network's weights read now,
    so that a broken file fails at set-up, not in the middle of a harvest).

    Raises:
        ParameterError: ``name`` is not one of CANE_SOURCES.
        VisionError: the shipped weights are missing or broken.
    """
    global _chosen
    check_cane_source(name)
    if name != "colour":
        from softarm.perception.detector.learned import default_detector

        default_detector()
    _chosen = name


def current_cane_source() -> str:
    """The name of this process's cane source."""
    return _chosen


def source_mask(bgr: npt.NDArray[np.uint8], look: CaneLook, source: str | None = None) -> BoolImage:
    """The cane pixels of a BGR image by ``source`` (None: this process's choice).

    Raises:
        ParameterError: ``source`` is not one of CANE_SOURCES.
        VisionError: the network is wanted and its weights are missing or broken.
    """
    name = _chosen if source is None else check_cane_source(source, "source")
    if name == "colour":
        return cane_mask(bgr, look)
    net = net_mask(bgr)
    return net & cane_mask(bgr, look) if name == "net+colour" else net


def net_mask(bgr: npt.NDArray[np.uint8]) -> BoolImage:
    """The shipped network's cane pixels of a BGR image (see the module docstring)."""
    from softarm.perception.detector.learned import cane_pixels

    result: BoolImage = cane_pixels(bgr) > 0
    return result


def candidate_masks(bgr: npt.NDArray[np.uint8], look: CaneLook) -> dict[str, BoolImage]:
    """Every candidate's cane pixels of one image, the network run once: the sources of
    CANE_SOURCES and ``net|colour``, the union (measured against the intersection,
    ``net+colour``, and not offered: :mod:`softarm.experiments.cane_sources`)."""
    colour = cane_mask(bgr, look)
    net = net_mask(bgr)
    return {"colour": colour, "net": net, "net+colour": net & colour, "net|colour": net | colour}
