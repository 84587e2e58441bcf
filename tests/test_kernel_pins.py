"""'Physics once' pins: the numba-compiled stepper evaluates the same equations as
the python originals and as the symbolic casadi model, and the smooth (tanh)
model's trajectory approaches the exact stick-slip simulator as eps shrinks.
"""

from __future__ import annotations

import numpy as np
import pytest

from heavecomp.friction import laws
from heavecomp.friction.laws import FrictionLaw
from heavecomp.params import paper_a
from heavecomp.effects import model as effects_model
from heavecomp.plants import cmc
from heavecomp.simulate import _kernel as K
from heavecomp.simulate.layout import Drive, Plant
from heavecomp.simulate import simulate
from heavecomp.simulate.excitation import ramp_factor

MODELS = ("none", "stribeck", "rotating_eq6", "rotating_eq7")
RTOL = 1e-9


def _states(n, seed):
    """Random states and inputs spanning the operating envelope (|v| >= 1 mm/s)."""
    rng = np.random.default_rng(seed)
    s = rng.uniform(-2.0, 2.0, n)
    v = rng.uniform(1e-3, 0.6, n) * rng.choice([-1.0, 1.0], n)
    yb = rng.uniform(-0.2, 0.15, n)  # includes lift-off (y_b > delta_0 ~ 0.1 m)
    vb = rng.uniform(-0.5, 0.5, n)
    zh = rng.uniform(-3.0, 3.0, n)
    dzh = rng.uniform(-2.0, 2.0, n)
    ddzh = rng.uniform(-1.0, 1.0, n)
    u = rng.uniform(-5e4, 5e4, n)
    return np.column_stack([s, v, yb, vb, zh, dzh, ddzh, u])


def _close(a, b, scale):
    """|a - b| <= RTOL * max(|b|, scale): relative, with a floor where the value crosses 0."""
    return abs(a - b) <= RTOL * max(abs(b), scale)


@pytest.mark.parametrize("model", MODELS)
def test_compiled_equations_equal_python_originals(model):
    p = paper_a(model)
    PP = cmc.plant_vector(p)
    law = FrictionLaw.from_params(p.friction)
    code, FP = law.code, law.FP
    F = 1e5  # N: force scale of the plant (WOB set-point ~ 1e5 N)
    for s, v, yb, vb, zh, dzh, ddzh, u in _states(200, 1):
        pr = cmc.gas_pressure(s, PP)
        assert _close(K.gas_pressure(s, PP), pr, 1e6)
        assert _close(K.tension(s, v, yb, vb, zh, dzh, PP), cmc.tension(s, v, yb, vb, zh, dzh, PP), F)
        assert _close(K.wob(yb, vb, PP), cmc.wob(yb, vb, PP), F)
        assert _close(K.holding_force(s, v, yb, vb, zh, dzh, ddzh, u, PP),
                      cmc.holding_force(s, v, yb, vb, zh, dzh, ddzh, u, PP), F)
        assert _close(K.lower_accel(s, v, yb, vb, zh, dzh, PP), cmc.lower_accel(s, v, yb, vb, zh, dzh, PP), 1.0)
        for d in (1.0, -1.0):
            assert _close(K.sliding_friction(code, d, s, v, FP, PP), cmc.sliding_friction(code, d, s, v, FP, PP), F)
        assert _close(K.static_limit(code, s, FP, PP), cmc.static_limit(code, s, FP, PP), F)
        assert _close(K.friction_jump(code, abs(v), pr, FP), laws.friction_jump(code, abs(v), pr, FP), F)
        assert _close(K.friction_cont(code, v, pr, FP), laws.friction_cont(code, v, pr, FP), F)
        Ff = cmc.sliding_friction(code, np.sign(v), s, v, FP, PP)
        assert _close(K.stroke_accel(s, v, yb, vb, zh, dzh, ddzh, u, Ff, PP),
                      cmc.stroke_accel(s, v, yb, vb, zh, dzh, ddzh, u, Ff, PP), 1.0)


