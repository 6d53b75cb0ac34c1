"""The one writer of output files: a temporary file in the same folder, fsync'd, then
renamed over the target.

A file written in place is lost when the write fails half-way: a full disk or a
file-size limit (``ulimit -f``) leaves the previous ``id.json`` truncated. Written aside
and renamed, the target is either the previous file or the complete new one, never a
mix; a failure removes the temporary file and is one :class:`~softarm.errors.OutputError`
line naming the file. Only regular files are replaced: renaming over ``/dev/full`` or a
FIFO would replace the device node itself.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import stat
from collections.abc import Iterator
from pathlib import Path

from softarm.errors import OutputError

__all__ = ["atomic_path", "check_target", "output_error", "write_text"]


def output_error(path: str | Path, what: str, exc: OSError) -> OutputError:
    """The one-line error of a failed write of ``path``."""
    return OutputError(f"cannot write {what} {str(path)!r}: {exc.strerror or exc}")


def check_target(path: str | Path, what: str) -> Path:
    """``path`` with symbolic links resolved (the rename replaces the file a link points
    to, not the link), refused when it exists and is not a regular file."""
    target = Path(os.path.realpath(path))
    try:
        mode = os.stat(target).st_mode
    except FileNotFoundError:
        return target
    except OSError as exc:
        raise output_error(path, what, exc) from None
    if not stat.S_ISREG(mode):
        kind = "a directory" if stat.S_ISDIR(mode) else "not a regular file"
        raise OutputError(f"cannot write {what} {str(path)!r}: it is {kind}")
    return target


def _temporary_name(target: Path) -> Path:
    # Hidden, unique, and with the target's suffix (cv2.FileStorage picks the format by it).
    tag = f"{os.getpid()}.{secrets.token_hex(4)}"
    return target.with_name(f".{target.stem}.{tag}.tmp{target.suffix}")


def _create(tmp: Path, target: Path) -> int:
    """A new file for writing; it takes the target's permissions when there is one, else
    the usual 0o666 less the umask (as ``open(path, "w")`` would)."""
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o666)
    with contextlib.suppress(FileNotFoundError):
        os.fchmod(fd, stat.S_IMODE(os.stat(target).st_mode))
    return fd


def _sync_folder(folder: Path) -> None:
    """fsync the folder, so the rename itself survives a power cut."""
    with contextlib.suppress(OSError):  # some file systems cannot sync a directory
        fd = os.open(folder, os.O_RDONLY | os.O_CLOEXEC)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _discard(tmp: Path) -> None:
    with contextlib.suppress(OSError):
        tmp.unlink()


def _replace(tmp: Path, target: Path) -> None:
    """fsync ``tmp``'s data, then rename it over ``target``."""
    fd = os.open(tmp, os.O_RDONLY | os.O_CLOEXEC)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
    os.replace(tmp, target)
    _sync_folder(target.parent)


def write_text(path: str | Path, text: str, what: str = "output file") -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically; ``what`` names it in errors."""
    with atomic_path(path, what) as tmp, open(tmp, "w", encoding="utf-8") as f:
        f.write(text)


@contextlib.contextmanager
def atomic_path(path: str | Path, what: str = "output file") -> Iterator[Path]:
    """A temporary path beside ``path`` for a writer that needs a file name (OpenCV, a
    recording); once the block ends without an error it is fsync'd and renamed over
    ``path``. On any error the temporary file is removed; an ``OSError`` becomes one
    :class:`OutputError` line and the previous ``path`` is left as it was. Missing
    folders of ``path`` are created (every output of softarm, file or folder, does so)."""
    target = check_target(path, what)
    tmp = _temporary_name(target)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        os.close(_create(tmp, target))
        yield tmp
        _replace(tmp, target)
    except OutputError:
        _discard(tmp)
        raise
    except OSError as exc:
        _discard(tmp)
        raise output_error(path, what, exc) from None
    except BaseException:
        _discard(tmp)
        raise
