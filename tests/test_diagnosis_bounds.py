"""Issue 14.3: a fitted parameter at its search bound lowers the confidence and says so.

A heave channel logged with the wrong sign gave `sensor_delay`, confidence medium, with the delay
stuck at its 3 s search limit: the candidate stood in for a defect it cannot describe."""

import pytest

from heavecomp.diagnosis.estimator import GapDiagnoser, at_bounds
from heavecomp.diagnosis.generator import generate


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


@pytest.mark.slow
def test_sign_flipped_heave_is_not_a_confident_effect_at_its_bound():
    """A no-effect run whose heave was logged with the wrong sign.  Before: `parameter_mismatch`, confidence
    medium, with four of its six multipliers at their search bounds (k_gas x0.2, C_v x20, k_ds x0.05,
    k_F x0.1) -- a confident answer from garbage."""
    from heavecomp.diagnosis.data import check_run

    tr = generate("none", seed=2, duration=300.0)
    cols = dict(tr.columns)
    cols["heave"] = -cols["heave"]
    d = GapDiagnoser(tr.nominal).fit(check_run(tr.t, cols, params=tr.nominal))
    v = d.verdict_
    best = d.candidates_[0]
    # the wrong sign leaves a large gap: not `none`
    assert v["effect"] != "none" and v["gap_to_noise"] > 3.0
    # the best candidate can only mimic it with parameters at their limits
    assert best["at_bound"] or v["effect"] == "inconclusive"
    named = v["effect"] != "inconclusive"
    assert not (named and v["confidence"] in ("medium", "high") and best["at_bound"])
    if named and best["at_bound"]:
        assert v["confidence"] == "low" and v["at_bound"] == best["at_bound"]
        assert any("search bound" in w for w in d.to_json()["warnings"])
