"""One estimator base for both gap diagnosers (issue 11 item 5): the CMC's GapDiagnoser and the
1-DOF axis' ResidualDiagnoser share get_params, the not-fitted error, ranking_ and effect_."""

import pytest

from heavecomp.diagnosis import GapDiagnoser
from heavecomp.estimator import GapEstimator, NotFittedError
from heavecomp.identification.inverse import AxisRegression
from heavecomp.identification.residual import ResidualDiagnoser
from heavecomp.params import paper_a


def test_both_diagnosers_are_gap_estimators_with_the_same_door():
    for cls in (GapDiagnoser, ResidualDiagnoser):
        assert issubclass(cls, GapEstimator)
        for name in ("fit", "get_params", "check_fitted", "ranking_", "effect_"):
            assert hasattr(cls, name), (cls.__name__, name)


@pytest.mark.parametrize("make", [lambda: GapDiagnoser(paper_a(), ["flow_loss"], split=0.5),
                                  lambda: ResidualDiagnoser(["friction_lag"], fit_window=(0.0, 5.0))])
def test_results_before_fit_are_a_one_line_error(make):
    d = make()
    assert not d.fitted
    for attr in ("ranking_", "effect_"):
        with pytest.raises(NotFittedError, match=f"^{type(d).__name__}: call fit\\(\\) first$"):
            getattr(d, attr)


def test_get_params_rebuilds_the_same_settings():
    d = GapDiagnoser(paper_a(), ["flow_loss", "sensor_delay"], split=0.5, penalty=0.05)
    p = d.get_params()
    assert p["split"] == 0.5 and p["penalty"] == 0.05 and list(p["candidates"]) == ["flow_loss", "sensor_delay"]
    assert GapDiagnoser(**p).get_params() == p
    assert "split=0.5" in repr(d) and "penalty=0.05" in repr(d) and "decimate" not in repr(d)
    r = ResidualDiagnoser(fit_window=(0.1, 12.0), dead_band=0.01)
    assert ResidualDiagnoser(**r.get_params()).get_params() == r.get_params()
    assert r.get_params()["fit_window"] == (0.1, 12.0) and r.get_params()["dead_band"] == 0.01


def test_axis_diagnoser_names_a_planted_effect_and_none_without_one():
    """The base's effect_ is what the diagnoser decided: the planted Stribeck peak (a term of the
    friction law the nominal lacks: parameter_mismatch of friction.static_force), or None."""
    import numpy as np
    from test_emps_identification import _synthetic

    rec, _ = _synthetic(lambda v, q: 8.0 * np.exp(-(v / 0.015) ** 2) * np.tanh(v / 2e-4))
    d = ResidualDiagnoser(fit_window=(0.1, 12.0), validate_window=(12.0, 19.9)).fit(AxisRegression(rec))
    assert d.effect_ == "parameter_mismatch" and d.ranking_[0]["effect"] == "parameter_mismatch"
    assert list(d.ranking_[0]["changes"]) == ["friction.static_force"]
    assert [r["score"] for r in d.ranking_] == sorted(r["score"] for r in d.ranking_)
    rec, _ = _synthetic(seed=3)
    d = ResidualDiagnoser(fit_window=(0.1, 12.0), validate_window=(12.0, 19.9)).fit(AxisRegression(rec))
    assert d.effect_ is None and d.fitted
