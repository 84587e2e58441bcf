"""Sea-state campaigns: batch == single runs, resumption, Dask, statistics method, bad input."""

from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from heavecomp.campaign import spec
from heavecomp.errors import InputError, ParameterError

ROOT = Path(__file__).resolve().parents[1]

TINY = """
[campaign]
name = "tiny"
duration = 90.0
seeds = 2
regimes = ["none", "rotating_eq7", "stribeck"]
chunk_size = 4

[scatter]
hs = [0.5, 1.0]
tp = [9.0, 12.0]
probability = [[0.5, 0.2], [0.3, 0.0]]

[band]
tolerance = 20e3
exposure = 1800.0

[outputs]
deviation_max = 100e3
bins = 80
figures = false
"""


@pytest.fixture(scope="module")
def tiny():
    return spec.loads(TINY, source="tiny.toml")


def _rows_by_id(path):
    from heavecomp.campaign.execute import read_table

    t = read_table(path)
    return {rid: {k: v[i] for k, v in t.items()} for i, rid in enumerate(t["run_id"])}


# ---------------------------------------------------------------- batch == single runs
@pytest.mark.slow
def test_batch_equals_single_runs(tiny):
    """Every statistic of the batch path equals the same numbers computed from simulate()'s series."""
    from heavecomp.campaign.batch import simulate_batch
    from heavecomp.simulate import simulate

    runs = [r for r in tiny.runs() if r.sea_state == 2][:3]  # one heave realisation, three regimes
    assert {r.regime for r in runs} == {"none", "rotating_eq7", "stribeck"}
    rows = simulate_batch(tiny, runs)
    o = tiny.outputs
    for run, row in zip(runs, rows):
        res = simulate(tiny.params_for(run), tiny.settings.duration)
        m = res.metrics()
        for key in ("wob_mean", "wob_std", "wob_min", "wob_max", "stick_fraction", "stroke_max", "pressure_min",
                    "pressure_max"):
            assert row[key] == pytest.approx(m[key], rel=1e-10, abs=1e-9), (run.regime, key)
        assert row["n_stick"] == m["n_stick"] and row["n_breakaway"] == m["n_breakaway"]
        win = res.window()
        dW = res["wob"][win] - run_w0(tiny, run)
        assert row["n_samples"] == dW.size
        # histogram of dW on the campaign's bins
        x = (dW + o.deviation_max) / (2 * o.deviation_max) * o.bins
        ref = np.bincount(np.clip(np.floor(x).astype(int) + 1, 0, o.bins + 1), minlength=o.bins + 2)
        from heavecomp.campaign.batch import hist_columns

        dev_cols, _ = hist_columns(o.bins)
        assert [row[c] for c in dev_cols] == ref.tolist()
        out = np.abs(dW) > 20e3
        assert row["frac_outside_band"] == pytest.approx(out.mean(), abs=1e-15)
        assert row["n_band_exits"] == int(np.sum(~out[:-1] & out[1:]))
        assert row["heave_hs"] == pytest.approx(4 * np.std(res["heave"][win]), rel=1e-9)


@pytest.mark.parametrize("hs, tp, gamma, seed, ramp, duration, spacing", [
    (1.0, 10.0, 3.3, 0, 20.0, 300.0, 0.005), (0.3, 16.0, 1.0, 7, 32.0, 100.0, 0.004), (2.0, 8.0, 5.0, 3, 0.0, 50.0, 0.01)])
def test_fast_jonswap_is_bit_identical_to_excitation(hs, tp, gamma, seed, ramp, duration, spacing):
    """The campaign's heave synthesis (cached spectrum, ramp applied on t < T_r only) restates
    excitation.jonswap: pinned to it exactly."""
    from heavecomp.campaign.batch import jonswap_samples
    from heavecomp.simulate import excitation

    ref = excitation.jonswap(hs, tp, gamma, seed, ramp, duration, spacing)
    cache = {}
    for _ in range(2):  # second call uses the cached spectrum
        got = jonswap_samples(hs, tp, gamma, seed, ramp, duration, spacing, cache)
        for a, b in ((got.z, ref.z), (got.dz, ref.dz), (got.ddz, ref.ddz)):
            assert np.array_equal(a, b)


def run_w0(camp, run):
    return camp.params_for(run).operating_point.wob_setpoint


