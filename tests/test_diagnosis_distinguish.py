"""Issue 30: confidence earned on the log itself.  The block test's false-alarm rate on pairs equal by
construction, a verdict that names the group the log cannot split (never one member with medium/high
confidence), the refit of the nominal's own parameters preferred when it explains as much, a verdict the
equation-error table does not support at most low, and the planted friction case of the issue."""

import math

import numpy as np
import pytest

from heavecomp.diagnosis import distinguish as D
from heavecomp.diagnosis.fitting import CandidateFit
from heavecomp.diagnosis.policy import VerdictPolicy
from heavecomp.diagnosis.verdict import Evidence, decide

CH = ("wob", "stroke", "pressure")
COMPONENTS = ("friction", "gas_spring", "flow_line", "string_formation", "sensors", "heave_input")


def _ar1(rng, n, phi):
    x = np.empty(n)
    x[0] = rng.normal()
    e = rng.normal(size=n) * math.sqrt(1 - phi * phi)
    for i in range(1, n):
        x[i] = phi * x[i - 1] + e[i]
    return x


def test_block_test_false_alarm_rate_is_near_its_stated_rate_on_autocorrelated_equal_pairs():
    """Two explanations that fit equally well (their per-sample loss differences have mean 0), with losses
    correlated over ~2 s (AR(1) at 25 Hz, phi = 0.98) as a replay's are over a stick-slip event: blocks of a
    wave period keep the false-alarm rate near the stated 1 %; the same test on single samples (a naive
    Vuong test) calls most such pairs apart."""
    rng = np.random.default_rng(0)
    t = np.arange(0, 200.0, 0.04)
    alpha, block = 0.01, 12.0
    blocked = naive = 0
    n = 400
    for _ in range(n):
        d = _ar1(rng, t.size, 0.98)
        z, nb = D.block_t(d, t, block)
        blocked += abs(z) > D.threshold(alpha, nb)
        zn = float(np.mean(d) / (np.std(d, ddof=1) / math.sqrt(d.size)))
        naive += abs(zn) > D.threshold(alpha, d.size)
    assert blocked / n <= 0.03
    assert naive / n >= 0.3
    # a real difference (0.5 noise sd in the mean) is told apart
    z, nb = D.block_t(_ar1(rng, t.size, 0.98) + 0.5, t, block)
    assert z > D.threshold(alpha, nb)


#: a refit that moved the seal's static and Coulomb forces (multipliers)
MOVED = {"gas_stiffness": 1.0, "static_force": 1.3, "coulomb_force": 1.3, "viscous_coefficient": 1.0,
         "drill_string_stiffness": 1.0, "formation_stiffness": 1.0}


def _fit(name, explained, n=1, shrink=0.5):
    values = MOVED if name == "parameter_mismatch" else {}
    return CandidateFit(name, {}, {}, {c: {"rms_before": 1.0, "rms_after": 1 - shrink, "shrink": shrink} for c in CH},
                        explained, explained, explained, n, explained - 0.03 * n, 0.0, values)


def _dist(group, pairs=()):
    return D.Distinguishability(tuple(pairs), tuple(group), 0.01, 6, 0, 12.0)


def _pair(a, b, stat, apart):
    return D.Pair(a, b, stat, 2.9, apart, 17, stat, stat)


ONES = {c: 1.0 for c in CH}
GAP = {c: {"rms_validate": 10.0} for c in CH}


def _shares(**kw):
    return {c: kw.get(c, 0.0) for c in COMPONENTS}


