"""The package's source files, parsed once per test process.

Several test modules scan the whole package's source (its layers, docstrings, error texts, what imports
what): each parsing every file again cost a process ~0.5-1 s per module. :func:`tree` parses a file on
its first call and hands the same tree to every later caller, who only reads it (``ast.walk``, node
attributes): a test never edits a tree it got here.
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path


def tree(path) -> ast.Module:
    """The parsed source of the file ``path`` (a ``str`` or ``Path``, relative paths resolved from the
    current folder), shared by every caller of this process."""
    return _parse(str(Path(path).resolve()))


@functools.cache
def _parse(path: str) -> ast.Module:
    return ast.parse(Path(path).read_text(encoding="utf-8"), filename=path)
