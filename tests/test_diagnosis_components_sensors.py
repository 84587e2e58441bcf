"""Sensors in the component residuals (heavecomp.diagnosis.components.channel_search): a channel that
misreads shows in every equation that reads it, a string that stiffens only in the lower-mass
balance.  Runs simulated by the project's own plant; the misreading is a generic clip of the reading
and the string's stiffening a cubic in its stretch, which no candidate fits: the benchmark's
``stiffening_string``, run in its truth stepper (compiled once for the suite, which
``tests/test_benchmark_truth.py`` compiles anyway; a test-only effect class cost a compile of its own,
about 50 s of CPU, 103 s at load 8)."""

import numpy as np
import pytest

from heavecomp.benchmark.truth import truth_composition
from heavecomp.benchmark.truth.stiffening_string import TruthStiffeningString
from heavecomp.diagnosis import components as CR
from heavecomp.diagnosis import equation_error as EE
from heavecomp.diagnosis.data import check_run
from heavecomp.diagnosis.stepper import simulate_fx
from heavecomp.params.sets import paper_a
from heavecomp.simulate import simulate

pytestmark = pytest.mark.slow  # loads (or compiles) the out-of-library truth stepper and simulates 2 x 240 s

NOISE = {"heave": 0.002, "stroke": 0.002, "pressure": 2e3, "wob": 400.0}
T = 240.0
CUT = 160.0  # fit before, held out after [s]


@pytest.fixture(scope="module")
def plant():
    return paper_a("stribeck")


def _residuals(p, cols):
    rng = np.random.default_rng(1)
    t = cols["t"]
    run = check_run(t, {c: cols[c] + rng.normal(0.0, NOISE[c], t.size) for c in NOISE}, params=p)
    cr = CR.residuals(run, p, heave_reference=0.0, noise=NOISE)
    return cr, cr.mask & (t < CUT), cr.mask & (t >= CUT)


def _columns(sim):
    return {"t": np.asarray(sim["t"], float), **{c: np.asarray(sim[c], float) for c in NOISE}}


def test_a_clipped_wob_reading_is_a_sensor(plant):
    """A load cell that reads at most its 85th percentile: the lower-mass and the top-mass balances
    both see the missing load, with the same coefficients; the channel search names the WOB."""
    cols = _columns(simulate(plant, T, rate=50.0))
    cr0, fit, val = _residuals(plant, cols)
    assert CR.channel_search(cr0, fit, val) is None  # a right reading is no sensor fault
    cols["wob"] = np.minimum(cols["wob"], np.quantile(cols["wob"], 0.85))
    cr, fit, val = _residuals(plant, cols)
    found = CR.channel_search(cr, fit, val)
    assert found is not None and found["component"] == "sensors" and found["channel"] == "wob"
    assert all(found["equations"][e]["shrink"] > 0.3 for e in ("lower_mass", "top_mass"))
    assert found["shrink"] > 0.5


def test_a_stiffening_string_stays_in_string_formation(plant):
    """A string that stiffens (cubic in its stretch): the WOB reads it right, so the top-mass balance
    holds; no channel explains two equations, and the open search on the string residual finds a power
    of the relative displacement."""
    sim = simulate_fx(plant, T, [TruthStiffeningString(k3=3e9)], rate=50.0, comp=truth_composition("stiffening_string"))
    cr, fit, val = _residuals(plant, _columns(sim))
    sh = cr.shares()
    assert max(sh, key=sh.get) == "string_formation"
    assert CR.channel_search(cr, fit, val) is None
    d = EE.open_search(cr.residual["string_formation"], cr.signals_for("string_formation"), fit, val,
                       component="string_formation")
    assert d is not None and {"rel_cubed", "rel_abs_rel"} & set(d["features"]) and d["shrink"] > 0.5
