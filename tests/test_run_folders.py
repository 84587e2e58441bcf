"""Issue 13.4: self-describing run folders — resolved parameters, version, command line, units; reruns
from the folder's own parameter file give the same numbers; timings kept out of tracked results."""

import json

import numpy as np
import pytest

from heavecomp.params import dumps, paper_a
from heavecomp.simulate import excitation

from _cli import run


_run = run  # in this process: these tests check the folders the commands write


@pytest.fixture
def rig_with_heave_file(tmp_path):
    """rig/rig.toml whose heave comes from rig/data/heave.csv (a relative path)."""
    rig = tmp_path / "rig"
    (rig / "data").mkdir(parents=True)
    t = np.arange(0, 100.0, 0.1)
    z = excitation.sine(0.8, 10.0, 20.0, 100.0, 0.1).z
    (rig / "data" / "heave.csv").write_text("t,heave\n" + "\n".join(f"{a:.3f},{b:.12g}" for a, b in zip(t, z)))
    p = paper_a().replace(heave={"kind": "file", "path": "data/heave.csv", "amplitude": None, "period": None,
                                 "ramp": None})
    (rig / "rig.toml").write_text(dumps(p))
    return rig / "rig.toml"


def test_params_copy_elsewhere_keeps_the_heave_file(rig_with_heave_file, tmp_path):
    other = tmp_path / "other"
    other.mkdir()
    r = _run("params", str(rig_with_heave_file), "-o", str(other / "rig.toml"), "-q")
    assert r.returncode == 0, r.stderr
    a = _run("simulate", str(rig_with_heave_file), "--duration", "60", "--out", str(tmp_path / "a"), "-q")
    b = _run("simulate", str(other / "rig.toml"), "--duration", "60", "--out", str(tmp_path / "b"), "-q")
    assert a.returncode == 0 and b.returncode == 0, (a.stderr, b.stderr)
    ma = json.loads((tmp_path / "a" / "metrics.json").read_text())
    mb = json.loads((tmp_path / "b" / "metrics.json").read_text())
    assert ma["wob_std"] == mb["wob_std"] and ma["wob_std"] > 1e3


def test_simulate_folder_reruns_from_its_own_parameter_file(rig_with_heave_file, tmp_path):
    first = tmp_path / "first"
    r = _run("simulate", str(rig_with_heave_file), "--duration", "60", "--out", str(first), "--friction", "stribeck")
    assert r.returncode == 0, r.stderr
    m = json.loads((first / "metrics.json").read_text())
    st = m["provenance"]
    assert st["parameters"] == "params.toml" and st["heavecomp_version"]
    assert st["command"].startswith("heavecomp simulate ") and "--friction stribeck" in st["command"]
    # the folder carries its heave: move it away from the rig and re-run from its own file
    moved = tmp_path / "elsewhere" / "run"
    moved.parent.mkdir()
    first.rename(moved)
    (rig_with_heave_file.parent / "data" / "heave.csv").unlink()
    r2 = _run("simulate", str(moved / "params.toml"), "--duration", "60", "--out", str(tmp_path / "second"))
    assert r2.returncode == 0, r2.stderr
    a = np.loadtxt(moved / "timeseries.csv", delimiter=",", skiprows=1)
    b = np.loadtxt(tmp_path / "second" / "timeseries.csv", delimiter=",", skiprows=1)
    np.testing.assert_array_equal(a, b)
    m2 = json.loads((tmp_path / "second" / "metrics.json").read_text())
    assert m2["heave"].pop("source").endswith("elsewhere/run/heave.csv")  # the copy, not the rig's file
    assert m["heave"].pop("source").endswith("rig/data/heave.csv")
    assert {k: v for k, v in m2.items() if k != "provenance"} == {k: v for k, v in m.items() if k != "provenance"}


