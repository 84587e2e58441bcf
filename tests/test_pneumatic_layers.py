"""The pneumatic and test-rig wings keep the package's layer order inside themselves, import their
own modules at module top, and only report/ and commands/ (the layers above) reach into them."""

from __future__ import annotations

import ast
from pathlib import Path

from _source import tree as tree_of  # the package's files, parsed once per process

PKG = Path(__file__).resolve().parents[1] / "heavecomp"

#: layer of each wing module: physics 1, stepper 2, analysis 5 (the package's numbering:
#: params 0, physics 1, stepper 2, controllers 3, closed loop 4, analysis 5, report 6, commands 7)
WING = {"heavecomp.pneumatic.friction": 1, "heavecomp.pneumatic.plant": 1, "heavecomp.pneumatic.stepper": 2,
        "heavecomp.pneumatic.linear": 5, "heavecomp.pneumatic.stickslip": 5, "heavecomp.pneumatic.measurement": 5,
        "heavecomp.test_rig.plant": 1}
#: what a wing module may import from the rest of the package, with the layer it sits in
OUTSIDE = {"heavecomp.errors": 0, "heavecomp.params": 0, "heavecomp.signals": 0, "heavecomp.friction": 1,
           "heavecomp.plants": 1, "heavecomp.simulate._kernel": 2, "heavecomp.simulate.cache": 2,
           "heavecomp.analysis.linear": 5}


def _imports(path: Path):
    """(module imported, at module top?) for every ``heavecomp`` import of a file."""
    tree = tree_of(path)
    top = {id(n) for n in tree.body}
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("heavecomp"):
            names = [f"{node.module}.{a.name}" for a in node.names]
            out += [(n, id(node) in top) for n in names]
        elif isinstance(node, ast.Import):
            out += [(a.name, id(node) in top) for a in node.names if a.name.startswith("heavecomp")]
    return out


def _layer(name: str):
    for table in (WING, OUTSIDE):
        for mod, lay in table.items():
            if name == mod or name.startswith(mod + "."):
                return lay
    return None


def _module(path: Path) -> str:
    return ".".join(path.relative_to(PKG.parent).with_suffix("").parts)


def test_wing_imports_only_down_and_at_module_top():
    for mod, layer in WING.items():
        path = PKG.parent / (mod.replace(".", "/") + ".py")
        for name, at_top in _imports(path):
            assert at_top, f"{mod}: imports {name} inside a function"
            lay = _layer(name)
            assert lay is not None, f"{mod}: imports {name}, which is not a layer the wing may use"
            assert lay <= layer, f"{mod} (layer {layer}) imports {name} (layer {lay}): upward"


def test_only_report_and_commands_reach_into_the_wings():
    users = set()
    for path in PKG.rglob("*.py"):
        mod = _module(path)
        if mod.startswith(("heavecomp.pneumatic", "heavecomp.test_rig")):
            continue
        if any(n.startswith(("heavecomp.pneumatic", "heavecomp.test_rig")) for n, _ in _imports(path)):
            users.add(mod)
    assert users, "nothing uses the wings: the scan is broken"
    assert all(u.startswith(("heavecomp.report.", "heavecomp.commands.")) for u in users), sorted(users)
