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
            # schema 4: the distance form of the frictional memory (issue 30 item 4)
            "friction_memory")


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


def test_effect_parameters_are_strict():
    """Unknown parameter names fail with the known ones; an effect outside the plant cannot be composed."""
    with pytest.raises(ParameterError, match=r"unknown parameter 'resistence'.*did you mean 'resistance'"):
        get("flow_loss")(resistence=1.0)
    with pytest.raises(ParameterError, match="not inside the plant"):
        composition((get("sensor_delay"),))
