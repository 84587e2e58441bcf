"""docs/quickstart-own-log.md cannot drift: every command in its bash blocks runs as written (issue 31 item 4).

The commands name the example log by its path in the repository and write their folders beside it: they run
from a scratch folder whose ``heavecomp/data`` links to the package's data (so the paths resolve), with
``heavecomp`` on the PATH running this tree.

The link is to the data only, not to the package: ``python -m heavecomp`` run from the scratch folder would
import a linked package through the scratch folder's own path, and numba keys its cache folders by the
absolute folder of each compiled source (``_UserProvidedCacheLocator.get_suitable_cache_subpath``), so every
run (a new ``tmp_path``) recompiled the nominal stepper and the 16-effect stepper of the diagnosis: 146 s of
the suite's wall, against ~30 s for the commands themselves. A folder ``heavecomp/`` with no
``__init__.py`` is only a namespace portion, so the regular package on ``PYTHONPATH`` (this tree) is imported.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "quickstart-own-log.md"


def commands() -> list[str]:
    blocks = re.findall(r"```bash\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.S)
    return [ln.strip() for b in blocks for ln in b.splitlines() if ln.strip().startswith("heavecomp ")]


def test_the_quickstart_has_the_whole_path():
    verbs = [c.split()[1] for c in commands()]
    assert verbs == ["params", "diagnose", "replay", "simulate", "simulate", "simulate", "monitor"]


def test_every_quickstart_command_runs(tmp_path):
    bin_ = tmp_path / ".bin"
    bin_.mkdir()
    (bin_ / "heavecomp").write_text(f'#!/bin/sh\nexec "{sys.executable}" -m heavecomp "$@"\n')
    (bin_ / "heavecomp").chmod(0o755)
    (tmp_path / "heavecomp").mkdir()
    (tmp_path / "heavecomp" / "data").symlink_to(ROOT / "heavecomp" / "data")
    env = dict(os.environ, PATH=f"{bin_}{os.pathsep}{os.environ['PATH']}", PYTHONPATH=str(ROOT))
    for cmd in commands():
        r = subprocess.run(["bash", "-c", cmd], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=1800)
        assert r.returncode == 0, f"{cmd}\n-> exit {r.returncode}: {r.stderr.strip()[-500:]}"
    assert (tmp_path / "qs_replay" / "replay.json").is_file() and (tmp_path / "qs_monitor" / "monitor.json").is_file()
    # the commands ran this tree's package from its own path (where its compiled kernels are cached)
    probe = subprocess.run([sys.executable, "-c", "import heavecomp; print(heavecomp.__file__)"], cwd=tmp_path,
                           env=env, capture_output=True, text=True)
    assert probe.stdout.strip() == str(ROOT / "heavecomp" / "__init__.py"), probe.stdout + probe.stderr
