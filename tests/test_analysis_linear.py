"""Linearisation of the CMC (issue 3): operating point, proper realisation, eq. 14, 2-DOF."""

import numpy as np
import pytest

from heavecomp.analysis.linear import RAW_OUTPUTS, OUTPUTS, linearise, linearise_details, operating_point
from heavecomp.errors import ParameterError
from heavecomp.params import paper_a
from heavecomp.params.cmc import G


@pytest.fixture(scope="module")
def pa():
    return paper_a("stribeck")


def test_operating_point_is_the_contract_equilibrium(pa):
    op = operating_point(pa.replace(friction={"model": "none"}))
    assert op.equilibrium
    W0 = pa.operating_point.wob_setpoint
    np.testing.assert_allclose(op.y[:4], [W0, 0.0, pa.p0, pa.drill_string.lower_mass * G - W0], rtol=1e-12)


def test_signal_names_and_dc_gain_equals_eq14(pa):
    sys = linearise(pa)
    assert list(sys.input_labels) == ["heave", "u_active"]
    assert list(sys.output_labels) == ["wob", "stroke", "pressure", "tension"]
    assert list(sys.state_labels) == ["top_displacement", "top_velocity", "lower_displacement", "lower_velocity"]
    dc = np.asarray(sys.dcgain())
    # heave up by 1 m lifts the string: WOB drops by k_eff (paper A eq. 14)
    assert dc[0, 0] == pytest.approx(-pa.k_eff, rel=1e-10)
    # static force balance on the lower mass: tension change = -WOB change
    assert dc[3, 0] == pytest.approx(pa.k_eff, rel=1e-10)
    # a constant active force F moves WOB by -F k_eff/k_gas ... the gas spring carries the rest
    kg = pa.compensator.gas_stiffness
    assert dc[0, 1] == pytest.approx(-pa.k_eff / kg, rel=1e-10)


def test_natural_frequencies_match_closed_form_2dof(pa):
    p = pa.replace(drill_string={"damping": 0.0}, formation={"damping": 0.0})
    sys = linearise(p)
    Mc, mb = p.compensator.moving_mass, p.drill_string.lower_mass
    kg, kd, kF = p.compensator.gas_stiffness, p.drill_string.stiffness, p.formation.stiffness
    K = np.array([[kg + kd, -kd], [-kd, kd + kF]])
    w_ref = np.sqrt(np.sort(np.linalg.eigvals(np.diag([1 / Mc, 1 / mb]) @ K).real))
    lam = np.linalg.eigvals(sys.A)
    assert np.max(np.abs(lam.real)) < 1e-9 * np.max(np.abs(lam))  # undamped: on the imaginary axis
    w = np.sort(np.abs(lam.imag))[::2]
    np.testing.assert_allclose(w, w_ref, rtol=1e-10)


def _raw_response(L, w, out):
    """Frequency response of the raw jacobian model driven by z, dz = jw z, ddz = -w^2 z."""
    H = []
    for wi in w:
        s = 1j * wi
        bz = L.B[:, 0] + s * L.B[:, 1] + s * s * L.B[:, 2]
        dz = L.D[:, 0] + s * L.D[:, 1] + s * s * L.D[:, 2]
        x = np.linalg.solve(s * np.eye(4) - L.A, bz)
        H.append((L.C @ x + dz)[out])
    return np.array(H)


@pytest.mark.parametrize("mode,v0", [("none", None), ("viscous", None), ("sliding", 0.05), ("sliding", -0.2)])
def test_state_shift_realisation_equals_raw_model(pa, mode, v0):
    """The LTI model with heave as only input reproduces the model driven by z_h, dz_h, ddz_h."""
    p = pa.replace(drill_string={"damping": 5e4})  # c_ds != 0 makes dz_h enter the tension
    L = linearise_details(p, friction=mode, velocity=v0)
    w = np.logspace(-3, 2, 40)
    idx = [RAW_OUTPUTS.index(o) for o in OUTPUTS]
    raw = _raw_response(L, w, idx)
    lti = np.array([L.sys(1j * wi)[:, 0] for wi in w])
    np.testing.assert_allclose(lti, raw, rtol=1e-9, atol=1e-9 * np.abs(raw).max())


def test_sliding_slope_is_the_friction_law_slope(pa):
    from heavecomp.friction.laws import FrictionLaw

    law = FrictionLaw.from_params(pa.friction)
    v0 = 0.03
    L = linearise_details(pa, friction="sliding", velocity=v0)
    h = 1e-6
    fd = (law.force(v0 + h, pa.p0) - law.force(v0 - h, pa.p0)) / (2 * h)
    assert L.friction_slope == pytest.approx(float(fd), rel=1e-6)
    # at v0 = 3 cm/s the Stribeck slope -(F_S - F_C)/v_S e^{-3} still lowers the damping
    assert L.friction_slope < pa.friction.viscous_coefficient
    # the pressure term C_p |p| sign(v0): dF_f/ds = C_p dp/ds = -C_p k_gas / A for v0 > 0,
    # an in-phase stiffness that softens the gas spring by C_p k_gas / A
    kg, A, Cp = pa.compensator.gas_stiffness, pa.area, pa.friction.pressure_coefficient
    L0 = linearise_details(pa, friction="viscous")
    dk = (L.A[1, 0] - L0.A[1, 0]) * pa.compensator.moving_mass
    assert dk == pytest.approx(Cp * kg / A, rel=1e-6)


def test_viscous_mode_damps_by_Cv(pa):
    L = linearise_details(pa, friction="viscous")
    assert L.friction_slope == pytest.approx(pa.friction.viscous_coefficient, rel=1e-12)
    assert list(L.sys.state_labels)[1] == "top_velocity_shifted"


def test_bad_modes_raise_one_line_errors(pa):
    with pytest.raises(ParameterError, match="^velocity: the sliding linearisation needs"):
        linearise(pa, friction="sliding")
    with pytest.raises(ParameterError, match="^friction = 'dry'"):
        linearise(pa, friction="dry")
    with pytest.raises(ParameterError, match="^friction.viscous_coefficient"):
        linearise(paper_a("none"), friction="viscous")


def test_sliding_operating_point_carries_the_law_friction(pa):
    """About a constant stroke velocity the friction force is the exact law's, unbalanced (not an equilibrium)."""
    from heavecomp.friction.laws import FrictionLaw

    v0 = 0.04
    op = operating_point(pa, velocity=v0, eps=v0 / 25)
    F = float(FrictionLaw.from_params(pa.friction).force(v0, pa.p0))
    assert op.y[4] == pytest.approx(F, rel=1e-12)
    assert not op.equilibrium
    assert op.xdot[1] == pytest.approx(-F / pa.compensator.moving_mass, rel=1e-9)
    assert op.u[1] == -v0  # platform moves, top mass at rest


def test_a_seal_effect_with_stiction_leaves_the_frictionless_linearisation_and_enters_the_sliding_one():
    """A parameter file with pressure_friction (stiction at the seal hook): the frictionless model has
    no seal friction, so it equals the nominal one; sliding, the effect's friction slope is there."""
    from heavecomp.analysis.linear import linearise_details
    from heavecomp.params import paper_a

    p = paper_a("stribeck")
    fx = [("pressure_friction", {"extra_pressure_coefficient": 0.01})]
    A0 = linearise_details(p, friction="none").sys.A
    assert np.allclose(linearise_details(p, friction="none", effects=fx).sys.A, A0)
    As = linearise_details(p, friction="sliding", velocity=0.2).sys.A
    assert not np.allclose(linearise_details(p, friction="sliding", velocity=0.2, effects=fx).sys.A, As)
