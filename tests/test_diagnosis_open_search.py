"""The open search per component (issue 22, proposal 2 of reports/calibration_validation/failures.md):
a component that is a part of another's equation is searched on its own parts only, the equations are
the parameter file's (its plant effects at their hooks), and a named law that is not the plant's is
replaced by the search's form.  Synthetic signals, no replay: each test is fast."""

import numpy as np
import pytest

from heavecomp.diagnosis import components as CR
from heavecomp.diagnosis import screen as S
from heavecomp.diagnosis.policy import VerdictPolicy
from heavecomp.params import paper_a
from heavecomp.plants.cmc import gas_pressure, plant_vectors

P = paper_a()
NOISE_P = 500.0  # measured-pressure noise [Pa]


def _motion(n=6001):
    t = np.linspace(0.0, 300.0, n)
    w1, w2 = 0.55, 0.23
    x = 0.4 * np.sin(w1 * t) + 0.3 * np.sin(w2 * t + 1.0)
    v = 0.4 * w1 * np.cos(w1 * t) + 0.3 * w2 * np.cos(w2 * t + 1.0)
    a = -0.4 * w1 ** 2 * np.sin(w1 * t) - 0.3 * w2 ** 2 * np.sin(w2 * t + 1.0)
    return t, x, v, a


def _residuals(line_drop, seed=0):
    """Component residuals whose gas law reads a cylinder pressure ``gas_pressure(x) + line_drop``
    (measured with noise); the balances read noise only."""
    t, x, v, a = _motion()
    rng = np.random.default_rng(seed)
    PP = plant_vectors(P)[2]
    p = gas_pressure(x, PP) + line_drop(v, a) + rng.normal(0.0, NOISE_P, t.size)
    eq = {"gas": p - gas_pressure(x, PP), "top_mass": rng.normal(0.0, 100.0, t.size),
          "lower_mass": rng.normal(0.0, 100.0, t.size)}
    z = np.zeros(t.size)
    sig = {"t": t, "x": x, "v": v, "a": a, "p": p, "dp": np.gradient(p, t), "wob": z + 1e5, "dwob": z,
           "zh": 0.1 * np.sin(0.4 * t), "dzh": 0.04 * np.cos(0.4 * t), "ddzh": -0.016 * np.sin(0.4 * t),
           "rel": x, "vrel": v}
    noise = {"gas": NOISE_P, "top_mass": 100.0, "lower_mass": 100.0}
    return CR._attribute(t, eq, sig, noise, np.ones(t.size, bool)), t < 200.0, t >= 200.0


def test_flow_line_is_searched_on_its_own_parts_and_recovers_a_turbulent_drop():
    """A turbulent orifice (K v|v|) in the line: the search finds v|v| with its coefficient, and never
    the gas law's own signals p and x (on spent run 590004 the whole library kept p and x, which
    rebuild the residual's definition, and returned nothing)."""
    K = -4e5
    cr, fit, val = _residuals(lambda v, a: K * v * np.abs(v))
    assert cr.own_features("flow_line") == ("v", "v_abs_v", "a")
    assert cr.own_features("gas_spring") is None  # an equation's own component keeps the whole library
    d = S.discover(cr, fit, val, VerdictPolicy())
    assert d is not None and d["component"] == "flow_line"
    assert d["features"] == ["v_abs_v"] and d["coefficients"]["v_abs_v"] == pytest.approx(K, rel=0.05)
    assert d["shrink"] > 0.8


def test_the_line_inertance_is_found_through_the_acceleration_feature():
    L = -9e4  # p = -L_eff a: the oil column accelerated by the plunger [Pa s^2/m]
    cr, fit, val = _residuals(lambda v, a: L * a)
    d = S.discover(cr, fit, val, VerdictPolicy())
    assert d is not None and d["component"] == "flow_line" and "a" in d["features"]
    assert d["coefficients"]["a"] == pytest.approx(L, rel=0.05)


def test_a_named_law_is_replaced_by_the_search_form_only_when_the_plant_does_not_follow_it():
    cr, fit, val = _residuals(lambda v, a: -4e5 * v * np.abs(v))  # turbulent: the laminar law is not the plant's
    form = S.named_form(cr, "flow_loss", fit, val)
    assert form is not None and form["replaces"] == "flow_loss" and form["features"] == ["v_abs_v"]
    assert form["bic"] < form["named"]["bic"] and form["shrink"] > form["named"]["shrink"]
    cr, fit, val = _residuals(lambda v, a: -1.2e5 * v)  # laminar: the named law is the plant's
    assert S.named_form(cr, "flow_loss", fit, val) is None
    assert S.named_form(cr, "parameter_mismatch", fit, val) is None  # no law of its own


def test_the_equations_are_the_parameter_files():
    """A calibrated file's flow_loss is part of its model: the gas law's residual against the file no
    longer holds its R v (with the nominal equations it did, and a re-diagnosis counted it twice)."""
    t, x, v, a = _motion()
    R = 1.1e5
    PP = plant_vectors(P)[2]
    pressure = gas_pressure(x, PP) - R * v
    z = np.zeros(t.size)
    heave, wob = 0.1 * np.sin(0.4 * t), z + 1e5
    nominal = CR.equations(t, heave, x, pressure, wob, P)[0]["gas"]
    filed = CR.equations(t, heave, x, pressure, wob, P.replace(effects=(("flow_loss", {"resistance": R}),)))[0]["gas"]
    mid = (t > 20.0) & (t < 280.0)
    rv = np.sqrt(np.mean((R * v[mid]) ** 2))
    assert np.sqrt(np.mean((nominal[mid] + R * v[mid]) ** 2)) < 0.05 * rv  # nominal: the drop -R v is left
    assert np.sqrt(np.mean(filed[mid] ** 2)) < 0.05 * rv  # the file's: nothing is left


def test_the_equations_compose_the_files_effects_as_the_stepper_does():
    """Two effects at the string hook act in the file's order in the stepper and the replay
    (``composition_for``); the component equations use the same composition, so a string term's stretch
    (recovered from the tension it is handed) is the replay's, not another order's (the order used to be
    the library's, which put the hook term last)."""
    from heavecomp.effects.compose import composition_for
    from heavecomp.effects.spec import plant_effects

    p = paper_a().replace(effects=[("string_term", {"rel": 2e5, "rel_median": 0.0}),
                                   ("string_damping", {"damping": 5e5})])
    fx, EP, _ = CR.file_hooks(p)
    eff = plant_effects(p)
    comp = composition_for(eff)
    PP = plant_vectors(p).PP
    args = (0.1, 0.5, 0.0, 0.0, 0.0, 0.0)  # s, v, yb, vb, zh, dzh: a stretch and a relative velocity
    T_eq = fx["tension_fx"](*args, np.zeros(4), PP, EP)
    T_stepper = comp.functions["tension_fx"](*args, np.zeros(4), PP, comp.ep(eff))
    T_nominal = composition_for([]).functions["tension_fx"](*args, np.zeros(4), PP, composition_for([]).ep([]))
    assert T_eq == pytest.approx(T_stepper, rel=1e-12) and abs(T_eq - T_nominal) > 1e3
