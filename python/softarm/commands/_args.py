"""Argument types and the parser class shared by every ``softarm`` subcommand.

Each validator is an argparse ``type=``: it runs while the command line is parsed, before
any work starts, so a bad value costs nothing and is reported as one line naming the
option (``softarm harvest: error: argument --seed: must be an integer >= 0, got '-5'``)
with exit status 2. Output paths are checked, not created: a run that will fail to save
its report must fail before the run, not after it (a failed check creates nothing).
"""

from __future__ import annotations

import argparse
import difflib
import math
import os
import re
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any, NoReturn, TypeVar

from softarm.errors import SoftarmError

__all__ = [
    "DefaultsFormatter",
    "Parser",
    "RawDefaultsFormatter",
    "add_quiet",
    "config_file",
    "data_file",
    "float_range",
    "image_file",
    "int_range",
    "non_negative_int",
    "output_dir",
    "output_file",
    "positive_int",
]

#: Upper bound of counts typed by a user (berries, repeats, seeds): far beyond any real
#: run, small enough that a typo (an extra zero or ten) cannot allocate the machine away.
MAX_COUNT = 1_000_000
#: Seeds feed ``numpy.random.default_rng``, which takes any non-negative integer; keep
#: them within 63 bits so they also fit every C ``int64`` they may be passed to.
MAX_SEED = 2**63 - 1


_A = TypeVar("_A", bound=argparse.Action)

_COMPLETE_FILE = {"bash": "_shtab_compgen_files", "zsh": "_files", "tcsh": "f"}
_COMPLETE_DIR = {"bash": "_shtab_compgen_dirs", "zsh": "_files -/", "tcsh": "d"}


def _says_nothing(default: object) -> bool:
    # Identity, not ==: a default of 0 (a seed) is worth showing, though 0 == False.
    return default is None or default is False or default is argparse.SUPPRESS


_LITERAL = re.compile(r"``([^`]+)``")
_ROLE = re.compile(r":[a-z]+:`~?([^`]+)`")
_SAYS_DEFAULT = re.compile(r"\(default:?\s+[^)\s]", re.IGNORECASE)  # "(default 80)"


def plain(text: str) -> str:
    """``text`` without reST markup (double backquotes, :role:`x`), for the terminal:
    command docstrings are also help text."""
    return _ROLE.sub(r"\1", _LITERAL.sub(r"\1", text))


class DefaultsFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Shows ``(default: X)`` after every option's help, except where the default says
    nothing (None, False: a flag that is off, an option that is absent) or the help
    already says it; reST markup of descriptions and help is dropped."""

    def _format_text(self, text: str) -> str:
        return super()._format_text(plain(text))

    def _expand_help(self, action: argparse.Action) -> str:
        return plain(super()._expand_help(action))

    def _get_help_string(self, action: argparse.Action) -> str | None:
        help_ = action.help or ""
        if _says_nothing(action.default) or "%(default)" in help_ or _SAYS_DEFAULT.search(help_):
            return help_
        if not action.option_strings and action.nargs not in ("?", "*"):
            return help_
        return f"{help_} (default: %(default)s)" if help_ else "(default: %(default)s)"


class RawDefaultsFormatter(DefaultsFormatter, argparse.RawDescriptionHelpFormatter):
    """:class:`DefaultsFormatter` that keeps the description's line breaks (for a
    description with example command lines)."""


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (no usage dump), exit status 2, and
    whose help shows the defaults. Subparsers inherit the class, so commands registered by
    ``sub.add_parser(...)`` behave the same without doing anything."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", DefaultsFormatter)
        if sys.version_info >= (3, 14):  # error() says "did you mean" itself, on every version
            kwargs.setdefault("suggest_on_error", False)
        super().__init__(*args, **kwargs)

    def _add_action(self, action: _A) -> _A:
        # An option with a default but no help text would hide its default from --help.
        if action.help is None and action.option_strings and not _says_nothing(action.default):
            action.help = ""
        # Path options complete file or folder names in `softarm completion` scripts
        # (shtab reads ``action.complete``; the values are shtab.FILE and DIRECTORY).
        if action.type in (output_file, image_file, config_file, data_file):
            action.complete = _COMPLETE_FILE  # type: ignore[attr-defined]
        elif action.type is output_dir:
            action.complete = _COMPLETE_DIR  # type: ignore[attr-defined]
        return super()._add_action(action)

    def parse_known_args(  # type: ignore[override]
        self, args: Any = None, namespace: Any = None
    ) -> tuple[argparse.Namespace, list[str]]:
        # What was typed, for error()'s "did you mean" (a subcommand's parser gets its own).
        self._typed = list(sys.argv[1:] if args is None else args)
        return super().parse_known_args(args, namespace)

    def error(self, message: str) -> NoReturn:
        unknown, near = _misspelt(self, getattr(self, "_typed", []))
        if near is not None:
            # Before "the following arguments are required: COMMAND", which a misspelt
            # --version gets: the typo is the error.
            message = f"unrecognized argument {unknown}; did you mean {near}?"
        elif (choice := _INVALID_CHOICE.search(message)) is not None:
            options = re.findall(r"'([^']*)'", choice["options"])
            near = next(iter(difflib.get_close_matches(choice["typed"], options, n=1)), None)
            message += f"; did you mean {near!r}?" if near else ""
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


_INVALID_CHOICE = re.compile(r"invalid choice: '(?P<typed>[^']*)' \(choose from (?P<options>.*)\)")


def _options_of(parser: argparse.ArgumentParser, typed: list[str]) -> list[str]:
    """The option strings of ``parser`` and of the subcommand named in ``typed``."""
    known = list(parser._option_string_actions)
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            command = next((t for t in typed if t in action.choices), None)
            if command is not None:
                known += _options_of(action.choices[command], typed)
    return known


def _misspelt(parser: argparse.ArgumentParser, typed: list[str]) -> tuple[str, str | None]:
    """The first typed option that no option of ``parser`` (or of its subcommand) starts
    with, and the nearest known one (difflib; argparse's own suggest_on_error covers
    only choices, and only from Python 3.14), or ("", None)."""
    known = _options_of(parser, typed)
    for token in typed:
        name = token.split("=", 1)[0]
        if token == "--":
            break
        if not name.startswith("--") or any(k.startswith(name) for k in known):
            continue
        near = difflib.get_close_matches(name, [k for k in known if k.startswith("--")], n=1)
        return name, near[0] if near else None
    return "", None


def _integer(text: str) -> int:
    try:
        return int(text, 10)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer, got {text!r}") from None


def int_range(lo: int, hi: int) -> Callable[[str], int]:
    """A ``type=`` accepting integers in [lo, hi]."""

    def parse(text: str) -> int:
        value = _integer(text)
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(
                f"must be an integer in [{lo}, {hi}], got {text!r}"
                if hi < MAX_SEED
                else f"must be an integer >= {lo}, got {text!r}"
            )
        return value

    parse.__name__ = f"integer in [{lo}, {hi}]"
    return parse


#: Seeds and other counts that may be zero.
non_negative_int = int_range(0, MAX_SEED)
#: Counts of things to do (berries, repeats): at least one.
positive_int = int_range(1, MAX_COUNT)


def float_range(lo: float, hi: float) -> Callable[[str], float]:
    """A ``type=`` accepting finite numbers in (lo, hi]."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
        if not (math.isfinite(value) and lo < value <= hi):
            raise argparse.ArgumentTypeError(f"must be a number in ({lo:g}, {hi:g}], got {text!r}")
        return value

    parse.__name__ = f"number in ({lo:g}, {hi:g}]"
    return parse


