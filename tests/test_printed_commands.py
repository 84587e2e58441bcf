"""Every command a report or the terminal prints runs when copied (issue 31 item 3).

A user's logger-shaped log (semicolons, epoch ms, mm, bar, hook load in tonnes: :mod:`logger_log`) of a plant whose
seal friction is 30 % above the nominal file is diagnosed, monitored and run as a fleet with the log's
``--columns``/``--units``; every ``heavecomp ...`` line of their ``report.md`` and stdout is then run VERBATIM by
``bash -c`` from the user's folder (``heavecomp`` on the PATH runs this tree), and must exit 0.  Every path a
last stdout line names exists (the final folder, never the staging ``.OUT.partial``).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from logger_log import COLUMNS, UNITS, nominal_toml, write_logger_log

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]
FLAGS = f"--columns {COLUMNS} --units {UNITS}"


@pytest.fixture(scope="module")
def user(tmp_path_factory):
    """(the user's folder, the shell environment with ``heavecomp`` on its PATH)."""
    from heavecomp.effects.spec import load

    home = tmp_path_factory.mktemp("user")
    bin_ = home / ".bin"
    bin_.mkdir()
    shim = bin_ / "heavecomp"
    shim.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m heavecomp "$@"\n')
    shim.chmod(0o755)
    env = dict(os.environ, PATH=f"{bin_}{os.pathsep}{os.environ['PATH']}",
               PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    nom = nominal_toml(home / "nominal.toml")
    p = load(nom)
    truth = p.replace(friction={"static_force": 1.3 * p.friction.static_force,
                                "coulomb_force": 1.3 * p.friction.coulomb_force})
    (home / "logs").mkdir()
    write_logger_log(home / "logs" / "rig.csv", truth, duration=150.0, rate=10.0)
    return home, env


def shell(cmd, home, env):
    r = subprocess.run(["bash", "-c", cmd], cwd=home, env=env, capture_output=True, text=True, timeout=1800)
    assert r.returncode == 0, f"{cmd}\n-> exit {r.returncode}: {r.stderr.strip().splitlines()[-1:]}"
    return r.stdout


def printed(*texts) -> list[str]:
    """The distinct ``heavecomp ...`` command lines of reports and terminal output, in the order printed (a line
    both the report and the terminal print runs once: the same line runs the same command)."""
    return list(dict.fromkeys(ln.strip() for t in texts for ln in t.splitlines() if ln.strip().startswith("heavecomp ")))


def named_paths(stdout: str) -> list[str]:
    """The paths the terminal's lines point at (``-> PATH``)."""
    return [m.group(1).rstrip(",") for m in re.finditer(r"-> (\S+)", stdout)]


def check(cmd, home, env, *, expect_commands=False):
    out = shell(cmd, home, env)
    for p in named_paths(out):
        assert ".partial" not in p and (home / p).exists(), (cmd, p)
    folder = home / cmd.split("--out ")[1].split()[0]
    md = (folder / "report.md").read_text()
    html = (folder / "report.html").read_text()
    assert ".partial" not in md + html + out
    cmds = printed(md, out)
    if expect_commands:
        assert cmds, f"{cmd}: no command printed"
    for c in cmds:
        shell(c, home, env)
    return cmds


def test_diagnose_what_next_commands_run_verbatim(user):
    home, env = user
    cmds = check(f"heavecomp diagnose logs/rig.csv --params nominal.toml --out diagA {FLAGS} --quiet", home, env,
                 expect_commands=True)
    assert any(c.startswith("heavecomp diagnose logs/rig.csv --params diagA/calibrated.toml") for c in cmds) \
        or len(cmds) == 2  # a named verdict ends in the re-diagnosis (needing no flags); `none` in two commands
    assert "columns = {" in (home / "diagA" / "calibrated.toml").read_text()


def test_diagnose_span_what_next_commands_run_verbatim_on_the_span(user):
    """A diagnosed span (as each ``monitor --diagnose`` segment is): every command that reads the log carries it."""
    home, env = user
    cmds = check(f"heavecomp diagnose logs/rig.csv --params nominal.toml --span 20:150 --out diagS {FLAGS} --quiet",
                 home, env, expect_commands=True)
    reads = [c for c in cmds if "logs/rig.csv" in c]
    assert reads and all("--span 20:150" in c for c in reads) and not any("--heave-file" in c for c in cmds), cmds


def test_monitor_printed_commands_run_verbatim(user):
    home, env = user
    check(f"heavecomp monitor logs/rig.csv --params nominal.toml --out mon {FLAGS}", home, env)


def test_fleet_printed_commands_run_verbatim(user):
    home, env = user
    check(f"heavecomp fleet logs --params nominal.toml --out fl {FLAGS} --workers 1", home, env)
