"""Real data with a withheld model term (issue 12 item 7): the EMPS record and the O-ring seal files
diagnosed against a nominal model that lacks one published term must name it; the full nominal
(the control) must not produce a gap of that size.  One diagnoser, the effect library's candidates."""

from __future__ import annotations

from pathlib import Path

import pytest

from heavecomp.identification.inverse import AxisRegression
from heavecomp.identification.plants import AxisFriction, SealFriction
from heavecomp.identification.residual import ResidualDiagnoser
from heavecomp.identification.seal import SealFrictionFit, load_seal_csv
from heavecomp.plants.axis import EMPS_PUBLISHED, load_emps

EMPS_WINDOWS = {"fit_window": (0.1, 15.0), "validate_window": (15.0, 24.7)}
SEAL_WINDOWS = {"fit_window": (0.0, 45.0), "validate_window": (45.0, 1e9), "dead_band": 2e-3}
CP = "friction.pressure_coefficient"
#: ~17 s on 2 cores (six diagnoses of the real records)
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def emps(data_dir):
    reg = AxisRegression(load_emps(data_dir / "emps" / "DATA_EMPS.mat"))
    return {w: ResidualDiagnoser(**EMPS_WINDOWS).fit(AxisFriction(reg, withheld=w))
            for w in ((), ("coulomb",), ("offset",))}


@pytest.fixture(scope="module")
def seal(data_dir):
    recs = [load_seal_csv(Path(data_dir) / "seal-friction" / f"O-ring_{p}bar.csv") for p in (1, 3, 5, 7)]
    sp = SealFrictionFit(n_boot=0).fit(recs).fits_["split"]
    nominal = {"friction.coulomb_force": sp["F_C"], CP: sp["C_p"], "direction_offset": sp["F_0"],
               "direction_offset_pressure": sp["C_0"]}
    out = {w: ResidualDiagnoser(**SEAL_WINDOWS).fit(SealFriction(recs, nominal, withheld=w)) for w in ((), (CP,))}
    out["nominal"] = nominal
    return out


def _reachable(full, withheld):
    return 1.0 - full.baseline_["rms_validate"] / withheld.baseline_["rms_validate"]


def test_emps_without_coulomb_names_the_coulomb_force(emps):
    d = emps[("coulomb",)]
    v = d.verdict_
    assert v["effect"] == "parameter_mismatch" and v["component"] == "friction"
    nominal, fitted = v["changes"]["friction.coulomb_force"]
    assert nominal == 0.0
    assert fitted == pytest.approx(EMPS_PUBLISHED["coulomb"], rel=0.25)
    # restoring the term is (nearly) all the verdict does: at least 95 % of what the full model reaches
    assert v["shrink"] >= 0.95 * _reachable(emps[()], d) > 0.5
    # runner-up far behind: no other friction effect stands in for the Coulomb force.  friction_memory (the
    # seal's memory over sliding distance, issue 30) modulates the friction with the direction of the last
    # stretch of sliding and so carries part of a direction-dependent force: it explains 0.35 against the
    # verdict's 0.75 (measured 2026-12-07); the other friction effects stay under 0.11.  Half the verdict's
    # shrink is the bar: the Coulomb force still wins by a factor of two
    assert d.results_[1]["shrink"] < 0.5 * v["shrink"]
    assert all(r["shrink"] < 0.3 * v["shrink"] for r in d.results_[1:] if r["effect"] != "friction_memory")


def test_emps_without_the_direction_asymmetry_names_asymmetric_friction(emps):
    """F_off + F_c sign(v) is an asymmetric Coulomb force while the axis moves: without F_off the
    diagnosis names asymmetric_friction, whose Coulomb column takes F_off's place (and whose viscous
    column the remainder the published model leaves)."""
    d = emps[("offset",)]
    v = d.verdict_
    assert v["effect"] == "asymmetric_friction" and v["component"] == "friction"
    # the full published model leaves a direction-dependent viscous remainder, which this verdict
    # also takes: its shrink reaches at least what restoring F_off alone does
    assert v["shrink"] >= _reachable(emps[()], d) > 0.3
    # more friction retracting: a negative Coulomb asymmetry, as the published offset
    assert v["parameters"]["asymmetric_friction"] < 0 and EMPS_PUBLISHED["offset"] < 0
    assert d.results_[1]["shrink"] < 0.3 * v["shrink"]


def test_emps_control_has_no_gap_of_a_withheld_terms_size(emps):
    full, without = emps[()], emps[("coulomb",)]
    assert "friction.coulomb_force" not in full.verdict_["changes"]
    assert full.verdict_["shrink"] < 0.5 * without.verdict_["shrink"]


def test_seal_without_pressure_coefficient_names_pressure_friction(seal):
    d = seal[(CP,)]
    v = d.verdict_
    assert v["effect"] == "pressure_friction" and v["component"] == "friction"
    assert v["parameters"]["pressure_friction"] == pytest.approx(seal["nominal"][CP], rel=0.2)
    assert v["shrink"] >= 0.95 * _reachable(seal[()], d) > 0.3
    assert d.results_[1]["shrink"] < 0.3 * v["shrink"]


def test_seal_control_names_no_pressure_friction(seal):
    full = seal[()]
    assert all(r["effect"] != "pressure_friction" for r in full.results_) or \
        next(r for r in full.results_ if r["effect"] == "pressure_friction")["shrink"] < 0.02
    assert full.verdict_["shrink"] < 0.3 * seal[(CP,)].verdict_["shrink"]