@pytest.mark.parametrize("model", MODELS)
def test_kernel_rhs_equals_casadi_model_away_from_zero_velocity(model):
    """The stepper's right-hand side (sliding in the direction of v) and its holding
    force equal the casadi model's xdot / outputs where tanh(v/eps) = sign(v)."""
    p = paper_a(model)
    PP = cmc.plant_vector(p)
    law = FrictionLaw.from_params(p.friction)
    eps = 1e-8  # |v| >= 1 mm/s >> eps: tanh(v/eps) is +-1 to the last bit
    f = effects_model.casadi_model(p, eps=eps)
    smooth = not law.has_stiction
    for s, v, yb, vb, zh, dzh, ddzh, u in _states(100, 2):
        xdot, y = f([s, v, yb, vb], [zh, dzh, ddzh, u])
        xdot, y = np.asarray(xdot).ravel(), np.asarray(y).ravel()
        Z, DZ, DDZ = np.array([zh, zh]), np.array([dzh, dzh]), np.array([ddzh, ddzh])
        # heave samples are constant, so heave_at(0) returns them exactly
        cm = 1.0 if K.contact_switch(yb, vb, PP) > 0 else 0.0  # the stepper's contact state here
        # held contact state = the clamped law wherever they agree (physics once)
        assert _close(K.lower_accel_contact(s, v, yb, vb, zh, dzh, cm, PP), cmc.lower_accel(s, v, yb, vb, zh, dzh, PP), 1.0)
        X = (s, v, yb, vb)  # the plain CMC's stepper: no effect states
        plant, drive = Plant(law.code, law.FP, PP, np.zeros(0), smooth), Drive(u, 1.0, Z, DZ, DDZ)
        k = K.rhs(0.0, X, K.SLIDING, float(np.sign(v)), cm, plant, drive)
        assert k[0] == v and k[2] == vb and len(k) == 4
        assert _close(k[1], xdot[1], 1.0)
        assert _close(k[3], xdot[3], 1.0)
        # outputs: wob, stroke, pressure, tension, friction
        assert _close(K.wob(yb, vb, PP), y[0], 1e5)
        assert _close(K.gas_pressure(s, PP), y[2], 1e6)
        assert _close(K.tension(s, v, yb, vb, zh, dzh, PP), y[3], 1e5)
        Ff = K.sliding_friction(law.code, float(np.sign(v)), s, v, law.FP, PP)
        assert _close(Ff, y[4], 1e4)
        # holding force = M_c dv + F_f (casadi) = kernel's hold
        # the stepper's holding force (at v = 0, where it decides stick or breakaway) = M_c dv of
        # the casadi model at v = 0, whose friction J tanh(0) + K(0) vanishes there
        hold, pr = K.hold(0.0, X, plant, drive)
        xdot0, y0 = f([s, 0.0, yb, vb], [zh, dzh, ddzh, u])
        assert float(y0[4]) == 0.0
        assert _close(hold, PP[cmc.MC] * float(xdot0[1]), 1e5)
        assert _close(pr, y[2], 1e6)
        # stuck mode: stroke frozen, lower mass as in the model
        k0 = K.rhs(0.0, X, K.STUCK, 1.0, cm, plant, drive)
        assert k0[0] == 0.0 and k0[1] == 0.0
        assert _close(k0[3], K.lower_accel(s, 0.0, yb, vb, zh, dzh, PP), 1.0)


def _check_nominal_hooks(fn, code, FP, PP, EP):
    """The composed hook functions ``fn`` with effect parameters EP are the CMC exactly."""
    for s, v, yb, vb, zh, dzh, ddzh, u in _states(200, 3):
        X = (s, v, yb, vb, 0.7, 0.3, 0.1)  # effect states (of effects switched off) anywhere
        for cm in (0.0, 1.0):
            pr, T, hold, dvb = fn["plant_fx"](s, v, yb, vb, X, zh, dzh, ddzh, u, cm, PP, EP)
            assert pr == cmc.gas_pressure(s, PP)
            assert T == cmc.tension(s, v, yb, vb, zh, dzh, PP)
            assert hold == cmc.holding_force(s, v, yb, vb, zh, dzh, ddzh, u, PP)
            assert dvb == cmc.lower_accel_contact(s, v, yb, vb, zh, dzh, cm, PP)
        pr = cmc.gas_pressure(s, PP)
        for d in (1.0, -1.0):
            for a in (d * v, -1e-3):  # also a trial step past a reversal (a < 0)
                assert fn["jump_fx"](code, a, pr, s, d, X, FP, EP) == laws.friction_jump(code, a, pr, FP)
            assert (fn["sliding_friction_fx"](code, d, v, pr, s, X, FP, EP)
                    == cmc.sliding_friction(code, d, s, v, FP, PP))
        assert fn["static_limit_fx"](code, pr, s, 1.0, X, 3.0, FP, EP) == cmc.static_limit(code, s, FP, PP)


