"""Conformance battery: every friction law and every registered effect through the same checks.

* units (and bounds) declared on every parameter;
* finite outputs at sampled states;
* dissipation: the friction opposes the motion, F v >= 0 (laws, and effects at the seal hook);
* zero size reproduces the nominal plant bit for bit (effects that have a zero size);
* numba = casadi: the stepper's compiled hook functions and the casadi model (traced from the
  same source) give the same state derivatives at sampled states.
"""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest

from heavecomp.effects.compose import composition, library_composition
from heavecomp.effects.registry import library
from heavecomp.friction import laws
from heavecomp.params import paper_a
from heavecomp.params.cmc import Friction
from heavecomp.effects import model as effects_model
from heavecomp.plants import cmc
from heavecomp.simulate import _kernel as K
from test_kernel_pins import _states  # random states and inputs spanning the operating envelope

MODELS = tuple(laws.CODES)
PLANT_EFFECTS = [n for n, c in library().items() if c.kind == "plant"]
RTOL = 1e-9


def _effect(name):
    cls = library()[name]
    return cls(**cls.from_x(cls.x0()))


# ---------------------------------------------------------------------------- units
@pytest.mark.parametrize("model", [m for m in MODELS if m != "none"])
def test_friction_law_parameters_declare_units(model):
    fields = {f.name: f for f in dataclasses.fields(Friction)}
    for key in laws.MODEL_KEYS[model]:
        meta = fields[key].metadata
        assert meta["unit"] and meta["unit"] != "-", key
        assert meta["bounds"][0] < meta["bounds"][1], key


@pytest.mark.parametrize("name", list(library()))
def test_effect_parameters_declare_units_bounds_and_symbols(name):
    cls = library()[name]
    assert cls.hook in ("seal_friction", "gas_spring", "line", "string", "channel", "heave")
    for f in cls.fields():
        assert f.metadata["unit"], f.name
        assert f.metadata["symbol"], f.name
        lo, hi = f.metadata["bounds"]
        assert lo <= f.default <= hi, f.name
    if cls.kind == "plant":
        assert cls.methods(), name  # acts at some hook
        assert bool(cls.states) == (cls.rates is not None or cls.string_rates is not None) == (cls.initial is not None), name


# ------------------------------------------------------------------ finite outputs
@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("name", [None] + PLANT_EFFECTS)
def test_finite_outputs_at_sampled_states(model, name):
    plant = cmc.plant_vectors(paper_a(model))
    effects = [] if name is None else [_effect(name)]
    comp = library_composition()
    EP = comp.ep(effects)
    fn = comp.functions
    x = tuple(comp.initial_state(plant.FP, plant.PP, EP)[4:4 + comp.n_states])
    for s, v, yb, vb, zh, dzh, ddzh, u in _states(50, 1):
        X = (s, v, yb, vb) + x
        vals = list(fn["plant_fx"](s, v, yb, vb, X, zh, dzh, ddzh, u, 1.0, plant.PP, EP))
        p = vals[0]
        vals.append(fn["sliding_friction_fx"](plant.code, np.sign(v), v, p, s, X, plant.FP, EP))
        vals.append(fn["static_limit_fx"](plant.code, p, s, np.sign(v), X, 2.0, plant.FP, EP))
        vals += list(fn["effect_rates"](s, v, p, 0.0 * v, 0.0 * v, X, plant.PP, plant.FP, EP))
        assert np.all(np.isfinite(vals)), vals


# ------------------------------------------------------------------ dissipation
@pytest.mark.parametrize("model", MODELS)
def test_friction_law_dissipates(model):
    law = laws.FrictionLaw.from_params(paper_a(model).friction)
    v = np.r_[-np.logspace(-6, 0.5, 60), np.logspace(-6, 0.5, 60)]
    for p in (-1e5, 0.0, 2.4e6, 5e6):
        F = law.force(v, p)
        assert np.all(F * v >= 0.0)
        assert np.all(law.smooth(v, p, eps=1e-3) * v >= 0.0)
    assert np.all(law.static_limit(np.array([0.0, 2.4e6])) >= 0.0)


