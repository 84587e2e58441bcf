"""Issue 21.6: library errors name the key, the command line names its own flag.

A library user has no ``--duration``: the library raises with ``option="duration"`` (and maybe an
``example``) and :func:`heavecomp.cli.message` turns that into the flag of the command being run, and
only when that command has it (``simulate`` has no ``--columns``)."""

import ast
from pathlib import Path

import numpy as np
import pytest

from heavecomp.cli import main
from heavecomp.errors import InputError

from _source import tree as tree_of  # the package's files, parsed once per process

PKG = Path(__file__).resolve().parents[1] / "heavecomp"

#: files another change is rewriting; their flag-naming messages go with that rewrite (issue 21.6)
PENDING: set = set()


def _raise_literals(tree):
    for node in ast.walk(tree):
        if isinstance(node, ast.Raise) and node.exc is not None:
            for sub in ast.walk(node.exc):
                if isinstance(sub, ast.Constant) and isinstance(sub.value, str):
                    yield node.lineno, sub.value


def test_no_library_error_text_names_a_cli_flag():
    hits = []
    for f in sorted(PKG.rglob("*.py")):
        rel = f.relative_to(PKG).as_posix()
        if rel.startswith("commands/") or rel == "cli.py" or rel in PENDING:
            continue
        for line, text in _raise_literals(tree_of(f)):
            if "--" in text:
                hits.append(f"{rel}:{line}: {text!r}")
    assert not hits, "library errors naming a command-line flag (raise with option=... instead):\n" + "\n".join(hits)


def test_the_scan_finds_a_flag_in_a_raise():
    tree = ast.parse('def f(x):\n    raise ValueError(f"--rate {x} Hz: too high")\n')
    assert [t for _, t in _raise_literals(tree) if "--" in t] == ["--rate "]


def _cli(argv, capsys):
    code = main([str(a) for a in argv])
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err and len(err.splitlines()) == 1, err
    return code, err


def test_library_names_the_key_and_the_cli_its_flag(paper_a_toml, tmp_path, capsys):
    from heavecomp.params import paper_a
    from heavecomp.simulate import simulate

    with pytest.raises(InputError) as e:
        simulate(paper_a(), -1.0)
    assert str(e.value).startswith("duration must be a positive number") and e.value.option == "duration"
    code, err = _cli(["simulate", paper_a_toml, "--duration", "-1", "--out", tmp_path / "o"], capsys)
    assert code == 2 and err == "heavecomp simulate: error: --duration must be a positive number of seconds, got -1.0"


def test_simulate_heave_file_error_suggests_no_flag_simulate_lacks(paper_a_toml, tmp_path, capsys):
    heave = tmp_path / "heave.csv"
    heave.write_text("time,elevation\n" + "".join(f"{0.1 * i:g},{np.sin(0.1 * i):.6f}\n" for i in range(200)))
    p = tmp_path / "file.toml"
    text = paper_a_toml.read_text()
    start = text.index("[heave]")
    end = text.index("\n[", start + 1)
    p.write_text(text[:start] + '[heave]\nkind = "file"\npath = "heave.csv"\n' + text[end:])
    code, err = _cli(["simulate", p, "--duration", "5", "--out", tmp_path / "o"], capsys)
    assert code == 2 and "missing column 'heave'" in err
    assert "--columns heave=NAME" in err  # simulate maps a heave file's columns (issue 31: --heave-file)
    assert not (tmp_path / "o").exists()
    assert main(["simulate", str(p), "--duration", "5", "--out", str(tmp_path / "o"), "--columns",
                 "heave=elevation,t=time", "--quiet"]) == 0
    code, err = _cli(["simulate", paper_a_toml, "--duration", "5", "--out", tmp_path / "o2", "--columns", "heave=z"],
                     capsys)
    assert code == 2 and "give --heave-file LOG" in err


@pytest.fixture(scope="module")
def rig_log(tmp_path_factory):
    """90 s of the paper-A rig at 20 Hz as a measured run (the contract's columns, SI)."""
    from heavecomp.params import paper_a
    from heavecomp.simulate import simulate

    d = tmp_path_factory.mktemp("rig")
    res = simulate(paper_a(), 90.0, rate=20.0)
    res.to_csv(d / "run.csv")
    return d / "run.csv"


@pytest.mark.parametrize("column, scale, unit", [("pressure", 1e-5, "bar"), ("wob", 1e-3, "kN")])
def test_unit_error_names_the_units_flag_on_the_command_line(rig_log, paper_a_toml, tmp_path, capsys,
                                                              column, scale, unit):
    import pandas as pd

    from heavecomp.diagnosis.data import load_run
    from heavecomp.params import load

    df = pd.read_csv(rig_log)
    df[column] *= scale
    f = tmp_path / "slipped.csv"
    df.to_csv(f, index=False)
    with pytest.raises(InputError) as e:
        load_run(f, load(paper_a_toml))
    assert f"looks like {unit}" in str(e.value) and "--" not in str(e.value)
    assert e.value.option == "units" and e.value.example == f"{column}={unit}"
    code, err = _cli(["diagnose", f, "--params", paper_a_toml, "--out", tmp_path / "o"], capsys)
    assert code == 2 and err.endswith(f"; use --units {column}={unit}"), err
    # the flag it names works: the same file with the unit declared passes the check
    run = load_run(f, load(paper_a_toml), units={column: unit})
    assert np.nanmean(run[column]) == pytest.approx(np.nanmean(pd.read_csv(rig_log)[column]), rel=1e-9)


def test_staging_folder_is_shown_as_the_out_the_user_gave(tmp_path, capsys):
    """A library message about the folder it writes (the staging folder) names the user's --out."""
    import json

    from heavecomp.campaign import spec
    from heavecomp.report.output import MARKER

    out = tmp_path / "camp"
    out.mkdir()
    (out / MARKER).write_text("")
    (out / "manifest.json").write_text(json.dumps({"fingerprint": "another campaign"}))
    code, err = _cli(["campaign", "default", "--out", out, "--workers", "1"], capsys)
    assert code == 2 and f"--out {out}: holds results of a different campaign" in err, err
    assert ".partial" not in err
    assert spec.default().fingerprint() in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["camp"]  # no staging folder left behind
