"""The score test before a full fit (issue 32 item 1): a candidate the equation error is blind to is
fitted in full only when the Gauss-Newton step from its null, on its probes' replays, predicts it
explains part of the held-out gap."""

import pytest

from heavecomp.benchmark import benchmark_case, generate
from heavecomp.diagnosis import score_test as T
from heavecomp.diagnosis.estimator import GapDiagnoser
from heavecomp.diagnosis.policy import VerdictPolicy
from heavecomp.effects.candidates import get

CANDIDATES = ["friction_lag", "flow_loss"]


def _diagnose(effect, seed):
    tr = generate(benchmark_case(effect, seed=seed, duration=120.0, rate=50.0))
    return GapDiagnoser(tr.nominal, candidates=CANDIDATES, n_jobs=2, second=0).fit(tr.to_run())


def _predicted(d, name):
    ctx = d.context_
    return T.predicted(ctx, [ctx.simulate([(name, dict(p))]) for p in get(name).fit.probes])


@pytest.mark.slow
def test_a_friction_candidate_is_left_out_where_the_gap_is_all_in_the_flow_line():
    d = _diagnose("flow_loss", 11)
    assert d.where_["components"]["flow_line"] > 0.9
    pre = d.prescreen_["friction_lag"]
    assert pre["replay"] is False
    st = pre["score_test"]
    assert st["explained"] < VerdictPolicy().score_test_explained
    assert len(st["probes"]) == len(get("friction_lag").fit.probes)
    row = next(r for r in d.candidates_ if r["effect"] == "friction_lag")
    assert row["skipped"].startswith("score test:")
    assert "friction_lag" not in {f.effect for f in d.fits_}
    assert d.verdict_["effect"] == "flow_loss"
    assert d.context_.replay.ledger.duplicates() == {}  # the probes are replays like any other


@pytest.mark.slow
def test_a_planted_friction_lag_passes_the_score_test():
    """On a log with a frictional lag planted the same test predicts a large share explained: the
    candidate is fitted (whether or not the equation error sent it to the test) and named."""
    d = _diagnose("friction_lag", 20000)
    assert d.prescreen_["friction_lag"]["replay"] is True
    got = _predicted(d, "friction_lag")
    assert got["explained"] >= 4 * VerdictPolicy().score_test_explained
    assert d.verdict_["effect"] == "friction_lag"


def test_only_blind_plant_candidates_with_probes_and_no_component_gap_are_tested():
    P = VerdictPolicy()
    fl, flow, memory = get("friction_lag"), get("flow_loss"), get("friction_memory")
    quiet = {"friction": 0.5}, {"friction": 0.001}, {"friction": True}
    assert T.needs_test(fl, "friction", *quiet, None, P)
    assert T.needs_test(memory, "friction", *quiet, {"shrink": 0.01}, P)
    assert not T.needs_test(memory, "friction", *quiet, {"shrink": 0.2}, P)  # its equation error sees a gap
    assert not T.needs_test(fl, "friction", {"friction": 5.0}, {"friction": 0.5}, {"friction": True}, None, P)
    assert not T.needs_test(fl, "friction", {"friction": 0.5}, {"friction": 0.001}, {"friction": False}, None, P)
    assert not T.needs_test(flow, "flow_line", {"flow_line": 0.5}, {"flow_line": 0.001}, {}, None, P)  # screened
    off = VerdictPolicy(score_test_explained=0.0)
    assert not T.needs_test(fl, "friction", *quiet, None, off)


def test_a_smooth_candidate_starts_at_its_score_tests_step():
    """A smooth candidate (string damping: no stick event's timing jumps with it) fitted after its score
    test starts at the test's Gauss-Newton step: the probes' common amplitude scaled by the fitted
    amplitudes' sum, the shape their amplitude-weighted mean; a friction candidate (not smooth), a zero
    step or no test gives no start."""
    sd, fl = get("string_damping"), get("friction_lag")
    probes = [dict(p) for p in sd.fit.probes]  # damping 1e5 at exponents 0.5, 1 and 2
    entry = {"score_test": {"amplitudes": [0.0, 0.5, 1.5], "probes": probes}}
    got = sd.from_x(T.start(sd, entry))
    assert got["damping"] == pytest.approx(2e5)
    assert got["exponent"] == pytest.approx((0.5 * 1.0 + 1.5 * 2.0) / 2.0)
    assert T.start(sd, {"score_test": {"amplitudes": [0.0, 0.0, 0.0], "probes": probes}}) is None
    assert T.start(sd, {"score_test": "pending"}) is None and T.start(sd, None) is None
    lag = {"score_test": {"amplitudes": [1.0, 0.0, 0.0], "probes": [dict(p) for p in fl.fit.probes]}}
    assert T.start(fl, lag) is None
