"""Compose the plant's hook functions for a set of effects (generated source, one per set).

:class:`Composition` lays out the effect-parameter vector ``EP`` of a set of effect classes
(per effect an on/off slot, then its parameters in field order: generated index constants
in :attr:`Composition.offsets`), gives the effects' states the slots after the plant's four in
the stepper's state ``X = (s, v, y_b, v_b, X[4], ..., X[3 + n_states])`` (as many as the
composition's effects have: none for the plain CMC) and writes the plant's hook functions as
Python source that calls each effect's own methods in the composition's order, behind its on/off slot:

``gas_fx, cylinder_pressure_fx, tension_fx, plant_fx, jump_fx, sliding_friction_fx,
static_limit_fx, effect_rates``

and the stepper's state arithmetic for that state size (``state_axpy``, ``state_rest``,
``state_dot``, ``state_load``, ``state_store``, ``state_record``).

The same generated functions are compiled by numba into the stepper
(:func:`heavecomp.simulate._kernel.kernel_for`) and called with casadi symbols by
:func:`heavecomp.effects.model.casadi_model`.  With no effect they are the CMC of
:mod:`heavecomp.plants.cmc` and the laws of :mod:`heavecomp.friction.laws` exactly.

One composition serves almost every run: the superset (:func:`library_composition`: the open
search's hook terms, then every registered plant effect), compiled once at install.
:func:`composition_for` picks it for any set of those effects, each switched on by its slot of EP,
so a calibrated file with a new mix of effects compiles nothing; only an effect outside it (the
benchmark generator's truth laws) gets a composition, and a compile, of its own.
"""

from __future__ import annotations

import hashlib
import inspect

import numpy as np

from heavecomp.errors import ParameterError
from heavecomp.friction import laws as _laws
from heavecomp.plants import cmc as _cmc
from heavecomp.effects.discovered_term import DiscoveredTerm
from heavecomp.effects.hook_term import GasTerm, LineTerm, StringTerm
from heavecomp.effects.registry import library

#: index of the first effect state in the stepper's state X (after s, v, y_b, v_b)
FIRST_SLOT = 4
#: the plant functions the generated source calls (compiled by the kernel under these names)
PLANT_FUNCTIONS = {"gas_pressure": _cmc.gas_pressure, "tension": _cmc.tension, "net_force": _cmc.net_force,
                   "lower_accel_tension": _cmc.lower_accel_tension, "friction_jump": _laws.friction_jump,
                   "friction_cont": _laws.friction_cont}
#: names of the generated functions, callees first
GENERATED = ("gas_fx", "cylinder_pressure_fx", "line_mass_fx", "tension_fx", "plant_fx", "jump_fx", "sliding_friction_fx",
             "static_limit_fx", "effect_rates", "state_axpy", "state_rest", "state_dot", "state_load",
             "state_store", "state_record")


