"""EMPS axis: the published inverse-model identification, its filter sensitivity, planted
parameters on synthetic records, and the held-out residual diagnosis."""

from __future__ import annotations

import json
import runpy

import numpy as np
import pytest

from heavecomp.errors import DataError
from heavecomp.identification.inverse import AxisRegression, InverseModelLS
from heavecomp.identification.residual import ResidualDiagnoser
from heavecomp.plants.axis import EMPS_PUBLISHED, AxisRecord, inverse_force, load_emps

ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def emps(data_dir):
    return load_emps(data_dir / "emps" / "DATA_EMPS.mat")


@pytest.fixture(scope="module")
def emps_fit(emps):
    return InverseModelLS().fit(emps)


def test_published_values_within_2_percent(emps_fit):
    """Whole record, as the benchmark: M, F_v, F_c, offset within 2 % of Janot et al. (2019)."""
    for k, pub in EMPS_PUBLISHED.items():
        assert emps_fit.params_[k] == pytest.approx(pub, rel=0.02), k


def test_published_values_on_a_cutoff_plateau(emps):
    """Above the 40 Hz parallel-filter band the estimates hardly move (the default 50 Hz is on a
    plateau, not a lucky point); filtering q at 10 Hz, below that band, leaves force content the
    model side lacks: the rms residual more than doubles and F_v leaves the 2 % band."""
    ests = {c: InverseModelLS(cutoff=c).fit(emps) for c in (10.0, 50.0, 100.0, 200.0)}
    for c in (100.0, 200.0):
        for k in EMPS_PUBLISHED:
            assert ests[c].params_[k] == pytest.approx(ests[50.0].params_[k], rel=0.01), (c, k)
    assert ests[10.0].rms_ > 2.0 * ests[50.0].rms_
    assert abs(ests[10.0].params_["viscous"] / EMPS_PUBLISHED["viscous"] - 1) > 0.02


def _synthetic(extra=None, seed=1, duration=20.0, fs=1000.0, noise=0.3):
    """Prescribed smooth trajectory, analytic derivatives; friction with a tanh sign (not sign)."""
    t = np.arange(0.0, duration, 1.0 / fs)
    w1, w2 = 2 * np.pi * 0.35, 2 * np.pi * 1.3
    q = 0.1 * (1 - np.cos(w1 * t)) + 0.01 * np.sin(w2 * t)
    dq = 0.1 * w1 * np.sin(w1 * t) + 0.01 * w2 * np.cos(w2 * t)
    ddq = 0.1 * w1 ** 2 * np.cos(w1 * t) - 0.01 * w2 ** 2 * np.sin(w2 * t)
    M, Fv, Fc, off = 80.0, 150.0, 15.0, -2.0
    F = M * ddq + Fv * dq + Fc * np.tanh(dq / 2e-4) + off
    if extra is not None:
        F = F + extra(dq, q)
    rng = np.random.default_rng(seed)
    F = F + noise * rng.standard_normal(t.size)
    q = q + 2e-7 * rng.standard_normal(t.size)      # encoder-like position noise
    return AxisRecord(t=t, q=q, force=F, name="synthetic"), dict(mass=M, viscous=Fv, coulomb=Fc, offset=off)


def test_planted_parameters_recovered_on_synthetic_axis():
    rec, true = _synthetic()
    est = InverseModelLS().fit(rec)
    for k, v in true.items():
        assert est.params_[k] == pytest.approx(v, rel=0.02), k
    assert inverse_force(0.0, 0.1, **{"M": 1, "Fv": 2.0, "Fc": 3.0, "Foff": -1.0}) == pytest.approx(2.2)


def test_diagnoser_names_a_planted_stribeck_effect():
    """Generated with a Gaussian Stribeck peak (exp(-(v/v_s)^2), v_s = 15 mm/s), fitted with the
    friction law's exponential Stribeck column: a different law, so the check is not circular.  The
    nominal (EMPS) law has no Stribeck term, so the diagnosis names the law's static force: a
    parameter_mismatch of friction.static_force (F_S - F_C > 0: a friction peak at low speed)."""
    rec, _ = _synthetic(lambda v, q: 8.0 * np.exp(-(v / 0.015) ** 2) * np.tanh(v / 2e-4))
    d = ResidualDiagnoser(fit_window=(0.1, 12.0), validate_window=(12.0, 19.9)).fit(AxisRegression(rec))
    assert d.best_["effect"] == "parameter_mismatch"
    assert d.best_["shrink"] > 0.3
    assert list(d.best_["changes"]) == ["friction.static_force"]
    assert d.best_["parameters"]["friction.static_force"] > 0          # friction peak at low speed
    assert 0.005 < d.best_["parameters"]["friction.stribeck_velocity"] < 0.05


def test_diagnoser_says_none_without_an_effect():
    rec, _ = _synthetic(seed=3)
    d = ResidualDiagnoser(fit_window=(0.1, 12.0), validate_window=(12.0, 19.9)).fit(AxisRegression(rec))
    assert d.best_ is None, d.results_[0]
    assert max(r["shrink"] for r in d.results_) < 0.02


def test_emps_residual_lives_in_the_negative_direction_and_viscous_asymmetry_shrinks_it(emps_fit):
    d = ResidualDiagnoser(fit_window=(0.1, 15.0), validate_window=(15.0, 24.7)).fit(emps_fit.regression_)
    w = d.where_["direction"]
    assert sum(v["share"] for v in w.values()) == pytest.approx(1.0)
    assert w["negative"]["share"] > 0.5
    # the library's asymmetric_friction, through its viscous column (its Coulomb column is the
    # published offset, already in the nominal: dropped)
    assert d.best_["effect"] == "asymmetric_friction" and d.best_["shrink"] > 0.15
    assert "asymmetric_friction" not in d.best_["parameters"]
    # more viscous friction moving in the negative direction than in the positive one
    assert d.best_["parameters"]["asymmetric_viscous"] < 0
    assert d.selection_[-1]["shrink"] >= d.best_["shrink"]


def test_load_emps_names_the_missing_variable(tmp_path):
    import scipy.io

    path = tmp_path / "bad.mat"
    scipy.io.savemat(path, {"t": np.arange(20.0), "qm": np.zeros(20), "gtau": 35.0})
    with pytest.raises(DataError, match=r"bad.mat: missing variable 'vir'$"):
        load_emps(path)
    scipy.io.savemat(path, {"t": np.arange(20.0), "qm": np.zeros(19), "vir": np.zeros(20), "gtau": 35.0})
    with pytest.raises(DataError, match="variable 'qm' has 19 samples, 't' has 20"):
        load_emps(path)


def test_emps_scenario_quick(tmp_path):
    mod = runpy.run_path(str(ROOT / "scenarios" / "emps_identification.py"), run_name="scenario")
    assert mod["main"](["--quick", "--out", str(tmp_path)]) == 0
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert m["max_abs_relative_error"] < 0.02
    assert m["split"]["validate"][0] == m["split"]["fit"][1]
    assert 0 < m["selection"][-1]["shrink"] < 1
    # held-out rms is of the order of the fit rms (no overfitting of the base model)
    b = m["baseline_fit_part"]
    assert 0.5 < b["rms_validate"] / b["rms_fit"] < 2.0
    for f in ("overlay.png", "residual_map.png", "cutoff_sensitivity.png", "report.md"):
        assert (tmp_path / f).stat().st_size > 1000