def test_units_for_every_column_and_metric(paper_a_toml, tmp_path):
    import pandas as pd

    out = tmp_path / "run"
    assert _run("simulate", str(paper_a_toml), "--duration", "30", "--out", str(out), "-q").returncode == 0
    ts = pd.read_csv(out / "timeseries.csv")
    units = pd.read_csv(out / "timeseries.units.csv", index_col="column")["unit"]
    assert list(units.index) == list(ts.columns)
    assert units["wob"] == "N" and units["t"] == "s" and units["pressure"] == "Pa"
    m = json.loads((out / "metrics.json").read_text())
    numeric = {k for k, v in m.items() if isinstance(v, (int, float, list)) and not isinstance(v, bool)}
    numeric |= {k for k, v in m["heave"].items() if isinstance(v, (int, float))}
    assert numeric <= set(m["units"]), numeric - set(m["units"])
    assert m["units"]["wob_std"] == "N" and m["units"]["stick_fraction"] == "-"
    # the wall time is machine-dependent: kept out of the tracked result
    assert not any("wall" in k for k in m)
    assert json.loads((out / "timings.json").read_text())["metrics.json"]["wall_time_s"] > 0


def test_analyse_and_stickslip_folders_are_self_describing(paper_a_toml, tmp_path):
    from heavecomp.report.provenance import units_of

    assert _run("analyse", str(paper_a_toml), "--out", str(tmp_path / "an"), "--points", "40", "-q").returncode == 0
    assert _run("stickslip", "default", "--duration", "1", "--out", str(tmp_path / "ss"), "-q").returncode == 0
    for f in (tmp_path / "an" / "analysis.json", tmp_path / "ss" / "metrics.json"):
        d = json.loads(f.read_text())
        assert units_of(d)[1] == [], f  # every number has a unit
        assert d["provenance"]["parameters"] == "params.toml"
        assert (f.parent / "params.toml").exists()
    fr = tmp_path / "an" / "frequency_response.units.csv"
    assert "omega,rad/s" in fr.read_text()
    assert "velocity,m/s" in (tmp_path / "ss" / "timeseries.units.csv").read_text()


def test_units_table_knows_when_it_does_not_know():
    from heavecomp.report.provenance import units_of

    units, missing = units_of({"wob_std": 1.0, "mystery_number": 2.0, "F_C_N": 3.0, "name": "x"})
    assert units == {"F_C_N": "N", "wob_std": "N"} and missing == ["mystery_number"]


def test_split_timings():
    from heavecomp.report.provenance import split_timings

    keep, t = split_timings({"a": 1, "wall_time_s": 2.0, "r": [{"wall_time": 1, "x": 2}],
                             "s": {"solve_time_ms_p99": 3, "wallet": 4}})
    assert keep == {"a": 1, "r": [{"x": 2}], "s": {"wallet": 4}}
    assert t == {"wall_time_s": 2.0, "r": [{"wall_time": 1}], "s": {"solve_time_ms_p99": 3}}


def test_simulation_result_to_pandas():
    import pandas as pd

    from heavecomp.simulate import simulate

    res = simulate(paper_a("stribeck"), 30.0, rate=10.0)
    df = res.to_pandas()
    assert df.index.name == "time" and df.index[1] == pytest.approx(0.1)
    np.testing.assert_array_equal(df["wob"].to_numpy(), res["wob"])
    assert df["stuck"].dtype == bool and df["stuck"].sum() == int((res["stuck"] > 0.5).sum())
    assert df.attrs["units"]["wob"] == "N" and df.attrs["units"]["time"] == "s"
    assert set(df.attrs["units"]) == {"time", *df.columns}
    flat = res.to_pandas(["wob", "stroke"], time_index=False)  # python-control's layout
    assert list(flat.columns) == ["time", "wob", "stroke"] and isinstance(flat.index, pd.RangeIndex)
    with pytest.raises(KeyError, match="no channel 'wab'"):
        res.to_pandas(["wab"])


