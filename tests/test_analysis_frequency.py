"""Frequency responses of the linearised CMC (issue 3): eq. 14, 2-DOF modes, batch == python-control,
linear model == small-amplitude nonlinear simulation."""

import numpy as np
import pytest

from heavecomp.analysis.frequency import (dc_gain, effective_stiffness, freqresp_batch, modes, response_table,
                                          transmissibility)
from heavecomp.analysis.linear import batch_matrices, batch_matrices_from_params, linearise, linearise_details
from heavecomp.params import paper_a


@pytest.fixture(scope="module")
def pa():
    return paper_a("stribeck")


def _K_M(p):
    kg, kd, kF = p.compensator.gas_stiffness, p.drill_string.stiffness, p.formation.stiffness
    K = np.array([[kg + kd, -kd], [-kd, kd + kF]])
    M = np.diag([p.compensator.moving_mass, p.drill_string.lower_mass])
    return K, M


def test_effective_stiffness_dc_is_eq14_and_frd(pa):
    import control as ct

    sys = linearise(pa)
    k = effective_stiffness(sys, [1e-6, 1e-4])
    assert isinstance(k, ct.FrequencyResponseData)
    np.testing.assert_allclose(np.asarray(k.frdata).ravel().real, pa.k_eff, rtol=1e-6)
    assert -dc_gain(sys) == pytest.approx(pa.k_eff, rel=1e-12)
    T = transmissibility(sys, [1e-6])
    assert abs(np.asarray(T.frdata).ravel()[0]) == pytest.approx(1.0, rel=1e-6)
    # far above both modes the lower mass cannot follow: WOB transmission falls off as 1/w^4 (mass-mass)
    w_hi = np.array([1e3, 1e4])
    kh = np.abs(np.asarray(effective_stiffness(sys, w_hi).frdata).ravel())
    assert np.log10(kh[0] / kh[1]) == pytest.approx(3.0, abs=0.05)  # c_F path: 1/w^3 asymptote


def test_natural_frequencies_and_damping_ratios_closed_form(pa):
    K, M = _K_M(pa)
    lam, phi = np.linalg.eig(np.linalg.solve(M, K))
    order = np.argsort(lam.real)
    w_ref = np.sqrt(lam.real[order])
    m = modes(linearise(pa))
    np.testing.assert_allclose(m["natural_frequencies"], w_ref, rtol=1e-10)
    # light damping: zeta_i = phi' C phi / (2 w_i phi' M phi) to first order
    cF, cd = pa.formation.damping, pa.drill_string.damping
    Cm = np.array([[cd, -cd], [-cd, cd + cF]])
    zeta_ref = [float(phi[:, i] @ Cm @ phi[:, i] / (2 * w_ref[k] * phi[:, i] @ M @ phi[:, i]))
                for k, i in enumerate(order)]
    np.testing.assert_allclose(m["damping_ratios"], zeta_ref, rtol=2e-3)
    assert m["damping_ratios"][0] > 0


def test_batch_response_equals_python_control():
    import control as ct

    rng = np.random.default_rng(3)
    n = 7
    kw = dict(gas_stiffness=rng.uniform(2e4, 1e5, n), moving_mass=rng.uniform(5e4, 1e5, n),
              lower_mass=rng.uniform(1e4, 6e4, n), string_stiffness=rng.uniform(2e5, 5e6, n),
              formation_stiffness=rng.uniform(1e4, 1e7, n), area=0.4, string_damping=rng.uniform(0, 5e4, n),
              formation_damping=rng.uniform(0, 5e4, n), friction_slope=rng.uniform(0, 2e4, n))
    A, B, C, D = batch_matrices(**kw)
    w = np.logspace(-2, 2, 50)
    H = freqresp_batch(A, B, C, D, w)
    for i in range(n):
        ref = ct.frequency_response(ct.ss(A[i], B[i], C[i], D[i]), w).frdata
        np.testing.assert_allclose(H[i], ref, rtol=1e-9, atol=1e-12 * np.abs(ref).max())


@pytest.mark.parametrize("mode,v0", [("none", None), ("viscous", None), ("sliding", 0.02), ("sliding", -0.3)])
def test_batch_matrices_pinned_to_casadi_linearisation(mode, v0):
    p = paper_a("rotating_eq7").replace(drill_string={"damping": 3e4, "stiffness": 7e5},
                                        formation={"stiffness": 3e5})
    L = linearise_details(p, friction=mode, velocity=v0)
    fs = -(L.A[1, 0] * p.compensator.moving_mass + p.compensator.gas_stiffness + p.drill_string.stiffness)
    M = batch_matrices_from_params(p, friction_slope=L.friction_slope, friction_stiffness=fs)
    for a, b in zip(M, (L.sys.A, L.sys.B, L.sys.C, L.sys.D)):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12 * np.abs(b).max())


def test_response_table_columns(pa):
    sys = linearise(pa)
    tab = response_table(sys, [1e-5, 1.0])
    assert tab["transmissibility"][0] == pytest.approx(1.0, rel=1e-6)
    assert tab["k_eff_mag"][0] == pytest.approx(pa.k_eff, rel=1e-6)
    # statically the series chain carries one force: gas spring k_gas |s| = k_eff z_h
    assert tab["stroke_per_heave_mag"][0] == pytest.approx(pa.k_eff / pa.compensator.gas_stiffness, rel=1e-6)
    assert abs(tab["stroke_per_heave_phase_deg"][0]) == pytest.approx(180.0, abs=1e-3)


@pytest.mark.parametrize("period", [12.0, 4.0])
def test_linear_model_matches_small_amplitude_nonlinear_simulation(pa, period):
    """1 cm sine heave, frictionless: steady WOB amplitude and phase of the stick-slip simulator."""
    from heavecomp.analysis.describing import simulated_response

    p = pa.replace(friction={"model": "none"})
    sys = linearise(p)
    w = 2 * np.pi / period
    H = freqresp_batch(sys.A, sys.B, sys.C, sys.D, [w])[0, 0, 0]
    sim = simulated_response(p, 0.01, period, settle_periods=10, measure_periods=4, rate=50.0)
    assert sim["wob_amplitude"] == pytest.approx(0.01 * abs(H), rel=1e-4)
    assert sim["wob_phase_deg"] == pytest.approx(np.degrees(np.angle(H)), abs=0.05)
