"""Configuration of a softarm installation in one TOML file: geometry, gains, camera
calibration and marker geometry, pressure channels, the serial port and the harvest's
tuning.

``load_config(path)`` parses and validates (every error is a
:class:`~softarm.errors.ConfigError` naming the key path, e.g. ``arm.sections[1].radius``);
``save_config(config, path)`` writes it back; ``default_config()`` is the blackberry arm
shipped as ``softarm/data/blackberry.toml``. Units are SI, except the pressure channels,
which are the hardware boundary (psi, volts). Unknown keys are errors: a typo must not
silently fall back to a default.

Every path the file names (a camera ``file``, a camera ``source`` that is a file, the
``[plant_model]`` ``file``) resolves against the file's own folder, not the working
directory; the camera intrinsics come from a ``file`` or from inline ``matrix`` and
``distortion``, and giving both is an error.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field, fields
from importlib import resources
from pathlib import Path
from typing import Any

from softarm._core import Gains
from softarm.config_table import TomlTable, resolve
from softarm.errors import ConfigError, ParameterError
from softarm.files import parse_toml, read_text, write_text
from softarm.hardware.camera import source_problem
from softarm.hardware.limits import (
    BAUD,
    FULL_SCALE_PSI,
    MAX_RATE_PSI_PER_S,
    RETRIES,
    SERIAL_TIMEOUT_S,
    STARTUP_DELAY_S,
    WATCHDOG_TIMEOUT_S,
)
from softarm.harvest_config import HarvestConfig
from softarm.identified_plant import IdentifiedPlant
from softarm.perception_config import PerceptionConfig, parse_perception
from softarm.units import MAX_PSI, METRES_PER_PSI, PA_PER_PSI

__all__ = [
    "ArmConfig",
    "CalibrationConfig",
    "CameraConfig",
    "ChannelsConfig",
    "Config",
    "GainsConfig",
    "HarvestConfig",
    "PerceptionConfig",
    "PlantModelConfig",
    "SectionConfig",
    "SerialConfig",
    "default_config",
    "dump_config",
    "load_config",
    "parse_config",
    "save_config",
]

Matrix = tuple[tuple[float, ...], ...]


@dataclass(frozen=True)
class SectionConfig:
    """One constant-curvature section (fields as ``softarm.Section``; metres, radians)."""

    radius: float
    rest_length: float
    lower: float
    upper: float
    offset: float
    twist: float


@dataclass(frozen=True)
class ArmConfig:
    """The arm: its sections, proximal first."""

    sections: tuple[SectionConfig, ...]


@dataclass(frozen=True)
class GainsConfig:
    """Resolver gain keywords (passed to ``softarm.Gains(**values)``); :func:`load_config`
    checks each against ``softarm.Gains`` and names the bad one (``gains.<key>``)."""

    values: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class CameraConfig:
    """One camera: its OpenCV source and intrinsics, inline or in a file, never both.

    ``file`` and a ``source`` that names a file are kept as written; ``folder`` is the
    config file's folder, which :attr:`path` and :attr:`device` resolve them against
    (it is not written back, and two configs differing only in it are equal).
    """

    source: int | str = 0
    matrix: Matrix | None = None
    distortion: tuple[float, ...] | None = None
    file: str | None = None
    folder: str | None = field(default=None, compare=False, repr=False)

    @property
    def path(self) -> str | None:
        """The camera file, resolved against the config file's folder."""
        return None if self.file is None else resolve(self.file, self.folder)

    @property
    def device(self) -> int | str:
        """The OpenCV source; a relative file name (not a URL or a GStreamer pipeline)
        resolved against the config file's folder."""
        if isinstance(self.source, int) or "://" in self.source or "!" in self.source:
            return self.source
        return resolve(self.source, self.folder)


