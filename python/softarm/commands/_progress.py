"""Progress output of long commands: a tqdm bar with the elapsed time and ETA on stderr,
and result lines on stdout written through the bar so the two never tear each other.

The bar is drawn only when stderr is a terminal (tqdm's ``disable=None``), so logs and
pipes get the result lines alone; ``quiet`` silences both. tqdm redraws only when an item
completes, and one berry takes seconds: a daemon thread redraws the bar every second so
that the elapsed time keeps moving.
"""

from __future__ import annotations

import sys
import threading
from types import TracebackType

from tqdm import tqdm

__all__ = ["Progress"]


class Progress:
    """``with Progress(total, "harvest", "berry", quiet) as p: ... p.line(text); p.advance()``."""

    def __init__(self, total: int | None, desc: str, unit: str = "it", quiet: bool = False):
        self.quiet = quiet
        self._bar: tqdm | None = None
        self._stop = threading.Event()
        self._ticker: threading.Thread | None = None
        if not quiet:
            self._bar = tqdm(
                total=total,
                desc=desc,
                unit=f" {unit}",
                file=sys.stderr,
                disable=None,
                dynamic_ncols=True,
                leave=False,
                bar_format="{desc}: {n_fmt}/{total_fmt}{unit} |{bar}| "
                "{elapsed} elapsed, ETA {remaining}",
            )
            if not self._bar.disable:
                self._ticker = threading.Thread(target=self._tick, daemon=True)
                self._ticker.start()

    def _tick(self) -> None:
        while not self._stop.wait(1.0):
            bar = self._bar
            if bar is not None:
                bar.refresh()

    def line(self, text: str, stderr: bool = False) -> None:
        """Print a result line above the bar (nothing when quiet); ``stderr``: a note
        that must stay off stdout (a command whose stdout is JSON)."""
        if not self.quiet:
            out = sys.stderr if stderr else sys.stdout
            tqdm.write(text, file=out)
            out.flush()

    def advance(self, n: int = 1) -> None:
        """Count ``n`` more items done."""
        if self._bar is not None:
            self._bar.update(n)

    def describe(self, text: str) -> None:
        """What is running now, shown after the bar."""
        if self._bar is not None:
            self._bar.set_postfix_str(text, refresh=True)

    def close(self) -> None:
        """Remove the bar."""
        self._stop.set()
        if self._ticker is not None:
            self._ticker.join()
            self._ticker = None
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()
