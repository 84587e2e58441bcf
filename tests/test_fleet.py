"""Issue 23.5: a folder of logs monitored log by log through the campaign executor, one summary table,
resume, a failing log recorded (not fatal), bad input refused before any work."""

import csv
import json

import pytest

from heavecomp import cli
from heavecomp.campaign import fleet as F

#: (file stem, planted changes [(t [s], label)], seed): 10-min logs at 10 Hz, changes at 8x their noise
PLANTED = (("a_friction", [(400.0, "pressure_friction")], 1), ("b_leak", [(400.0, "gas_leak")], 2),
           ("c_none", [], 4))


@pytest.fixture(scope="module")
def fleet_dir(tmp_path_factory):
    """Three generated logs with a planted change (or none) and one of 60 s (too short to monitor), and
    the nominal parameter file."""
    from heavecomp.benchmark.long_logs import COMPONENT, long_log
    from heavecomp.params import dumps

    d = tmp_path_factory.mktemp("fleet")
    (d / "logs").mkdir()
    truth = {}
    for name, changes, seed in PLANTED:
        r = long_log(changes, seed=seed, duration=600.0, rate=10.0, size=8.0)
        r.to_csv(d / "logs" / f"{name}.csv")
        truth[name] = [COMPONENT[label] for _, label in changes]
    short = long_log([], seed=7, duration=150.0, rate=10.0)
    short.cropped(90.0).to_csv(d / "logs" / "d_short.csv")
    (d / "p.toml").write_text(dumps(r.nominal))
    return d, truth


def _rows(path):
    with open(path, newline="") as fh:
        return {r["log"]: r for r in csv.DictReader(fh)}


def _fleet(*args):
    return cli.main(["fleet", *map(str, args), "--quiet"])


@pytest.mark.slow
def test_table_has_a_row_per_log_with_the_planted_component_and_the_failure(fleet_dir, tmp_path):
    d, truth = fleet_dir
    assert _fleet(d / "logs", "--params", d / "p.toml", "--out", tmp_path / "o", "--workers", "1") == 0
    rows = _rows(tmp_path / "o" / "fleet.csv")
    assert sorted(rows) == ["a_friction", "b_leak", "c_none", "d_short"]
    for name, comps in truth.items():
        r = rows[name]
        assert r["status"] == "done"
        found = [c.split()[1] for c in r["changes (t [s] component size [noise sigma])"].split("; ") if c]
        # the planted component, and nothing on the log without a change (a leak grows after its first alarm:
        # the monitor may raise it again, always as the gas spring)
        assert sorted(set(found)) == sorted(set(comps)), (name, found)
        assert int(r["segments [-]"]) == 1 + len(found)
        assert float(r["duration [h]"]) == pytest.approx(600.0 / 3600.0, abs=1e-3)
    # the 60 s log fails inside its task: recorded with its one-line reason, the fleet goes on (exit 0)
    bad = rows["d_short"]
    assert bad["status"] == "failed" and "120 s" in bad["reason"] and "\n" not in bad["reason"]
    changes = _rows(tmp_path / "o" / "changes.csv")
    assert set(changes) == {"a_friction", "b_leak"}
    assert float(changes["a_friction"]["t [s]"]) > 400.0  # detected after the planted onset
    with open(tmp_path / "o" / "changes.units.csv") as fh:
        assert "t [s],s" in fh.read()
    mon = json.loads((tmp_path / "o" / "logs" / "a_friction" / "monitor.json").read_text())
    assert mon["changes"][0]["component"] == "friction"
    assert not (tmp_path / "o" / "logs" / "d_short" / "monitor.json").exists()
    html = (tmp_path / "o" / "report.html").read_text()
    assert "data:image/png;base64" in html and "Provenance" in html


def _counting(monkeypatch):
    """Count the monitor's calls (the tasks run in this process with workers=1)."""
    from heavecomp.diagnosis import monitor as M

    calls = []
    real = M.monitor

    def counted(run, params, **kw):
        calls.append(run.source)
        return real(run, params, **kw)

    monkeypatch.setattr(M, "monitor", counted)
    return calls