@dataclass(frozen=True)
class CalibrationConfig:
    """Cameras, extrinsics and marker geometry: ``T_C1_base`` (base in the eye-to-hand
    camera C1) and ``T_C2_EE`` (end effector in the eye-in-hand camera C2), 4×4, or
    ``None`` if unknown; ``T_EE_cube``, the marker cube in the end-effector frame (eq. 22;
    as built: 5 cm behind the gripper frame), ``berry_tag``, the side (m) of the
    berry ArUco tags (the paper's 12 mm, section III-D), and ``T_base_tag``, the base
    tag on its bracket in the base frame (None: not known), which the cane fit leaves
    out as the rig's own (:mod:`softarm.perception.self_filter`); ``marker_body``, the
    body carrying the tracked tags (:data:`softarm.vision.marker_body.MARKER_BODIES`:
    the paper's ``"cube"`` or the ``"frustum"``, docs/hardware.md), its tags of side
    ``marker_length`` (m)."""

    c1: CameraConfig = field(default_factory=CameraConfig)
    c2: CameraConfig = field(default_factory=lambda: CameraConfig(source=1))
    T_C1_base: Matrix | None = None
    T_C2_EE: Matrix | None = None
    T_EE_cube: Matrix = ((1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, -0.05),
                         (0.0, 0.0, 0.0, 1.0))  # fmt: skip
    berry_tag: float = 0.012
    T_base_tag: Matrix | None = None
    marker_body: str = "cube"
    marker_length: float = 0.08


@dataclass(frozen=True)
class ChannelsConfig:
    """Pressure channels: DAQ analog outputs in actuator order and the safety limits."""

    names: tuple[str, ...] = tuple(f"Dev1/ao{i}" for i in range(9))
    voltage_range: tuple[float, float] = (0.0, 5.0)
    full_scale_psi: float = 0.5e6 / PA_PER_PSI  # ITV1031: 0.5 MPa (assumed)
    p_max: float = MAX_PSI
    max_rate_psi_per_s: float = 100.0
    watchdog_timeout_s: float = 0.5
    metres_per_psi: float = METRES_PER_PSI


@dataclass(frozen=True)
class SerialConfig:
    """The Arduino's serial port."""

    port: str = "/dev/ttyACM0"
    baud: int = 115200
    timeout_s: float = 0.5
    retries: int = 2
    startup_delay_s: float = 2.0


@dataclass(frozen=True)
class PlantModelConfig:
    """The plant ``softarm identify`` measured (``[plant_model]``): either ``file``, an
    ``id.json`` path relative to the config file, or the per-channel lists inline (the
    keys of ``id.json``; see :mod:`softarm.identified_plant`)."""

    file: str | None = None
    tau_s: tuple[float, ...] | None = None
    metres_per_psi: tuple[float, ...] | None = None
    hysteresis_psi: tuple[float, ...] | None = None
    dead_time_s: tuple[float, ...] | None = None
    control_period_s: float | None = None


@dataclass(frozen=True)
class Config:
    """A whole installation."""

    arm: ArmConfig
    gains: GainsConfig = field(default_factory=GainsConfig)
    calibration: CalibrationConfig = field(default_factory=CalibrationConfig)
    channels: ChannelsConfig = field(default_factory=ChannelsConfig)
    serial: SerialConfig = field(default_factory=SerialConfig)
    plant_model: PlantModelConfig | None = None
    #: ``[harvest]``: the state machine's tuning (:class:`softarm.harvest.HarvestConfig`).
    harvest: HarvestConfig = field(default_factory=HarvestConfig)
    #: ``[perception]``: C1's stereo source for the markerless harvest (None: the tags).
    perception: PerceptionConfig | None = None


def load_config(path: str | Path) -> Config:
    """Read and validate a TOML configuration file.

    Raises:
        ConfigError: the file is missing, not TOML, or a value is invalid (the message
            names the key path and the value).
    """
    text = read_text(path, "config file")
    return parse_config(text, source=str(path), folder=Path(path).parent)


def parse_config(text: str, source: str = "<string>", folder: str | Path | None = None) -> Config:
    """Validate TOML text (see :func:`load_config`); the paths it names resolve against
    ``folder`` (None: as written, against the working directory)."""
    root = TomlTable(parse_toml(text, source), "", source)
    root.folder = None if folder is None else str(folder)
    return _build(root)