@pytest.mark.parametrize("name", ["paper_a_wob", "friction_laws"])
def test_scenario_rerun_writes_the_same_bytes(tmp_path, name):
    """A re-run leaves git clean: every tracked output is byte-identical; wall times only in timings.json."""
    import runpy
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    import shutil

    out = tmp_path / "run"
    outs = [tmp_path / "first", out]
    for k in range(2):  # re-run into the same folder, as over reports/<name>
        mod = runpy.run_path(str(root / "scenarios" / f"{name}.py"), run_name="scenario")
        assert mod["main"](["--quick", "--out", str(out)]) == 0
        if k == 0:
            shutil.copytree(out, outs[0])
    files = sorted(p.name for p in outs[0].iterdir() if p.name != "timings.json")
    assert {"metrics.json", "report.md", "report.html"} <= set(files)
    assert files == sorted(p.name for p in outs[1].iterdir() if p.name != "timings.json")
    for f in files:
        assert (outs[0] / f).read_bytes() == (outs[1] / f).read_bytes(), f"{f} differs between two runs"
    m = json.loads((outs[0] / "metrics.json").read_text())
    assert m["provenance"]["command"] == f"python scenarios/{name}.py --quick --out {out}"
    assert "wall" not in json.dumps({k: v for k, v in m.items() if k != "units"})
    assert (root / "reports" / ".gitignore").read_text().split() == ["timings.json"]


@pytest.mark.parametrize("rel", ["reports/diagnosis_example/diagnosis.json", "reports/emps_identification/metrics.json",
                                 "reports/seal_friction/metrics.json", "reports/campaign_default/statistics.json"])
def test_every_number_of_the_other_commands_outputs_has_a_unit(rel):
    """diagnose, identify and campaign results: the units table covers every number (timings aside)."""
    from pathlib import Path

    from heavecomp.report.provenance import split_timings, units_of

    data, _ = split_timings(json.loads((Path(__file__).resolve().parents[1] / rel).read_text()))
    units, missing = units_of(data)
    assert missing == [] and units


def test_json_results_rounded_above_last_bit_noise():
    from heavecomp.report.provenance import round_floats

    a, b = 97202.81366735144, 97202.8136673514  # the same WOB mean from two machines
    assert a != b and round_floats({"x": [a]}) == round_floats({"x": [b]})
    assert round_floats(0.1 + 0.2) == 0.3 and round_floats(3) == 3 and round_floats(True) is True


def test_campaign_runs_csv_has_a_unit_per_column(tmp_path):
    import shutil
    from pathlib import Path

    import pandas as pd

    from heavecomp.report.provenance import write_units_csv

    src = Path(__file__).resolve().parents[1] / "reports" / "campaign_default" / "runs.csv"
    shutil.copy(src, tmp_path / "runs.csv")
    head = pd.read_csv(tmp_path / "runs.csv", nrows=1).columns
    write_units_csv(tmp_path / "runs.csv", list(head))
    u = pd.read_csv(tmp_path / "runs.units.csv", index_col="column", keep_default_na=False)["unit"]
    assert list(u.index) == list(head)
    assert u["wob_std"] == "N" and u["n_stick"] == "count" and u["dev_000"] == "count" and u["hs"] == "m"


def test_a_command_that_takes_no_heave_needs_no_heave_file(rig_with_heave_file, tmp_path):
    """Issue 21.2: the diagnosis (whose heave is the measured run's) and analyse crashed in
    write_params, after all their work, when [heave] path named a file that was not there."""
    from heavecomp.errors import ParameterError
    from heavecomp.params import load
    from heavecomp.report.provenance import finish

    params = load(rig_with_heave_file)
    (rig_with_heave_file.parent / "data" / "heave.csv").unlink()
    out = tmp_path / "diag"
    finish(out, params=params, json_files=(), heave_used=False)
    back = load(out / "params.toml")
    assert back.heave is None and not (out / "heave.csv").exists()  # neither copied nor recorded
    assert back.compensator == params.compensator
    with pytest.raises(ParameterError, match=r"^heave.path: .*heave.csv is not a file"):
        finish(tmp_path / "sim", params=params, json_files=())  # a command that uses the heave: named, one line
    r = _run("analyse", str(rig_with_heave_file), "--points", "20", "--out", str(tmp_path / "a"), "-q")
    assert r.returncode == 0, r.stderr
    assert "[heave]" not in (tmp_path / "a" / "params.toml").read_text()


