"""Issue 14.3: a fitted parameter at its search bound lowers the confidence and says so.

A heave channel logged with the wrong sign gave `sensor_delay`, confidence medium, with the delay
stuck at its 3 s search limit: the candidate stood in for a defect it cannot describe."""

import pytest

from heavecomp.diagnosis.estimator import GapDiagnoser, at_bounds
from heavecomp.benchmark import benchmark_case, generate


def test_at_bounds_reads_the_candidates_own_search_range():
    assert at_bounds("sensor_delay", {"channel": "wob", "delay": 3.0}) == [
        {"parameter": "delay", "value": 3.0, "side": "upper", "bound": 3.0, "unit": "s"}]
    assert at_bounds("sensor_delay", {"channel": "wob", "delay": 0.4}) == []
    # log-scaled parameters are judged on the log scale: 1e7 is the upper bound, 1e6 is inside
    assert at_bounds("flow_loss", {"resistance": 1e7})[0]["side"] == "upper"
    assert at_bounds("flow_loss", {"resistance": 1e6}) == []
    # parameter_mismatch: named as in the verdict's parameters, the value as a multiplier of the nominal
    from heavecomp.effects import get

    vals = {f.name: 1.0 for f in get("parameter_mismatch").fields()}
    vals["gas_stiffness"] = 0.2
    hit = at_bounds("parameter_mismatch", vals)
    assert [(h["parameter"], h["side"], h["unit"]) for h in hit] == [("compensator.gas_stiffness", "lower", "x nominal")]
    # a share whose search range is its physical range: 0 is an answer (a symmetric breakaway), not a bound hit
    assert at_bounds("asymmetric_friction", {"asymmetry": -0.3, "breakaway": 0.0}) == []
    assert at_bounds("asymmetric_friction", {"asymmetry": -0.9, "breakaway": 0.5})[0]["parameter"] == "asymmetry"


@pytest.mark.slow
def test_sign_flipped_heave_is_named_or_not_confident():
    """A no-effect run whose heave was logged with the wrong sign.  Before issue 14: `parameter_mismatch`,
    confidence medium, with four of its six multipliers at their search bounds -- a confident answer from
    garbage.  With heave_reference's scale limited to 0.5-1.5: `sensor_gain` on the stroke, factor -0.95,
    confidence high (wrong channel).  Now heave_reference may flip the sign and names it."""
    from heavecomp.diagnosis.data import check_run

    tr = generate(benchmark_case("none", seed=2, duration=300.0))
    cols = dict(tr.columns)
    cols["heave"] = -cols["heave"]
    d = GapDiagnoser(tr.nominal).fit(check_run(tr.t, cols, params=tr.nominal))
    v = d.verdict_
    best = d.candidates_[0]
    # the wrong sign leaves a large gap: not `none`
    assert v["effect"] != "none" and v["gap_to_noise"] > 3.0
    if v["effect"] == "heave_reference":
        # the library names it: the heave the compensator sees is the logged one times -1
        assert -1.1 < v["parameters"]["scale"] < -0.9, v["parameters"]
        return
    # anything else can only stand in for it (e.g. a stroke sensor read with the wrong sign: with a good
    # passive compensation the WOB hardly tells the two apart) and must not be confident
    assert v["confidence"] == "low", v
    named = v["effect"] != "inconclusive"
    if named and best["at_bound"]:
        assert v["at_bound"] == best["at_bound"]
        assert any("search bound" in w for w in d.to_json()["warnings"])