def default_config() -> Config:
    """The shipped blackberry-arm configuration (``softarm/data/blackberry.toml``)."""
    text = resources.files("softarm.data").joinpath("blackberry.toml").read_text("utf-8")
    return parse_config(text, source="softarm/data/blackberry.toml")


def save_config(config: Config, path: str | Path) -> None:
    """Write ``config`` as TOML that :func:`load_config` reads back to an equal Config."""
    write_text(path, dump_config(config), "config file")


# --- validation -------------------------------------------------------------------------


def _section(t: TomlTable) -> SectionConfig:
    s = SectionConfig(
        radius=t.number("radius", positive=True),
        rest_length=t.number("rest_length", positive=True),
        lower=t.number("lower"),
        upper=t.number("upper"),
        offset=t.number("offset", lo=0.0),
        twist=t.number("twist"),
    )
    if s.lower >= s.upper:
        raise t.error("upper", f"must be greater than lower = {s.lower!r}")
    t.done()
    return s


def _matrix(t: TomlTable, name: str, rows: int, cols: int | None = None) -> Any:
    value = t.get(name, None)
    if value is None:
        return None
    shape_ok = isinstance(value, list) and (
        len(value) == rows if cols is not None else len(value) > 0
    )
    if cols is not None:
        shape_ok = shape_ok and all(isinstance(r, list) and len(r) == cols for r in value)
    flat = [x for r in value for x in r] if cols is not None and shape_ok else value
    if not shape_ok or not all(
        isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x) for x in flat
    ):
        shape = f"{rows}x{cols}" if cols is not None else "non-empty"
        raise t.error(name, f"must be a {shape} array of finite numbers")
    if cols is None:
        return tuple(float(x) for x in value)
    return tuple(tuple(float(x) for x in r) for r in value)


def _pose(t: TomlTable, name: str) -> Matrix | None:
    m: Matrix | None = _matrix(t, name, 4, 4)
    if m is None:
        return None
    if m[3] != (0.0, 0.0, 0.0, 1.0):
        raise t.error(name, "must have last row [0, 0, 0, 1]")
    r = [row[:3] for row in m[:3]]
    for i in range(3):
        for j in range(3):
            dot = sum(r[k][i] * r[k][j] for k in range(3))
            if abs(dot - (1.0 if i == j else 0.0)) > 1e-6:
                raise t.error(name, "must have an orthonormal rotation block")
    det = (
        r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
        - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
        + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0])
    )
    if det < 0.0:
        raise t.error(name, "must have a rotation block with determinant +1")
    return m


def _camera(t: TomlTable, default_source: int) -> CameraConfig:
    source = t.get("source", default_source)
    if source_problem(source) is not None:
        raise t.error("source", str(source_problem(source)))
    file = t.get("file", None)
    if file is not None and (not isinstance(file, str) or not file):
        raise t.error("file", "must be a path string")
    matrix, distortion = _matrix(t, "matrix", 3, 3), _matrix(t, "distortion", 0)
    inline = [name for name in ("matrix", "distortion") if name in t.data]
    if file is not None and inline:
        raise ConfigError(
            f"{t.source}: {t.key(inline[0])} and {t.key('file')} are both given: "
            "the intrinsics come from one place, the file or the inline values"
        )
    cam = CameraConfig(source, matrix, distortion, file, t.folder)
    t.done()
    return cam


def _build(root: TomlTable) -> Config:
    """The whole configuration, one table after the other in a fixed order (the first
    bad key in that order is the one reported); the channels are checked against the
    arm's elongation ranges, so they come after it."""
    arm = _arm(root.table("arm", required=True))
    gains = GainsConfig(_gains(root.table("gains")))
    calibration = _calibration(root.table("calibration"))
    channels = _channels(root.table("channels"), arm)
    serial = _serial(root.table("serial"))
    plant_model = _plant_model(root.table("plant_model"), len(channels.names))
    harvest = _harvest(root.table("harvest"))
    perception = parse_perception(root.table("perception")) if "perception" in root.data else None
    root.done()
    return Config(arm, gains, calibration, channels, serial, plant_model, harvest, perception)