class Composition:
    """The hook functions of the CMC for the effect classes ``classes`` (in the order given).

    Parameters
    ----------
    classes : sequence of Effect classes
        The plant effects of the composition (``kind == "plant"``), each once, in the order their
        hooks are applied (:func:`hook_order` for a file's effects; the superset's is
        :func:`library_composition`).

    Attributes
    ----------
    classes : tuple of Effect classes
    offsets : dict
        name -> index of the effect's on/off slot in EP (its parameters follow).
    slots : dict
        name -> state slots (indices into X) of the effect's states.
    n_states : int
        Number of effect states (X has 4 + n_states entries).
    n_ep : int
    source : str
        The generated Python source.
    functions : dict
        name -> generated function (numpy / casadi evaluation).
    key : str
        Hash of the generated source and of the effects' source files (names compiled kernels).
    """

    def __init__(self, classes=()):
        self.classes = tuple(classes)
        names = [c.name for c in self.classes]
        if len(set(names)) != len(names):
            raise ParameterError(f"effects listed twice: {', '.join(names)}")
        for c in self.classes:
            if c.kind != "plant":
                raise ParameterError(f"effect {c.name} acts at the {c.hook!r} hook, not inside the plant")
        self.offsets, self.slots = {}, {}
        k, nxt = 0, FIRST_SLOT
        for c in self.classes:
            self.offsets[c.name] = k
            k += 1 + c.n_params()
            self.slots[c.name] = tuple(range(nxt, nxt + len(c.states)))
            nxt += len(c.states)
        self.n_states = nxt - FIRST_SLOT
        self.n_ep = k
        self.source = self._generate()
        ns = dict(PLANT_FUNCTIONS)
        for i, c in enumerate(self.classes):
            for m in c.methods():
                ns[f"E{i}_{m}"] = getattr(c, m)
        exec(compile(self.source, f"<heavecomp effects: {' + '.join(names) or 'none'}>", "exec"), ns)
        self.functions = {f: ns[f] for f in GENERATED}
        h = hashlib.sha256(self.source.encode())
        for c in self.classes:
            h.update(inspect.getsource(inspect.getmodule(c)).encode())
        self.key = h.hexdigest()[:12]

    # ------------------------------------------------------------------ source
    def _calls(self, method, target, args):
        """Lines applying every effect's ``method`` to ``target``, each behind its on/off slot."""
        lines = []
        for i, c in enumerate(self.classes):
            if getattr(c, method) is None:
                continue
            o = self.offsets[c.name]
            x = "(" + "".join(f"X[{s}], " for s in self.slots[c.name]) + ")"
            prm = "".join(f", EP[{o + 1 + j}]" for j in range(c.n_params()))
            lines += [f"    if EP[{o}] != 0.0:  # {c.name}",
                      f"        {target} = E{i}_{method}({args.format(x=x)}{prm})"]
        return lines

    def _generate(self) -> str:
        L = ["# generated by heavecomp.effects.compose.Composition: do not edit", ""]
        L += ["def gas_fx(s, v, X, PP, EP):", "    p = gas_pressure(s, PP)"]
        L += self._calls("gas", "p", "s, v, p, {x}, PP") + ["    return p", ""]
        L += ["def cylinder_pressure_fx(s, v, X, PP, EP):", "    p = gas_fx(s, v, X, PP, EP)"]
        L += self._calls("line", "p", "v, p, {x}, PP") + ["    return p", ""]
        L += ["def line_mass_fx(s, v, X, PP, EP):",
              '    """The mass [kg] the line\'s oil adds to the stroke (its inertance times A^2; 0: none)."""',
              "    m = 0.0 * v"]
        L += self._calls("line_mass", "m", "v, m, {x}, PP") + ["    return m", ""]
        L += ["def tension_fx(s, v, yb, vb, zh, dzh, X, PP, EP):", "    T = tension(s, v, yb, vb, zh, dzh, PP)"]
        L += self._calls("string", "T", "dzh + v - vb, T, {x}, PP") + ["    return T", ""]
        L += ["def plant_fx(s, v, yb, vb, X, zh, dzh, ddzh, u, contact, PP, EP):",
              '    """(cylinder pressure, tension, holding force, dv_b/dt) with the contact state held."""',
              "    p = cylinder_pressure_fx(s, v, X, PP, EP)",
              "    T = tension_fx(s, v, yb, vb, zh, dzh, X, PP, EP)",
              "    return p, T, net_force(p, T, ddzh, u, PP), lower_accel_tension(T, yb, vb, contact, PP)", ""]
        L += ["def jump_fx(code, a, p, s, d, X, FP, EP):", "    J = friction_jump(code, a, p, FP)"]
        L += self._calls("jump", "J", "code, a, p, J, s, d, {x}, FP") + ["    return J", ""]
        L += ["def sliding_friction_fx(code, direction, v, p, s, X, FP, EP):",
              "    return (jump_fx(code, direction * v, p, s, direction, X, FP, EP) * direction"
              " + friction_cont(code, v, p, FP))", ""]
        L += ["def static_limit_fx(code, p, s, d, X, tau, FP, EP):", "    lim = jump_fx(code, 0.0 * p, p, s, d, X, FP, EP)"]
        L += self._calls("static", "lim", "code, p, lim, tau, s, d, {x}, FP") + ["    return lim", ""]
        n, f = self.n_states, FIRST_SLOT
        idx = range(f, f + n)
        L += ["def effect_rates(s, v, p, dvs, es, X, PP, FP, EP):"] + [f"    d{i} = 0.0 * v" for i in idx]
        for i, c in enumerate(self.classes):
            if c.rates is None and c.string_rates is None:
                continue
            o, sl = self.offsets[c.name], self.slots[c.name]
            x = "(" + "".join(f"X[{s}], " for s in sl) + ")"
            prm = "".join(f", EP[{o + 1 + j}]" for j in range(c.n_params()))
            call = (f"E{i}_rates(s, v, p, {x}, PP, FP{prm})" if c.rates is not None
                    else f"E{i}_string_rates(dvs, es, {x}, PP{prm})")  # a string state: the stretch and its rate
            L += [f"    if EP[{o}] != 0.0:  # {c.name}", f"        r = {call}"]
            L += [f"        d{s} = r[{j}]" for j, s in enumerate(sl)]
        L += ["    return (" + "".join(f"d{i}, " for i in idx) + ")", ""]
        # the stepper's state arithmetic for X of 4 + n entries (numba: tuples of a fixed size)
        every = range(f + n)
        L += ["def state_axpy(X, h, k):", "    return (" + ", ".join(f"X[{i}] + h * k[{i}]" for i in every) + ")", ""]
        L += ["def state_rest(X):", "    return (X[0], 0.0, " + "".join(f"X[{i}], " for i in range(2, f + n)) + ")", ""]
        L += ["def state_dot(ds, dv, dyb, dvb, s, v, p, dvs, es, X, PP, FP, EP):",
              '    """dX/dt: the plant\'s four derivatives, then the effects\' rates (es, dvs: the string\'s stretch '
              'from the operating point and its rate)."""']
        if n:
            L += ["    r = effect_rates(s, v, p, dvs, es, X, PP, FP, EP)",
                  "    return (ds, dv, dyb, dvb, " + "".join(f"r[{j}], " for j in range(n)) + ")", ""]
        else:
            L += ["    return (ds, dv, dyb, dvb)", ""]
        L += ["def state_load(state):", '    """(X, tau) from the state array [s, v, y_b, v_b, effect states..., tau]."""',
              "    return (" + "".join(f"state[{i}], " for i in every) + f"), state[{f + n}]", ""]
        L += ["def state_store(state, X, tau):"] + [f"    state[{i}] = X[{i}]" for i in every]
        L += [f"    state[{f + n}] = tau", "    return 0", ""]
        L += ["def state_record(out, pos, col, X):",
              '    """Effect states into out[pos, col:] as far as it has columns."""']
        L += [f"    if col + {j} < out.shape[1]:\n        out[pos, col + {j}] = X[{f + j}]" for j in range(n)]
        L += ["    return 0", ""]
        return "\n".join(L)

    # ------------------------------------------------------------------ runs
    def ep(self, effects=()) -> np.ndarray:
        """EP for effect instances ``effects`` (each of a class of this composition; the others off)."""
        EP = np.zeros(self.n_ep)
        for e in effects:
            if e.name not in self.offsets:
                raise ParameterError(f"effect {e.name} is not part of this composition "
                                     f"({', '.join(self.offsets) or 'none'})")
            o = self.offsets[e.name]
            EP[o] = 1.0
            EP[o + 1:o + 1 + e.n_params()] = e.prm
        return EP

    def _active(self, EP):
        for c in self.classes:
            o = self.offsets[c.name]
            if EP[o] != 0.0:
                yield c, tuple(float(v) for v in EP[o + 1:o + 1 + c.n_params()])

    def adds_stiction(self, EP) -> bool:
        """True when an active effect adds friction that jumps with sign(v)."""
        return any(c.adds_stiction for c, _ in self._active(EP))

    def initial_state(self, FP, PP, EP) -> np.ndarray:
        """State ``[s, v, y_b, v_b, effect states..., tau]`` (4 + :attr:`n_states` + 1 entries) at
        rest at the operating point (effect states at their :meth:`Effect.initial` values; those of
        effects switched off 0)."""
        X0 = np.zeros(FIRST_SLOT + self.n_states + 1)
        for c, prm in self._active(EP):
            if c.states:
                X0[list(self.slots[c.name])] = c.initial(FP, PP, *prm)
        return X0

    def steady_states(self, v, FP, PP, EP, X0, prev=None) -> None:
        """Set the effect states of ``X0`` to their steady values sliding at ``v`` (segment restarts).

        A slow state (an effect without ``steady``: a drift, a warming) carries on from ``prev``
        (the state where the previous segment ended), or stays as it is in ``X0`` without one."""
        for c, prm in self._active(EP):
            if not c.states:
                continue
            sl = list(self.slots[c.name])
            if c.steady is not None:
                X0[sl] = c.steady(v, FP, PP, *prm)
            elif prev is not None:
                X0[sl] = np.asarray(prev)[sl]