@pytest.mark.parametrize("model", ["stribeck", "rotating_eq6", "rotating_eq7"])
@pytest.mark.parametrize("name", [n for n in PLANT_EFFECTS if library()[n].hook == "seal_friction"])
def test_seal_effects_dissipate(model, name):
    """With the effect on (its memory anywhere between 0 and its steady range) the friction
    still opposes the motion and the static limit is not negative."""
    plant = cmc.plant_vectors(paper_a(model))
    comp = library_composition()
    EP = comp.ep([_effect(name)])
    fn = comp.functions
    FS, FC = plant.FP[laws.FS], plant.FP[laws.FC]
    for mem in np.linspace(0.0, FS - FC, 5):
        for v in np.r_[-np.logspace(-5, 0, 30), np.logspace(-5, 0, 30)]:
            for p, s in itertools.product((0.0, 2.4e6, 4e6), np.linspace(-1.5, 1.5, 7)):
                X = (s, v, 0.0, 0.0) + (mem,) * comp.n_states  # the memory in every effect slot
                F = fn["sliding_friction_fx"](plant.code, np.sign(v), v, p, s, X, plant.FP, EP)
                assert F * v >= 0.0, (v, p, s, F)
                assert fn["static_limit_fx"](plant.code, p, s, np.sign(v), X, 3.0, plant.FP, EP) >= 0.0


def _memory_states(cls, plant, prm):
    """States a seal effect's memory reaches (its own slots): its value at rest, its steady values sliding
    at 1 mm/s to 1 m/s either way, and the points half-way between any two of them."""
    if not cls.states:
        return [()]
    FP, PP = plant.FP, plant.PP
    ends = [np.asarray(cls.initial(FP, PP, *prm), dtype=float)]
    ends += [np.asarray(cls.steady(v, FP, PP, *prm), dtype=float) for v in np.r_[-np.logspace(-3, 0, 4),
                                                                                  np.logspace(-3, 0, 4)]]
    return [tuple(0.5 * (a + b)) for a, b in itertools.product(ends, ends)]


@pytest.mark.parametrize("model", ["stribeck", "rotating_eq6", "rotating_eq7"])
@pytest.mark.parametrize("name", [n for n in PLANT_EFFECTS if library()[n].hook == "seal_friction"])
def test_static_limit_holds_the_friction_the_motion_starts_against(model, name):
    """At rest the static limit in a direction is at least the sliding friction at v = 0 in that direction
    (with the effect's memory as it stands): else a holding force between the two neither sticks (it
    exceeds the limit) nor moves the stroke that way (the friction it would slide against is larger), and
    the stepper reverses at every stop until its event cap (friction_memory once scaled its static limit
    by its factor twice: tests/test_effects_friction_memory.py).  At the stop, tau = 0."""
    plant = cmc.plant_vectors(paper_a(model))
    cls = library()[name]
    e = _effect(name)
    comp = library_composition()
    EP = comp.ep([e])
    fn = comp.functions
    slots = [k - 4 for k in comp.slots[name]]
    for mem in _memory_states(cls, plant, e.prm):
        x = np.zeros(comp.n_states)
        x[slots] = mem
        for p, s, d in itertools.product((0.0, 2.4e6, 4e6), np.linspace(-1.5, 1.5, 5), (-1.0, 1.0)):
            X = (s, 0.0, 0.0, 0.0) + tuple(x)
            lim = fn["static_limit_fx"](plant.code, p, s, d, X, 0.0, plant.FP, EP)
            kinetic = fn["sliding_friction_fx"](plant.code, d, 0.0, p, s, X, plant.FP, EP) * d
            assert lim >= kinetic, (mem, p, s, d, lim, kinetic)


# ------------------------------------------------------------ zero size = nominal
def _with_null():
    out = []
    for n in PLANT_EFFECTS:
        if library()[n].null(cmc.plant_vectors(paper_a())) is not None:
            out.append(n)
    return out


