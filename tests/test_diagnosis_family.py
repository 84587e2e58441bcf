"""Issue 30 item 4: an effect that is one law of a broader contract class is reported by the contract's name.

``friction_memory`` (a memory over sliding distance, LuGre/Dahl) is a law of the contract's
``friction_lag`` (frictional memory: "friction depends on the velocity history ... pre-sliding"): the verdict
names ``friction_lag`` with ``law = "distance"`` and ``member = "friction_memory"``; the candidates table keeps
one row per member; two laws of one family are never each other's rival (margin, group); ``calibrated.toml``
carries the member class so every command replays it; a scorer counts either law right for a
``friction_lag`` truth."""

import pytest

from heavecomp.diagnosis import distinguish as D
from heavecomp.diagnosis.calibrate import calibrate, to_toml
from heavecomp.diagnosis.fitting import CandidateFit
from heavecomp.diagnosis.policy import VerdictPolicy
from heavecomp.diagnosis.verdict import Evidence, decide, label
from heavecomp.effects.candidates import by_family, family_of, law_of, same_family

CH = ("wob", "stroke", "pressure")
COMPONENTS = ("friction", "gas_spring", "flow_line", "string_formation", "sensors", "heave_input")
ONES = {c: 1.0 for c in CH}
GAP = {c: {"rms_validate": 10.0} for c in CH}
MEMORY = {"relaxation_length": 0.05, "depth": 0.3}
LAG = {"lag_time": 0.3, "drop_time": 0.05}


def _fit(name, explained, n=2, values=None):
    values = values if values is not None else {"friction_memory": MEMORY, "friction_lag": LAG}.get(name, {})
    return CandidateFit(name, dict(values), {}, {c: {"rms_before": 1.0, "rms_after": 0.5, "shrink": 0.5} for c in CH},
                        explained, explained, explained, n, explained - 0.03 * n, 0.0, dict(values))


def _shares(**kw):
    return {c: kw.get(c, 0.0) for c in COMPONENTS}


def _pair(a, b, stat, apart):
    return D.Pair(a, b, stat, 2.9, apart, 17, stat, stat)


def _dist(group, pairs=()):
    return D.Distinguishability(tuple(pairs), tuple(group), 0.01, 6, 0, 12.0)


def test_the_families_of_the_library():
    assert family_of("friction_memory") == "friction_lag" and law_of("friction_memory") == "distance"
    assert family_of("friction_lag") == "friction_lag" and law_of("friction_lag") == "time"
    assert family_of("gas_thermal") == "gas_heat_transfer" and law_of("gas_thermal") == "relaxation"
    assert family_of("gas_heat_transfer") == "gas_heat_transfer" and law_of("gas_heat_transfer") == "effective_index"
    assert family_of("dwell_stiction") == "dwell_stiction" and law_of("dwell_stiction") == ""
    assert family_of("sensor_gain:wob") == "sensor_gain:wob" and family_of("none") == "none"
    assert same_family("friction_memory", "friction_lag") and not same_family("friction_lag", "dwell_stiction")
    assert by_family(["friction_memory", "dwell_stiction", "friction_lag"]) == ["friction_memory", "dwell_stiction"]


def test_a_distance_memory_is_named_friction_lag_with_its_law_and_its_sibling_is_no_rival():
    """friction_memory explains 0.95, friction_lag 0.93 (a score margin of 0.02: low, were they rivals),
    flow_loss 0.4.  Not tested on the log: the verdict is friction_lag, law distance, fitted as
    friction_memory, high by its margin to flow_loss; its parameters are the member's."""
    fits = [_fit("friction_memory", 0.95), _fit("friction_lag", 0.93), _fit("flow_loss", 0.4, n=1)]
    v = decide(fits, GAP, ONES, ONES, VerdictPolicy(), Evidence(_shares(friction=0.9))).body
    assert (v["effect"], v["law"], v["member"]) == ("friction_lag", "distance", "friction_memory")
    assert v["parameters"] == MEMORY and v["confidence"] == "high"
    assert v["margin"] == pytest.approx(fits[0].score - fits[2].score)
    assert label(v) == "friction_lag (law: distance, fitted as friction_memory)"