@pytest.mark.parametrize("model", MODELS)
def test_effect_plant_without_effects_is_the_cmc_bit_for_bit(model):
    """One stepper serves simulate() and the diagnosis: the plant's hook functions with no effect
    (compiled: what simulate() integrates) and the library's with every effect off are the CMC of
    plants/cmc.py exactly, so simulate() did not change when the effect hooks were added."""
    from heavecomp.effects.compose import composition, library_composition

    p = paper_a(model)
    plant = cmc.plant_vectors(p)
    none = composition(())
    _check_nominal_hooks(K.compiled_hooks(none), plant.code, plant.FP, plant.PP, K.NO_EFFECTS)
    lib = library_composition()
    _check_nominal_hooks(lib.functions, plant.code, plant.FP, plant.PP, lib.ep([]))


def test_compiled_effect_hooks_equal_python_originals():
    """The kernel's compiled hook functions of the library (every effect on) and of the generator's
    truth laws evaluate the same generated source as the numpy functions."""
    from heavecomp.benchmark.truth import TRUTH, truth_composition
    from heavecomp.effects.compose import library_composition
    from heavecomp.effects.registry import library

    p = paper_a("stribeck")
    plant = cmc.plant_vectors(p)
    PP = plant.PP
    rng = np.random.default_rng(4)
    lib_effects = [c(**c.from_x(c.x0())) for c in library().values() if c.kind == "plant"]
    truth = [TRUTH["friction_lag"](lag_time_speed=1.5), TRUTH["dwell_stiction"](dF=1e4, tau_d=1.0),
             TRUTH["pressure_friction"](k=0.03, p_th=0.9 * p.p0), TRUTH["gas_heat_transfer"](gamma=1.4, tau_th=4.0),
             TRUTH["flow_loss"](K=3e5), TRUTH["string_damping"](c_q=5e5)]
    for comp, effects in ((library_composition(), lib_effects), (truth_composition(), truth)):
        EP = comp.ep(effects)
        fc, fp = K.compiled_hooks(comp), comp.functions
        for s, v, yb, vb, zh, dzh, ddzh, u in _states(100, 5):
            x = (s, v, yb, vb, rng.uniform(0.9, 1.1), abs(v) * rng.uniform(0.5, 1.5), rng.uniform(0, 2e4),
                 rng.uniform(-1.0, 1.0),  # friction_memory's direction state (the library's fourth)
                 rng.uniform(0.98, 1.02))  # gas_thermal's temperature ratio (the fifth)
            # the truth stepper's further states (its laws off here: their values must not matter)
            x = x + tuple(rng.uniform(0.9, 1.1, max(0, 4 + comp.n_states - len(x))))
            tau = rng.uniform(0, 5)
            for a, b in zip(fc["plant_fx"](s, v, yb, vb, x, zh, dzh, ddzh, u, 1.0, PP, EP),
                            fp["plant_fx"](s, v, yb, vb, x, zh, dzh, ddzh, u, 1.0, PP, EP)):
                assert _close(a, b, 1e5)
            pr = fp["cylinder_pressure_fx"](s, v, x, PP, EP)
            for code in (laws.NONE, laws.STRIBECK, laws.EQ7):
                FP = plant.FP.copy()
                FP[laws.VT] = 0.05 if code == laws.EQ7 else 0.0
                assert _close(fc["sliding_friction_fx"](code, np.sign(v), v, pr, s, x, FP, EP),
                              fp["sliding_friction_fx"](code, np.sign(v), v, pr, s, x, FP, EP), 1e5)
                assert _close(fc["static_limit_fx"](code, pr, s, np.sign(v), x, tau, FP, EP),
                              fp["static_limit_fx"](code, pr, s, np.sign(v), x, tau, FP, EP), 1e5)
            for a, b in zip(fc["effect_rates"](s, v, pr, 0.3 * v, 0.01 * s, x, PP, plant.FP, EP),
                            fp["effect_rates"](s, v, pr, 0.3 * v, 0.01 * s, x, PP, plant.FP, EP)):
                assert _close(a, b, 1e4)


def test_heave_interpolation_reproduces_quintics():
    """The stepper's quintic Hermite interpolation of (z, dz, ddz) is exact for a
    polynomial of degree 5 (the event location evaluates the heave between samples)."""
    c = np.array([0.3, -0.2, 0.05, 0.01, -0.002, 1e-4])
    P = np.polynomial.Polynomial(c)
    sp = 0.37
    tg = np.arange(12) * sp
    Z, DZ, DDZ = P(tg), P.deriv(1)(tg), P.deriv(2)(tg)
    for t in np.linspace(0.0, tg[-1], 97):
        z, dz, ddz = K.heave_at(t, sp, Z, DZ, DDZ)
        assert z == pytest.approx(P(t), abs=1e-12)
        assert dz == pytest.approx(P.deriv(1)(t), abs=1e-11)
        assert ddz == pytest.approx(P.deriv(2)(t), abs=1e-10)


