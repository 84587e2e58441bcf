"""Layers that hold (issue 11 item 4), read from the import graph of the package's source.

params -> physics (friction, plants, effects) -> stepper (simulate) -> controllers ->
closed loop -> analysis / diagnosis / campaign / identification / benchmark -> report -> commands.
A module may import its own layer or a lower one, never a higher one; no two modules
import each other, directly or round a cycle; the package's own imports sit at module top,
except imports of modules that load a heavy third-party library (numba, casadi, ...) at
their top, which stay inside the functions that need them (import time of the CLI).

Every module's AST is parsed (no import is executed), so a new upward import anywhere,
in a function or at top, fails here.
"""

from __future__ import annotations

import ast
import collections
from pathlib import Path

import pytest

from _source import tree as tree_of  # the package's files, parsed once per process

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "heavecomp"

LAYERS = ("base", "params", "physics", "stepper", "controllers", "closed loop", "analysis", "report", "commands")

#: module prefix -> layer; the longest matching prefix wins
LAYER_OF = {
    "heavecomp": "base",                      # __version__
    "heavecomp.errors": "base",
    "heavecomp.signals": "base",              # signal processing used by analysis and identification
    "heavecomp.params": "params",
    "heavecomp.friction": "physics",
    "heavecomp.plants": "physics",
    "heavecomp.effects": "physics",
    "heavecomp.simulate": "stepper",
    "heavecomp.controllers": "controllers",
    "heavecomp.closed_loop": "closed loop",
    "heavecomp.analysis": "analysis",
    "heavecomp.diagnosis": "analysis",
    "heavecomp.campaign": "analysis",
    "heavecomp.identification": "analysis",
    "heavecomp.benchmark": "analysis",        # the withheld-effect benchmark: checks diagnosis, beside it
    "heavecomp.estimator": "analysis",        # base of the gap diagnosers
    "heavecomp.benchmark": "analysis",        # generated truth: withheld effects, corrupted logs
    "heavecomp.independent": "analysis",      # the clean-room truth generator (issue 30 item 5), beside benchmark
    "heavecomp.report": "report",
    # the wings (paper B's pneumatic cylinder, paper A's rotating-piston rig) keep the same order
    "heavecomp.pneumatic.friction": "physics",
    "heavecomp.pneumatic.plant": "physics",
    "heavecomp.pneumatic.stepper": "stepper",
    "heavecomp.pneumatic": "analysis",        # linear, stickslip, measurement
    "heavecomp.test_rig": "physics",
    # modules that draw figures and write reports belong to the report layer wherever they sit
    # today (issue 11 item 4 moves them into heavecomp/report/)
    "heavecomp.report.rigs": "report",
    "heavecomp.commands": "commands",
    "heavecomp.cli": "commands",
    "heavecomp.__main__": "commands",         # `python -m heavecomp` (issue 13 item 8)
}
#: LAYER_OF entries for modules that may not exist yet
EXPECTED = {"heavecomp.__main__"}

#: upward imports that are known and owned by another item of issue 11 (report/ becomes the
#: only writer); each entry must still exist, so the list can only shrink
KNOWN_UPWARD = {
}

#: third-party libraries that take long to import; modules loading one at top are imported lazily
HEAVY_LIBRARIES = {"numba", "casadi", "control", "osqp", "pandas", "pyarrow", "matplotlib", "scipy", "dask",
                   "lasio", "xarray", "pythonfmu3", "fmpy"}
#: compiled modules without Python source (the ahead-of-time numba kernel setup.py may build)
COMPILED = {"heavecomp.simulate._cmc_aot"}

Import = collections.namedtuple("Import", "importer target at_top line")


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _top_level_nodes(tree: ast.Module) -> set[int]:
    """ids of the nodes that run when the module is imported: the module body and its if/try
    blocks, not the bodies of functions (nor of classes, which hold no imports here)."""
    ids, todo = set(), list(tree.body)
    while todo:
        node = todo.pop()
        ids.add(id(node))
        if isinstance(node, (ast.If, ast.Try, ast.ExceptHandler)):
            todo.extend(n for n in ast.iter_child_nodes(node)
                        if not isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)))
    return ids


def _parse():
    modules = {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}
    own, third = [], []
    for name, path in modules.items():
        tree = tree_of(path)
        top = _top_level_nodes(tree)
        is_pkg = path.name == "__init__.py"
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:  # relative import
                    anchor = name.split(".") if is_pkg else name.split(".")[:-1]
                    anchor = anchor[:len(anchor) - node.level + 1]
                    base = ".".join(anchor + ([base] if base else []))
                # `from pkg import submodule` imports the submodule
                targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules or f"{base}.{a.name}" in COMPILED
                           else base for a in node.names]
            else:
                continue
            for t in dict.fromkeys(targets):
                rec = Import(name, t, id(node) in top, node.lineno)
                (own if t.split(".")[0] == "heavecomp" else third).append(rec)
    return modules, own, third


#: the parsed package, filled by the first test of this module a process runs (not at collection: parsing
#: every module costs each pytest-xdist worker ~1.5 s of CPU, also the worker that runs none of these tests)
MODULES, OWN, THIRD = {}, [], []


@pytest.fixture(scope="module", autouse=True)
def _parsed():
    if not MODULES:
        modules, own, third = _parse()
        MODULES.update(modules)
        OWN.extend(own)
        THIRD.extend(third)
    assert MODULES and OWN and THIRD, "parsed no module: every check below would pass vacuously"


