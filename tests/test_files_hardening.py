"""Issue 26, items 3 and 8: every file softarm reads goes through one bounded reader and
every output through one atomic writer (softarm.files).

The reader's cases run against every loader, so a loader that bypasses it fails here: a
400-digit integer, a 5,000-digit number, 3,000 levels of nesting, bytes that are not
UTF-8, a FIFO, /dev/zero, a directory and a missing file each give one ConfigError line
naming the file (an InputError for a run log), never an OverflowError, ValueError,
RecursionError, UnicodeDecodeError, a hang or an exhausted memory.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from softarm.calibration import Calibration
from softarm.config import load_config
from softarm.errors import ConfigError, InputError, OutputError
from softarm.files import write_text
from softarm.harvest.records.log import read_log
from softarm.identified_plant import load_identified
from softarm.sim.plant_file import load_plant_file
from softarm.sweep import load_gains, load_spec
from softarm.vision.camera_model import CameraModel

#: Every loader, by the kind of document it reads.
TOML_LOADERS: dict[str, Callable[[Path], Any]] = {
    "hw.toml": load_config,
    "plant.toml": load_plant_file,
    "sweep.toml": load_spec,
    "gains.toml": load_gains,
    "model.toml": Calibration.load,
}
JSON_LOADERS: dict[str, Callable[[Path], Any]] = {
    "id.json": load_identified,
    "camera.json": CameraModel.load,
}
ALL_LOADERS = {**TOML_LOADERS, **JSON_LOADERS, "run.jsonl": lambda p: list(read_log(p))}

DEEP = "[" * 3000 + "]" * 3000
TOML_CASES: dict[str, bytes] = {
    "400 digits": ("n = " + "9" * 400 + "\n").encode(),
    "5000 digits": ("n = " + "9" * 5000 + "\n").encode(),
    "3000 levels": ("n = " + DEEP + "\n").encode(),
    "not UTF-8": b"n = '\xff\xfe'\n",
    "byte-order mark": b"\xef\xbb\xbfn = 1\n",
}
JSON_CASES: dict[str, bytes] = {
    "400 digits": ('{"format": 1, "n": ' + "9" * 400 + "}").encode(),
    "5000 digits": ('{"format": 1, "n": ' + "9" * 5000 + "}").encode(),
    "3000 levels": ('{"format": 1, "n": ' + DEEP + "}").encode(),
    "not UTF-8": b'{"format": "\xff"}',
}


def _one_line_naming(exc: BaseException, path: Path) -> None:
    text = str(exc)
    assert "\n" not in text and str(path.name) in text, text


@pytest.mark.parametrize("case", list(TOML_CASES))
@pytest.mark.parametrize("name", list(TOML_LOADERS))
def test_hostile_toml_is_one_config_error(tmp_path: Path, name: str, case: str) -> None:
    path = tmp_path / name
    path.write_bytes(TOML_CASES[case])
    with pytest.raises(ConfigError) as err:
        TOML_LOADERS[name](path)
    _one_line_naming(err.value, path)


@pytest.mark.parametrize("case", list(JSON_CASES))
@pytest.mark.parametrize("name", list(JSON_LOADERS))
def test_hostile_json_is_one_config_error(tmp_path: Path, name: str, case: str) -> None:
    path = tmp_path / name
    path.write_bytes(JSON_CASES[case])
    with pytest.raises(ConfigError) as err:
        JSON_LOADERS[name](path)
    _one_line_naming(err.value, path)


@pytest.mark.parametrize("case", list(JSON_CASES))
def test_hostile_log_line_is_one_input_error_naming_the_line(tmp_path: Path, case: str) -> None:
    path = tmp_path / "run.jsonl"
    path.write_bytes(b'{"kind": "step", "t": 0.0}\n' + JSON_CASES[case] + b"\n")
    with pytest.raises(InputError, match=r"run\.jsonl: line 2") as err:
        list(read_log(path))
    _one_line_naming(err.value, path)


@pytest.fixture
def alarm() -> Iterator[None]:
    """Fail, rather than hang CI, if a read blocks for more than 10 s."""

    def fail(*_: object) -> None:
        raise AssertionError("the read blocked")

    previous = signal.signal(signal.SIGALRM, fail)
    signal.alarm(10)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


def _special(tmp_path: Path, kind: str) -> Path:
    if kind == "fifo":
        os.mkfifo(tmp_path / "fifo")
        return tmp_path / "fifo"
    if kind == "directory":
        return tmp_path
    if kind == "missing":
        return tmp_path / "missing"
    return Path("/dev/zero")


@pytest.mark.parametrize("kind", ["fifo", "/dev/zero", "directory", "missing"])
@pytest.mark.parametrize("name", list(ALL_LOADERS))
def test_a_path_that_is_not_a_regular_file_is_refused_without_reading(
    tmp_path: Path, alarm: None, name: str, kind: str
) -> None:
    path = _special(tmp_path, kind)
    error = InputError if name == "run.jsonl" else ConfigError
    with pytest.raises(error) as err:
        ALL_LOADERS[name](path)
    _one_line_naming(err.value, path)


def cli(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    """``softarm ARGV`` in process: (exit status, stderr)."""
    from softarm import cli as command_line

    try:
        status = command_line.main(argv)
    except SystemExit as exc:  # an argument refused while parsing
        status = int(exc.code or 0)
    return status, capsys.readouterr().err


def test_config_check_on_a_fifo_is_one_line(tmp_path: Path, alarm: None, capsys) -> None:
    os.mkfifo(tmp_path / "hw.toml")
    status, err = cli(["config", "check", str(tmp_path / "hw.toml")], capsys)
    assert status == 2
    assert err.count("\n") == 1 and "not a regular file" in err


def test_a_file_beyond_the_size_bound_is_refused(tmp_path: Path) -> None:
    from softarm.files import read_text

    path = tmp_path / "big.toml"
    path.write_bytes(b"#" * 2049)
    with pytest.raises(ConfigError, match="larger than 2048 bytes"):
        read_text(path, "file", max_bytes=2048)


# --- the writer -----------------------------------------------------------------------


def test_write_to_a_device_is_one_line_and_replaces_nothing() -> None:
    with pytest.raises(OutputError, match="not a regular file") as err:
        write_text("/dev/full", "x")
    assert "\n" not in str(err.value)
    assert Path("/dev/full").is_char_device()


def test_write_under_a_file_is_one_line(tmp_path: Path) -> None:
    (tmp_path / "a_file").write_text("")  # a missing folder is made; one under a file cannot
    with pytest.raises(OutputError, match="a_file"):
        write_text(tmp_path / "a_file" / "missing" / "r.json", "{}")


def test_a_failed_write_leaves_the_previous_file_and_no_temporary(tmp_path: Path) -> None:
    """The issue's repro: under ``ulimit -f 2`` a good id.json was left truncated at
    2,048 bytes. The write now fails with one line and the old file is intact."""
    from softarm.identified_plant import IdentifiedPlant

    plant = IdentifiedPlant((0.1,) * 9, (4.7e-4,) * 9, (1.0,) * 9, (0.0,) * 9)
    path = tmp_path / "id.json"
    plant.save(path)
    before = path.read_bytes()
    script = (
        "import resource, sys\n"
        "from softarm.identified_plant import IdentifiedPlant\n"
        "from softarm.errors import OutputError\n"
        "resource.setrlimit(resource.RLIMIT_FSIZE, (2048, 2048))\n"
        "p = IdentifiedPlant((0.2,) * 9, (4.7e-4,) * 9, (1.0,) * 9, (0.0,) * 9,"
        " metadata={'pad': 'x' * 10000})\n"
        "try:\n    p.save(sys.argv[1])\nexcept OutputError as e:\n    print(e); sys.exit(2)\n"
    )
    run = subprocess.run(
        [sys.executable, "-c", script, str(path)], capture_output=True, text=True, timeout=60
    )
    assert run.returncode == 2, run.stderr
    assert run.stdout.count("\n") == 1 and "id.json" in run.stdout
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["id.json"]


def test_a_write_keeps_the_permissions_of_the_file_it_replaces(tmp_path: Path) -> None:
    path = tmp_path / "hw.toml"
    path.write_text("old")
    path.chmod(0o640)
    write_text(path, "new")
    assert path.read_text() == "new" and (path.stat().st_mode & 0o777) == 0o640


@pytest.mark.parametrize("argv", [["config", "init"], ["calibrate", "--sim", "--out"]])
def test_an_output_on_a_device_fails_before_any_work(argv: list[str], capsys) -> None:
    status, err = cli([*argv, "/dev/full"], capsys)
    assert status == 2
    assert err.count("\n") == 1 and "not a regular file" in err and "Traceback" not in err
