"""The superset composition (issue 32): one stepper, compiled at install, serves every set of registered
effects and the open search's hook terms, with each hook term applied first at its hook."""

from pathlib import Path

import numpy as np
import pytest

from heavecomp.effects import compose
from heavecomp.effects.compose import composition, composition_for, hook_order, library_composition
from heavecomp.effects.registry import effect_class, library
from heavecomp.effects.spec import classes, load, plant_effects
from heavecomp.params import paper_a
from heavecomp.plants.cmc import plant_vectors

DATA = Path(__file__).parent / "data"
CASE = DATA / "calibrated_hook_terms.toml"


def _file_effects():
    return plant_effects(load(CASE))


def test_a_calibrated_files_registered_effects_and_hook_terms_run_on_the_superset():
    """pressure_friction + line_term + string_term (a calibrated file's mix) is the one composition the install
    compiles, not a composition of its own (which cost a 30-90 s compile on first use); so is every hook term
    with any registered plant effect."""
    eff = _file_effects()
    assert [e.name for e in eff] == ["pressure_friction", "line_term", "string_term"]
    lib = library_composition()
    assert composition_for(eff) is lib
    terms = [classes()[n]() for n in ("discovered_term", "gas_term", "line_term", "string_term")]
    registered = [c() for c in library().values() if c.kind == "plant"]
    assert composition_for(terms + registered) is lib
    assert composition_for(terms[2:3]) is lib


def test_an_effect_outside_the_superset_still_gets_its_own_composition():
    """The benchmark generator's truth laws are not in the superset: their composition is their own, with a hook
    term (if any) first."""
    from heavecomp.benchmark.truth import TRUTH

    truth = TRUTH["string_damping"](c_q=5e5)
    term = classes()["string_term"](rel=1e5)
    comp = composition_for([truth, term])
    assert comp is not library_composition()
    assert comp.classes == (type(term), type(truth))


def test_the_superset_applies_each_hook_term_first_at_its_hook():
    """The terms were fitted on the hook's nominal value (string_term recovers the stretch from the nominal
    tension): whatever order a file lists them in, each sees the nominal value at its hook, in the stepper's
    composition and in the casadi model's alike."""
    lib = library_composition()
    for term in compose.hook_terms():
        at_hook = [c for c in lib.classes if c.hook == term.hook]
        assert at_hook[0] is term
    damp, term = effect_class("string_damping"), classes()["string_term"]
    assert hook_order([damp, term]) == (term, damp)
    p = paper_a()
    PP = plant_vectors(p).PP
    s, v, yb, vb, zh, dzh = 0.1, 0.5, 0.0, 0.0, 0.2, 0.3
    dv = dzh + v - vb
    nominal = composition(()).functions["tension_fx"](s, v, yb, vb, zh, dzh, (), PP, np.zeros(0))
    fx = [damp(damping=5e5), term(rel=2e5, v=1e4)]
    T = lib.functions["tension_fx"](s, v, yb, vb, zh, dzh, (0.0,) * (4 + lib.n_states), PP, lib.ep(fx))
    # the term on the nominal tension (its stretch zh + s - yb recovered exactly), then the damping
    assert T == pytest.approx(nominal + 1e4 * dv + 2e5 * (zh + s - yb) + 5e5 * dv, rel=1e-12)
    listed_first = lib.functions["tension_fx"](s, v, yb, vb, zh, dzh, (0.0,) * (4 + lib.n_states), PP,
                                               lib.ep(fx[::-1]))
    assert listed_first == T


def test_the_casadi_model_applies_the_hook_terms_as_the_stepper_does():
    """A file that lists string_damping before string_term: the casadi model (linearisation, MPC) composes
    them as the stepper's superset does, so its tension is the stepper's."""
    from heavecomp.effects.model import casadi_model

    p = paper_a()
    inst = [effect_class("string_damping")(damping=5e5), classes()["string_term"](rel=2e5, v=1e4)]
    f = casadi_model(p, eps=0.01, effects=inst)
    s, v, yb, vb, zh, dzh = 0.1, 0.5, 0.0, 0.0, 0.2, 0.3
    _, y = f([s, v, yb, vb], [zh, dzh, 0.0, 0.0])
    lib = library_composition()
    T = lib.functions["tension_fx"](s, v, yb, vb, zh, dzh, (0.0,) * (4 + lib.n_states), plant_vectors(p).PP,
                                    lib.ep(inst))
    assert float(y[3]) == pytest.approx(T, rel=1e-12)


@pytest.mark.slow
def test_the_superset_stepper_runs_the_files_effects_as_their_own_composition_does():
    """The compiled superset (every other effect off) and the composition of exactly the file's classes (hook
    terms first) integrate the same trajectory: 1200 steps (30 s) of the paper-A case with pressure_friction,
    line_term and string_term, through stick-slip."""
    from heavecomp.diagnosis.stepper import simulate_fx

    p = load(CASE)
    eff = plant_effects(p)
    exact = composition(hook_order(type(e) for e in eff))
    assert exact is not library_composition() and exact.n_ep < library_composition().n_ep
    a = simulate_fx(p, 30.0, eff, rate=50.0, dt=0.025)
    b = simulate_fx(p, 30.0, eff, rate=50.0, dt=0.025, comp=exact)
    assert a["stuck"].min() == 0.0 and a["stuck"].max() == 1.0  # it slides and sticks
    nominal = simulate_fx(p, 30.0, [], rate=50.0, dt=0.025)
    assert np.max(np.abs(a["wob"] - nominal["wob"])) > 1e4  # the terms are on: 10 kN and more at the bit
    for ch in ("stroke", "pressure", "wob", "tension", "friction"):
        scale = np.max(np.abs(b[ch])) + 1e-9
        assert np.max(np.abs(a[ch] - b[ch])) <= 1e-9 * scale, ch
