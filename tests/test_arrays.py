"""Labelled arrays (issue 33 item 3): campaign, fleet and monitor results as xarray.Datasets with
coordinates and units, written by the commands as netCDF and read back equal."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from heavecomp.data import EXAMPLE_PARAMS, EXAMPLE_RUN

from heavecomp.io.arrays import open_dataset

from _cli import run
from test_campaign_table import TINY

xr = None  #: xarray, imported by the first test of this module a process runs (below), not at collection


@pytest.fixture(scope="module", autouse=True)
def _xarray():
    """Every test here needs xarray (skipped, saying why, without it). Imported here rather than at the
    module's top: collection imports every test module in every pytest-xdist worker, and xarray with
    pandas costs ~0.7 s of CPU each."""
    global xr
    xr = pytest.importorskip("xarray", reason="xarray not installed: pip install 'heavecomp[arrays]'")

MAP = "t=Time,heave=MRU_heave,stroke=CMC_pos,pressure=P_main,wob=WOB"
UNITS = "t=ms,pressure=bar,wob=kN,stroke=mm"


def _roundtrip(ds, path):
    from heavecomp.io.arrays import open_dataset, write

    write(ds, path)
    back = open_dataset(path)
    xr.testing.assert_identical(back, ds)  # values, coordinates and every attribute (units)
    return back


def test_campaign_netcdf_round_trip_with_sea_state_and_regime_coordinates(tmp_path):
    from heavecomp.campaign.execute import read_table
    from heavecomp.campaign.tables import to_xarray

    (tmp_path / "tiny.toml").write_text(TINY)
    r = run("campaign", tmp_path / "tiny.toml", "--out", tmp_path / "camp", "--workers", "1", "--format", "netcdf")
    assert r.returncode == 0, r.stderr
    ds = open_dataset(tmp_path / "camp" / "campaign.nc")
    mine = to_xarray(tmp_path / "camp", name="tiny-table")
    xr.testing.assert_identical(ds, mine)
    _roundtrip(mine, tmp_path / "again.nc")
    assert set(ds.dims) == {"sea_state", "regime", "variant", "seed"}
    assert list(ds["regime"].values) == ["none", "stribeck"] and ds["hs"].attrs["units"] == "m"
    assert ds["wob_std"].attrs["units"] == "N" and ds["frac_outside_band"].attrs["units"] == "-"
    table = read_table(tmp_path / "camp" / "runs.csv")
    for k in range(len(table["run_id"])):  # every run is the cell of its labels
        cell = ds["wob_std"].sel(sea_state=int(table["sea_state"][k]), regime=table["regime"][k],
                                 variant=table["variant"][k], seed=int(table["seed"][k]))
        assert float(cell) == pytest.approx(float(table["wob_std"][k]), rel=1e-12)
        assert float(ds["hs"].sel(sea_state=int(table["sea_state"][k]))) == pytest.approx(float(table["hs"][k]))
    # the zero-probability cell is not simulated: no sea state of it
    assert ds.sizes["sea_state"] == 3


@pytest.fixture(scope="module")
def fleet_dir(tmp_path_factory):
    base = tmp_path_factory.mktemp("fleet")
    logs = base / "logs"
    logs.mkdir()
    shutil.copy(EXAMPLE_RUN, logs / "a.csv.gz")
    import gzip

    head = gzip.decompress(EXAMPLE_RUN.read_bytes()).decode().splitlines()[:301]
    (logs / "b.csv").write_text("\n".join(head) + "\n")  # 30 s: fails in its task (too short), a padded log
    r = run("fleet", logs, "--params", EXAMPLE_PARAMS, "--out", base / "out", "--workers", "1", "--columns", MAP,
            "--units", UNITS, "--format", "netcdf")
    return base, r


def test_fleet_netcdf_round_trip_over_logs_and_segments(fleet_dir):
    from heavecomp.report.fleet import to_xarray

    base, r = fleet_dir
    if r.returncode != 0:
        pytest.fail(r.stderr)
    ds = open_dataset(base / "out" / "fleet.nc")
    mine = to_xarray(base / "out", source=str(base / "logs"))
    xr.testing.assert_identical(ds, mine)
    assert list(ds["log"].values) == ["a", "b"] and list(ds["status"].values) == ["done", "failed"]
    seg = json.loads((base / "out" / "logs" / "a" / "monitor.json").read_text())["segments"]
    assert np.allclose(ds["wob_setpoint"].sel(log="a").values[:len(seg)], [s["operating_point"]["wob_setpoint"] for s in seg])
    assert np.isnan(ds["start"].sel(log="b").values).all() and ds["start"].attrs["units"] == "s"
    _roundtrip(mine, base / "again.nc")


def test_monitor_netcdf_round_trip(tmp_path):
    from heavecomp.io.arrays import monitor_dataset

    r = run("monitor", EXAMPLE_RUN, "--params", EXAMPLE_PARAMS, "--out", tmp_path / "m", "--columns", MAP,
            "--units", UNITS, "--format", "netcdf")
    assert r.returncode == 0, r.stderr
    mon = json.loads((tmp_path / "m" / "monitor.json").read_text())
    ds = _roundtrip(monitor_dataset(mon), tmp_path / "again.nc")
    back = open_dataset(tmp_path / "m" / "monitor.nc")
    assert float(back["start"][0]) == mon["segments"][0]["start"] == float(ds["start"][0])
    assert ds.sizes["segment"] == len(mon["segments"]) and ds.sizes["change"] == len(mon["changes"])
    assert set(ds["component"].values) == set(mon["segments"][0]["gap_to_noise"])
    assert ds["gap_to_noise"].attrs["units"] == "noise sigma"
