"""Effect library battery: names and parameter metadata, dissipation, and that each truth law used by
the withheld-effect generator is NOT the candidate's law (else the benchmark proves nothing)."""

import dataclasses

import numpy as np
import pytest

from heavecomp.effects import CANDIDATES, EFFECT_NAMES, get, terms as T
from heavecomp.errors import ParameterError

CONTRACT = ("friction_lag", "dwell_stiction", "pressure_friction", "gas_heat_transfer", "flow_loss",
            "string_damping", "sensor_delay", "parameter_mismatch")


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
        assert lo < f.default < hi, f.name
    x = cls.x0()
    lo, hi = cls.bounds_x()
    assert np.all(lo < x) and np.all(x < hi)
    # x <-> values round trip
    vals = cls.from_x(x)
    np.testing.assert_allclose(cls.to_x(vals), x)


def test_unknown_effect_names_the_known_ones():
    with pytest.raises(ParameterError, match=r"unknown effect 'dwell_sticton' \(did you mean 'dwell_stiction'\?\).*friction_lag"):
        get("dwell_sticton")


@pytest.mark.parametrize("name", ["friction_lag", "dwell_stiction", "pressure_friction"])
def test_friction_magnitude_stays_positive_dissipative(name):
    """J >= F_C > 0 for every speed and pressure: the friction opposes the motion (F v >= 0)."""
    FP = np.array([23e3, 12e3, 0.01, 10e3, 2e-3, 0.0])
    EP = T.zero_ep()
    cls = get(name)
    if cls.kind == "plant":
        cls.write_ep(cls.from_x(cls.x0()), EP)
    for a in np.linspace(0, 1, 21):
        for p in (0.0, 2.4e6, 3e6):
            for el in (0.0, 11e3):
                J = T.friction_magnitude_fx(a, p, 0.0, el, FP, EP)
                assert J >= FP[1] - 1e-9


def test_zero_ep_is_the_nominal_physics():
    """With EP = 0 every term vanishes: nominal gas law, no line drop, eq. 4 friction, no dwell."""
    from heavecomp.friction.laws import friction_jump
    from heavecomp.params import paper_a
    from heavecomp.plants.cmc import gas_pressure, plant_vector

    p = paper_a()
    PP = plant_vector(p)
    FP = np.array([23e3, 12e3, 0.01, 10e3, 2e-3, 0.0])
    EP = T.zero_ep()
    for s in (-1.0, 0.0, 0.7):
        assert T.gas_pressure_fx(s, 1.0, PP, EP) == pytest.approx(gas_pressure(s, PP), rel=1e-12)
    for a in (0.0, 0.005, 0.3):
        assert T.friction_magnitude_fx(a, 2.4e6, 0.0, 0.0, FP, EP) == pytest.approx(friction_jump(1, a, 2.4e6, FP))
    assert T.line_drop(0.4, EP) == 0.0 and T.dwell_gain(5.0, EP) == 0.0 and T.string_damping_fx(0.3, EP) == 0.0


def test_dwell_truth_is_not_the_candidate_law():
    """Best power law a tau^beta through the saturating exponential leaves a clear misfit."""
    from scipy.optimize import least_squares

    tau = np.linspace(0.05, 10, 200)
    EP = T.zero_ep()
    EP[T.DWELL_DF_TRUTH], EP[T.DWELL_TAU_TRUTH] = 10e3, 1.0
    truth = T.dwell_gain(tau, EP)

    def r(x):
        E2 = T.zero_ep()
        E2[T.DWELL_A_CAND], E2[T.DWELL_BETA_CAND] = np.exp(x[0]), x[1]
        return T.dwell_gain(tau, E2) - truth

    res = least_squares(r, [np.log(5e3), 0.5], bounds=([0, 0.05], [15, 1.0]))
    assert np.sqrt(np.mean(res.fun ** 2)) > 0.05 * 10e3


def test_flow_truth_is_not_the_candidate_law():
    """Orifice (v|v|) vs laminar line (v): the best linear fit of the quadratic drop misses by > 15 %."""
    v = np.linspace(-0.6, 0.6, 101)
    EP = T.zero_ep()
    EP[T.FLOW_K_TRUTH] = 3e5
    truth = T.line_drop(v, EP)
    R = float(truth @ v / (v @ v))
    assert np.sqrt(np.mean((R * v - truth) ** 2)) > 0.15 * np.sqrt(np.mean(truth ** 2))


def test_thermal_truth_limits_isothermal_and_adiabatic():
    """Fast heat exchange -> isothermal (theta -> 1); none -> adiabatic theta = (V0/V)^(gamma-1)."""
    from heavecomp.params import paper_a
    from heavecomp.plants.cmc import plant_vector

    PP = plant_vector(paper_a())
    EP = T.zero_ep()
    EP[T.TH_GAMMA_TRUTH], EP[T.TH_TAU_TRUTH] = 1.4, 1e9  # ~no exchange
    s, th, dt, v = 0.0, 1.0, 1e-3, -0.5
    for _ in range(1000):  # 1 s at -0.5 m/s
        th += dt * T.truth_thermal_rate(s, v, th, PP, EP)
        s += dt * v
    ratio = PP[5] / (PP[5] + PP[0] * s)
    assert th == pytest.approx(ratio ** 0.4, rel=1e-3)
    EP[T.TH_TAU_TRUTH] = 1e-3
    assert abs(T.truth_thermal_rate(s, 0.0, th, PP, EP)) > 0  # relaxes back towards 1
    assert T.truth_thermal_rate(s, 0.0, 1.0, PP, EP) == 0.0
