"""Sensors in the component residuals (heavecomp.diagnosis.components.channel_search): a channel that
misreads shows in every equation that reads it, a string that stiffens only in the lower-mass
balance.  Runs simulated by the project's own plant; the misreading is a generic clip of the reading
and the string's stiffening a cubic in its stretch, neither a candidate nor a truth law."""

from dataclasses import dataclass

import numpy as np
import pytest

from heavecomp.diagnosis import components as CR
from heavecomp.diagnosis import equation_error as EE
from heavecomp.diagnosis.data import check_run
from heavecomp.effects.base import Effect
from heavecomp.params.core import q
from heavecomp.params.sets import paper_a
from heavecomp.plants.cmc import KDS, T0
from heavecomp.simulate import simulate

pytestmark = pytest.mark.slow  # compiles an effect composition (~1-2 min on 2 busy cores)

NOISE = {"heave": 0.002, "stroke": 0.002, "pressure": 2e3, "wob": 400.0}
T = 240.0
CUT = 160.0  # fit before, held out after [s]


class CubicString(Effect):
    """Test-only: a drill string that stiffens with its stretch, T += k3 ((T - T_0) / k_ds)^3."""

    name = "test_cubic_string"
    hook = "string"

    @dataclass(frozen=True)
    class Params:
        k3: float = q(0.0, "N/m^3", bounds=(0.0, 1e12), symbol="k_3", doc="cubic stiffening")

    @staticmethod
    def string(dv, T, x, PP, k3):
        e = (T - PP[T0]) / PP[KDS]
        return T + k3 * e * e * e


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
    return {"t": sim.t, **{c: np.asarray(sim[c], float) for c in NOISE}}


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
    sim = simulate(plant, T, rate=50.0, effects=[CubicString(k3=3e9)])
    cr, fit, val = _residuals(plant, _columns(sim))
    sh = cr.shares()
    assert max(sh, key=sh.get) == "string_formation"
    assert CR.channel_search(cr, fit, val) is None
    d = EE.open_search(cr.residual["string_formation"], cr.signals_for("string_formation"), fit, val,
                       component="string_formation")
    assert d is not None and {"rel_cubed", "rel_abs_rel"} & set(d["features"]) and d["shrink"] > 0.5
