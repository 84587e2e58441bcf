"""A plain clone is complete: nothing tracked reaches outside the repository (issue 13, item 1)."""

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
# spelt in pieces so that this file does not match itself
OUTSIDE = [".." + "/shared", "shared" + "/spec", "shared" + "/data", "shared" + "/style", "HEAVECOMP_" + "SHARED"]
TEXT = {".py", ".md", ".toml", ".txt", ".cfg", ".ini", ".json", ".yml", ".yaml", ".html", ""}


def _tracked():
    try:
        out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, timeout=60, check=True)
        files = [ROOT / f for f in out.stdout.splitlines()]
    except (OSError, subprocess.SubprocessError):  # not a git checkout: every file under the root
        files = [p for p in ROOT.rglob("*") if p.is_file() and ".git" not in p.parts]
    return [f for f in files if f.suffix in TEXT and f.is_file()]


def test_no_tracked_file_reaches_outside_the_repository():
    hits = []
    for f in _tracked():
        text = f.read_text(encoding="utf-8", errors="replace")
        for pat in OUTSIDE:
            if pat in text:
                hits.append(f"{f.relative_to(ROOT)}: {pat}")
    assert not hits, hits


def test_markdown_links_resolve_inside_the_repository():
    bad = []
    for f in [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md")), ROOT / "heavecomp" / "data" / "README.md"]:
        for target in re.findall(r"\]\(([^)\s]+)\)", f.read_text(encoding="utf-8")):
            if re.match(r"^[a-z]+://|^#|^mailto:", target):
                continue
            path = (f.parent / target.split("#")[0]).resolve()
            if not path.exists() or ROOT not in path.parents:
                bad.append(f"{f.relative_to(ROOT)} -> {target}")
    assert not bad, bad


@pytest.mark.parametrize("name", ["EMPS", "SEAL_FRICTION", "WAVERIDER", "EXAMPLE_RUN", "EXAMPLE_PARAMS"])
def test_shipped_data_is_in_the_package(name):
    import heavecomp.data as D

    p = getattr(D, name)
    assert p.exists() and D.ROOT in p.parents
    assert (D.ROOT / "README.md").read_text(encoding="utf-8").count(p.name if p.is_file() else p.name + "/") >= 1


def test_cli_help_stays_inside_the_repository():
    from heavecomp.cli import build_parser

    parser, _ = build_parser()
    texts = [parser.format_help()]
    for action in parser._subparsers._group_actions:  # noqa: SLF001 - argparse has no public walk
        texts += [p.format_help() for p in action.choices.values()]
    joined = "\n".join(texts)
    assert not [p for p in OUTSIDE if p in joined]
    assert "diagnose" in joined and "--columns" in joined
