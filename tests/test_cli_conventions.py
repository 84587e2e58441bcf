"""Issue 13.8: CLI conventions — ``python -m heavecomp``, "did you mean" for mistyped flags, ``--quiet``
on every command, progress while large files are written."""

import subprocess
import sys

import pytest

from heavecomp.cli import COMMANDS, _leaf_parsers, build_parser


def _run(*args):
    return subprocess.run([sys.executable, "-m", "heavecomp", *args], capture_output=True, text=True)


def test_python_dash_m_runs_the_cli():
    r = _run("--version")
    assert r.returncode == 0 and r.stdout.startswith("heavecomp ")


@pytest.mark.parametrize("argv,suggestion", [
    (["simulate", "p.toml", "--durtion", "3", "--out", "x"], "--duration"),
    (["simulate", "p.toml", "--duration", "3", "--out", "x", "--controler", "pid"], "--controller"),
    (["analyse", "p.toml", "--out", "x", "--omega-mx", "3"], "--omega-max"),
    (["identify", "seal", "f.csv", "--out", "x", "--n-bot", "30"], "--n-boot"),
])
def test_mistyped_flag_gets_one_line_with_the_closest_option(argv, suggestion):
    r = _run(*argv)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert f"did you mean '{suggestion}'?" in lines[0]
    assert "Traceback" not in r.stderr


def test_every_command_has_quiet():
    parser, _ = build_parser()
    leaves = list(_leaf_parsers(parser))
    assert len(leaves) >= len(COMMANDS)  # identify has two leaves
    for p in leaves:
        assert "--quiet" in p._option_string_actions, p.prog
        assert "-q" in p._option_string_actions, p.prog  # diagnose defined --quiet alone (issue 21.6)


def test_diagnose_takes_dash_q():
    parser, _ = build_parser("diagnose")
    args = parser.parse_args(["diagnose", "run.csv", "--params", "p.toml", "--out", "o", "-q"])
    assert args.quiet is True


def test_quiet_silences_summary_but_not_errors(paper_a_toml, tmp_path):
    from _cli import run  # in-process: the summary's text needs no process boundary (saves ~1.2 s of CPU);
    # what --quiet leaves on a shell's stdout and stderr, and the error it keeps, do (subprocesses below)

    loud = run("analyse", str(paper_a_toml), "--out", str(tmp_path / "a"), "--points", "50")
    quiet = _run("analyse", str(paper_a_toml), "--out", str(tmp_path / "b"), "--points", "50", "--quiet")
    assert loud.returncode == quiet.returncode == 0
    assert "natural frequencies" in loud.stdout
    assert quiet.stdout == "" and quiet.stderr == ""
    assert (tmp_path / "b" / "analysis.json").exists()
    bad = _run("analyse", str(paper_a_toml), "--out", str(tmp_path / "c"), "--points", "1", "--quiet")
    assert bad.returncode == 2 and "--points" in bad.stderr


def test_params_quiet_checks_a_file_silently_and_keeps_a_built_in_set_on_stdout(paper_a_toml):
    r = _run("params", str(paper_a_toml), "--quiet")  # a check: the exit code is the answer (U12)
    assert r.returncode == 0 and r.stdout == "" and r.stderr == ""
    r = _run("params", "paper_a", "--quiet")  # the TOML asked for is the output, not a summary
    assert r.returncode == 0 and "[compensator]" in r.stdout and r.stderr == ""


def test_csv_writer_reports_progress_to_the_end(tmp_path):
    import numpy as np

    from heavecomp.simulate.core import write_csv

    seen = []
    data = np.arange(30_000.0).reshape(-1, 3)
    write_csv(tmp_path / "x.csv", data, ("a", "b", "c"), block=1000, progress=seen.append)
    assert len(seen) == 10 and seen == sorted(seen) and seen[-1] == 1.0
    back = np.loadtxt(tmp_path / "x.csv", delimiter=",", skiprows=1)
    np.testing.assert_array_equal(back, data)
