"""Meta-test: every public function has a numpydoc ``Parameters`` section (issue 20, item 6).

A public function is a module-level ``def`` whose name does not start with ``_``, in a module of
``heavecomp/`` whose path has no part starting with ``_`` (``__init__.py`` counts as public),
taking at least one argument.  Its docstring must have a ``Parameters`` section (a line
``Parameters`` followed by a line of dashes) with one entry ``name : type`` per argument;
``*args``/``**kwargs`` are listed as ``*args``/``**kwargs`` or by their bare name, and
``a, b : float`` names two.  Units go into the type line (``s : float [m]``), as in the rest of
the project; this test cannot tell whether an argument has a unit, review does.

Methods are not checked (only module-level functions); a public class that defines its own
``__init__`` with arguments is checked the same way, on the class docstring or on the
``__init__`` docstring.

Two checks:

* ``test_public_functions_have_parameters``: every argument is listed, with a type.  The
  modules in ``PENDING`` are skipped, and the test fails once a pending module is complete, so
  the list only shrinks: remove its entry then.
* ``test_no_stale_parameter_names``: every name in any ``Parameters`` section of a public
  function or class is an actual argument, so a renamed or removed argument cannot leave its
  description behind (prose at entry indentation inside the section fails the same way).
  Pending modules are skipped here too, but a pending module only counts as complete when it
  also has no stale name.
"""

from __future__ import annotations

import ast
import pathlib
import re

import pytest

from _source import tree as tree_of  # the package's files, parsed once per process

ROOT = pathlib.Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "heavecomp"

# Modules whose public functions or classes still lack (complete) Parameters sections; their
# owners are rewriting them in parallel branches.  The lead removes each entry once the module
# has its sections after those branches are merged (the test fails on an entry that is complete,
# so this set only shrinks).  Path relative to the repository root.
PENDING: set[str] = set()  # every module is complete now; a new one documents its functions from the start

_ENTRY = re.compile(r"^(?P<names>\*{0,2}\w+(?:\s*,\s*\*{0,2}\w+)*)(?:\s+:\s*(?P<type>\S.*))?$")
_DASHES = re.compile(r"^\s*-{3,}\s*$")


def _public_modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(ROOT)
        if any(part.startswith("_") and part != "__init__.py" for part in rel.parts):
            continue
        yield rel.as_posix()


class _Parsed(dict):
    """Public module path -> its parsed tree, parsed when a test first asks for it (collection needs only
    the paths: parsing them all there costs every pytest-xdist worker ~0.7 s of CPU)."""

    def __missing__(self, path):
        tree = self[path] = tree_of(ROOT / path)
        return tree


def _arguments(fn: ast.FunctionDef, skip_self: bool = False) -> list[str]:
    a = fn.args
    names = [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs]
    if skip_self and names and names[0] in ("self", "cls"):
        names = names[1:]
    if a.vararg:
        names.append("*" + a.vararg.arg)
    if a.kwarg:
        names.append("**" + a.kwarg.arg)
    return names


def _documented(module: ast.Module):
    """(name, line, arguments, docstrings to look in) of each checked object."""
    for node in module.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and not node.name.startswith("_"):
            args = _arguments(node)
            if args:
                yield node.name, node.lineno, args, [ast.get_docstring(node) or ""]
        elif isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
            init = next((b for b in node.body
                         if isinstance(b, ast.FunctionDef) and b.name == "__init__"), None)
            if init is None:
                continue
            args = _arguments(init, skip_self=True)
            if args:
                yield (node.name, node.lineno, args,
                       [ast.get_docstring(node) or "", ast.get_docstring(init) or ""])


def parameters_section(doc: str) -> list[tuple[list[str], bool]] | None:
    """Entries of the numpydoc ``Parameters`` section of ``doc``: (names, has a type line).

    ``None`` when there is no section.  An entry is a line at the section's own indentation; the
    more indented lines under it are its description; the section ends at the next header (a
    line followed by dashes).  A line at entry indentation that is not ``name[, name] : type``
    is returned as its whole text with no type, so it fails as a stale name.
    """
    lines = doc.expandtabs().splitlines()
    for i in range(len(lines) - 1):
        if lines[i].strip() == "Parameters" and _DASHES.match(lines[i + 1]):
            break
    else:
        return None
    indent = len(lines[i]) - len(lines[i].lstrip())
    entries = []
    j = i + 2
    while j < len(lines):
        line = lines[j]
        if j + 1 < len(lines) and line.strip() and _DASHES.match(lines[j + 1]):
            break                                           # next section
        if line.strip() and len(line) - len(line.lstrip()) == indent:
            m = _ENTRY.match(line.strip())
            if m:
                names = [n.strip() for n in m["names"].split(",")]
                entries.append((names, m["type"] is not None))
            else:
                entries.append(([line.strip()], False))
        j += 1
    return entries