def test_realised_heave_and_quasi_static_wob(tiny):
    """Realised H_s of the JONSWAP heave is near the target, and without friction the WOB std tends to the
    quasi-static estimate k_eff * std(z_h) (paper A eqs. 13-14) as the sea gets slower: the dynamic
    amplification shrinks with T_p (the eigenfrequency is above the wave frequency)."""
    from heavecomp.campaign.batch import simulate_batch

    camp = dataclasses.replace(tiny, settings=dataclasses.replace(tiny.settings, duration=400.0))
    runs = [spec.Run(f"tp{tp:g}", 0, 0.5, tp, 1.0, "none", "base", 7) for tp in (8.0, 12.0, 25.0)]
    rows = simulate_batch(camp, runs)
    k_eff = tiny.base_params().k_eff
    ratios = []
    for run, row in zip(runs, rows):
        assert row["heave_hs"] == pytest.approx(run.hs, rel=0.2)
        assert row["stick_fraction"] == 0.0
        ratios.append(row["wob_std"] / (k_eff * row["heave_hs"] / 4))
    assert ratios[0] > ratios[1] > ratios[2] > 0.98, ratios
    assert ratios[2] == pytest.approx(1.0, abs=0.05), ratios


# ---------------------------------------------------------------- resumption
def test_resume_skips_finished_runs_and_gives_the_same_table(tiny, tmp_path):
    from heavecomp.campaign.execute import TABLE, run_campaign

    n = len(tiny.runs())
    a = run_campaign(tiny, tmp_path / "a", workers=1, limit=8)  # an "interrupted" campaign
    assert (a.n_simulated, a.complete) == (8, False)
    # a run killed mid-write leaves a partial last line: it must be discarded and re-run
    with (tmp_path / "a" / TABLE).open("a") as fh:
        fh.write("ss0003-none-base-s99,3,1.0,9.0")
    b = run_campaign(tiny, tmp_path / "a", workers=1)
    assert (b.n_skipped, b.n_simulated, b.complete) == (8, n - 8, True)
    c = run_campaign(tiny, tmp_path / "a", workers=1)
    assert (c.n_skipped, c.n_simulated) == (n, 0)
    resumed = _rows_by_id(tmp_path / "a" / TABLE)
    assert len(resumed) == n and sorted(resumed) == sorted(r.run_id for r in tiny.runs())
    fresh = _rows_by_id(run_campaign(tiny, tmp_path / "b", workers=1).table_path)
    for rid, row in fresh.items():
        for k in ("wob_std", "wob_max", "frac_outside_band", "dev_040"):
            assert resumed[rid][k] == row[k]


def test_resume_into_other_campaign_refused(tiny, tmp_path):
    from heavecomp.campaign.execute import run_campaign

    run_campaign(tiny, tmp_path, workers=1, limit=1)
    other = spec.loads(TINY.replace("tolerance = 20e3", "tolerance = 25e3"))
    with pytest.raises(InputError, match="different campaign"):
        run_campaign(other, tmp_path, workers=1)


# ---------------------------------------------------------------- Dask
@pytest.mark.slow
def test_tiny_campaign_on_local_dask_cluster(tiny, tmp_path):
    distributed = pytest.importorskip("distributed")
    from heavecomp.campaign.execute import run_campaign

    small = dataclasses.replace(tiny, regimes=("none", "stribeck"),
                                settings=dataclasses.replace(tiny.settings, duration=60.0, chunk_size=2))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        info = run_campaign(small, tmp_path / "dask", scheduler=cluster.scheduler_address)
    assert info.executor == "dask" and info.workers == 2 and info.complete
    local = _rows_by_id(run_campaign(small, tmp_path / "local", workers=1).table_path)
    remote = _rows_by_id(info.table_path)
    assert sorted(local) == sorted(remote)
    for rid in local:
        assert remote[rid]["wob_std"] == local[rid]["wob_std"]
        assert remote[rid]["n_band_exits"] == local[rid]["n_band_exits"]