# ----------------------------------------------------------------------------
# smooth model -> exact stick-slip as eps -> 0
# ----------------------------------------------------------------------------
def _smooth_trajectory(p, eps, T, rate):
    """The casadi model (tanh friction) integrated by scipy LSODA with its exact Jacobian."""
    import casadi as ca
    from scipy.integrate import solve_ivp

    f = effects_model.casadi_model(p, eps=eps)
    x, u = ca.SX.sym("x", 4), ca.SX.sym("u", 4)
    xdot, y = f(x, u)
    F = ca.Function("F", [x, u], [xdot, ca.jacobian(xdot, x), y[0]])
    hv = p.heave
    a, w = hv.amplitude, 2 * np.pi / hv.period

    def heave(t):
        r, dr, ddr = (float(q) for q in ramp_factor(t, hv.ramp))
        z, dz, ddz = a * np.sin(w * t), a * w * np.cos(w * t), -a * w * w * np.sin(w * t)
        return [r * z, dr * z + r * dz, ddr * z + 2 * dr * dz + r * ddz, 0.0]

    def rhs(t, xx):
        return np.asarray(F(xx, heave(t))[0]).ravel()

    def jac(t, xx):
        return np.asarray(F(xx, heave(t))[1])

    te = np.arange(int(round(T * rate)) + 1) / rate
    sol = solve_ivp(rhs, (0.0, T), np.zeros(4), method="LSODA", jac=jac, t_eval=te, rtol=1e-8, atol=1e-10)
    assert sol.success
    wob = np.array([float(F(xx, heave(t))[2]) for t, xx in zip(sol.t, sol.y.T)])
    return sol.t, wob


@pytest.mark.slow
def test_smooth_model_approaches_exact_stick_slip_as_eps_shrinks():
    """tanh-regularised friction creeps while it should stick; the creep, and with it
    the WOB error against the exact simulator, shrinks ~linearly with eps."""
    p = paper_a("stribeck")
    T, rate = 48.0, 20.0  # fade-in + two wave periods with four stick phases
    exact = simulate(p, T, dt=0.0025, rate=rate)
    m = exact.t >= p.heave.ramp
    errs = []
    for eps in (1e-3, 1e-4, 1e-5):
        t, w = _smooth_trajectory(p, eps, T, rate)
        np.testing.assert_allclose(t, exact.t, atol=1e-9)
        errs.append(float(np.sqrt(np.mean((w[m] - exact["wob"][m]) ** 2))))
    print("rms WOB error of the tanh model vs exact stick-slip, eps = 1e-3, 1e-4, 1e-5 m/s:", errs)
    # each decade of eps cuts the error by at least 4x (observed ~8x), and eps = 1e-5 is within 50 N
    assert errs[0] > 4 * errs[1] > 16 * errs[2]
    assert errs[2] < 50.0


def test_advance_in_pieces_equals_one_call():
    """``K.advance`` may be called repeatedly (once per control interval): the mode and
    direction carried in ``mode_dir`` make the result independent of where the run is
    cut, also when a cut falls inside a stick phase."""
    from heavecomp.simulate.core import run_kernel
    from heavecomp.simulate.excitation import make_heave

    p = paper_a("stribeck")
    h, T, out_every = 0.01, 60.0, 5
    n = int(round(T / h))
    hs = make_heave(p.heave, n * h, 0.5 * h)
    plant = cmc.plant_vectors(p)
    whole, st_whole, _ = run_kernel(plant, hs, h, n, out_every)
    # 0.1 s pieces (a control interval); 600 cuts, many of them while stuck
    parts, st_parts, _ = run_kernel(plant, hs, h, n, out_every, chunk_steps=10)
    assert whole.shape == parts.shape
    assert np.count_nonzero(whole[:, K.CHANNELS.index("stuck")]) > 50
    np.testing.assert_allclose(parts, whole, rtol=1e-9, atol=1e-9)
    assert st_parts["n_stick"] == st_whole["n_stick"] and st_parts["n_breakaway"] == st_whole["n_breakaway"]
