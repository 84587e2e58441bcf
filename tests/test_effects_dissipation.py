"""Meta-test: every registered plant effect dissipates at both ends of its parameter bounds.

An effect may shift a preload (a gas charge, a warming) or change a stiffness, which stores
energy and gives it back; what it must never do is feed energy into the motion.  At each hook
the part of the effect's term that is odd in the velocity is the non-conservative one, so at
sampled states, for the effect with every parameter at its lower and at its upper bound (one at a
time, and all together):

* seal friction: F v >= 0, and the static limit is not negative;
* gas spring and line: the cylinder pressure is not higher while extending than while
  retracting at the same stroke, (p_cyl(v) - p_cyl(-v)) v <= 0 (p_cyl A pushes the stroke up);
* string: the tension is not lower while the string stretches than while it shortens,
  (T(dv) - T(-dv)) dv >= 0 (dv = dz_h + v - v_b, the extension rate).

The composition's hook functions are the plain Python source the stepper compiles and casadi
traces (``Composition.functions``), so the checks run without a compile.
"""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest

from heavecomp.effects.compose import composition
from heavecomp.effects.registry import library
from heavecomp.params import paper_a
from heavecomp.plants import cmc

PLANT_EFFECTS = sorted(n for n, c in library().items() if c.kind == "plant")
VELOCITIES = np.logspace(-4, 0.3, 12)           # m/s
STROKES = np.linspace(-1.5, 1.5, 5)              # m
PRESSURES = (0.0, 2.4e6, 4.5e6)                  # Pa


def _ends(cls):
    """Parameter sets at the ends of the bounds: each parameter alone at each end, then all at once."""
    fields = dataclasses.fields(cls.Params)
    base = {f.name: f.default for f in fields}
    out = []
    for f in fields:
        for end in f.metadata["bounds"]:
            out.append({**base, f.name: float(end)})
    for i in (0, 1):
        out.append({f.name: float(f.metadata["bounds"][i]) for f in fields})
    return out


def _states(comp):
    """Effect-state values to sample: 0 and a spread of positive and negative memories."""
    n = comp.n_states
    if not n:
        return [()]
    return [(m,) * n for m in (0.0, 0.05, -0.05, 5e3, -5e3)]


@pytest.mark.parametrize("name", PLANT_EFFECTS)
@pytest.mark.parametrize("model", ["stribeck", "rotating_eq7"])
def test_effect_dissipates_at_both_ends_of_its_bounds(name, model):
    cls = library()[name]
    comp = composition((cls,))
    fn = comp.functions
    plant = cmc.plant_vectors(paper_a(model))
    PP, FP = plant.PP, plant.FP
    checked = 0
    for values in _ends(cls):
        EP = comp.ep([cls(**values)])
        for mem, s, v, p in itertools.product(_states(comp), STROKES, VELOCITIES, PRESSURES):
            X = (s, v, 0.0, 0.0) + tuple(mem)
            Xm = (s, -v, 0.0, 0.0) + tuple(mem)
            if cls.hook == "seal_friction":
                for sv, XX in ((v, X), (-v, Xm)):
                    F = fn["sliding_friction_fx"](plant.code, np.sign(sv), sv, p, s, XX, FP, EP)
                    assert F * sv >= 0.0, (values, s, sv, p, mem, F)
                    for d in (-1.0, 1.0):
                        assert fn["static_limit_fx"](plant.code, p, s, d, XX, 3.0, FP, EP) >= 0.0
            elif cls.hook in ("gas_spring", "line"):
                up = fn["cylinder_pressure_fx"](s, v, X, PP, EP)
                down = fn["cylinder_pressure_fx"](s, -v, Xm, PP, EP)
                assert (up - down) * v <= 1e-9 * abs(up), (values, s, v, mem, up, down)
            elif cls.hook == "string":
                for dzh in (-0.5, 0.0, 0.5):
                    dv = dzh + v
                    up = fn["tension_fx"](s, v, 0.0, 0.0, 0.0, dzh, X, PP, EP)
                    # the same state with the extension rate's sign flipped: -dz_h - v = -dv
                    down = fn["tension_fx"](s, -v, 0.0, 0.0, 0.0, -dzh, Xm, PP, EP)
                    assert (up - down) * dv >= -1e-9 * abs(up), (values, s, v, dzh, up, down)
            else:
                pytest.fail(f"effect {name}: hook {cls.hook!r} has no dissipation check; add one here")
            checked += 1
    assert checked > 0