def _arm(t: TomlTable) -> ArmConfig:
    """``[arm]``: its ``sections``, a non-empty array of tables, each named by its index
    in the errors (``arm.sections[1].radius``)."""
    raw = t.get("sections")
    if not isinstance(raw, list) or not raw or not all(isinstance(s, dict) for s in raw):
        raise t.error("sections", "must be a non-empty array of tables")
    key = t.key("sections")
    arm = ArmConfig(
        tuple(_section(TomlTable(s, f"{key}[{i}]", t.source)) for i, s in enumerate(raw))
    )
    t.done()
    return arm


def _calibration(t: TomlTable) -> CalibrationConfig:
    """``[calibration]``: the two cameras, the hand-eye poses, the cube mount and the
    berry tag's size; a key not given keeps the default of :class:`CalibrationConfig`."""
    c1_t, c2_t = t.table("c1"), t.table("c2")
    d = CalibrationConfig()
    calibration = CalibrationConfig(
        _camera(c1_t, 0),
        _camera(c2_t, 1),
        _pose(t, "T_C1_base"),
        _pose(t, "T_C2_EE"),
        _pose(t, "T_EE_cube") or d.T_EE_cube,
        t.number("berry_tag", d.berry_tag, positive=True),
        _pose(t, "T_base_tag"),
        _marker_body(t, d.marker_body),
        t.number("marker_length", d.marker_length, positive=True),
    )
    t.done()
    return calibration


#: The marker bodies' names (softarm.vision.marker_body.MARKER_BODIES, listed here so that
#: reading a config imports neither the vision layer nor OpenCV; a test keeps them equal).
MARKER_BODY_NAMES = ("cube", "frustum")


def _marker_body(t: TomlTable, default: str) -> str:
    """``marker_body``: one of the bodies softarm.vision.marker_body names."""
    body = t.get("marker_body", default)
    if body == default:
        return default
    if body not in MARKER_BODY_NAMES:
        raise t.error("marker_body", f"must be one of {', '.join(MARKER_BODY_NAMES)}")
    return str(body)


def _channel_names(t: TomlTable, d: ChannelsConfig, arm: ArmConfig) -> tuple[str, ...]:
    """``channels.names``: distinct strings, three per section of ``arm``."""
    names = t.get("names", list(d.names))
    if not isinstance(names, list) or not all(isinstance(n, str) and n for n in names):
        raise t.error("names", "must be an array of channel-name strings")
    if len(names) != 3 * len(arm.sections):
        raise t.error("names", f"must name {3 * len(arm.sections)} channels (3 per section)")
    if len(set(names)) != len(names):
        raise t.error("names", "must not repeat a channel")
    return tuple(names)


def _channels(t: TomlTable, arm: ArmConfig) -> ChannelsConfig:
    """``[channels]``: the analog outputs and the pressure map, each safety setting inside
    the range the drivers accept (``softarm.hardware.limits``), and every section's
    elongation range within what ``p_max`` can produce."""
    d = ChannelsConfig()
    names = _channel_names(t, d, arm)
    vr = _matrix(t, "voltage_range", 2) or d.voltage_range
    if len(vr) != 2 or not vr[0] < vr[1]:
        raise t.error("voltage_range", "must be [v_min, v_max] with v_min < v_max")
    channels = ChannelsConfig(
        names=names,
        voltage_range=(vr[0], vr[1]),
        full_scale_psi=t.within(
            "full_scale_psi",
            t.number("full_scale_psi", d.full_scale_psi, positive=True),
            FULL_SCALE_PSI,
        ),
        p_max=t.number("p_max", d.p_max, positive=True),
        max_rate_psi_per_s=t.within(
            "max_rate_psi_per_s",
            t.number("max_rate_psi_per_s", d.max_rate_psi_per_s, positive=True),
            MAX_RATE_PSI_PER_S,
        ),
        watchdog_timeout_s=t.within(
            "watchdog_timeout_s",
            t.number("watchdog_timeout_s", d.watchdog_timeout_s, positive=True),
            WATCHDOG_TIMEOUT_S,
        ),
        metres_per_psi=t.number("metres_per_psi", d.metres_per_psi, positive=True),
    )
    if channels.p_max > channels.full_scale_psi:
        raise t.error("p_max", f"must not exceed full_scale_psi = {channels.full_scale_psi!r}")
    reach = channels.p_max * channels.metres_per_psi
    for i, s in enumerate(arm.sections):
        if s.upper > reach * (1.0 + 1e-9) or s.lower < 0.0:
            raise ConfigError(
                f"{t.source}: arm.sections[{i}] elongation range [{s.lower!r}, {s.upper!r}]"
                f" m is outside what channels.p_max = {channels.p_max!r} psi can produce "
                f"([0, {reach!r}] m at {channels.metres_per_psi!r} m/psi)"
            )
    t.done()
    return channels