@pytest.mark.slow
def test_diagnose_with_a_missing_heave_file_in_the_nominal_set(rig_with_heave_file, tmp_path):
    """The diagnosis takes its heave from the measured run: a nominal [heave] path that does not exist
    is neither read, copied nor recorded (it crashed in write_params after the whole fit)."""
    from heavecomp.params import load
    from heavecomp.simulate import simulate

    res = simulate(load(rig_with_heave_file), 80.0, rate=20.0)
    res.to_csv(tmp_path / "run.csv")
    (rig_with_heave_file.parent / "data" / "heave.csv").unlink()
    out = tmp_path / "d"
    r = _run("diagnose", str(tmp_path / "run.csv"), "--params", str(rig_with_heave_file), "--out", str(out),
             "--candidates", "sensor_gain", "-q")
    assert r.returncode == 0, r.stderr
    assert json.loads((out / "diagnosis.json").read_text())["verdict"]["effect"]
    assert "[heave]" not in (out / "params.toml").read_text() and not (out / "heave.csv").exists()


def test_a_declared_unit_beats_the_name_lookup():
    """Issue 21.6: units attached where each value is made -- a stroke offset in m is not given the N
    that the key name 'offset' has elsewhere (the diagnosis.json defect)."""
    from heavecomp.report.provenance import declare_units, strip_declared, undeclared, units_of

    guessed, _ = units_of({"stroke": {"offset": 0.01}})
    assert guessed == {"offset": "N"}  # what the name alone gives: wrong for a stroke
    r = {"stroke": declare_units({"offset": 0.01, "gain": 1.02}, {"offset": "m", "gain": "-"}),
         "wob": declare_units({"offset": 250.0}, {"offset": "N"}),
         "noise": 1.0}
    declare_units(r, {"window": "s"})
    r["window"] = [0.0, 30.0]
    units, missing = units_of(r)
    assert units["offset"] == "m" and units["wob.offset"] == "N" and units["gain"] == "-" and units["window"] == "s"
    assert missing == ["noise"] and undeclared(r) == ["noise"]
    assert "_units" not in json.dumps(strip_declared(r))


def test_simulate_metrics_declare_every_unit(paper_a_toml, tmp_path):
    """metrics.json of simulate cannot name a wrong unit: every number's unit is declared where it is made."""
    from heavecomp.params import load
    from heavecomp.report.provenance import finish, undeclared
    from heavecomp.report.simulation import write_outputs
    from heavecomp.simulate import simulate
    from heavecomp.simulate.core import SimulationResult

    params = load(paper_a_toml).replace(heave={"kind": "jonswap", "hs": 2.0, "tp": 10.0, "amplitude": None,
                                                "period": None})
    res = simulate(params, 20.0)
    assert set(res.metrics()) <= set(SimulationResult.METRIC_UNITS)  # a new metric needs its unit
    m = write_outputs(res, tmp_path)
    assert undeclared(m) == []
    finish(tmp_path, params=params, csv_files=("timeseries.csv",))
    written = json.loads((tmp_path / "metrics.json").read_text())
    assert "_units" not in json.dumps(written)
    u = written["units"]
    assert u["wob_std"] == "N" and u["stroke_max"] == "m" and u["hs"] == "m" and u["repeat_period"] == "s"
    assert u["n_stick"] == "count" and u["k_eff_eq14"] == "N/m" and u["stats_window"] == "s"


def test_campaign_metrics_declare_every_unit():
    from pathlib import Path

    from heavecomp.report.campaign import summary
    from heavecomp.report.provenance import undeclared, units_of

    st = json.loads((Path(__file__).resolve().parents[1] / "reports" / "campaign_default" / "statistics.json")
                    .read_text())
    m = summary(st)
    assert undeclared(m) == []
    units, missing = units_of(m)
    assert missing == [] and units["band_exits_per_hour"] == "1/h" and units["dev_max_in_exposure"] == "N"