def test_unreachable_scheduler_is_one_line_error(tiny, tmp_path, monkeypatch):
    pytest.importorskip("distributed")
    from heavecomp.campaign import execute
    from heavecomp.campaign.execute import run_campaign

    monkeypatch.setattr(execute, "CONNECT_TIMEOUT", "2s")

    with pytest.raises(InputError, match="scheduler tcp://127.0.0.1:1: cannot connect"):
        run_campaign(tiny, tmp_path, scheduler="tcp://127.0.0.1:1", limit=1)


# ---------------------------------------------------------------- statistics method
def test_exceedance_from_histogram_recovers_gaussian_tail():
    """Planted data: a Gaussian dW with sigma = 15 kN; the histogram method gives P(|dW| > x) = erfc(x/(sigma sqrt 2))."""
    from heavecomp.campaign.stats import _abs_bins, exceedance_from_counts, level_at

    rng = np.random.default_rng(3)
    sigma, D, nb = 15e3, 100e3, 80
    d = rng.normal(0, sigma, 2_000_000)
    x = (d + D) / (2 * D) * nb
    hist = np.bincount(np.clip(np.floor(x).astype(int) + 1, 0, nb + 1), minlength=nb + 2)
    q = exceedance_from_counts(_abs_bins(hist, nb))
    xs = np.arange(nb // 2 + 1) * 2 * D / nb
    exact = np.array([math.erfc(v / (sigma * math.sqrt(2))) for v in xs])
    ok = exact > 1e-3  # >= 2000 samples beyond x: sampling noise < 3 %
    assert np.allclose(q[ok], exact[ok], rtol=0.05)
    assert level_at(xs, q, 1e-2) == pytest.approx(2.5758 * sigma, rel=0.02)
    assert np.all(np.diff(q) <= 0)


def test_long_term_is_probability_weighted_and_consistent(tiny, tmp_path):
    """Long-term = sum p_s x short-term; the histogram tail at the band edge equals the on-the-fly band counter."""
    from heavecomp.campaign.execute import read_table, run_campaign
    from heavecomp.campaign.stats import statistics

    info = run_campaign(tiny, tmp_path, workers=1)
    st = statistics(tiny, read_table(info.table_path))
    xs = np.asarray(st["x_abs"])
    kb = int(np.argmin(np.abs(xs - 20e3)))
    assert xs[kb] == pytest.approx(20e3)
    for key, g in st["groups"].items():
        p = np.array([s["probability"] for s in g["short_term"]])
        assert p.sum() == pytest.approx(1.0)  # the zero cell is skipped, the rest sum to 1
        f = np.array([s["frac_outside_band"] for s in g["short_term"]])
        assert g["long_term"]["frac_outside_band"] == pytest.approx(p @ f)
        for s in g["short_term"]:
            assert s["exceed_abs"][kb] == pytest.approx(s["frac_outside_band"], abs=2e-3)
            assert 0.0 <= s["p_leave_exposure"] <= 1.0
    e = st["regime_effect"]
    # paper A, section 4: friction raises the WOB disturbance; eq. 7 sits between none and eq. 4
    assert (e["none/base"]["frac_outside_band"] < e["rotating_eq7/base"]["frac_outside_band"]
            < e["stribeck/base"]["frac_outside_band"])


# ---------------------------------------------------------------- campaign file and CLI
def test_variants_grid_and_sample():
    g = spec.loads(TINY + '\n[variations]\nmode = "grid"\n[variations.grid]\n"drill_string.stiffness" = [208e3, 2.08e6]\n'
                   '"formation.stiffness" = [1e6, 5e5, 2e5]\n')
    assert len(g.variants) == 6 and len(g.runs()) == 6 * len(spec.loads(TINY).runs())
    p = g.params_for(next(r for r in g.runs() if r.variant == "v005"))
    assert (p.drill_string.stiffness, p.formation.stiffness) == (2.08e6, 2e5)
    # the variant reaches the plant: the batch row of a softer formation equals simulate() with that k_F
    from heavecomp.campaign.batch import simulate_batch
    from heavecomp.simulate import simulate

    pick = [r for r in g.runs() if r.regime == "none" and r.sea_state == 1 and r.variant in ("v003", "v005")][:2]
    rows = {row["variant"]: row for row in simulate_batch(g, pick)}
    assert rows["v005"]["formation.stiffness"] == 2e5 and rows["v003"]["formation.stiffness"] == 1e6
    for run in pick:
        ref = simulate(g.params_for(run), g.settings.duration).metrics()["wob_std"]
        assert rows[run.variant]["wob_std"] == pytest.approx(ref, rel=1e-10)
    assert abs(rows["v005"]["wob_std"] / rows["v003"]["wob_std"] - 1) > 0.02
    s = spec.loads(TINY + '\n[variations]\nmode = "sample"\nn = 5\nseed = 1\n[variations.sample]\n'
                   '"friction.static_force" = [15e3, 30e3]\n')
    vals = [dict(v.overrides)["friction.static_force"] for v in s.variants]
    assert len(vals) == 5 and all(15e3 <= v <= 30e3 for v in vals) and len(set(vals)) == 5


@pytest.mark.parametrize("edit, message", [
    (("regimes = [\"none\", \"rotating_eq7\", \"stribeck\"]", "regimes = [\"stribek\"]"),
     "campaign.regimes: unknown friction model 'stribek' (did you mean 'stribeck'?)"),
    (("[0.3, 0.0]", "[0.3, 0.1]"), "scatter.probability: must sum to 1, sums to 1.1"),
    (("duration = 90.0", "duraton = 90.0"), "campaign.duraton: unknown key (did you mean 'duration'?)"),
    (("tp = [9.0, 12.0]", "tp = [9.0, 12.0, 14.0]"), "scatter.probability: row 1 must have 3 values"),
    (("tolerance = 20e3", "relative = 0.2\ntolerance = 20e3"), "band.tolerance: give exactly one of"),
    (("[outputs]", "[outputs]\nformat = \"xlsx\""), "outputs.format"),
    (("[band]", "[variations]\nmode = \"grid\"\n[variations.grid]\n\"friction.statc_force\" = [1.0]\n[band]"),
     "friction.statc_force: unknown key"),
])
def test_bad_campaign_file_one_line_exit_2(tmp_path, edit, message):
    bad = tmp_path / "bad.toml"
    assert edit[0] in TINY
    bad.write_text(TINY.replace(edit[0], edit[1], 1))
    with pytest.raises(ParameterError) as exc:
        spec.load(bad)
    assert message in str(exc.value) and "\n" not in str(exc.value)
    r = subprocess.run([sys.executable, "-m", "heavecomp.cli", "campaign", str(bad), "--out", str(tmp_path / "o")],
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert r.stderr.strip().startswith("heavecomp campaign: error:") and len(r.stderr.strip().splitlines()) == 1
    assert message in r.stderr


def test_cli_runs_and_resumes(tmp_path):
    camp = tmp_path / "c.toml"
    camp.write_text(TINY.replace("duration = 90.0", "duration = 40.0").replace('regimes = ["none", "rotating_eq7", "stribeck"]',
                                                                                'regimes = ["none", "stribeck"]'))
    cmd = [sys.executable, "-m", "heavecomp.cli", "campaign", str(camp), "--out", str(tmp_path / "o"), "--workers", "1"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "12 runs simulated, 0 resumed" in r.stdout
    m = json.loads((tmp_path / "o" / "metrics.json").read_text())
    assert set(m["long_term"]) == {"none/base", "stribeck/base"}
    r2 = subprocess.run(cmd, capture_output=True, text=True)
    assert "0 runs simulated, 12 resumed" in r2.stdout
    r3 = subprocess.run(cmd[:-1] + ["0"], capture_output=True, text=True)
    assert r3.returncode == 2 and "--workers must be >= 1" in r3.stderr


def test_default_campaign_is_documented_illustrative_platform_heave():
    c = spec.default()
    assert "illustrative" in c.scatter.note and "platform" in c.scatter.note
    assert sum(p for *_, p in c.scatter.cells()) == pytest.approx(1.0)
    assert c.regimes == ("none", "rotating_eq7", "stribeck")


def test_parquet_export_and_relative_band(tmp_path):
    pytest.importorskip("pyarrow")
    pd = pytest.importorskip("pandas")
    import pyarrow.parquet as pq

    from heavecomp.campaign.execute import read_table
    from heavecomp.report.campaign import run_and_report

    camp = spec.loads(TINY.replace("duration = 90.0", "duration = 40.0").replace("tolerance = 20e3", "relative = 0.1")
                      .replace("[outputs]", "[outputs]\nformat = \"parquet\""))
    info, st = run_and_report(camp, tmp_path, workers=1)
    tab = pq.read_table(tmp_path / "runs.parquet")
    csv_tab = read_table(info.table_path)
    assert tab.num_rows == len(camp.runs()) == csv_tab["run_id"].size
    assert np.array_equal(np.sort(tab.column("wob_std").to_numpy()), np.sort(csv_tab["wob_std"]))
    assert st["band_half_width"] == pytest.approx(0.1 * 98.1e3)  # 10 % of the paper-A set-point
    # tidy and typed (issue 13.5): counts stay integers, no wide histogram columns
    runs = pd.read_parquet(tmp_path / "runs.parquet")
    assert runs["n_stick"].dtype == np.int64 and runs["seed"].dtype == np.int64
    assert runs["regime"].dtype == "category" and not any(c.startswith("dev_") for c in runs.columns)
    h = pd.read_parquet(tmp_path / "histograms.parquet")
    assert list(h.columns) == ["run_id", "histogram", "bin", "lower_N", "upper_N", "count"]
    assert h["count"].dtype == np.int64
    # every sample of a run lies in one deviation bin; the bin edges tile the real line
    dev = h[h["histogram"] == "deviation"]
    per_run = dev.groupby("run_id")["count"].sum()
    n_samples = runs.set_index("run_id")["n_samples"]
    assert (per_run.sort_index().to_numpy() == n_samples.sort_index().to_numpy()).all()
    one = dev[dev["run_id"] == runs["run_id"][0]].sort_values("bin")
    assert np.isneginf(one["lower_N"].iloc[0]) and np.isposinf(one["upper_N"].iloc[-1])
    np.testing.assert_array_equal(one["upper_N"].to_numpy()[:-1], one["lower_N"].to_numpy()[1:])


def test_cli_killed_mid_campaign_resumes(tmp_path):
    """SIGKILL the CLI after its first finished chunk; the rerun simulates only the rest."""
    import signal
    import time

    camp = tmp_path / "c.toml"
    camp.write_text(TINY.replace("duration = 90.0", "duration = 600.0").replace("chunk_size = 4", "chunk_size = 1")
                    .replace("seeds = 2", "seeds = 3"))
    n = len(spec.load(camp).runs())
    out = tmp_path / "o"
    cmd = [sys.executable, "-m", "heavecomp.cli", "campaign", str(camp), "--out", str(out), "--workers", "1"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    from heavecomp.report.output import staging_path

    table = staging_path(out) / "runs.csv"  # a running campaign writes beside --out (issue 21.3)
    t0 = time.time()
    while time.time() - t0 < 60:
        if table.is_file() and table.read_text().count("\n") >= 2:
            break
        time.sleep(0.01)
    proc.send_signal(signal.SIGKILL)
    proc.communicate()
    assert proc.returncode == -signal.SIGKILL
    done = table.read_text().count("\n") - 1
    assert 1 <= done < n
    assert not out.exists()  # a killed campaign leaves no folder that reads as a result
    r = subprocess.run(cmd, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert not table.exists()
    table = out / "runs.csv"
    first = r.stdout.splitlines()[0]
    resumed = int(first.split(" resumed")[0].split()[-1])
    assert resumed >= done and first.startswith(f"{n - resumed} runs simulated")
    assert sorted(_rows_by_id(table)) == sorted(x.run_id for x in spec.load(camp).runs())


def test_campaign_over_the_run_size_budget_is_refused_before_any_chunk(tmp_path):
    """A chunk of 64 runs of 28 h holds ~12 GB of heave samples at once: one line naming
    settings.chunk_size, exit 2, and no table written (checked before any chunk runs)."""
    camp = tmp_path / "big.toml"
    camp.write_text(TINY.replace("duration = 90.0", "duration = 1.0e5").replace("chunk_size = 4", "chunk_size = 64")
                    .replace("seeds = 2", "seeds = 20"))
    out = tmp_path / "o"
    r = subprocess.run([sys.executable, "-m", "heavecomp.cli", "campaign", str(camp), "--out", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2, r.stderr
    err = r.stderr.strip().splitlines()
    assert len(err) == 1 and "settings.chunk_size = 64" in err[0] and "GiB budget" in err[0], err
    assert not (out / "runs.csv").exists()
