"""The one writer of output folders (a dataset, a recording of frames): a fresh hidden
folder beside the target, filled, then moved into place as a whole.

Written in place, a run stopped half-way over an earlier output leaves a mix: the old
``annotations.json`` describing new images, an old ``frames.json`` beside new frames.
Written aside, the target is either the earlier output or the complete new one; a
failure or a stop removes the fresh folder. An existing target is replaced only when it
is empty or holds an earlier output of the same kind (its ``marker`` file): any other
folder is refused before anything is written, never deleted.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import shutil
from pathlib import Path

from softarm.errors import OutputError

__all__ = ["FreshFolder"]


class FreshFolder:
    """A fresh folder for the output ``target`` (``what`` names it in errors), whose
    earlier outputs hold the file ``marker``. Write into :attr:`path`; :meth:`commit`
    moves it into place, :meth:`discard` removes it. As a context manager: commit when
    the block ends, discard when it raises (a stop too).

    Raises:
        OutputError: the target exists and is not a folder, or is a folder that holds
            other files than an earlier output (it must be empty or hold ``marker``),
            or the fresh folder cannot be made.
    """

    def __init__(self, target: str | Path, what: str, marker: str) -> None:
        self.target = Path(os.path.realpath(target))
        self.what = what
        _check_replaceable(Path(target), self.target, what, marker)
        tag = f"{os.getpid()}.{secrets.token_hex(4)}"
        self.path = self.target.with_name(f".{self.target.name}.{tag}.tmp")
        try:
            self.target.parent.mkdir(parents=True, exist_ok=True)
            self.path.mkdir()
        except OSError as exc:
            raise OutputError(
                f"cannot write {what} {str(target)!r}: {exc.strerror or exc}"
            ) from None
        self._done = False

    def commit(self) -> Path:
        """Move the fresh folder into place (an earlier output there is removed once the
        new one is in place); the target's path."""
        old = self.target.with_name(self.path.name[:-4] + ".old")
        try:
            if self.target.exists():
                os.replace(self.target, old)
            os.replace(self.path, self.target)
        except OSError as exc:
            self.discard()
            raise OutputError(
                f"cannot move {self.what} into {str(self.target)!r}: {exc.strerror or exc}"
            ) from None
        self._done = True
        shutil.rmtree(old, ignore_errors=True)
        return self.target

    def discard(self) -> None:
        """Remove the fresh folder and what it holds (nothing after :meth:`commit`)."""
        if not self._done:
            self._done = True
            shutil.rmtree(self.path, ignore_errors=True)

    def __enter__(self) -> Path:
        return self.path

    def __exit__(self, exc_type: object, exc: object, tb: object) -> None:
        if exc_type is None:
            self.commit()
        else:
            self.discard()


def _check_replaceable(given: Path, target: Path, what: str, marker: str) -> None:
    """Refuse a target that is not a folder, or a folder that is neither empty nor an
    earlier output (it holds ``marker``)."""
    if not target.exists():
        return
    if not target.is_dir():
        raise OutputError(f"cannot write {what} {str(given)!r}: it exists and is not a folder")
    cwd = Path(os.path.realpath(os.getcwd()))
    if cwd == target or target in cwd.parents:  # it would be moved away under us
        raise OutputError(
            f"cannot write {what} {str(given)!r}: it holds the working directory; "
            "give a folder outside it"
        )
    with contextlib.suppress(OSError):
        if (target / marker).is_file() or not any(target.iterdir()):
            return
    raise OutputError(
        f"cannot write {what} {str(given)!r}: the folder holds other files than an "
        f"earlier {what} (no {marker}); give a new or empty folder"
    )