def test_a_verdict_the_log_cannot_split_is_the_group_with_the_groups_confidence():
    """dwell_stiction explains 0.95 and friction_lag 0.93 (a score margin of 0.02: low as one name).  When
    the block test cannot tell them apart, the verdict names the group, best first, and its confidence is
    the group's (margin to the best outside it, 0.55: high); apart, the single name keeps its low."""
    fits = [_fit("dwell_stiction", 0.95), _fit("friction_lag", 0.93), _fit("flow_loss", 0.4)]
    ev = dict(shares=_shares(friction=0.9))
    pairs = [_pair("dwell_stiction", "friction_lag", 0.7, False), _pair("dwell_stiction", "flow_loss", 8.0, True)]
    v = decide(fits, GAP, ONES, ONES, VerdictPolicy(),
               Evidence(**ev, distinct=_dist(["dwell_stiction", "friction_lag"], pairs))).body
    assert v["effect"] == "dwell_stiction" and v["group"] == ["dwell_stiction", "friction_lag"]
    assert v["confidence"] == "high" and "cannot tell" in v["group_note"]
    assert v["distinguishable"]["pairs"][0]["apart"] is False and v["distinguishable"]["false_alarm_rate"] == 0.01
    pairs[0] = _pair("dwell_stiction", "friction_lag", 5.0, True)
    v = decide(fits, GAP, ONES, ONES, VerdictPolicy(), Evidence(**ev, distinct=_dist(["dwell_stiction"], pairs))).body
    assert v["effect"] == "dwell_stiction" and "group" not in v and v["confidence"] == "low"


def test_the_refit_of_the_nominal_leads_a_group_it_explains_as_much_in():
    """Issue 30 item 3: pressure_friction (1 parameter) scores above parameter_mismatch (2 released) by the
    penalty alone; the log cannot tell them apart: the nominal structure with other values is the verdict,
    the new mechanism stays in the group."""
    fits = [_fit("pressure_friction", 0.98), _fit("parameter_mismatch", 0.99, n=2), _fit("flow_loss", 0.3)]
    pairs = [_pair("pressure_friction", "parameter_mismatch", 0.4, False),
             _pair("pressure_friction", "flow_loss", 9.0, True)]
    v = decide(fits, GAP, ONES, ONES, VerdictPolicy(),
               Evidence(_shares(friction=0.9), distinct=_dist(["pressure_friction", "parameter_mismatch"], pairs))).body
    assert v["effect"] == "parameter_mismatch" and v["group"] == ["parameter_mismatch", "pressure_friction"]
    assert "no new mechanism" in v["group_note"]


def test_a_candidate_the_test_prefers_leads_over_the_best_by_score():
    """The held-out test finds parameter_mismatch significantly better than pressure_friction (the issue's
    0.82 against 0.70 shrink), which won the score by its penalty: parameter_mismatch is the verdict, at
    most medium."""
    fits = [_fit("pressure_friction", 0.98), _fit("parameter_mismatch", 1.0, n=2), _fit("flow_loss", 0.3)]
    pairs = [_pair("parameter_mismatch", "pressure_friction", 3.4, True),
             _pair("parameter_mismatch", "flow_loss", 9.0, True)]
    v = decide(fits, GAP, ONES, ONES, VerdictPolicy(),
               Evidence(_shares(friction=0.9), distinct=_dist(["parameter_mismatch"], pairs))).body
    assert v["effect"] == "parameter_mismatch" and v["confidence"] == "medium"
    assert "t = +3.40" in v["lead_note"]


def test_a_verdict_the_equation_error_table_does_not_support_is_at_most_low():
    """Issue 30 item 2: flow_loss explains 0.95 (high alone) while the table puts 85 % of the gap in
    friction and 5 % in the flow line: low, and a warning says why."""
    fits = [_fit("flow_loss", 0.95), _fit("gas_leak", 0.2)]
    got = decide(fits, GAP, ONES, ONES, VerdictPolicy(), Evidence(_shares(friction=0.85, flow_line=0.05)))
    assert got.body["confidence"] == "low"
    assert any("equation-error gap" in w and "lowered from high to low" in w for w in got.warnings)
    got = decide(fits, GAP, ONES, ONES, VerdictPolicy(), Evidence(_shares(flow_line=0.85, friction=0.05)))
    assert got.body["confidence"] == "high" and not got.warnings
    # a stroke read with an offset lands in the gas law's own part (structure), not in a sensors part: a table
    # with the gap in the gas spring does not disagree with it (tuning seed 20012)
    off = CandidateFit("sensor_offset", {"channel": "stroke", "offset": -0.03}, {},
                       {c: {"rms_before": 1.0, "rms_after": 0.5, "shrink": 0.5} for c in CH}, 0.95, 0.95, 0.95, 1,
                       0.92, 0.0, {"channel": "stroke", "offset": -0.03})
    got = decide([off, _fit("gas_leak", 0.2)], GAP, ONES, ONES, VerdictPolicy(), Evidence(_shares(gas_spring=1.0)))
    assert got.body["confidence"] == "high" and got.body["component_table"]["largest"] == "gas_spring"


