"""A log too long to replay is refused before any work, in one line (the run-size budget)."""

import re

import numpy as np
import pytest

from heavecomp.diagnosis import GapDiagnoser
from heavecomp.diagnosis.data import check_run
from heavecomp.errors import InputError
from heavecomp.params import paper_a


def test_a_30_hour_log_is_refused_naming_its_length():
    p = paper_a("stribeck")
    t = np.arange(0.0, 60 * 3600.0, 1.0)  # 60 h at 1 Hz: 1.08e7 replay steps at the 20 ms replay step
    z = 0.5 * np.sin(2 * np.pi * t / 12.0)
    cols = {"heave": z, "stroke": -z, "pressure": np.full(t.size, 1e7), "wob": np.full(t.size, 2e5)}
    run = check_run(t, cols, params=p, source="long.csv")
    with pytest.raises(InputError) as exc:
        GapDiagnoser(p).fit(run)
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith("long.csv: the log is 60 h long") and "budget" in msg


# ---------------------------------------------------------------- the whole diagnosis' memory (issue 23.1)
from heavecomp.params import budget as B  # noqa: E402


def test_the_estimate_grows_with_the_span_and_with_the_jobs_replays():
    one = B.diagnosis_bytes(30_000, 60_000, 1)
    two = B.diagnosis_bytes(30_000, 60_000, 2)
    long = B.diagnosis_bytes(540_000, 1_080_000, 2)
    assert two["replays"] > one["replays"] and two["samples"] == one["samples"]
    assert long["total"] > 10 * (two["total"] - two["base"])


def test_a_span_too_large_for_the_room_is_refused_naming_its_samples():
    # 3 h at 50 Hz diagnosed whole, 2 GB of room
    with pytest.raises(InputError) as exc:
        B.check_diagnosis_memory(540_000, 1_080_000, jobs=2, duration=10800.0, rate=50.0, source="long.csv",
                                 available=(2e9, "the memory available on this machine", 0.0))
    msg = str(exc.value)
    assert "\n" not in msg and msg.startswith("long.csv: the diagnosis of 1.08e+04 s would take")
    assert "its 5.4e+05 samples (1.08e+04 s at 50 Hz) need 1.62 GB, its replays (1.08e+06 steps, 2 jobs)" in msg
    assert "a shorter span or fewer jobs" in msg and exc.value.option == ("span", "jobs")


def test_the_jobs_decide_when_the_replays_do_not_fit():
    # room for the replays of one job but not of two: two jobs are refused naming the replays, one job passes
    n, m = 1_000, 2_000_000
    one = B.diagnosis_bytes(n, m, 1)["total"]
    two = B.diagnosis_bytes(n, m, 2)["total"]
    room = (one + two) / 2
    with pytest.raises(InputError) as exc:
        B.check_diagnosis_memory(n, m, jobs=2, duration=20000.0, rate=0.05, source="x.csv",
                                 available=(room, "the address-space limit (ulimit -v)", 0.0))
    assert "replays (2e+06 steps, 2 jobs)" in str(exc.value) and "ulimit -v" in str(exc.value)
    assert B.check_diagnosis_memory(n, m, jobs=1, duration=20000.0, rate=0.05, source="x.csv",
                                    available=(room, "the address-space limit (ulimit -v)", 0.0))["total"] == one


def test_the_command_refuses_before_any_replay(tmp_path, capsys, monkeypatch):
    from heavecomp.cli import main
    from heavecomp.diagnosis import replay
    from heavecomp.params import dumps

    p = paper_a()
    nominal = tmp_path / "nominal.toml"
    nominal.write_text(dumps(p))
    t = np.arange(0.0, 3000.0, 0.1)
    z = 0.5 * np.sin(2 * np.pi * t / 10)
    data = np.column_stack([t, z, -0.9 * z, p.p0 + 1e5 * z, p.operating_point.wob_setpoint + 2e4 * z])
    log = tmp_path / "long.csv"
    np.savetxt(log, data, delimiter=",", header="t,heave,stroke,pressure,wob", comments="", fmt="%.6f")

    def no_replay(*a, **k):
        raise AssertionError("a replay ran before the memory check")

    monkeypatch.setattr(replay, "prepare", no_replay)
    monkeypatch.setattr(B, "available_bytes", lambda: (50e6, "the memory available on this machine", 0.0))
    rc = main(["diagnose", str(log), "--params", str(nominal), "--out", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, err
    # the default span of a 3000 s log is its last 600 s: that is what the estimate is about
    assert "the diagnosis of 600 s would take" in err and "--span" in err and "--jobs" in err, err


def test_a_log_too_long_to_read_is_refused_before_reading(tmp_path, capsys, monkeypatch):
    from heavecomp.cli import main
    from heavecomp.diagnosis import data
    from heavecomp.params import dumps

    nominal = tmp_path / "nominal.toml"
    nominal.write_text(dumps(paper_a()))
    log = tmp_path / "log.csv"
    log.write_text("t,heave,stroke,pressure,wob\n" + "".join(f"{0.1 * k:.1f},0.1,0.1,1e7,2e5\n" for k in range(20000)))

    def no_read(*a, **k):
        raise AssertionError("the log was read before the memory check")

    monkeypatch.setattr(data, "load_run", no_read)
    monkeypatch.setattr(B, "available_bytes", lambda: (1e6, "the memory available on this machine", 0.0))
    rc = main(["diagnose", str(log), "--params", str(nominal), "--out", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1, err
    assert re.search(r"reading and checking the log's 2(\.\d+)?e\+04 rows \(estimated from its size\) would take", err)
    assert "cut the log into parts" in err
    # rows not known before reading (bzip2): nothing is refused up front
    assert B.check_read_memory(None, source="x.csv.bz2", available=(0.0, "", 0.0)) == 0.0