def test_a_time_lag_is_named_friction_lag_with_law_time():
    fits = [_fit("friction_lag", 0.95), _fit("friction_memory", 0.94), _fit("dwell_stiction", 0.3, n=1)]
    v = decide(fits, GAP, ONES, ONES, VerdictPolicy(), Evidence(_shares(friction=0.9))).body
    assert (v["effect"], v["law"], v["member"]) == ("friction_lag", "time", "friction_lag")
    assert v["confidence"] == "high"


def test_a_warning_names_the_family_and_its_law_not_only_the_member():
    """A warning written before the verdict takes its family's name still says it: a friction_memory fit at
    its search bound reads ``friction_lag (law: distance, fitted as friction_memory)`` in the warning."""
    import dataclasses

    hit = {"parameter": "relaxation_length", "value": 0.2, "side": "upper", "bound": 0.2}
    fits = [dataclasses.replace(_fit("friction_memory", 0.95), at_bound=(hit,)), _fit("flow_loss", 0.4, n=1)]
    got = decide(fits, GAP, ONES, ONES, VerdictPolicy(), Evidence(_shares(friction=0.9)))
    said = [w for w in got.warnings if "search bound" in w]
    assert got.body["confidence"] == "low" and len(said) == 1
    assert said[0].startswith("verdict friction_lag (law: distance, fitted as friction_memory): fitted relaxation_length")


def test_a_group_of_one_family_is_a_single_name_and_a_mixed_group_names_each_family_once():
    """The block test cannot tell the two laws apart: one answer, friction_lag, its law the better fit's
    (distance), no group; with dwell_stiction also inside, the group is [friction_lag, dwell_stiction]."""
    fits = [_fit("friction_memory", 0.95), _fit("friction_lag", 0.93), _fit("flow_loss", 0.4, n=1)]
    pairs = [_pair("friction_memory", "friction_lag", 0.5, False), _pair("friction_memory", "flow_loss", 9.0, True)]
    got = decide(fits, GAP, ONES, ONES, VerdictPolicy(),
                 Evidence(_shares(friction=0.9), distinct=_dist(["friction_memory", "friction_lag"], pairs)))
    v = got.body
    assert (v["effect"], v["law"]) == ("friction_lag", "distance") and "group" not in v
    assert v["confidence"] == "high" and "laws of friction_lag" in v["law_note"]
    assert got.members == ("friction_memory",)
    fits = [_fit("friction_memory", 0.95), _fit("dwell_stiction", 0.94, n=1), _fit("friction_lag", 0.93),
            _fit("flow_loss", 0.4, n=1)]
    pairs = [_pair("friction_memory", "dwell_stiction", 0.3, False), _pair("friction_memory", "friction_lag", 0.5, False),
             _pair("friction_memory", "flow_loss", 9.0, True)]
    got = decide(fits, GAP, ONES, ONES, VerdictPolicy(), Evidence(
        _shares(friction=0.9), distinct=_dist(["friction_memory", "dwell_stiction", "friction_lag"], pairs)))
    v = got.body
    assert v["group"] == ["friction_lag", "dwell_stiction"] and v["law"] == "distance"
    assert v["group_members"] == ["friction_memory", "dwell_stiction"]
    assert v["group_laws"] == {"friction_lag": "distance"}
    assert got.members == ("friction_memory", "dwell_stiction")
    assert "`friction_memory`" not in v["group_note"]


def test_a_group_counts_two_laws_of_one_family_once_towards_its_size():
    assert D.within_families(["friction_memory", "friction_lag", "dwell_stiction", "pressure_friction"], 3) == \
        ("friction_memory", "friction_lag", "dwell_stiction", "pressure_friction")
    assert D.within_families(["a_effect", "friction_memory", "b_effect", "friction_lag", "c_effect"], 2) == \
        ("a_effect", "friction_memory", "friction_lag")


