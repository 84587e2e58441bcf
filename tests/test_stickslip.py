"""Paper B's critical curve: limits, closed form vs ODE, Jacobian pin, agreement with nonlinear runs; CMC breakout."""

import math

import numpy as np
import pytest

from heavecomp.pneumatic import linear as PL
from heavecomp.pneumatic import stickslip as SS
from heavecomp.pneumatic import plant as pn


def test_critical_curve_limits():
    assert SS.critical_D(0.0) == 0.0
    assert SS.critical_D(1.0) == math.inf
    assert SS.critical_D(0.999) > 1e3
    z = np.linspace(0.01, 0.95, 30)
    Dc = SS.critical_curve(z)
    assert np.all(np.diff(Dc) > 0)  # more damping -> larger friction drop needed
    # undamped limit: y_min = -sqrt(1 + D^2) < -1 for any D > 0; small zeta -> D_cr ~ O(sqrt(zeta))
    assert SS.critical_D(1e-4) < 0.1


@pytest.mark.parametrize("zeta,D", [(0.1, 0.5), (0.3, 4.0), (0.5, 15.0), (0.2, 2.45)])
def test_overshoot_closed_form_matches_the_ode(zeta, D):
    from scipy.integrate import solve_ivp

    sol = solve_ivp(lambda t, y: [y[1], -2 * zeta * y[1] - y[0]], (0, 40), [-1.0, D], rtol=1e-11, atol=1e-12,
                    dense_output=True, max_step=0.01)
    tt = np.linspace(0, 40, 400001)
    y = sol.sol(tt)[0]
    ymax, ymin = SS.overshoot(zeta, D)
    assert ymax == pytest.approx(y.max(), rel=1e-6)
    i = np.argmax(y)
    assert ymin == pytest.approx(y[i:].min(), rel=1e-6)


def test_critical_point_is_where_velocity_just_returns_to_zero():
    for z in (0.1, 0.3, 0.6):
        Dc = SS.critical_D(z)
        assert SS.overshoot(z, Dc)[1] == pytest.approx(-1.0, abs=1e-9)


def test_linearisation_pinned_to_casadi_jacobian_of_the_plant():
    p = pn.default()
    for q in (p, p.replace(exhaust_area=2e-6, supply_pressure=0.15e6)):  # choked and unchoked exhaust
        lin = PL.linearise(q, convention="full")
        J = PL.casadi_jacobian(q)
        np.testing.assert_allclose(J, lin.A, rtol=1e-7, atol=1e-9 * np.abs(lin.A).max())
        paper = PL.linearise(q, convention="paper")
        _, Vb = pn.chamber_volumes(paper.position, q.plant_vector())
        assert paper.a - lin.a == pytest.approx(q.kappa * q.area * lin.u0 / Vb, rel=1e-9)
        # eigenvalues of the 2x2 are the roots of s^2 + 2 zeta w_n s + w_n^2
        ev = np.linalg.eigvals(lin.A)
        assert np.prod(ev).real == pytest.approx(lin.omega_n ** 2, rel=1e-9)
        assert -np.sum(ev).real == pytest.approx(2 * lin.zeta * lin.omega_n, rel=1e-9)


def test_choked_exhaust_gives_no_valve_damping_in_the_full_linearisation():
    lin = PL.linearise(pn.default(), convention="full")
    assert abs(lin.a) < 1e-9 * lin.b * pn.default().area / pn.default().mass


@pytest.mark.parametrize("factor,expect", [(0.4, False), (2.5, True)])
def test_simulation_agrees_with_the_curve_away_from_it(factor, expect):
    p = pn.default()
    lin = PL.linearise(p)
    target = factor * SS.critical_D(lin.zeta)
    drop = target * p.mass * lin.u0 * lin.omega_n  # D* is linear in F_s1 - F_C (c = C here)
    q = SS.vary(p, {"friction_drop": drop})
    lq = PL.linearise(q)
    assert lq.D == pytest.approx(target, rel=1e-6)
    assert SS.predicts_stick_slip(lq.zeta, lq.D) is expect
    assert SS.nonlinear_sticks(q) is expect


def test_small_grid_agreement():
    p = pn.default()
    g = SS.grid_map(p, "viscous_coefficient", np.geomspace(8, 250, 6), "friction_drop", np.geomspace(1, 120, 6))
    assert g["agreement"] >= 0.85
    # both outcomes occur (the grid straddles the curve)
    assert 0 < g["nonlinear"].sum() < g["nonlinear"].size


def test_minimum_velocity_is_on_the_critical_curve():
    p = pn.default()
    mv = SS.minimum_velocity(p, nonlinear=False)
    lin = PL.linearise(p.replace(exhaust_area=mv["linear_exhaust_area"]))
    assert lin.u0 == pytest.approx(mv["linear_u0"], rel=1e-9)
    assert lin.D == pytest.approx(SS.critical_D(lin.zeta), rel=1e-4)
    assert mv["linear_u0"] < pn.equilibrium(p)[0]  # default cylinder is stick-slip free after a stick


