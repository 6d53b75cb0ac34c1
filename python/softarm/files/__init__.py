"""Every configuration and data file softarm reads or writes goes through this package.

Reading (:mod:`~softarm.files.read`): the path must be a regular file of bounded size,
the bytes UTF-8 and the document TOML or JSON that parses; the parsed document is then
checked for depth and integer range (:mod:`~softarm.files.document`), and each loader
checks its values against declared ranges (:mod:`~softarm.files.ranges`). Every failure
is one :class:`~softarm.errors.ConfigError` line naming the file and the key.

Writing (:mod:`~softarm.files.write`): a temporary file in the same folder, fsync'd and
renamed over the target, so a failed write (full disk, file-size limit) is one
:class:`~softarm.errors.OutputError` line and leaves the previous file intact. A folder
of outputs is written the same way (:mod:`~softarm.files.fresh`): filled aside, then
moved into place.

A leaf: imports nothing of softarm but :mod:`softarm.errors`.
"""

from softarm.files.document import MAX_DEPTH, MAX_INT, check_document
from softarm.files.fresh import FreshFolder
from softarm.files.ranges import Range, integer, number, numbers, shown
from softarm.files.read import (
    MAX_BYTES,
    load_json,
    load_toml,
    open_regular,
    parse_json,
    parse_toml,
    read_text,
)
from softarm.files.write import atomic_path, check_target, output_error, write_text

__all__ = [
    "MAX_BYTES",
    "MAX_DEPTH",
    "MAX_INT",
    "FreshFolder",
    "Range",
    "atomic_path",
    "check_document",
    "check_target",
    "integer",
    "load_json",
    "load_toml",
    "number",
    "numbers",
    "open_regular",
    "output_error",
    "parse_json",
    "parse_toml",
    "read_text",
    "shown",
    "write_text",
]
