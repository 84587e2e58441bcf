"""Component residuals of the CMC (heavecomp.diagnosis.components): an effect planted in one model
component shows up in that component's share, from the measured signals alone."""

import numpy as np
import pytest

from heavecomp.diagnosis import components as CR
from heavecomp.diagnosis import equation_error as EE
from heavecomp.diagnosis.data import check_run
from heavecomp.effects.charge_drift import ChargeDrift
from heavecomp.effects.pressure_friction import PressureFriction
from heavecomp.params.sets import paper_a
from heavecomp.simulate import simulate

pytestmark = pytest.mark.slow  # compiles two effect compositions (~2 min on 2 busy cores)

NOISE = {"heave": 0.002, "stroke": 0.002, "pressure": 2e3, "wob": 400.0}
T = 240.0


@pytest.fixture(scope="module")
def nominal():
    p = paper_a("stribeck")
    return p, simulate(p, T, rate=50.0)


def _measured(p, sim, seed=0):
    rng = np.random.default_rng(seed)
    t = sim.t
    cols = {c: sim[c] + rng.normal(0.0, NOISE[c], t.size) for c in NOISE}
    return check_run(t, cols, params=p)


def _components(p, nominal_sim, effects):
    sim = simulate(p, T, rate=50.0, effects=effects)
    run = _measured(p, sim)
    floor = {c: nominal_sim[c] for c in ("stroke", "pressure", "wob")}
    return CR.residuals(run, p, heave_reference=0.0, noise=NOISE, floor_channels=floor)


def test_shares_are_the_contract_components(nominal):
    p, nom = nominal
    cr = _components(p, nom, [ChargeDrift(charge_error=0.03)])
    sh = cr.shares()
    assert tuple(sh) == ("friction", "gas_spring", "flow_line", "string_formation", "sensors", "heave_input")
    assert [r["unit"] for r in cr.table()] == ["N", "Pa", "Pa", "N", "-", "N"]


def test_gas_charge_error_lands_in_gas_spring(nominal):
    p, nom = nominal
    cr = _components(p, nom, [ChargeDrift(charge_error=0.03)])
    sh = cr.shares()
    assert max(sh, key=sh.get) == "gas_spring" and sh["gas_spring"] > 0.5
    # the gas residual is the charge error itself: (p + p_atm) x 0.03 at the measured stroke
    r = cr.residual["gas_spring"][cr.mask]
    expected = 0.03 * (p.p0 + 101325.0)
    assert np.median(r) == pytest.approx(expected, rel=0.15)
    # the open search on that residual names the charge error, held out: 0.03 (p + p_atm) reads as
    # 0.03 p (the spring's scale) or as an offset (the preload)
    t = cr.t
    d = EE.open_search(cr.residual["gas_spring"], cr.signals_for("gas_spring"), cr.mask & (t < 160.0),
                       cr.mask & (t >= 160.0), component="gas_spring")
    assert d is not None and d["features"] in (["p"], ["const"]) and d["shrink"] > 0.5
    if d["features"] == ["p"]:
        assert d["coefficients"]["p"] == pytest.approx(0.03, rel=0.1)


def test_pressure_friction_lands_in_friction(nominal):
    p, nom = nominal
    cr = _components(p, nom, [PressureFriction(extra_pressure_coefficient=3e-3)])
    sh = cr.shares()
    assert max(sh, key=sh.get) == "friction" and sh["friction"] > 0.5
    # the friction residual recovers the planted force dC_p |p| sign(v) (sliding samples)
    r, sig = cr.residual["friction"], cr.signals
    ok = cr.mask & np.isfinite(r)
    k = np.linalg.lstsq((np.abs(sig["p"]) * np.sign(sig["v"]))[ok, None], r[ok], rcond=None)[0][0]
    assert k == pytest.approx(3e-3, rel=0.2)


def test_line_inertance_lands_in_flow_line(nominal):
    """The oil column in the line between cylinder and gas bank must be accelerated: the cylinder
    pressure reads p_gas - L ds''/dt (L [Pa s^2/m], the inertance seen from the stroke).  Planted in
    the measured pressure (out of every candidate), the gas law's residual is that term, and the
    attribution puts it in the line, not the gas spring (scoring seed 70028 read 99.5 % gas_spring
    before the acceleration column was the line's)."""
    p, nom = nominal
    run = _measured(p, nom)
    acc = np.gradient(np.gradient(nom["stroke"], nom.t), nom.t)
    cols = {c: run[c] for c in ("heave", "stroke", "wob")}
    cols["pressure"] = run["pressure"] - 1e5 * acc
    planted = check_run(run.t, cols, params=p)
    floor = {c: nom[c] for c in ("stroke", "pressure", "wob")}
    sh = CR.residuals(planted, p, heave_reference=0.0, noise=NOISE, floor_channels=floor).shares()
    assert max(sh, key=sh.get) == "flow_line" and sh["flow_line"] > 0.5