def _serial(t: TomlTable) -> SerialConfig:
    """``[serial]``: the Arduino's port and link settings, each inside the range the
    driver accepts."""
    d = SerialConfig()
    port = t.get("port", d.port)
    if not isinstance(port, str) or not port:
        raise t.error("port", "must be a non-empty string")
    baud, retries = t.get("baud", d.baud), t.get("retries", d.retries)
    if isinstance(baud, bool) or not isinstance(baud, int) or baud <= 0:
        raise t.error("baud", "must be a positive integer")
    if isinstance(retries, bool) or not isinstance(retries, int) or retries < 0:
        raise t.error("retries", "must be a non-negative integer")
    serial = SerialConfig(
        port,
        t.within("baud", baud, BAUD),
        t.within("timeout_s", t.number("timeout_s", d.timeout_s, positive=True), SERIAL_TIMEOUT_S),
        t.within("retries", retries, RETRIES),
        t.within(
            "startup_delay_s",
            t.number("startup_delay_s", d.startup_delay_s, lo=0.0),
            STARTUP_DELAY_S,
        ),
    )
    t.done()
    return serial


def _harvest(t: TomlTable) -> HarvestConfig:
    """``[harvest]``: fields of :class:`HarvestConfig`, each checked on its own so that
    the error names ``harvest.<key>``; the keys not given keep their defaults."""
    defaults = HarvestConfig()
    names = {f.name for f in fields(HarvestConfig)}
    values: dict[str, Any] = {}
    for name, value in t.data.items():
        if name not in names:
            raise ConfigError(
                f"{t.source}: unknown key {t.key(name)!r} (a softarm.harvest.HarvestConfig "
                f"field: {', '.join(sorted(names))})"
            )
        t.used.add(name)
        if isinstance(value, list):  # approach: TOML has arrays, the dataclass a tuple
            value = tuple(float(x) if isinstance(x, int) and not isinstance(x, bool) else x
                          for x in value)  # fmt: skip
        is_number = isinstance(value, int | float) and not isinstance(value, bool)
        if isinstance(getattr(defaults, name), float) and is_number:
            value = float(value)
        try:
            HarvestConfig(**{name: value})
        except ParameterError as exc:
            message = str(exc)
            message = message[len(name) :].lstrip() if message.startswith(name) else message
            raise ConfigError(f"{t.source}: {t.key(name)} {message}") from None
        values[name] = value
    t.done()
    return HarvestConfig(**values)


#: Every keyword of ``softarm.Gains`` (its fields, as ``Gains.as_dict`` lists them).
GAIN_KEYS: tuple[str, ...] = tuple(Gains().as_dict())


