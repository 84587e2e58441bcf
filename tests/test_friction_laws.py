"""Friction laws of paper A: limits, reductions, dissipation — one battery for every law."""

import numpy as np
import pytest

from heavecomp.friction.laws import FrictionLaw, hydromechanical_friction
from heavecomp.params import paper_a

P = 2.4e6  # Pa, the paper-A operating pressure
V = np.concatenate([-np.logspace(-5, 0, 200)[::-1], np.logspace(-5, 0, 200)])


def law(model, vt=0.05, **kw):
    base = dict(static_force=23e3, coulomb_force=12e3, stribeck_velocity=0.01, viscous_coefficient=10e3,
                pressure_coefficient=2e-3, tangential_velocity=vt)
    base.update(kw)
    return FrictionLaw(model, **base)


ALL = ["none", "stribeck", "rotating_eq6", "rotating_eq7"]


@pytest.mark.parametrize("model", ALL)
def test_dissipative_and_odd(model):
    f = law(model)
    F = f.force(V, P)
    assert np.all(np.isfinite(F))
    assert np.all(F * V >= 0)                          # friction dissipates while sliding
    np.testing.assert_allclose(f.force(-V, P), -F)     # odd in the velocity
    Fs = f.smooth(V, P, eps=1e-4)
    assert np.all(Fs * V >= 0)


@pytest.mark.parametrize("model", ["rotating_eq6", "rotating_eq7"])
def test_rotating_laws_reduce_to_eq4_at_zero_tangential_velocity(model):
    np.testing.assert_allclose(law(model, vt=0.0).force(V, P), law("stribeck").force(V, P), rtol=1e-13)
    assert law(model, vt=0.0).static_limit(P) == pytest.approx(law("stribeck").static_limit(P))


def test_eq4_values():
    f = law("stribeck")
    # at v -> 0+: F_S + C_p p ; far above v_S: F_C + C_v v + C_p p
    assert f.static_limit(P) == pytest.approx(23e3 + 2e-3 * P)
    assert f.force(1e-9, P) == pytest.approx(23e3 + 2e-3 * P, rel=1e-6)
    assert f.force(0.5, P) == pytest.approx(12e3 + 10e3 * 0.5 + 2e-3 * P, rel=1e-12)


def test_eq6_lowers_static_peak_keeps_jump():
    f6 = law("rotating_eq6")
    F0 = 12e3 + 11e3 * np.exp(-0.05 / 0.01)
    assert f6.static_limit(P) == pytest.approx(F0 + 2e-3 * P)       # jump 2 reduced ...
    assert f6.static_limit(P) < law("stribeck").static_limit(P)
    assert f6.force(1e-9, 0.0) - f6.force(-1e-9, 0.0) == pytest.approx(2 * F0, rel=1e-6)  # ... sign jump kept


def test_eq7_viscous_like_around_zero():
    f7 = law("rotating_eq7")
    # without pressure drop there is no jump: continuous and linear near v = 0
    assert f7.static_limit(0.0) == 0.0
    v = np.linspace(-1e-4, 1e-4, 21)
    F = f7.force(v, 0.0)
    slope = (12e3 + 11e3 * np.exp(-0.05 / 0.01)) / 0.05 + 10e3
    np.testing.assert_allclose(F, slope * v, rtol=1e-5, atol=1e-9)
    # outside the small band the Coulomb level remains (paper A Fig. 8)
    vv = np.hypot(0.5, 0.05)
    assert f7.force(0.5, 0.0) == pytest.approx((12e3 + 11e3 * np.exp(-vv / 0.01)) * 0.5 / vv + 5e3, rel=1e-12)
    # with pressure, only the C_p |p| part can stick
    assert f7.static_limit(P) == pytest.approx(2e-3 * P)


@pytest.mark.parametrize("model", ALL)
def test_smooth_converges_to_exact_away_from_zero(model):
    f = law(model)
    v = V[np.abs(V) > 1e-3]
    errs = [np.max(np.abs(f.smooth(v, P, eps=e) - f.force(v, P))) for e in (1e-3, 1e-4, 1e-5)]
    assert errs[-1] < 1e-6 * 23e3 or errs[0] == 0
    assert errs[0] >= errs[1] >= errs[2]
    with pytest.raises(ValueError, match="eps"):
        f.smooth(v, P, eps=0.0)


def test_from_params_and_unknown_model():
    f = FrictionLaw.from_params(paper_a("rotating_eq7").friction)
    assert f.model == "rotating_eq7" and f.FP[5] == 0.05
    from heavecomp.errors import ParameterError
    with pytest.raises(ParameterError, match="did you mean 'stribeck'"):
        FrictionLaw("stribek")


def test_hydromechanical_efficiency_eqs_1_to_3():
    Fp = np.array([100e3, 100e3, -100e3, -100e3])
    v = np.array([0.1, -0.1, -0.1, 0.1])
    F = hydromechanical_friction(Fp, v, eta=0.9)
    # positive load (pressure force drives): (1 - eta) F_p ; negative load: (1/eta - 1)|F_p|
    np.testing.assert_allclose(np.abs(F), [10e3, 100e3 / 0.9 - 100e3, 10e3, 100e3 / 0.9 - 100e3])
    assert np.all(F * v > 0)
    # it vanishes with the pressure force: no static or Coulomb friction (paper A's objection)
    assert hydromechanical_friction(0.0, 0.1, 0.9) == 0.0
