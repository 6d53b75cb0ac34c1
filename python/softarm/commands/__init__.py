"""Subcommands of the ``softarm`` command line, one module each."""
