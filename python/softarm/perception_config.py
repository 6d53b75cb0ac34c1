"""The ``[perception]`` table of hw.toml: where C1's stereo images come from and how
they are calibrated, for the markerless harvest on the hardware (docs/hardware.md).

``stereo = "zed2"`` is one side-by-side USB video device (``device``, an index or a
path; the ZED2 without its SDK), split into its halves; ``stereo = "pair"`` is two
OpenCV devices (``left``, ``right``). ``calibration`` is a ``stereo.yml`` written by
``softarm camera calibrate`` (resolved against the config file's folder); ``berries``
is ``"markerless"`` (found by perception, the default) or ``"tags"`` (ArUco tags);
``survey`` (true by default) takes C2 to pairs of views of the bush before the first
berry, to complete the canes C1 fits (:mod:`softarm.harvest.runs.cane_survey`); ``detector``
is the berry detector, ``"colour"`` (the default), ``"net"`` or ``"net+colour"``
(:mod:`softarm.perception.detector.choice`); ``canes`` is where the cane pixels come
from, the same three names (:mod:`softarm.perception.cane_source`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

from softarm.config_table import TomlTable, resolve
from softarm.errors import ConfigError

__all__ = [
    "BERRY_MODES",
    "CANE_SOURCES",
    "DETECTORS",
    "STEREO_SOURCES",
    "BerryMode",
    "PerceptionConfig",
    "StereoSource",
    "check_perception",
    "parse_perception",
]


class StereoSource(StrEnum):
    """C1's stereo source: one side-by-side device (a ZED2), or two devices."""

    ZED2 = "zed2"
    PAIR = "pair"


class BerryMode(StrEnum):
    """How the berries are found: by perception, or by their ArUco tags."""

    MARKERLESS = "markerless"
    TAGS = "tags"


#: The stereo sources' names.
STEREO_SOURCES = tuple(s.value for s in StereoSource)
#: The berry modes' names.
BERRY_MODES = tuple(m.value for m in BerryMode)
#: The berry detectors (softarm.perception.detector.choice.DETECTORS, listed here so
#: that reading a config imports no perception).
DETECTORS = ("colour", "net", "net+colour")
#: The cane-pixel sources (softarm.perception.cane_source.CANE_SOURCES, listed here for
#: the same reason).
CANE_SOURCES = ("colour", "net", "net+colour")


@dataclass(frozen=True)
class PerceptionConfig:
    """``[perception]``: the stereo source, its calibration file, the berry mode,
    whether C2 surveys the canes, the berry detector and the cane pixels' source;
    ``folder`` is the config
    file's, which paths resolve against."""

    stereo: StereoSource = StereoSource.ZED2
    calibration: str = "stereo.yml"
    device: int | str | None = None
    left: int | str | None = None
    right: int | str | None = None
    berries: BerryMode = BerryMode.MARKERLESS
    survey: bool = True
    detector: str = "colour"
    canes: str = "colour"
    folder: str | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        # Names given as strings (Python callers) become the enums the rigs compare.
        object.__setattr__(self, "stereo", StereoSource(self.stereo))
        object.__setattr__(self, "berries", BerryMode(self.berries))

    @property
    def calibration_path(self) -> str:
        """The ``stereo.yml``, resolved against the config file's folder."""
        return resolve(self.calibration, self.folder)

    def devices(self) -> tuple[int | str, ...]:
        """The OpenCV sources: (device,) for a ZED2, (left, right) for a pair; a
        relative file name resolved against the config file's folder."""
        raw = (self.device,) if self.stereo is StereoSource.ZED2 else (self.left, self.right)
        return tuple(_device(d, self.folder) for d in raw if d is not None)


def _device(source: int | str, folder: str | None) -> int | str:
    if isinstance(source, int) or "://" in source or "!" in source:
        return source
    return resolve(source, folder)


def parse_perception(t: TomlTable) -> PerceptionConfig:
    """``[perception]`` checked key by key; a key not given takes its default (an empty
    table is the ZED2 on device 0 with ``stereo.yml``, not no table)."""
    stereo = StereoSource(_choice(t, "stereo", STEREO_SOURCES, "zed2"))
    calibration = t.get("calibration", "stereo.yml")
    if not isinstance(calibration, str) or not calibration:
        raise t.error("calibration", "must be a path string (a stereo.yml)")
    wanted = ("device",) if stereo is StereoSource.ZED2 else ("left", "right")
    unwanted = ("left", "right") if stereo is StereoSource.ZED2 else ("device",)
    for name in unwanted:
        if name in t.data:
            raise t.error(name, f"is not a key of stereo = {stereo.value!r} (it takes {wanted})")
    sources = {name: _source(t, name, 0 if name == "device" else None) for name in wanted}
    eyes = [_device(sources[name], t.folder) for name in wanted]
    if len(eyes) == 2 and eyes[0] == eyes[1]:
        raise t.error("right", "must be another device than perception.left (one per eye)")
    berries = BerryMode(_choice(t, "berries", BERRY_MODES, "markerless"))
    survey = t.get("survey", True)
    if not isinstance(survey, bool):
        raise t.error("survey", "must be true or false")
    detector = _choice(t, "detector", DETECTORS, "colour")
    canes = _choice(t, "canes", CANE_SOURCES, "colour")
    config = PerceptionConfig(
        stereo, calibration, berries=berries, survey=survey, detector=detector,
        canes=canes, folder=t.folder, **sources,
    )  # fmt: skip
    t.done()
    return config


def _choice(t: TomlTable, name: str, allowed: tuple[str, ...], default: str) -> str:
    value: Any = t.get(name, default)
    if value not in allowed:
        raise t.error(name, f"must be one of {', '.join(repr(a) for a in allowed)}")
    return str(value)


def _source(t: TomlTable, name: str, default: int | None) -> int | str:
    from softarm.hardware.camera import source_problem

    value: Any = t.get(name, ... if default is None else default)
    problem = source_problem(value)
    if problem is not None:
        raise t.error(name, problem)
    source: int | str = value
    return source


def check_perception(perception: PerceptionConfig | None) -> None:
    """Open and parse the calibration file (``config check``).

    Raises:
        ConfigError: it is missing or broken, named as ``perception.calibration``.
    """
    if perception is None:
        return
    from softarm.vision.stereo_files import read_stereo

    try:
        read_stereo(perception.calibration_path)
    except ConfigError as exc:
        raise ConfigError(f"perception.calibration: {exc}") from None