# ------------------------------------------------------------------ the planted case
def _friction_high(duration, rate=25.0, factor=1.3, seed=3):
    """The nominal paper-A plant in a JONSWAP sea with the seal's static and Coulomb forces x ``factor``,
    logged at ``rate`` with the benchmark's noise (2 mm heave and stroke, 2 kPa, 400 N)."""
    from heavecomp.diagnosis.data import check_run
    from heavecomp.benchmark.testbed import truth_dt
    from heavecomp.diagnosis.stepper import CHANNELS as SC, run_fx
    from heavecomp.effects.compose import composition
    from heavecomp.params import paper_a
    from heavecomp.plants.cmc import plant_vectors
    from heavecomp.simulate import excitation

    nominal = paper_a()
    truth = nominal.replace(friction={"static_force": 23e3 * factor, "coulomb_force": 12e3 * factor})
    comp = composition(())
    h = truth_dt(truth, rate)  # the generator's finer step
    n = int(math.ceil(duration / h))
    hs = excitation.jonswap(2.5, 10.0, 3.3, seed, 24.0, n * h, 0.5 * h)
    out = run_fx(plant_vectors(truth), comp, comp.ep([]), hs, h, n, int(round(1.0 / rate / h)))
    t = out[:, 0]
    cols = {c: out[:, SC.index(c)].copy() for c in ("heave", "stroke", "pressure", "wob")}
    rng = np.random.default_rng(seed)
    for c, s in {"heave": 2e-3, "stroke": 2e-3, "pressure": 2e3, "wob": 400.0}.items():
        cols[c] += rng.normal(0, s, t.size)
    return nominal, check_run(t, cols, params=nominal)


@pytest.mark.slow
def test_seal_friction_30_percent_high_is_a_parameter_error_not_pressure_friction():
    """The issue's user log: the seal's static and Coulomb forces 30 % high, 600 s at 25 Hz.  Before,
    pressure_friction (medium) won on a penalty that counted six parameters when two moved; now the refit
    of the nominal's own parameters is the verdict (it fits the held-out log at least as well and adds no
    mechanism), with F_S and F_C near the truth (29.9 and 15.6 kN) and the block test's pairs reported."""
    from heavecomp.diagnosis.estimator import GapDiagnoser

    nominal, run = _friction_high(600.0)
    d = GapDiagnoser(nominal, n_jobs=2).fit(run)
    j = d.to_json()
    v = j["verdict"]
    assert j["schema"] == 4
    assert v["effect"] == "parameter_mismatch", v
    assert v["parameters"]["friction.static_force"] == pytest.approx(29.9e3, rel=0.05)
    assert v["parameters"]["friction.coulomb_force"] == pytest.approx(15.6e3, rel=0.05)
    pm = next(c for c in j["candidates"] if c["effect"] == "parameter_mismatch")
    assert pm["n_params"] == 2  # it pays for what it released
    assert {p["b"] for p in v["distinguishable"]["pairs"]} >= {"pressure_friction"}
    assert v["distinguishable"]["false_alarm_measured"]["null_pairs"] >= 3
    assert isinstance(v["separate_by"], list)