_CACHE: dict = {}


def composition(classes=()) -> Composition:
    """The (memoised) :class:`Composition` of ``classes``.

    Parameters
    ----------
    classes : sequence of Effect classes
        The plant effects of the composition, in the order their hooks are applied.
    """
    key = tuple(classes)
    if key not in _CACHE:
        _CACHE[key] = Composition(key)
    return _CACHE[key]


def hook_terms() -> tuple:
    """The open search's terms at the plant's hooks (not registered effects, not diagnosis candidates):
    ``discovered_term`` (seal friction, :mod:`heavecomp.effects.discovered_term`), ``gas_term``,
    ``line_term`` and ``string_term`` (:mod:`heavecomp.effects.hook_term`), in that order."""
    return DiscoveredTerm, GasTerm, LineTerm, StringTerm


def hook_order(classes) -> tuple:
    """``classes`` (each once) in the order their hooks are applied: the hook terms (:func:`hook_terms`)
    first, then the others in the order given.

    A hook term was fitted on its hook's nominal signals (the open search's residual of the nominal
    model at that hook), and :class:`heavecomp.effects.hook_term.StringTerm` recovers the stretch from
    the tension it is handed by the nominal string law: applied first at its hook it sees the nominal
    value, whatever other effect the file adds there and wherever the file lists it.  Every
    composition of a file's effects (the stepper's, the casadi model's, the component equations')
    applies them in this order.

    Parameters
    ----------
    classes : iterable of Effect classes
        Plant effect classes.
    """
    classes = tuple(dict.fromkeys(classes))
    terms = hook_terms()
    return tuple(c for c in classes if c in terms) + tuple(c for c in classes if c not in terms)


def library_composition() -> Composition:
    """The superset composition: the hook terms (:func:`hook_terms`, first at their hooks, see
    :func:`hook_order`) and every registered plant effect (registry order).  One compiled stepper
    (compiled at install, :func:`heavecomp.simulate.stepper.install_steps`) serves every set of them:
    the diagnosis' candidates and a calibrated file's effects with the open search's terms, each
    behind its on/off slot of EP (off: the CMC exactly)."""

    return composition(hook_terms() + tuple(c for c in library().values() if c.kind == "plant"))


def composition_for(effects) -> Composition:
    """The superset composition (:func:`library_composition`) when every effect in ``effects``
    (instances) is a registered effect or a hook term (no compile: it is compiled at install), else
    the composition of exactly their classes (e.g. the benchmark generator's truth laws), in
    :func:`hook_order`.

    Parameters
    ----------
    effects : sequence of Effect
        Plant effect instances.
    """

    lib = library()
    terms = hook_terms()
    if all(lib.get(e.name) is type(e) or type(e) in terms for e in effects):
        return library_composition()
    return composition(hook_order(type(e) for e in effects))
