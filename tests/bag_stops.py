"""A SIGTERM raised while a ROS 2 bag is being written (after ``after`` messages), for the
tests of what a stop then leaves behind (issue 42 item 19)."""

from __future__ import annotations

import os
import signal
from collections.abc import Iterable, Iterator
from typing import Any

import pytest


def sigterm_while_writing_bag(monkeypatch: pytest.MonkeyPatch, after: int) -> None:
    """Make ``softarm.viz.bag.writer`` signal SIGTERM to this process once ``after``
    messages have gone into the bag."""
    from softarm.viz.bag import writer

    write = writer._write

    def stopped_mid_write(w: Any, m: Any, messages: Iterable[Any]) -> Any:
        def stop_after_some(items: Iterable[Any]) -> Iterator[Any]:
            for n, item in enumerate(items):
                if n == after:
                    os.kill(os.getpid(), signal.SIGTERM)
                yield item

        return write(w, m, stop_after_some(messages))

    monkeypatch.setattr(writer, "_write", stopped_mid_write)