def test_effects_without_a_zero_size_are_memories():
    """Only an effect whose zero size is singular (a memory's time constant) may lack one."""
    for n in set(PLANT_EFFECTS) - set(_with_null()):
        assert library()[n].states, n


@pytest.mark.parametrize("name", _with_null())
def test_zero_size_reproduces_the_nominal_plant_bit_for_bit(name):
    from heavecomp.simulate import simulate

    p = paper_a("stribeck")
    plant = cmc.plant_vectors(p)
    cls = library()[name]
    e = cls(**cls.null(plant))
    comp = library_composition()
    EP = comp.ep([e])
    fn = comp.functions
    for s, v, yb, vb, zh, dzh, ddzh, u in _states(50, 2):
        X = (s, v, yb, vb) + (0.0,) * comp.n_states
        pr, T, hold, dvb = fn["plant_fx"](s, v, yb, vb, X, zh, dzh, ddzh, u, 1.0, plant.PP, EP)
        assert pr == cmc.gas_pressure(s, plant.PP)
        assert T == cmc.tension(s, v, yb, vb, zh, dzh, plant.PP)
        assert hold == cmc.holding_force(s, v, yb, vb, zh, dzh, ddzh, u, plant.PP)
        assert (fn["sliding_friction_fx"](plant.code, np.sign(v), v, pr, s, X, plant.FP, EP)
                == cmc.sliding_friction(plant.code, np.sign(v), s, v, plant.FP, plant.PP))
    ref = simulate(p, 30.0, rate=20.0)
    got = simulate(p, 30.0, rate=20.0, effects=[e])  # the library's compiled stepper
    np.testing.assert_array_equal(got.data, ref.data)


# ------------------------------------------------------------------ numba = casadi
def _kernel_xdot(hooks, n_eff, plant, EP, X, w, u):
    s, v, yb, vb = X[:4]
    xe = tuple(float(a) for a in X)
    zh, dzh, ddzh = w
    cm = 1.0 if K.contact_switch(yb, vb, plant.PP) > 0 else 0.0
    p, T, hold, dvb = hooks["plant_fx"](s, v, yb, vb, xe, zh, dzh, ddzh, u, cm, plant.PP, EP)
    Ff = hooks["sliding_friction_fx"](plant.code, float(np.sign(v)), v, p, s, xe, plant.FP, EP)
    rates = hooks["effect_rates"](s, v, p, dzh + v - vb, zh + s - yb, xe, plant.PP, plant.FP, EP)
    m = plant.PP[cmc.MC] + hooks["line_mass_fx"](s, v, xe, plant.PP, EP)  # the line's oil moves with the stroke
    return np.r_[v, (hold - Ff) / m, vb, dvb, rates]


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("name", [None] + PLANT_EFFECTS)
def test_numba_equals_casadi_at_sampled_states(model, name):
    """The stepper's compiled hooks (the composition of exactly this effect, as the casadi model
    uses) and the casadi model: same xdot where tanh(v/eps) = sign(v)."""
    p = paper_a(model)
    plant = cmc.plant_vectors(p)
    effects = [] if name is None else [_effect(name)]
    comp = composition(tuple(type(e) for e in effects))
    EP = comp.ep(effects)
    hooks = K.compiled_hooks(comp)
    n_eff = sum(len(c.states) for c in comp.classes)
    f = effects_model.casadi_model(p, eps=1e-8, effects=effects)
    rng = np.random.default_rng(7)
    for s, v, yb, vb, zh, dzh, ddzh, u in _states(40, 3):
        X = np.r_[s, v, yb, vb, rng.uniform(0.5, 1.5, n_eff) * (comp.initial_state(plant.FP, plant.PP, EP)[4:4 + n_eff] + 1.0)]
        if K.contact_switch(yb, vb, plant.PP) <= 0 and cmc.wob(yb, vb, plant.PP) != 0:
            continue
        xk = _kernel_xdot(hooks, n_eff, plant, EP, X, (zh, dzh, ddzh), u)
        xc = np.asarray(f(X, [zh, dzh, ddzh, u])[0]).ravel()
        scale = np.r_[1.0, 1.0, 1.0, 1.0, np.abs(xc[4:]) + 1.0]
        assert np.all(np.abs(xk - xc) <= RTOL * np.maximum(np.abs(xc), scale)), (xk, xc)


