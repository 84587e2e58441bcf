"""Effect library battery: names and parameter metadata, dissipation, and that each truth law used by
the withheld-effect generator is NOT the candidate's law (else the benchmark proves nothing)."""

import dataclasses

import numpy as np
import pytest

from heavecomp.benchmark import truth as TR
from heavecomp.effects import CANDIDATES, EFFECT_NAMES, get
from heavecomp.effects.compose import composition
from heavecomp.errors import ParameterError

CONTRACT = ("friction_lag", "dwell_stiction", "pressure_friction", "gas_heat_transfer", "flow_loss",
            "string_damping", "sensor_delay", "parameter_mismatch",
            # schema 2 (diagnosis-contract.md)
            "asymmetric_friction", "position_friction", "gas_leak", "sensor_gain", "sensor_offset", "heave_reference",
            # schema 4: the distance form of the frictional memory and the gas's thermal relaxation (issue 30
            # item 4): laws of the friction_lag and gas_heat_transfer classes
            "friction_memory", "gas_thermal",
            # the hysteretic law of the string_damping class (a Bouc-Wen share of the string's stiffness)
            "string_hysteresis",
            # the inertance law of the flow_loss class (the line's oil as a mass on the stroke)
            "line_inertia")


def test_contract_names_exactly():
    assert set(EFFECT_NAMES) == set(CONTRACT)
    for name, cls in CANDIDATES.items():
        assert cls.name == name


@pytest.mark.parametrize("name", CONTRACT)
def test_every_parameter_has_unit_bounds_and_a_guess_inside(name):
    cls = get(name)
    assert cls.n_params() >= 1
    for f in dataclasses.fields(cls.Params):
        lo, hi = f.metadata["bounds"]
        assert f.metadata["unit"], f.name
        # a parameter whose bounds are its physical range (``limits``, e.g. a share) may default to one of them
        assert (lo <= f.default <= hi) if f.name in cls.limits else (lo < f.default < hi), f.name
    x = cls.x0()
    lo, hi = cls.bounds_x()
    assert np.all(lo < x) and np.all(x < hi)
    # x <-> values round trip
    vals = cls.from_x(x)
    np.testing.assert_allclose(cls.to_x(vals), x)


def test_unknown_effect_names_the_known_ones():
    with pytest.raises(ParameterError, match=r"unknown effect 'dwell_sticton' \(did you mean 'dwell_stiction'\?\).*friction_lag"):
        get("dwell_sticton")


def test_dwell_truth_is_not_the_candidate_law():
    """Best power law a tau^beta through the saturating exponential leaves a clear misfit."""
    from scipy.optimize import least_squares

    tau = np.linspace(0.05, 10, 200)
    truth = TR.TruthDwell.static(1, 0.0, 0.0, tau, 0.0, 1.0, (), None, 10e3, 1.0)
    cand = get("dwell_stiction")

    def r(x):
        return cand.static(1, 0.0, 0.0, tau, 0.0, 1.0, (), None, np.exp(x[0]), x[1]) - truth

    res = least_squares(r, [np.log(5e3), 0.5], bounds=([0, 0.05], [15, 1.0]))
    assert np.sqrt(np.mean(res.fun ** 2)) > 0.05 * 10e3


def test_flow_truth_is_not_the_candidate_law():
    """Orifice (v|v|) vs laminar line (v): the best linear fit of the quadratic drop misses by > 15 %."""
    v = np.linspace(-0.6, 0.6, 101)
    truth = -TR.TruthOrifice.line(v, 0.0, (), None, 3e5)
    R = float(truth @ v / (v @ v))
    assert np.sqrt(np.mean((R * v - truth) ** 2)) > 0.15 * np.sqrt(np.mean(truth ** 2))
    assert np.allclose(-get("flow_loss").line(v, 0.0, (), None, R), R * v)  # the candidate is that linear fit's law


def test_thermal_truth_limits_isothermal_and_adiabatic():
    """Fast heat exchange -> isothermal (theta -> 1); none -> adiabatic theta = (V0/V)^(gamma-1)."""
    from heavecomp.params import paper_a
    from heavecomp.plants.cmc import A, V0, plant_vector

    PP = plant_vector(paper_a())
    rate = TR.TruthThermalGas.rates
    s, th, dt, v = 0.0, 1.0, 1e-3, -0.5
    for _ in range(1000):  # 1 s at -0.5 m/s, ~no exchange
        th += dt * rate(s, v, 0.0, (th,), PP, None, 1.4, 1e9)[0]
        s += dt * v
    ratio = PP[V0] / (PP[V0] + PP[A] * s)
    assert th == pytest.approx(ratio ** 0.4, rel=1e-3)
    assert abs(rate(s, 0.0, 0.0, (th,), PP, None, 1.4, 1e-3)[0]) > 0  # relaxes back towards 1
    assert rate(s, 0.0, 0.0, (1.0,), PP, None, 1.4, 1e-3)[0] == 0.0


