"""Issue 21.6: the pandas doors take what a user hands them -- ``load_run(DataFrame)`` reads the frame,
``runs_frame("camp/")`` reads the folder -- and anything else is one line, never a traceback."""

import numpy as np
import pytest

from heavecomp.errors import InputError


@pytest.fixture(scope="module")
def sim():
    from heavecomp.params import paper_a
    from heavecomp.simulate import simulate

    return simulate(paper_a(), 90.0, rate=20.0)


def test_load_run_reads_a_frame_like_the_file_it_would_be_written_to(sim, tmp_path):
    from heavecomp.diagnosis.data import load_run
    from heavecomp.params import paper_a

    sim.to_csv(tmp_path / "run.csv")
    from_file = load_run(tmp_path / "run.csv", paper_a())
    from_frame = load_run(sim.to_pandas(), paper_a())  # time as the index
    flat = load_run(sim.to_pandas(time_index=False).rename(columns={"time": "t"}), paper_a())  # time as a column
    for run in (from_frame, flat):
        np.testing.assert_allclose(run.t, from_file.t, rtol=0, atol=1e-9)
        for c in ("heave", "stroke", "pressure", "wob"):
            np.testing.assert_allclose(run[c], from_file[c], rtol=1e-9)  # the CSV keeps 10 digits


def test_load_run_frame_takes_units_and_columns(sim):
    from heavecomp.diagnosis.data import load_run
    from heavecomp.params import paper_a

    df = sim.to_pandas().rename(columns={"wob": "WOB_kN"})
    df["WOB_kN"] = df["WOB_kN"] / 1e3
    by_header = load_run(df, paper_a())  # the unit in the header, as for a file with this header
    np.testing.assert_allclose(by_header["wob"], sim["wob"], rtol=1e-12)
    assert by_header.measurement["units"]["wob"] == "kN"
    run = load_run(df.rename(columns={"WOB_kN": "W"}), paper_a(), columns={"wob": "W"}, units={"wob": "kN"})
    np.testing.assert_allclose(run["wob"], sim["wob"], rtol=1e-12)
    assert run.measurement["units"]["wob"] == "kN" and run.measurement["columns"]["wob"] == "W"
    without = load_run(df.rename(columns={"WOB_kN": "W"}), paper_a())  # WOB is optional (contract schema 3)
    assert "wob" not in without.sensors and any("no column 'wob'" in w and "wob=NAME" in w for w in without.warnings)


@pytest.mark.parametrize("rename, kw, fragment", [
    ({"pressure": "pressure [mm]"}, {}, "column 'pressure' ('pressure [mm]'): unit 'mm' is a length unit"),
    ({}, {"columns": {"pressure": "nope"}}, "column 'pressure' mapped to 'nope': no such column"),
    ({"pressure": "p_bar"}, {"units": {"pressure": "kPa"}}, "the header says bar, the declared unit is kPa"),
])
def test_load_run_frame_is_checked_as_the_file_would_be(sim, tmp_path, rename, kw, fragment):
    """The frame's columns and units take the file reader's checks (one path): a header unit of the wrong kind,
    a mapping to no column, a header unit the declared one contradicts are one line naming the column, the
    same line as for the CSV file with that header."""
    from heavecomp.diagnosis.data import load_run
    from heavecomp.errors import DataError
    from heavecomp.params import paper_a

    df = sim.to_pandas()[["heave", "stroke", "pressure", "wob"]].rename(columns=rename)
    with pytest.raises(DataError) as e:
        load_run(df, paper_a(), **kw)
    msg = str(e.value)
    assert fragment in msg and msg.startswith("<DataFrame>: ") and "\n" not in msg
    f = tmp_path / "r.csv"
    df.to_csv(f)
    with pytest.raises(DataError) as e2:
        load_run(f, paper_a(), **kw)
    assert str(e2.value).split(": ", 1)[1].split("; header:")[0] == msg.split(": ", 1)[1].split("; header:")[0]


def test_runs_frame_reads_a_campaign_folder(tmp_path):
    from heavecomp.campaign.execute import read_table
    from heavecomp.campaign.tables import histograms_frame, runs_frame

    camp = tmp_path / "camp"
    camp.mkdir()
    (camp / "runs.csv").write_text("run_id,regime,variant,seed,n_stick,wob_std,dev_under,dev_000,dev_001,dev_over,"
                                   "peak_000,peak_over\n"
                                   "a,none,base,1,3,1200.5,0,1,2,0,3,0\n"
                                   "b,stribeck,base,2,7,1500.25,0,0,3,0,1,2\n")
    by_dict = runs_frame(read_table(camp / "runs.csv"))
    for given in (f"{camp}/", camp, camp / "runs.csv"):
        df = runs_frame(given)
        assert df.equals(by_dict) and list(df["n_stick"]) == [3, 7] and df["n_stick"].dtype == np.int64
    h = histograms_frame(str(camp), 10e3, 2)
    assert int(h["count"].sum()) == 1 + 2 + 3 + 3 + 1 + 2
    assert set(h["run_id"]) == {"a", "b"}


@pytest.mark.parametrize("given, fragment", [("nowhere/", "nowhere/runs.csv: results table not found"),
                                             (3, "expected a campaign folder")])
def test_runs_frame_refuses_in_one_line(tmp_path, monkeypatch, given, fragment):
    from heavecomp.campaign.tables import runs_frame

    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError) as e:
        runs_frame(given)
    assert fragment in str(e.value) and "\n" not in str(e.value)


def test_load_run_frame_derives_the_wob_from_the_hook_load_as_a_file(sim, tmp_path):
    """A frame with a hook load and no WOB column: W = string weight - hook load, as for a file (the string
    weight from the parameter file's [measurement] table or the keyword); without one, one line naming the
    column and the key."""
    from heavecomp.diagnosis.data import load_run
    from heavecomp.errors import DataError
    from heavecomp.params import load, paper_a
    from heavecomp.params.cmc import save

    W_s = 1.5e6
    df = sim.to_pandas()[["heave", "stroke", "pressure", "wob"]]
    df = df.assign(hook_load=W_s - df["wob"]).drop(columns="wob")
    run = load_run(df, paper_a(), string_weight=W_s)
    np.testing.assert_allclose(run["wob"], sim["wob"], rtol=1e-9)
    assert run.measurement["wob_from"]["string_weight_N"] == W_s
    toml = tmp_path / "p.toml"
    save(paper_a(), toml)
    toml.write_text(toml.read_text() + f"\n[measurement]\nstring_weight = {W_s}\n")
    np.testing.assert_allclose(load_run(df, load(toml))["wob"], sim["wob"], rtol=1e-9)
    with pytest.raises(DataError) as e:
        load_run(df, paper_a())
    assert "'hook_load'" in str(e.value) and "string_weight" in str(e.value) and "\n" not in str(e.value)