def test_no_effect_shows_no_component_gap(nominal):
    p, nom = nominal
    cr = _components(p, nom, [])
    assert max(cr.gap().values()) < 1.0


def _residuals_of(friction_residual, v, t):
    """A ComponentResiduals holding only a friction residual (stationarity reads residual, signals, mask)."""
    from heavecomp.diagnosis.components import ComponentResiduals
    return ComponentResiduals(t, {}, {}, {}, {"friction": friction_residual}, {"t": t, "v": v}, np.ones(t.size, bool))


def test_stationarity_tells_a_constant_friction_error_from_a_warming_seal():
    """A wrong Coulomb force is the same error all run long: its coefficient on sign(v) holds across the
    windows.  A seal that warms loses friction with time (J (1 - beta theta), theta -> 1 over ~100 s):
    the same mean error, but the first window's coefficient is far from the last ones'."""
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 600.0, 0.02)
    v = 0.3 * np.sin(2 * np.pi * t / 9.0) + 0.1 * np.sin(2 * np.pi * t / 6.3)
    noise = rng.normal(0.0, 600.0, t.size)
    constant = -4000.0 * np.sign(v) + noise
    warming = -6000.0 * (1.0 - np.exp(-t / 100.0)) * np.sign(v) + noise
    st_c = _residuals_of(constant, v, t).stationarity("friction")
    st_w = _residuals_of(warming, v, t).stationarity("friction")
    assert st_c["drifting"] == []
    assert st_w["drifting"] == ["sign_v"]
    sign_v = st_w["coefficients"][0]
    assert sign_v["feature"] == "sign_v" and sign_v["unit"] == "N"
    first, last = sign_v["value"][0], sign_v["value"][-1]
    assert first > 0.6 * last  # less negative early: the seal had not warmed yet


def test_prescreen_skips_sliding_friction_candidates_only_without_a_friction_gap(nominal):
    """With no effect the friction residual shows no gap: the candidates the top-mass balance sees while
    sliding (pressure, position, direction) are not replayed; dwell stiction and frictional lag, which
    act at breakaway and reversals where the balance is blind, are, and so is the six-parameter refit."""
    from heavecomp.diagnosis.policy import VerdictPolicy
    from heavecomp.diagnosis.screen import prescreen

    p, nom = nominal
    cr = _components(p, nom, [])
    sliding = ["pressure_friction", "position_friction", "asymmetric_friction"]
    always = ["friction_lag", "dwell_stiction", "parameter_mismatch"]
    pre = prescreen(cr, cr.shares(), cr.t < 160.0, cr.t >= 160.0, sliding + always, VerdictPolicy())
    assert [pre[n]["replay"] for n in sliding] == [False] * 3
    assert [pre[n]["replay"] for n in always] == [True] * 3


def test_a_heave_reading_is_replayed_where_a_logged_angle_leaves_the_split_blind(nominal):
    """No effect: the heave_input residual shows no gap, so the heave reading is not replayed.  With a vessel
    angle in the log the lever arm's L sin(theta) is in no column of the equation-error split (a 12.8 m lever
    arm put 98 % of a scored log's gap in string_formation and 1.6 % in heave_input), so the split cannot rule
    the reading out: it is replayed."""
    import numpy as np

    from heavecomp.diagnosis.policy import VerdictPolicy
    from heavecomp.diagnosis.screen import prescreen

    p, nom = nominal
    cr = _components(p, nom, [])
    names = ["heave_reference", "pressure_friction", "friction_lag"]  # friction_lag: always replayed
    pre = prescreen(cr, cr.shares(), cr.t < 160.0, cr.t >= 160.0, names, VerdictPolicy())
    assert [pre[n]["replay"] for n in names] == [False, False, True]
    cr.signals["pitch"] = 0.01 * np.sin(2 * np.pi * cr.t / 9.0)
    pre = prescreen(cr, cr.shares(), cr.t < 160.0, cr.t >= 160.0, names, VerdictPolicy())
    assert [pre[n]["replay"] for n in names] == [True, False, True]