def _listed(entries) -> dict[str, bool]:
    out = {}
    for names, typed in entries:
        for n in names:
            out[n] = typed
    return out


def _matches(arg: str, listed: dict[str, bool]) -> str | None:
    for name in (arg, arg.lstrip("*")):
        if name in listed:
            return name
    return None


def _problems(module: ast.Module) -> list[str]:
    """What is missing in ``module``: undocumented arguments and entries without a type."""
    out = []
    for name, line, args, docs in _documented(module):
        sections = [s for s in (parameters_section(d) for d in docs) if s is not None]
        if not sections:
            out.append(f"{name} (line {line}): no Parameters section")
            continue
        listed = _listed([e for s in sections for e in s])
        for arg in args:
            key = _matches(arg, listed)
            if key is None:
                out.append(f"{name} (line {line}): argument {arg!r} not in Parameters")
            elif not listed[key]:
                out.append(f"{name} (line {line}): {arg!r} has no type line ('{key} : type')")
    return out


PATHS = tuple(_public_modules())
MODULES = _Parsed()


def test_pending_lists_existing_modules():
    assert sorted(PENDING - set(PATHS)) == [], "PENDING names a module that does not exist"


def _stale(module: ast.Module) -> list[str]:
    """Names in a ``Parameters`` section of ``module`` that are not arguments."""
    out = []
    for name, line, args, docs in _documented(module):
        for doc in docs:
            for names, _ in parameters_section(doc) or []:
                for n in names:
                    if n not in args and "*" + n not in args and "**" + n not in args:
                        out.append(f"{name} (line {line}): {n!r} is not an argument {args}")
    return out


def _skip_pending(path):
    if path in PENDING:
        problems = _problems(MODULES[path]) + _stale(MODULES[path])
        assert problems, (f"{path} is complete now: remove it from PENDING in "
                          f"tests/test_docstrings.py")
        pytest.skip(f"pending: {len(problems)} to document")


@pytest.mark.parametrize("path", sorted(PATHS))
def test_public_functions_have_parameters(path):
    _skip_pending(path)
    problems = _problems(MODULES[path])
    assert problems == [], f"{path}:\n  " + "\n  ".join(problems)


@pytest.mark.parametrize("path", sorted(PATHS))
def test_no_stale_parameter_names(path):
    _skip_pending(path)
    stale = _stale(MODULES[path])
    assert stale == [], f"{path}:\n  " + "\n  ".join(stale)


def test_parser_reads_numpydoc():
    """The section parser on a known docstring (so the two checks above cannot pass vacuously)."""
    doc = ("Summary.\n\nParameters\n----------\ns, v : float [m], [m/s]\n    Stroke, velocity.\n"
           "n\n    No type.\n*args : float\n\nReturns\n-------\nx : float\n")
    assert parameters_section(doc) == [(["s", "v"], True), (["n"], False), (["*args"], True)]
    assert parameters_section("Summary only.") is None
    module = ast.parse(f'def f(s, v, n, *args, k=1):\n    """{doc}"""\n')
    assert _problems(module) == ["f (line 1): 'n' has no type line ('n : type')",
                                 "f (line 1): argument 'k' not in Parameters"]
    assert _stale(module) == []
    renamed = ast.parse(f'def f(s, w, n, *args, k=1):\n    """{doc}"""\n')
    assert _stale(renamed) == ["f (line 1): 'v' is not an argument ['s', 'w', 'n', 'k', '*args']"]
    prose = ast.parse('def g(x):\n    """S.\n\n    Parameters\n    ----------\n    x : float\n\n'
                      '    The result holds x.\n    """\n')
    assert _stale(prose) == ["g (line 1): 'The result holds x.' is not an argument ['x']"]
