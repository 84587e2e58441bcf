"""Paper B's pneumatic meter-out cylinder: orifice flow, adiabatic chambers, Exp. 2, compiled = source."""

import math

import numpy as np
import pytest

from heavecomp.errors import ParameterError
from heavecomp.pneumatic import plant as pn


@pytest.fixture(scope="module")
def p():
    return pn.default()


@pytest.fixture(scope="module")
def exp2(p):
    from heavecomp.pneumatic import stepper as PS

    return PS.simulate(p, 3.0, rate=1000.0)


def test_choked_flow_does_not_depend_on_downstream_pressure(p):
    Pu = 6e5
    b = pn.critical_ratio(1.4)
    assert b == pytest.approx(0.5283, abs=1e-4)
    G = [pn.orifice_flow(Pu, r * Pu, 1e-6, 293.15, 1.4, 287.0) for r in (0.1, 0.3, 0.5, b)]
    assert np.ptp(G) == 0.0
    # choked mass flow: S P sqrt(kappa/(R T) (2/(kappa+1))^((kappa+1)/(kappa-1)))
    ref = 1e-6 * Pu * math.sqrt(1.4 / (287 * 293.15) * (2 / 2.4) ** (2.4 / 0.4))
    assert G[0] == pytest.approx(ref, rel=1e-12)
    # unchoked: falls to zero at equal pressures, antisymmetric in direction
    assert pn.orifice_flow(Pu, 0.8 * Pu, 1e-6, 293.15, 1.4, 287.0) < G[0]
    assert pn.orifice_flow(Pu, Pu, 1e-6, 293.15, 1.4, 287.0) == 0.0
    assert pn.orifice_flow(0.7 * Pu, Pu, 1e-6, 293.15, 1.4, 287.0) == \
        -pn.orifice_flow(Pu, 0.7 * Pu, 1e-6, 293.15, 1.4, 287.0)


def test_closed_chambers_compress_adiabatically(p):
    """With both valves shut, P V^kappa is constant: dP/dt = -kappa P dV/dt / V."""
    PP = p.plant_vector()
    PP[pn.I_SS] = 0.0
    PP[pn.I_SE] = 0.0
    rng = np.random.default_rng(1)
    for _ in range(20):
        x, v = rng.uniform(0, p.stroke), rng.uniform(-0.5, 0.5)
        Pa, Pb = rng.uniform(1e5, 7e5, 2)
        dPa, dPb = pn.pressure_rates(x, v, Pa, Pb, PP)
        Va, Vb = pn.chamber_volumes(x, PP)
        assert dPa == pytest.approx(-p.kappa * Pa * p.area * v / Va, rel=1e-12)
        assert dPb == pytest.approx(+p.kappa * Pb * p.area * v / Vb, rel=1e-12)


def test_exp2_sticks_once_near_1p3_s_and_restarts_near_1p7_s(exp2):
    st = exp2["stats"]
    assert st["n_stick"] == 1 and st["n_breakaway"] == 2
    assert 1.15 < st["t_first_stick"] < 1.45
    assert 1.55 < st["t_second_breakaway"] < 1.85
    assert st["end_of_stroke"] == 0.0


def test_exp2_settles_at_the_equilibrium_velocity(p, exp2):
    u0, Pb = pn.equilibrium(p)
    late = exp2["t"] > 2.7
    assert np.mean(exp2["velocity"][late]) == pytest.approx(u0, rel=0.03)
    assert 0.02 < u0 < 0.04  # paper B: u_0 ~ 0.03 m/s
    # force balance at the equilibrium: A (P_s - P_b) = F_C + C u_0 (decelerating branch, F_k = F_C)
    assert p.area * (p.supply_abs - Pb) == pytest.approx(p.coulomb_force + p.viscous_coefficient * u0, rel=1e-9)


def test_stuck_friction_never_exceeds_the_static_limit(p, exp2):
    st = exp2["stuck"] > 0.5
    moved = exp2["t"] > exp2["stats"]["t_first_breakaway"]
    assert np.all(np.abs(exp2["friction"][st & moved]) <= p.stick_static_force + 1e-6)
    assert np.all(exp2["velocity"][st] == 0.0)


def test_compiled_functions_equal_their_source(p):
    from heavecomp.pneumatic import stepper as PS
    from heavecomp.pneumatic import friction as fr

    PP, FPB = p.plant_vector(), p.friction.FPB
    rng = np.random.default_rng(0)
    for _ in range(50):
        x, v = rng.uniform(0, p.stroke), rng.uniform(-0.2, 0.2)
        Pa, Pb = rng.uniform(1e5, 7e5, 2)
        assert PS.pressure_rates(x, v, Pa, Pb, PP) == pn.pressure_rates(x, v, Pa, Pb, PP)
        s = abs(v)
        assert PS.branch_magnitude(s, 20.0, FPB) == fr.branch_magnitude(s, 20.0, FPB)


def test_three_regime_branches():
    from heavecomp.pneumatic.friction import ThreeRegimeFriction

    f = ThreeRegimeFriction(28.0, 20.0, 8.0, 64.0, 0.06, 8.0)
    # accelerating branch starts at the static force, decelerating at F_k; both join the EHDL line at u_cr
    assert f.accelerating(1e-12) == pytest.approx(20.0)
    assert f.accelerating(1e-12, static=28.0) == pytest.approx(28.0)
    assert f.decelerating(1e-12) == pytest.approx(8.0)
    for v in (0.06, 0.1):
        assert f.accelerating(v) == pytest.approx(8.0 + 64.0 * v) == f.decelerating(v)
    assert f.accelerating(-0.03) == -f.accelerating(0.03)
    with pytest.raises(ParameterError, match="stick_static_force"):
        ThreeRegimeFriction(28.0, 5.0, 8.0, 64.0, 0.06, 8.0)


def test_parameter_file_errors_name_the_key(tmp_path):
    f = tmp_path / "p.toml"
    f.write_text("[pneumatic]\nexhaust_aera = 1e-7\n")
    with pytest.raises(ParameterError, match=r"pneumatic\.exhaust_aera: unknown key \(did you mean 'exhaust_area'\?\)"):
        pn.load(f)
    f.write_text("[pneumatic]\nbore = 0.0\n")
    with pytest.raises(ParameterError, match=r"pneumatic\.bore = 0 m is outside"):
        pn.load(f)
    f.write_text(pn.dumps(pn.default()))
    assert pn.load(f) == pn.default()