@pytest.mark.slow
def test_resume_skips_finished_logs(fleet_dir, tmp_path, monkeypatch):
    from heavecomp.report.fleet import run_and_report

    d, _ = fleet_dir
    calls = _counting(monkeypatch)
    tasks = F.plan(d / "logs", d / "p.toml")
    settings = F.Settings()
    info, _ = run_and_report(tasks, tmp_path / "o", settings, workers=1, limit=2)  # an interrupted fleet
    assert (info.n_computed, info.n_skipped) == (2, 0) and len(calls) == 2
    first = {k: F.read_task(tmp_path / "o" / F.RESULTS / k)["fleet_run"] for k in ("a_friction", "b_leak")}
    info, summary = run_and_report(tasks, tmp_path / "o", settings, workers=1)
    assert (info.n_computed, info.n_skipped) == (2, 2)
    assert len(calls) == 3 and calls[2].endswith("c_none.csv")  # d_short fails before the monitor: too short
    for k, run_id in first.items():  # not recomputed: written by the first run
        assert F.read_task(tmp_path / "o" / F.RESULTS / k)["fleet_run"] == run_id
    assert [r["status"] for r in summary["fleet"]] == ["done", "done", "done", "failed"]
    # other settings are another result: nothing is taken over
    info, _ = run_and_report(tasks, tmp_path / "o", F.Settings(block=20.0), workers=1)
    assert info.n_skipped == 0


@pytest.mark.slow
def test_cli_resume_keeps_a_complete_fleet_and_without_it_recomputes(fleet_dir, tmp_path):
    d, _ = fleet_dir
    out = tmp_path / "o"
    args = [d / "logs", "--params", d / "p.toml", "--out", out, "--workers", "1"]
    assert _fleet(*args) == 0
    before = F.read_task(out / F.RESULTS / "a_friction")["fleet_run"]
    assert _fleet(*args, "--resume") == 0
    assert F.read_task(out / F.RESULTS / "a_friction")["fleet_run"] == before
    assert _fleet(*args) == 0  # no --resume: a new result, whole
    assert F.read_task(out / F.RESULTS / "a_friction")["fleet_run"] != before


@pytest.mark.slow
def test_a_log_that_fails_in_its_task_is_recorded_not_fatal(fleet_dir, tmp_path, monkeypatch):
    from heavecomp.diagnosis import monitor as M
    from heavecomp.report.fleet import run_and_report

    d, _ = fleet_dir

    def broken(run, params, **kw):
        if "b_leak" in run.source:
            raise FloatingPointError("singular block\nsecond line")
        return real(run, params, **kw)

    real = M.monitor
    monkeypatch.setattr(M, "monitor", broken)
    tasks = [t for t in F.plan(d / "logs", d / "p.toml") if t.key in ("b_leak", "c_none")]
    info, summary = run_and_report(tasks, tmp_path / "o", F.Settings(), workers=1)
    assert info.n_failed == 1 and info.n_computed == 2
    rows = {r["log"]: r for r in summary["fleet"]}
    assert rows["b_leak"]["status"] == "failed"
    assert rows["b_leak"]["reason"] == "FloatingPointError: singular block second line"
    assert rows["c_none"]["status"] == "done"
    # a failed log is tried again by a resume
    monkeypatch.setattr(M, "monitor", real)
    info, _ = run_and_report(tasks, tmp_path / "o", F.Settings(), workers=1)
    assert (info.n_skipped, info.n_computed, info.n_failed) == (1, 1, 0)


def _fake_folder(tmp_path, header="t,heave,stroke,pressure,wob"):
    """Logs whose checks fail (or that are never read): no simulation needed."""
    logs = tmp_path / "logs"
    logs.mkdir()
    for name in ("a_friction.csv", "c_none.csv"):
        (logs / name).write_text(header + "\n" + "".join(f"{0.1 * i:.1f},0,0.5,2.4e6,1e5\n" for i in range(50)))
    from heavecomp.params import dumps, paper_a

    (tmp_path / "p.toml").write_text(dumps(paper_a()))
    return logs


