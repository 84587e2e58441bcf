"""Issue 11.4 (part): report/ draws every figure — no module below it imports matplotlib or the figure helpers.

Nothing outside report/ and commands/ draws (the pneumatic plots and the closed-loop writer moved in).
"""

import re
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "heavecomp"
#: modules still allowed to draw below report/ (none)
KNOWN: set[str] = set()
DRAWS = re.compile(r"^\s*(import matplotlib|from matplotlib|from heavecomp\.report\.figures import|"
                   r"from heavecomp\.report import figures)|\.savefig\(|\b_plt\(\)", re.M)


def test_only_report_and_commands_draw():
    drawing = set()
    for f in PKG.rglob("*.py"):
        rel = f.relative_to(PKG).as_posix()
        if rel.startswith(("report/", "commands/")):
            continue
        if DRAWS.search(f.read_text(encoding="utf-8")):
            drawing.add(rel)
    assert drawing <= KNOWN, f"drawing outside heavecomp/report/: {sorted(drawing - KNOWN)}"


def test_the_pattern_catches_drawing_code():
    assert DRAWS.search("    from heavecomp.report.figures import _plt\n")
    assert DRAWS.search("fig.savefig(path)")
    assert not DRAWS.search('"""figures drawn by :mod:`heavecomp.report.figures`"""')
