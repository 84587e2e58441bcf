"""Nothing a user types into a scenario script gives a traceback (brief: bad input): a bad ``--out``
is one line naming the flag and exit code 2, before any work; any InputError raised later is one
line and exit 2 as well."""

import importlib.util
from pathlib import Path

import pytest

from heavecomp.errors import InputError
from heavecomp.report.scenario import run

#: arguments a scenario requires besides --out
REQUIRED = {"diagnosis_validation": ["--set", "tuning"]}
SCENARIOS = sorted(p for p in (Path(__file__).resolve().parents[1] / "scenarios").glob("*.py"))


def _load(path):
    spec = importlib.util.spec_from_file_location(f"scenario_{path.stem}", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_bad_out_is_one_line_exit_2(path, tmp_path, capsys):
    if "parse_args(" not in path.read_text():
        pytest.skip("has no --out (example_run.py rewrites the shipped example log)")
    mod = _load(path)
    blocker = tmp_path / "a_file"
    blocker.write_text("x")
    with pytest.raises(SystemExit) as exc:
        run(mod.main, [*REQUIRED.get(path.stem, []), "--out", str(blocker / "sub")])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--out" in err[0] and "Traceback" not in err[0], err


def test_input_error_inside_a_scenario_is_one_line(capsys):
    def main(argv=None):
        raise InputError("heave.file 'x.csv': not found")

    assert run(main, []) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["scenario: error: heave.file 'x.csv': not found"]
