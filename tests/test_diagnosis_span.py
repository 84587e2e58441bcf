"""Which stretch of a long log the diagnosis analyses: named, never silent (issue 23.1)."""

import numpy as np
import pytest

from heavecomp.diagnosis import span as SP
from heavecomp.diagnosis.data import check_run
from heavecomp.errors import InputError
from heavecomp.params import paper_a


def test_a_short_log_is_analysed_whole_a_long_one_its_last_stretch():
    short = SP.choose(SP.MAX_WHOLE)
    assert short.whole and (short.start, short.end) == (0.0, SP.MAX_WHOLE)
    day = SP.choose(86400.0)
    assert day.rule == "last" and (day.start, day.end) == (86400.0 - SP.DEFAULT_SPAN, 86400.0)
    assert "24 h long" in day.reason and "monitor" in day.reason and "\n" not in day.reason
    j = day.to_json()
    assert j["duration_s"] == SP.DEFAULT_SPAN and j["log_duration_s"] == 86400.0 and j["rule"] == "last"


def test_a_named_span_is_analysed_as_named():
    s = SP.choose(10800.0, SP.parse("3600:4200"))
    assert (s.start, s.end, s.rule) == (3600.0, 4200.0, "user")
    assert SP.choose(10800.0, SP.parse("10000:")).end == 10800.0
    assert SP.choose(10800.0, SP.parse(":900")).start == 0.0


@pytest.mark.parametrize("text, fragment", [
    ("3600", "expected START:END"), ("a:b", "'a' is not a number"), ("-5:100", "must be a finite time"),
    ("200:100", "END 100 s must come after START 200 s"),
])
def test_a_malformed_span_is_one_line(text, fragment):
    with pytest.raises(InputError) as e:
        SP.parse(text)
    assert fragment in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("span, fragment", [
    ((20000.0, None), "START 20000 s is past the log's end (10800 s)"), ((0.0, 20000.0), "END 20000 s is past"),
    ((100.0, 130.0), "spans 30 s; diagnose needs at least 60 s"),
])
def test_a_span_outside_the_log_is_refused(span, fragment):
    with pytest.raises(InputError) as e:
        SP.choose(10800.0, span)
    assert fragment in str(e.value)


def test_the_cut_restarts_the_clock_and_says_why():
    p = paper_a()
    t = np.arange(0.0, 3000.0, 0.1)
    z = 0.5 * np.sin(2 * np.pi * t / 10)
    run = check_run(t, {"heave": z, "stroke": -0.9 * z, "pressure": p.p0 + 1e5 * z,
                        "wob": p.operating_point.wob_setpoint + 2e4 * z}, params=p, source="long.csv")
    s = SP.choose(run.duration)
    cut = SP.cut(run, s)
    assert cut.t[0] == 0.0 and abs(cut.duration - SP.DEFAULT_SPAN) < 0.11
    k = int(np.searchsorted(run.t, s.start - 1e-9))
    assert np.array_equal(cut["heave"], run["heave"][k:])
    assert cut.warnings[-1].startswith("analysed span: the log is 3000 s long: the diagnosis analyses its last 600 s")
    assert SP.cut(run, SP.choose(run.duration, (0.0, None))) is not run
    assert SP.cut(cut, SP.choose(cut.duration)) is cut  # whole: unchanged


@pytest.mark.slow
def test_diagnose_names_the_span_of_a_long_log_in_every_result(tmp_path, capsys):
    """A 1500 s log: the last 600 s are diagnosed, and stderr, diagnosis.json and the report say so."""
    import json

    from heavecomp.benchmark.long_logs import long_log
    from heavecomp.cli import main
    from heavecomp.params import dumps

    run = long_log([], seed=3, duration=1500.0, rate=10.0)
    log = tmp_path / "long.csv"
    cols = ("heave", "stroke", "pressure", "wob")
    np.savetxt(log, np.column_stack([run.t] + [run.columns[c] for c in cols]), delimiter=",",
               header="t," + ",".join(cols), comments="", fmt="%.10g")
    nominal = tmp_path / "nominal.toml"
    nominal.write_text(dumps(run.nominal))
    out = tmp_path / "out"
    rc = main(["diagnose", str(log), "--params", str(nominal), "--out", str(out), "--quiet",
               "--candidates", "flow_loss"])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert "diagnose: the log is 1500 s long: the diagnosis analyses its last 600 s" in err and "--span" in err
    d = json.loads((out / "diagnosis.json").read_text())
    assert d["span"]["rule"] == "last" and d["span"]["start_s"] == 900.0 and d["span"]["end_s"] == 1500.0
    assert abs(d["split"]["validate"][1] - 600.0) < 0.2  # the diagnosis' clock is the span's
    assert "analysed span: the log is 1500 s long" in (out / "report.md").read_text()