def _theta(rate, prm, amp, f, PP, T=40.0, dt=5e-3):
    """theta - 1 over the second half of T s of a sinusoidal stroke (amplitude amp [m], f [Hz]), explicit steps."""
    t = np.arange(0.0, T, dt)
    s, v = amp * np.sin(2 * np.pi * f * t), amp * 2 * np.pi * f * np.cos(2 * np.pi * f * t)
    th, out = 1.0, np.empty(t.size)
    for k in range(t.size):
        out[k] = th
        th += dt * rate(s[k], v[k], 0.0, (th,), PP, None, *prm)[0]
    return out[t > T / 2] - 1.0


def test_thermal_candidate_spans_isothermal_to_adiabatic():
    """gas_thermal: no exchange -> adiabatic, p_abs = p0_abs (V0/V)^gamma; a fast exchange -> isothermal,
    p_abs = p0_abs V0/V; and the hook adds only the law's difference from the nominal polytropic gas."""
    from heavecomp.params import paper_a
    from heavecomp.plants.cmc import A, N, P0ABS, PATM, V0, gas_pressure, plant_vector

    PP = plant_vector(paper_a())
    g = get("gas_thermal")
    s, v, dt = 0.0, -0.5, 1e-3
    th_ad, th_iso = 1.0, 1.0
    for _ in range(1000):  # 1 s at -0.5 m/s
        th_ad += dt * g.rates(s, v, 0.0, (th_ad,), PP, None, 1.4, 1e9)[0]
        th_iso += dt * g.rates(s, v, 0.0, (th_iso,), PP, None, 1.4, 1e-3)[0]
        s += dt * v
    r = PP[V0] / (PP[V0] + PP[A] * s)
    p_nom = gas_pressure(s, PP)
    assert g.gas(s, v, p_nom, (th_ad,), PP, 1.4, 1e9) + PP[PATM] == pytest.approx(PP[P0ABS] * r ** 1.4, rel=1e-3)
    assert g.gas(s, v, p_nom, (th_iso,), PP, 1.4, 1e-3) + PP[PATM] == pytest.approx(PP[P0ABS] * r, rel=1e-4)
    assert g.gas(s, v, 123.0, (th_iso,), PP, 1.4, 1e-3) - g.gas(s, v, 0.0, (th_iso,), PP, 1.4, 1e-3) == 123.0
    assert PP[N] != 1.0 and PP[N] != 1.4  # the nominal is an effective index: neither limit


def test_thermal_truth_is_not_the_candidate_law():
    """The generator's exchange (conduction + natural convection, its rate growing with the temperature
    difference) has no one time constant: the candidate's best single tau_th over a large and a small stroke
    misses its temperature swing by > 4 % rms."""
    from scipy.optimize import minimize_scalar
    from heavecomp.params import paper_a
    from heavecomp.plants.cmc import plant_vector

    PP = plant_vector(paper_a())
    cases = [(0.6, 0.1), (0.05, 0.1)]
    truth = np.concatenate([_theta(TR.TruthThermalGas.rates, (1.4, 4.0), a, f, PP) / a for a, f in cases])
    cand = get("gas_thermal")

    def err(lt):
        c = np.concatenate([_theta(cand.rates, (1.4, np.exp(lt)), a, f, PP) / a for a, f in cases])
        return np.sqrt(np.mean((c - truth) ** 2))

    best = minimize_scalar(err, bounds=(np.log(0.3), np.log(50.0)), method="bounded")
    assert best.fun > 0.04 * np.sqrt(np.mean(truth ** 2))


def test_effect_parameters_are_strict():
    """Unknown parameter names fail with the known ones; an effect outside the plant cannot be composed."""
    with pytest.raises(ParameterError, match=r"unknown parameter 'resistence'.*did you mean 'resistance'"):
        get("flow_loss")(resistence=1.0)
    with pytest.raises(ParameterError, match="not inside the plant"):
        composition((get("sensor_delay"),))