def test_influence_directions_of_paper_b_fig6():
    inf = SS.influence(pn.default(), factors=(1.0, 2.0))

    def ratio(var):
        r = inf[var]
        return r["D"][1] / SS.critical_D(r["zeta"][1]) / (r["D"][0] / SS.critical_D(r["zeta"][0]))

    assert ratio("friction_drop") > 1 and ratio("bore") > 1          # more stick-slip
    assert ratio("viscous_coefficient") < 1 and ratio("exhaust_area") < 1  # less stick-slip


def test_cmc_zero_stroke_below_the_breakout_amplitude():
    from heavecomp.analysis.stick_map import cmc_breakout_amplitude, cmc_stick_map
    from heavecomp.params import paper_a

    p = paper_a()
    a0 = cmc_breakout_amplitude(p, 12.0, "stribeck")
    m = cmc_stick_map(p, [0.5 * a0, 2.0 * a0], [12.0], ("stribeck",), n_periods=1.0)
    sf = m["stribeck"]["stick_fraction"][0]
    assert sf[0] == pytest.approx(1.0)
    assert sf[1] < 0.95
    assert m["stribeck"]["stroke_p2p"][0, 0] < 1e-9 < m["stribeck"]["stroke_p2p"][0, 1]


def test_cli_bad_input_exits_2(capsys):
    from heavecomp.cli import main

    assert main(["stickslip", "default", "--map", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "heavecomp stickslip: error: --map must be a grid size between 2 and 200, got 1"
    assert main(["stickslip", "nonexistent.toml"]) == 2
    assert "nonexistent.toml: no such parameter file" in capsys.readouterr().err


def _by_imag(ev):
    ev = np.asarray(ev, dtype=complex)
    return ev[np.lexsort((ev.real, ev.imag))]


def test_pneumatic_linearisation_is_a_named_statespace_with_the_closed_form_poles():
    """issue 13: the pneumatic linearisation as a python-control StateSpace; its poles are the
    roots of s^2 + 2 zeta* omega_n s + omega_n^2 (closed form) and, in the full convention,
    the eigenvalues of the casadi Jacobian of the plant's own functions."""
    import control as ct

    p = pn.default()
    for q in (p, p.replace(exhaust_area=2e-6, supply_pressure=0.15e6)):   # choked and unchoked exhaust
        for conv in ("paper", "full"):
            lin = PL.linearise(q, convention=conv)
            sys = lin.sys
            assert isinstance(sys, ct.StateSpace)
            assert sys.state_labels == ["velocity", "pressure_b"]
            assert sys.input_labels == ["force"] and sys.output_labels == ["velocity", "pressure_b"]
            wn, z = lin.omega_n, lin.zeta
            closed = _by_imag(np.roots([1.0, 2 * z * wn, wn * wn]))
            np.testing.assert_allclose(_by_imag(sys.poles()), closed, rtol=1e-9)
            np.testing.assert_allclose(_by_imag(lin.poles()), closed, rtol=1e-9)
            (w_mode, z_mode), = lin.modes()                                 # one oscillatory mode
            assert w_mode == pytest.approx(wn, rel=1e-9) and z_mode == pytest.approx(z, rel=1e-9)
            if conv == "full":
                J = PL.casadi_jacobian(q)
                np.testing.assert_allclose(_by_imag(sys.poles()), _by_imag(np.linalg.eigvals(J)), rtol=1e-7)
            # a steady extra force F speeds the piston up by F a / (A b + a c) = F a / (M omega_n^2)
            dc = np.asarray(ct.dcgain(sys)).reshape(2)
            assert dc[0] == pytest.approx(lin.a / (q.mass * wn * wn), rel=1e-9)
            assert dc[1] == pytest.approx(lin.b * dc[0] / lin.a, rel=1e-9)   # dp = b w / a


def test_linear_model_modes_of_the_cmc():
    """The CMC's Linearisation is the same LinearModel: its modes are the 2-DOF eigenfrequencies."""
    from heavecomp.analysis.linear import LinearModel, linearise_details
    from heavecomp.params import paper_a

    pa = paper_a()
    lin = linearise_details(pa, friction="none")
    assert isinstance(lin, LinearModel) and isinstance(PL.linearise(pn.default()), LinearModel)
    c, ds, fo = pa.compensator, pa.drill_string, pa.formation
    M = np.diag([c.moving_mass, ds.lower_mass])
    K = np.array([[c.gas_stiffness + ds.stiffness, -ds.stiffness], [-ds.stiffness, ds.stiffness + fo.stiffness]])
    w_undamped = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real))
    modes = lin.modes()
    assert [w for w, _ in modes] == sorted(w for w, _ in modes)
    lightly = [w for w, z in modes if abs(z) < 0.3]
    np.testing.assert_allclose(lightly, w_undamped, rtol=0.05)