def _writable(folder: Path) -> str | None:
    """None when a file can be created in ``folder``, else why not. A real probe (a
    temporary file, removed at once): ``os.access`` says yes to root even on /proc or a
    read-only mount."""
    try:
        with tempfile.TemporaryFile(dir=folder):
            return None
    except OSError as exc:
        return exc.strerror or str(exc)


def _nearest_existing(path: Path) -> Path:
    for candidate in (path, *path.parents):
        if candidate.exists():
            return candidate
    return Path(".")


def output_file(text: str) -> Path:
    """A ``type=`` for a file the command will write: not a directory, writable itself
    if it exists, in a writable directory or in folders that can be made in one (the
    nearest existing one writable). Nothing is created here: as every output of softarm
    (file or folder), the command creates the missing folders when it writes."""
    path = Path(text)
    if not text or text.endswith(("/", os.sep)) or path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a directory; give a file name")
    parent = _nearest_existing(path.parent)
    if not parent.is_dir():
        raise argparse.ArgumentTypeError(
            f"cannot write {text!r}: {str(parent)!r} is a file, not a folder"
        )
    if path.exists() and not path.is_file():
        raise argparse.ArgumentTypeError(
            f"cannot write {text!r}: not a regular file (a device or FIFO is not replaced)"
        )
    if path.exists() and not os.access(path, os.W_OK):
        raise argparse.ArgumentTypeError(f"cannot write {text!r}: permission denied")
    why = _writable(parent)
    if why is not None:
        raise argparse.ArgumentTypeError(
            f"cannot write {text!r}: folder {str(parent)!r} is not writable ({why})"
        )
    return path


#: Formats matplotlib writes without extra packages, by file-name suffix.
IMAGE_SUFFIXES = frozenset(
    {".png", ".pdf", ".svg", ".svgz", ".eps", ".ps", ".jpg", ".jpeg", ".tif", ".tiff", ".webp"}
)


def image_file(text: str) -> Path:
    """A ``type=`` for a figure the command will save: :func:`output_file` with a suffix
    that names a format matplotlib can write."""
    path = output_file(text)
    if path.suffix.lower() not in IMAGE_SUFFIXES:
        raise argparse.ArgumentTypeError(
            f"{text!r}: unknown image format {path.suffix or '(no suffix)'!r}; "
            f"use one of {', '.join(sorted(IMAGE_SUFFIXES))}"
        )
    return path


def output_dir(text: str) -> Path:
    """A ``type=`` for a folder the command will create or fill: an existing writable
    directory, or a path whose nearest existing ancestor is a writable directory.
    Nothing is created here (the command creates it once the run is under way)."""
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} exists and is not a directory")
    base = _nearest_existing(path)
    if not base.is_dir():
        raise argparse.ArgumentTypeError(
            f"cannot create {text!r}: {str(base)!r} is a file, not a directory"
        )
    why = _writable(base)
    if why is not None:
        raise argparse.ArgumentTypeError(
            f"cannot write into {text!r}: {str(base)!r} is not writable ({why})"
        )
    return path


def config_file(text: str) -> Path:
    """A ``type=`` for a configuration or data file the command will read: a regular file
    of bounded size, UTF-8 without a byte-order mark (the checks of
    :func:`softarm.files.read_text`; a FIFO or ``/dev/zero`` is refused, not read)."""
    from softarm.files import read_text

    try:
        read_text(text, "file")
    except SoftarmError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return Path(text)


def data_file(text: str) -> Path:
    """A ``type=`` for a data file read line by line (a run log, of any length): an
    existing regular file (:func:`softarm.files.open_regular`); its lines are checked
    as they are read."""
    from softarm.files import open_regular

    try:
        open_regular(text, "file").close()
    except SoftarmError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return Path(text)


def add_quiet(parser: argparse.ArgumentParser) -> None:
    """``--quiet``: no progress bar and no per-item lines, only the summary and errors."""
    parser.add_argument(
        "-q", "--quiet", action="store_true", help="print only the summary and errors"
    )
