"""Runtime docstrings for the native classes, taken from the type stub ``_core.pyi``.

The stub is the reference documentation of ``softarm._core`` (units, equations, errors);
the compiled classes carry only the one-line summary of their Rust doc comment. So that
``help(softarm.Gains)`` says as much as the stub, each class documented in the stub gets a
docstring that is read from it on first use (no cost at import): the stub's class
docstring, the constructor's signature and a line per documented member. Where the stub
is absent (a stripped install) or says less, the class keeps its own docstring.
"""

from __future__ import annotations

import ast
import functools
import re
import textwrap
from pathlib import Path
from types import ModuleType

__all__ = ["apply_stub_docstrings"]


def _signature(fn: ast.FunctionDef) -> str:
    args = ast.unparse(fn.args)
    for first in ("cls, ", "self, "):
        if args.startswith(first):
            args = args[len(first) :]
    if args in ("cls", "self"):
        args = ""
    returns = f" -> {ast.unparse(fn.returns)}" if fn.returns is not None else ""
    return f"({args}){returns}"


def _summary(doc: str) -> str:
    """The first sentence of a docstring's first paragraph, however many lines it spans
    (its first line alone was often cut mid-sentence)."""
    paragraph = " ".join(doc.split("\n\n")[0].split())
    end = re.search(r"(?<!Eq)(?<!eq)(?<!e\.g)(?<!i\.e)\.(\s+[A-Z(`]|$)", paragraph)
    return paragraph if end is None else paragraph[: end.start() + 1]


def _class_doc(node: ast.ClassDef) -> str | None:
    doc = ast.get_docstring(node)
    if not doc:
        return None
    lines = [doc]
    members: list[str] = []
    for item in node.body:
        if not isinstance(item, ast.FunctionDef):
            continue
        if item.name in ("__new__", "__init__"):
            lines += ["", f"Constructor: {node.name}{_signature(item)}"]
            continue
        member_doc = ast.get_docstring(item)
        if member_doc and not item.name.startswith("_"):
            members += textwrap.wrap(
                f"{item.name}: {_summary(member_doc)}", 88, initial_indent="    ",
                subsequent_indent="        ",
            )  # fmt: skip
    if members:
        lines += ["", "Members:", *members]
    return "\n".join(lines)


@functools.cache
def _stub_docs(path: Path) -> dict[str, str]:
    try:
        tree = ast.parse(path.read_text("utf-8"))
    except (OSError, SyntaxError, ValueError):
        return {}
    docs = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef) and (doc := _class_doc(node)) is not None:
            docs[node.name] = doc
    return docs


class _LazyDoc:
    """A ``__doc__`` read from the stub when first asked for. ``type.__doc__`` calls
    ``__get__`` of the object stored in the class dict, so pydoc and ``help`` see a str."""

    def __init__(self, stub: Path, name: str, own: str | None) -> None:
        self.stub, self.name, self.own = stub, name, own or ""

    def __get__(self, obj: object, owner: type | None = None) -> str:
        doc = _stub_docs(self.stub).get(self.name, "")
        return doc if len(doc) > len(self.own) else self.own


def apply_stub_docstrings(module: ModuleType, stub: Path | None = None) -> None:
    """Give each class of ``module`` named in the stub a docstring read from the stub."""
    stub = stub or Path(__file__).with_name("_core.pyi")
    for name in dir(module):
        cls = getattr(module, name)
        if not isinstance(cls, type) or cls.__module__ != module.__name__:
            continue
        try:
            cls.__doc__ = _LazyDoc(stub, name, cls.__doc__)  # type: ignore[assignment]
        except (AttributeError, TypeError):  # an immutable type: keep its own
            pass