def _gains(t: TomlTable) -> dict[str, Any]:
    """``[gains]``: each key a ``softarm.Gains`` keyword whose value the resolver takes,
    checked here so that the error names ``gains.<key>`` (not only when a rig is built)."""
    for name, value in t.data.items():
        t.used.add(name)
        items = value if isinstance(value, list) else [value]
        if not all(isinstance(x, int | float | str) for x in items) or (
            any(isinstance(x, float) and not math.isfinite(x) for x in items)
        ):
            raise t.error(name, "must be a finite number, bool, string or a list of them")
        if name not in GAIN_KEYS:
            raise ConfigError(
                f"{t.source}: unknown key {t.key(name)!r} (a softarm.Gains keyword: "
                f"{', '.join(GAIN_KEYS)})"
            )
        try:
            Gains(**{name: value})
        except (ValueError, TypeError) as exc:
            raise t.error(name, f"is refused by softarm.Gains ({exc})") from None
    try:  # the keys together (a constraint between two gains)
        Gains(**t.data)
    except (ValueError, TypeError) as exc:
        raise ConfigError(f"{t.source}: {t.path}: {exc}") from None
    t.done()
    return dict(t.data)


def _plant_model(t: TomlTable, n_channels: int) -> PlantModelConfig | None:
    """``[plant_model]``: a file name, or the identified lists checked as ``id.json``."""
    if not t.data:
        return None
    t.used.update(t.data)
    file = t.data.get("file")
    if file is not None:
        if not isinstance(file, str) or not file:
            raise t.error("file", "must be a path string (an id.json from softarm identify)")
        if len(t.data) > 1:
            others = sorted(set(t.data) - {"file"})
            raise ConfigError(f"{t.source}: {t.key(others[0])}: give either file or the lists")
        return PlantModelConfig(file=file)
    plant = IdentifiedPlant.from_mapping(t.data, where=f"{t.source}: {t.path}")
    if plant.n_channels != n_channels:
        raise ConfigError(
            f"{t.source}: {t.key('tau_s')} has {plant.n_channels} values, "
            f"channels.names has {n_channels}"
        )
    return PlantModelConfig(
        None, plant.tau_s, plant.metres_per_psi, plant.hysteresis_psi, plant.dead_time_s,
        plant.control_period_s if "control_period_s" in t.data else None,
    )  # fmt: skip


# --- writing ----------------------------------------------------------------------------


def _toml(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)  # a JSON string is a valid TOML basic string
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    raise ConfigError(f"cannot write {value!r} ({type(value).__name__}) to TOML")


def _key(name: str) -> str:
    return name if name and all(c.isalnum() or c in "_-" for c in name) else json.dumps(name)


def _lines(values: dict[str, Any]) -> list[str]:
    return [f"{_key(k)} = {_toml(v)}" for k, v in values.items() if v is not None]


def dump_config(config: Config) -> str:
    """The TOML text of ``config`` (what :func:`save_config` writes)."""
    out = ["# softarm configuration (SI units; pressures in psi, voltages in V).", ""]
    for s in config.arm.sections:
        out += ["[[arm.sections]]", *_lines(asdict(s)), ""]
    out += ["[gains]", *_lines(config.gains.values), ""]
    cal = config.calibration
    poses = {"T_C1_base": cal.T_C1_base, "T_C2_EE": cal.T_C2_EE, "T_EE_cube": cal.T_EE_cube}
    tags: dict[str, Any] = {"berry_tag": cal.berry_tag, "T_base_tag": cal.T_base_tag}
    tags |= {"marker_body": cal.marker_body, "marker_length": cal.marker_length}
    out += ["[calibration]", *_lines({**poses, **tags}), ""]
    for name, cam in (("c1", cal.c1), ("c2", cal.c2)):
        written = {k: v for k, v in asdict(cam).items() if k != "folder"}
        out += [f"[calibration.{name}]", *_lines(written), ""]
    out += ["[channels]", *_lines(asdict(config.channels)), ""]
    out += ["[serial]", *_lines(asdict(config.serial)), ""]
    out += ["[harvest]", *_lines(asdict(config.harvest))]
    if config.plant_model is not None:
        out += ["", "[plant_model]", *_lines(asdict(config.plant_model))]
    if config.perception is not None:
        written = {k: v for k, v in asdict(config.perception).items() if k != "folder"}
        out += ["", "[perception]", *_lines(written)]
    return "\n".join(out) + "\n"