@pytest.mark.parametrize("case,named", [
    ("empty", "no log found"),
    ("hook", "measurement.string_weight"),  # a hook load and no WOB: the string weight it needs is named
    ("m.toml", "unknown key 'parms'"),
    ("m2.toml", "logs.\"zzz.csv\": no such log"),
    ("no params", "no parameter file"),
])
def test_bad_input_exits_2_naming_it_before_any_work(tmp_path, capsys, case, named):
    logs = _fake_folder(tmp_path)
    (tmp_path / "empty").mkdir()
    (tmp_path / "hook").mkdir()
    (tmp_path / "hook" / "b.csv").write_text((logs / "c_none.csv").read_text().replace("wob", "hookload", 1))
    p = tmp_path / "p.toml"
    (tmp_path / "m.toml").write_text(f'params = "{p}"\n[logs."c_none.csv"]\nparms = "x.toml"\n')
    (tmp_path / "m2.toml").write_text(f'params = "{p}"\n[logs."zzz.csv"]\nunits = {{wob = "kN"}}\n')
    args = {"empty": [tmp_path / "empty", "--params", p],
            "hook": [tmp_path / "hook", "--params", p],
            "m.toml": [logs, "--manifest", tmp_path / "m.toml"],
            "m2.toml": [logs, "--manifest", tmp_path / "m2.toml"],
            "no params": [logs]}[case]
    capsys.readouterr()
    assert cli.main(["fleet", *map(str, args), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and named in err[0], err
    assert not (tmp_path / "o").exists()


def test_manifest_gives_each_log_its_own_parameters_and_units(tmp_path):
    logs = _fake_folder(tmp_path)
    p = tmp_path / "p.toml"
    (tmp_path / "m.toml").write_text(f'params = "{p}"\nunits = {{wob = "N"}}\n'
                                     f'[logs."c_none.csv"]\nunits = "pressure=Pa"\ncolumns = {{wob = "wob"}}\n')
    tasks = {t.key: t for t in F.plan(logs, manifest=tmp_path / "m.toml", check=False)}
    assert tasks["c_none"].units == {"wob": "N", "pressure": "Pa"} and tasks["c_none"].columns == {"wob": "wob"}
    assert tasks["a_friction"].units == {"wob": "N"} and tasks["a_friction"].params == str(p.resolve())
    # a log's own entry wins over the arguments, which win over the manifest's top level
    tasks = {t.key: t for t in F.plan(logs, manifest=tmp_path / "m.toml", units={"wob": "kN"}, check=False)}
    assert tasks["a_friction"].units == {"wob": "kN"} and tasks["c_none"].units["pressure"] == "Pa"


def test_logs_are_found_by_folder_or_glob_and_named_by_their_path(tmp_path):
    for rel in ("a.csv", "b.csv.gz", "b.units.csv", ".hidden.csv", "notes.toml", "sub/c.parquet", "sub/d.csv"):
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text("x")
    root, files = F.find_logs(tmp_path)
    assert [f.name for f in files] == ["a.csv", "b.csv.gz"]  # a folder: its own logs, not sub-folders
    root, files = F.find_logs(f"{tmp_path}/**/*.csv*")
    assert sorted(F._key(root, f) for f in files) == ["a", "b", "sub--d"]
    with pytest.raises(F.InputError, match="no log found"):
        F.find_logs(tmp_path / "sub" / "*.mat")


@pytest.mark.slow
def test_dask_workers_give_the_same_table_as_one_process(fleet_dir, tmp_path):
    distributed = pytest.importorskip("distributed")
    from heavecomp.report.fleet import run_and_report

    d, _ = fleet_dir
    tasks = [t for t in F.plan(d / "logs", d / "p.toml") if t.key in ("a_friction", "c_none", "d_short")]
    _, local = run_and_report(tasks, tmp_path / "one", F.Settings(), workers=1)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        info, remote = run_and_report(tasks, tmp_path / "dask", F.Settings(), scheduler=cluster.scheduler_address)
    assert info.executor == "dask" and info.workers == 2 and info.n_computed == 3
    assert remote["fleet"] == local["fleet"] and remote["changes"] == local["changes"]


@pytest.mark.slow
def test_an_interrupted_fleet_is_resumed_from_its_staging_folder(fleet_dir, tmp_path, monkeypatch):
    from heavecomp.diagnosis import monitor as M
    from heavecomp.report.output import staging_path

    d, _ = fleet_dir
    real = M.monitor

    def interrupted(run, params, **kw):
        if "b_leak" in run.source:
            raise KeyboardInterrupt
        return real(run, params, **kw)

    monkeypatch.setattr(M, "monitor", interrupted)
    out = tmp_path / "o"
    args = [d / "logs", "--params", d / "p.toml", "--out", out, "--workers", "1"]
    assert _fleet(*args) == 130
    assert not out.exists()  # whole or absent
    kept = staging_path(out) / F.RESULTS
    assert sorted(p.name for p in kept.iterdir()) == ["a_friction"]  # the finished log, whole
    first = F.read_task(kept / "a_friction")["fleet_run"]
    monkeypatch.setattr(M, "monitor", real)
    calls = _counting(monkeypatch)  # the real monitor again, counted
    assert _fleet(*args, "--resume") == 0
    assert [c.rsplit("/", 1)[-1] for c in calls] == ["b_leak.csv", "c_none.csv"]
    assert F.read_task(out / F.RESULTS / "a_friction")["fleet_run"] == first


@pytest.mark.slow
def test_diagnose_gives_each_gap_segment_its_verdict_and_group(fleet_dir, tmp_path):
    d, _ = fleet_dir
    (tmp_path / "logs").mkdir()
    (tmp_path / "logs" / "a_friction.csv").symlink_to(d / "logs" / "a_friction.csv")
    assert _fleet(tmp_path / "logs", "--params", d / "p.toml", "--out", tmp_path / "o", "--workers", "1",
                  "--diagnose") == 0
    with open(tmp_path / "o" / "segments.csv", newline="") as fh:
        segs = list(csv.DictReader(fh))
    assert [s["verdict"] for s in segs][0] == "-"  # the reference stretch is not diagnosed
    v = segs[1]
    # the planted seal friction's component; which friction law is the diagnosis' own test (test_diagnosis_*)
    assert v["verdict component"] == "friction" and v["verdict"] in v["group"]
    diag = json.loads((tmp_path / "o" / "logs" / "a_friction" / "segment_1" / "diagnosis.json").read_text())
    assert diag["verdict"]["effect"] == v["verdict"]
    row = _rows(tmp_path / "o" / "fleet.csv")["a_friction"]
    assert row["verdicts (segment: effect, confidence, group)"].startswith(f"1: {v['verdict']}, {v['confidence']}")


def _binary_logs(folder, n=20000, wob="wob"):
    """A Parquet and a .mat log of n samples at 10 Hz at paper A's operating point (no simulation needed), the
    WOB column named ``wob``; and paper A's parameter file."""
    import numpy as np
    import pyarrow as pa
    import pyarrow.parquet as pq
    import scipy.io

    from heavecomp.params import dumps, paper_a

    P = paper_a()
    t = 0.1 * np.arange(n)
    cols = {"t": t, "heave": np.sin(t), "stroke": 0.1 * np.sin(t), "pressure": P.p0 + 1e4 * np.sin(t),
            wob: P.operating_point.wob_setpoint + 1e3 * np.sin(t)}
    logs = folder / "logs"
    logs.mkdir(parents=True)
    pq.write_table(pa.table(cols), logs / "a.parquet", row_group_size=4000)
    scipy.io.savemat(logs / "b.mat", cols)
    (folder / "p.toml").write_text(dumps(P))
    return logs, folder / "p.toml"


def test_the_check_before_work_reads_a_binary_log_s_start_only(tmp_path, monkeypatch, capsys):
    """Brief item 5: a Parquet or .mat log is read whole once (in its task), not also by the check before any
    work: the check reads a Parquet log's first rows (their magnitudes still checked) and a .mat log's
    variable headers (scipy.io.whosmat, no loadmat); bad input is still one line naming the column, exit 2."""
    import pyarrow.parquet as pq
    import scipy.io

    from heavecomp.io import series as S

    logs, p = _binary_logs(tmp_path)
    rows = []
    real_iter = pq.ParquetFile.iter_batches

    def counted(self, *a, **kw):
        for b in real_iter(self, *a, **kw):
            rows.append(b.num_rows)
            yield b

    def no_loadmat(*a, **kw):
        raise AssertionError("loadmat: a .mat log read whole by the check")

    monkeypatch.setattr(pq.ParquetFile, "iter_batches", counted)
    monkeypatch.setattr(scipy.io, "loadmat", no_loadmat)
    assert [t.key for t in F.plan(logs, p)] == ["a", "b"]
    assert 0 < sum(rows) <= S.HEAD_ROWS < 20000

    def refused(folder, *args):
        capsys.readouterr()
        assert cli.main(["fleet", str(folder), "--params", str(p), *args, "--out", str(tmp_path / "o")]) == 2
        assert not (tmp_path / "o").exists()
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1, err
        return err[0]

    assert "a.parquet: column 'wob': mean" in refused(logs, "--units", "wob=kN")  # the head's magnitudes
    assert "column 'wob' mapped to 'W': no such column" in refused(logs, "--columns", "wob=W")
    mm, _ = _binary_logs(tmp_path / "mm", wob="wob_mm")  # a header unit of the wrong kind
    msg = refused(mm)
    assert "column 'wob' ('wob_mm'): unit 'mm' is a length unit" in msg and ("a.parquet" in msg or "b.mat" in msg)
    (mm / "a.parquet").unlink()
    assert "b.mat: column 'wob' ('wob_mm'): unit 'mm' is a length unit" in refused(mm)
