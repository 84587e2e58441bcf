"""The example measured run shipped with the package (issue 13 item 6): it reads in its rig shape,
is reproducible from its generator, and diagnoses end to end in one command."""

from __future__ import annotations

import gzip
import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from heavecomp.data import EXAMPLE_PARAMS, EXAMPLE_RUN

ROOT = Path(__file__).resolve().parents[1]
MAP = "t=Time,heave=MRU_heave,stroke=CMC_pos,pressure=P_main,wob=WOB"
UNITS = "t=ms,pressure=bar,wob=kN,stroke=mm"
PARQUET = EXAMPLE_RUN.with_name("rig_log_example.parquet")


def _scenario():
    spec = importlib.util.spec_from_file_location("example_run", ROOT / "scenarios" / "example_run.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_example_is_rig_shaped_and_reads_to_si():
    from heavecomp.diagnosis.data import load_run
    from heavecomp.io.series import parse_mapping
    from heavecomp.params import load

    header = gzip.decompress(EXAMPLE_RUN.read_bytes()).decode().splitlines()[0]
    assert header == "Time,MRU_heave,CMC_pos,P_main,WOB"
    p = load(EXAMPLE_PARAMS)
    runs = [load_run(f, p, columns=parse_mapping(MAP), units=parse_mapping(UNITS)) for f in (EXAMPLE_RUN, PARQUET)]
    for run in runs:
        assert run.t.size == 6001 and abs(run.dt - 0.1) < 1e-9
        # SI after conversion: WOB around W_0, pressure around p_0, stroke in metres
        assert abs(np.mean(run["wob"]) / p.operating_point.wob_setpoint - 1) < 0.05
        assert abs(np.mean(run["pressure"]) / p.p0 - 1) < 0.05
        assert 0.05 < np.std(run["stroke"]) < 2.0
    for c in ("heave", "stroke", "pressure", "wob"):
        np.testing.assert_allclose(runs[0][c], runs[1][c], rtol=1e-12)
    assert runs[1].measurement["format"] == "parquet" and runs[0].measurement["compression"] == "gzip"


def test_example_is_reproducible_from_its_generator(tmp_path):
    """scenarios/example_run.py rewrites the shipped CSV byte for byte (seeded; gzip mtime 0)."""
    mod = _scenario()
    mod.write(tmp_path / "rig_log_example.csv.gz", tmp_path / "rig_log_example.toml")
    assert (tmp_path / "rig_log_example.csv.gz").read_bytes() == EXAMPLE_RUN.read_bytes()
    assert (tmp_path / "rig_log_example.toml").read_text() == EXAMPLE_PARAMS.read_text()


@pytest.mark.slow
def test_example_diagnoses_end_to_end(tmp_path, capsys):
    """The README's one command, on the Parquet copy: exit 0, the honest verdict 'none' (the run was
    made with the nominal parameters), and diagnosis.json records how the log was read."""
    from heavecomp.cli import main

    rc = main(["diagnose", str(PARQUET), "--params", str(EXAMPLE_PARAMS), "--out", str(tmp_path),
               "--columns", MAP, "--units", UNITS, "--quiet"])
    out = capsys.readouterr()
    assert rc == 0, out.err
    d = json.loads((tmp_path / "diagnosis.json").read_text())
    assert d["verdict"]["effect"] == "none", d["verdict"]
    m = d["measurement"]
    assert m["format"] == "parquet" and m["units"]["t"] == "ms"
    assert "wob: kN -> N (x 1000)" in m["conversions"]