def test_calibrated_file_carries_the_member_class(tmp_path):
    """The calibrated file of a friction_lag (law distance) verdict holds the friction_memory entry with its
    fitted parameters, and it reads back (every command reads it the same way)."""
    from heavecomp.params import sets
    from heavecomp.params.cmc import load

    nominal = sets.paper_a()
    v = {"effect": "friction_lag", "law": "distance", "member": "friction_memory", "confidence": "high",
         "parameters": dict(MEMORY), "shrink": 0.7}
    cal = calibrate(nominal, {"verdict": v})
    assert [c["name"] for c in cal.changes if c["kind"] == "effect"] == ["friction_memory"]
    text = to_toml(cal, "log.csv")
    assert "friction_lag (law: distance, fitted as friction_memory)" in text
    (tmp_path / "c.toml").write_text(text)
    back = load(tmp_path / "c.toml")
    entries = dict(back.effects)
    assert entries["friction_memory"] == pytest.approx(MEMORY)


# ------------------------------------------------------------------ end to end, on the generator's truth laws
SIZE = (4.5, 5.5)  #: the planted effect's largest channel gap over the noise floor [-]
FRICTION = "friction_memory,friction_lag,dwell_stiction,parameter_mismatch"


def _diagnosed(tmp, case, candidates=FRICTION):
    """``heavecomp diagnose`` on a generated log (the benchmark's truth law, never the candidate's equation),
    as a user runs it, among the frictional candidates and the refit of the nominal."""
    import json as _json

    from heavecomp.benchmark import generate
    from heavecomp.cli import main
    from heavecomp.params import dumps

    tr = generate(case)
    log, nom = tr.to_csv(tmp / "run.csv"), tmp / "nominal.toml"
    nom.write_text(dumps(tr.nominal))
    assert main(["diagnose", str(log), "--params", str(nom), "--out", str(tmp / "d"), "--candidates", candidates,
                 "--jobs", "1", "--quiet"]) == 0
    return log, nom, _json.loads((tmp / "d" / "diagnosis.json").read_text())


@pytest.mark.slow
def test_a_lugre_bristle_reads_friction_lag_law_distance_and_its_calibrated_file_replays(tmp_path):
    """The generator's LuGre bristle (relaxation length 3-6 cm, scripts/third_set_logs.py's class) at 5 x its
    floor: the verdict is the contract's friction_lag with law distance, fitted as friction_memory; the
    candidates table keeps both laws' rows; calibrated.toml carries friction_memory and ``heavecomp replay``
    runs on it and ranks it before the nominal."""
    import json as _json

    from heavecomp.benchmark import Case
    from heavecomp.cli import main

    log, nom, d = _diagnosed(tmp_path, Case("friction_memory", 300101, "named", duration=300.0, size=SIZE))
    v = d["verdict"]
    assert (v["effect"], v.get("law"), v.get("member")) == ("friction_lag", "distance", "friction_memory"), v
    assert {"friction_memory", "friction_lag"} <= {c["effect"] for c in d["candidates"]}
    assert "friction_memory" not in (v.get("group") or [])
    cal = tmp_path / "d" / "calibrated.toml"
    assert 'name = "friction_memory"' in cal.read_text()
    assert "law: distance" in (tmp_path / "d" / "report.md").read_text()
    assert main(["replay", str(log), "--params", str(nom), "--params", str(cal), "--out", str(tmp_path / "r"),
                 "--quiet"]) == 0
    rep = _json.loads((tmp_path / "r" / "replay.json").read_text())
    assert rep["ranking"][0] == str(cal), rep["ranking"]


@pytest.mark.slow
def test_a_time_lag_reads_friction_lag_law_time(tmp_path):
    """The generator's frictional lag in time (its own truth law) among the frictional laws: friction_lag, law
    time, fitted as friction_lag (the distance law explains 0.12 of it).  The refit of the nominal is left
    out: on this seed the log cannot tell it from the lag and it leads their group as the simpler model
    (item 3), which is not what this test is about."""
    from heavecomp.benchmark import Case

    _, _, d = _diagnosed(tmp_path, Case("friction_lag", 300104, "named", duration=300.0, size=SIZE),
                         "friction_memory,friction_lag,dwell_stiction")
    v = d["verdict"]
    assert (v["effect"], v.get("law"), v.get("member")) == ("friction_lag", "time", "friction_lag"), v