def layer(module: str) -> str:
    best = max((p for p in LAYER_OF if module == p or module.startswith(p + ".")), key=len, default=None)
    if best is None:
        raise KeyError(module)
    return LAYER_OF[best]


def _heavy_modules() -> set[str]:
    """Own modules that import a heavy library at top, directly or through an own module."""
    heavy = {i.importer for i in THIRD if i.at_top and i.target.split(".")[0] in HEAVY_LIBRARIES} | COMPILED
    top_edges = [(i.importer, i.target) for i in OWN if i.at_top]
    grew = True
    while grew:
        grew = False
        for a, b in top_edges:
            if b in heavy and a not in heavy:
                heavy.add(a)
                grew = True
    return heavy


def test_every_module_has_a_layer():
    missing = []
    for m in MODULES:
        try:
            layer(m)
        except KeyError:
            missing.append(m)
    assert not missing, f"add these modules to LAYER_OF: {missing}"
    stale = [p for p in LAYER_OF if p not in EXPECTED and not any(m == p or m.startswith(p + ".") for m in MODULES)]
    assert not stale, f"LAYER_OF names modules that no longer exist: {stale}"


def upward_imports(imports=None) -> list[Import]:
    rank = {name: k for k, name in enumerate(LAYERS)}
    return [i for i in (OWN if imports is None else imports)
            if i.target in MODULES and rank[layer(i.target)] > rank[layer(i.importer)]]


def test_nothing_imports_upward():
    found = upward_imports()
    new = [f"{i.importer}:{i.line} ({layer(i.importer)}) imports {i.target} ({layer(i.target)})"
           for i in found if (i.importer, i.target) not in KNOWN_UPWARD]
    assert not new, "upward imports:\n" + "\n".join(new)
    stale = set(KNOWN_UPWARD) - {(i.importer, i.target) for i in found}
    assert not stale, f"fixed, remove from KNOWN_UPWARD: {sorted(stale)}"


def test_the_check_sees_an_upward_import():
    """The rule is live: a stepper module importing a controller is caught, one importing physics is not."""
    fake = [Import("heavecomp.simulate.core", "heavecomp.controllers.base", False, 1),
            Import("heavecomp.simulate.core", "heavecomp.plants.cmc", True, 2)]
    assert upward_imports(fake) == fake[:1]


def _cycles(edges) -> list[list[str]]:
    graph = collections.defaultdict(set)
    for a, b in edges:
        graph[a].add(b)
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):  # Tarjan's strongly connected components
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in list(graph):
        if v not in index:
            visit(v)
    return out


def _module_edges():
    """importer -> imported module, for every import (top or lazy), parent packages excluded."""
    return {(i.importer, i.target) for i in OWN
            if i.target in MODULES and i.target != i.importer and not i.importer.startswith(i.target + ".")}


def test_no_import_cycles_between_modules():
    cycles = _cycles(_module_edges())
    assert not cycles, f"import cycles: {cycles}"


def test_no_import_cycles_between_packages():
    def pkg(m):
        return ".".join(m.split(".")[:2])

    cycles = _cycles({(pkg(a), pkg(b)) for a, b in _module_edges() if pkg(a) != pkg(b)})
    assert not cycles, f"package cycles: {cycles}"


def test_the_cycle_check_sees_a_cycle():
    assert _cycles({("a", "b"), ("b", "c"), ("c", "a"), ("c", "d")}) == [["a", "b", "c"]]


#: layers whose modules import the library inside their functions: a command module is loaded
#: to build its parser, so ``heavecomp CMD --help`` and bad arguments answer without numpy and the
#: library (50 ms instead of 460 ms); nothing imports a command, so the graph stays visible
LAZY_LAYERS = {"commands"}


def test_own_imports_sit_at_module_top():
    """In-function imports of the package's own modules only for modules that load a heavy library,
    in the command layer, or for a known upward import waiting to be moved."""
    heavy = _heavy_modules()
    hidden = [f"{i.importer}:{i.line} imports {i.target}" for i in OWN
              if not i.at_top and i.target not in heavy and (i.importer, i.target) not in KNOWN_UPWARD
              and not (layer(i.importer) in LAZY_LAYERS and i.importer != "heavecomp.cli")]
    assert not hidden, f"{len(hidden)} imports of the package's own modules inside functions:\n" + "\n".join(hidden)


def test_heavy_libraries_are_not_imported_by_the_cli_or_light_layers():
    """The CLI entry point and the packages every command loads stay free of heavy imports at top."""
    heavy = _heavy_modules()
    assert "heavecomp.simulate._kernel" in heavy  # numba at top: the check sees it
    for m in ("heavecomp", "heavecomp.cli", "heavecomp.errors", "heavecomp.params", "heavecomp.simulate",
              "heavecomp.simulate.core", "heavecomp.controllers", "heavecomp.closed_loop"):
        assert m not in heavy, f"{m} imports a heavy library at top ({', '.join(sorted(HEAVY_LIBRARIES))})"


def test_the_command_line_parser_loads_no_heavy_library():
    """Building every command's parser loads no heavy library, nor numpy (commands import the
    library in ``run``)."""
    import subprocess
    import sys

    code = ("import sys, heavecomp.cli; heavecomp.cli.build_parser(); "
            f"print(' '.join(sorted(m for m in {sorted(HEAVY_LIBRARIES | {'numpy'})!r} if m in sys.modules)))")
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == ""
