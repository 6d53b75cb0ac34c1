"""Child processes that a test stops with a signal start with SIGINT and SIGTERM at their
defaults: a harness started in the background of a non-interactive shell ignores SIGINT,
and an ignored signal is inherited across exec (Python then installs no Ctrl-C handler),
so the child would never see the Ctrl-C the test sends."""

from __future__ import annotations

import signal


def default_signals() -> None:
    """``preexec_fn`` for ``subprocess``: SIGINT and SIGTERM back to their defaults."""
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, signal.SIG_DFL)
