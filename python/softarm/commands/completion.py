"""softarm completion SHELL: print a tab-completion script for the shell, generated
from the parser itself by shtab (optional extra ``completion``), so it never lags behind
the commands and options.

    softarm completion bash > ~/.local/share/bash-completion/completions/softarm
    softarm completion zsh > "${fpath[1]}/_softarm"
"""

from __future__ import annotations

import argparse

from softarm.commands._args import RawDefaultsFormatter
from softarm.errors import SoftarmError

SHELLS = ("bash", "zsh", "tcsh", "fish")


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Register the ``completion`` subcommand."""
    p = sub.add_parser(
        "completion",
        help="print a shell completion script (bash, zsh, tcsh, fish)",
        description=__doc__,
        formatter_class=RawDefaultsFormatter,
    )
    p.add_argument("shell", choices=SHELLS, help="the shell to complete in")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Print the script."""
    try:
        import shtab
    except ImportError as exc:
        raise SoftarmError(
            "shell completion needs shtab: pip install 'softarm[completion]' (or shtab)"
        ) from exc
    from softarm.cli import build_parser

    print(shtab.complete(build_parser(), shell=args.shell), end="")
    return 0