# ------------------------------------------------- the one linear model, pinned
@pytest.mark.parametrize("change", [{}, {"drill_string": {"damping": 5e4}}, {"formation": {"stiffness": 4e5}}])
def test_linear_model_is_the_casadi_jacobian(change):
    """cmc.modal_matrices (eigenvalues, default steps, band edges) = the jacobian of the casadi
    model at the operating point, frictionless, bit on the rock."""
    import casadi as ca

    p = paper_a("none").replace(**change)
    f = effects_model.casadi_model(p)
    x, u = ca.SX.sym("x", 4), ca.SX.sym("u", 4)
    A = np.array(ca.Function("A", [x, u], [ca.jacobian(f(x, u)[0], x)])(np.zeros(4), np.zeros(4)))
    M, C, Kk = cmc.modal_matrices(p)
    Minv = np.linalg.inv(M)
    ref = np.block([[np.zeros((2, 2)), np.eye(2)], [-Minv @ Kk, -Minv @ C]])
    A2 = A[np.ix_([0, 2, 1, 3], [0, 2, 1, 3])]  # (s, y_b, v, v_b)
    np.testing.assert_allclose(A2, ref, rtol=1e-6, atol=1e-9 * np.abs(ref).max())


@pytest.mark.parametrize("model", ["stribeck", "rotating_eq7"])
def test_steepest_slope_is_the_laws_derivative_at_rest(model):
    """laws.steepest_slope (sets the default step) bounds the slope of the law itself near v = 0+
    tightly: |dF/dv| <= it <= |dF/dv| + C_v (eq. 4: the Stribeck drop (F_S - F_C)/v_S less C_v)."""
    law = laws.FrictionLaw.from_params(paper_a(model).friction)
    d = 1e-7
    v = np.array([d, 2 * d])
    F = law.force(v, 0.0)
    slope = abs(F[1] - F[0]) / d
    bound = laws.steepest_slope(law.code, law.FP)
    assert slope <= bound * (1 + 1e-3)
    assert bound <= (slope + law.FP[laws.CV]) * (1 + 1e-3)


# -------------------------------------------------- channel and heave effects
OUTSIDE_EFFECTS = [n for n, c in library().items() if c.kind in ("output", "heave")]


@pytest.mark.parametrize("name", OUTSIDE_EFFECTS)
def test_channel_and_heave_effects_finite_and_null(name):
    """Finite readings at sampled series; at its null values the effect leaves the series bit for bit
    (the whole run: tests/test_effects_schema2.py)."""
    cls = library()[name]
    t = np.linspace(0.0, 30.0, 601)
    y = 2e5 + 3e4 * np.sin(0.5 * t) + np.random.default_rng(1).normal(0.0, 50.0, t.size)
    null = cls.null(None)
    assert null is not None, name
    if cls.kind == "output":
        e, e0 = cls(channel="wob", **_effect(name).values), cls(channel="wob", **null)
        assert np.all(np.isfinite(e.measure(t, t, y)))
        np.testing.assert_array_equal(e0.measure(t, t, y), y)
    else:
        hs = _heave_samples(t, y)
        e, e0 = _effect(name), cls(**null)
        out = e.transform(hs)
        assert all(np.all(np.isfinite(a)) for a in (out.z, out.dz, out.ddz))
        same = e0.transform(hs)
        for a, b in ((same.z, hs.z), (same.dz, hs.dz), (same.ddz, hs.ddz)):
            np.testing.assert_array_equal(a, b)


def _heave_samples(t, z):
    from heavecomp.simulate.excitation import HeaveSamples

    return HeaveSamples(float(t[1] - t[0]), z, np.gradient(z, t), np.gradient(np.gradient(z, t), t))
