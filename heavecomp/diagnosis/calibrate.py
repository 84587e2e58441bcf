"""The calibrated model: the nominal parameter file plus what the diagnosis found (contract schema 3).

:func:`calibrate` is a pure function from the nominal parameters and a diagnosis' ``to_json()``
dict (``diagnosis.json``) to the calibrated parameters and the list of changes; :func:`to_toml`
writes it as a parameter file (``DIR/calibrated.toml``) that every command reads.  What each verdict
writes:

================================  ============================================================
verdict                           calibrated.toml
================================  ============================================================
a plant effect (``string_damping``,  an ``[[effects]]`` entry with the fitted values (the plant
``dwell_stiction``, ...)            changes: ``simulate``, ``analyse``, the MPCs use it)
a law of a family (``friction_lag``,  the fitted member's entry (``name = "friction_memory"``): the class
``law = "distance"``)                 that was fitted, with its values (``verdict.member``)
``parameter_mismatch``            the refitted values in their tables (F_C clipped to F_S, as the fit;
                                  a moved top mass with the gas stiffness of the same gas bank),
                                  and ``[anchor]``: the values they were refitted from (kept from the
                                  file when it has one), the centre of a re-diagnosis' refit box
a sensor effect (``sensor_gain``,   an ``[[effects]]`` entry that corrects how a log is read
``sensor_offset``, ``sensor_delay``,  (``load_run`` undoes it); the plant is left as it is
``heave_reference``)
``discovered`` (friction)         ``discovered_term`` (:mod:`heavecomp.effects.discovered_term`)
                                  with the open search's coefficients
``discovered`` (flow_line,        ``line_term`` / ``gas_term`` / ``string_term`` at the component's
gas_spring, string_formation)     hook (:mod:`heavecomp.effects.hook_term`), when its features have a
                                  form there
``discovered`` (sensors)          ``sensor_term`` (:mod:`heavecomp.effects.sensor_term`): the
                                  channel search's misreading, a correction of how the log is read
``none``                          the nominal unchanged, a comment saying so
``inconclusive``                  the nominal unchanged, a comment saying why
================================  ============================================================

A second effect the diagnosis named (``verdict.second_effect``) is added the same way.  Given the log
(:func:`write`'s ``run``), a drifting effect's state at the log's start is fitted too (:func:`start_state`:
a gas leak that began before the log is carried as ``charge_drift``, the charge at the log's start).

:func:`replay_shrink` checks the calibrated model: it replays the log with it (the diagnosis' own
replay, :class:`heavecomp.diagnosis.replay.Replay`) and measures the held-out shrink the diagnosis
reported.  The diagnosis replays the parameter file's plant effects in every replay (the nominal
replay and every candidate's), so ``diagnose LOG --params calibrated.toml`` diagnoses what is left
after the calibration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from heavecomp.diagnosis.estimator import GapDiagnoser
from heavecomp.diagnosis.data import MeasuredRun, load_run
from heavecomp.diagnosis import replay as R
from heavecomp.diagnosis import verdict as V
from heavecomp.effects.candidates import MISMATCH_KEYS, ParameterMismatch
from heavecomp.effects.discovered_term import COMPONENT as DISCOVERED_COMPONENT
from heavecomp.effects.discovered_term import FEATURES as DISCOVERED_FEATURES
from heavecomp.effects import hook_term as HT
from heavecomp.effects import sensor_term as ST
from heavecomp.effects.sensor_lag import SensorLag
from heavecomp.diagnosis.policy import DEFAULT as DEFAULT_POLICY
from heavecomp.effects.spec import build, classes, correct, reading_effects
from heavecomp.errors import InputError
from heavecomp.params import dumps

#: file name of the calibrated model in the diagnosis folder
FILE = "calibrated.toml"
#: effects whose state drifts with no steady value (a log starts wherever the drift had got to), and the
#: effect and parameter that hold that state at the log's start: a gas leak that began before the log has
#: already moved the charge by then, which ``gas_leak`` (its change counted from the log's start) cannot say
START_STATE = {"gas_leak": ("charge_drift", "charge_error")}
#: function evaluations of the start-state refit (each one replay of the log)
START_NFEV = 30


@dataclass
class Calibrated:
    """The calibrated model: ``params`` (a :class:`~heavecomp.params.CMCParams`), ``changes`` (one dict
    per change: ``kind`` effect | parameter, ``name``, values), ``why`` (one line per comment of the
    file), ``expected_shrink`` (the held-out shrink the diagnosis reported for it [-]) and ``verdict``."""

    params: object
    changes: list = field(default_factory=list)
    why: list = field(default_factory=list)
    expected_shrink: float = 0.0
    verdict: str = ""
    #: the verdict's own held-out shrink when the calibrated model adds to what the verdict fitted (a start
    #: state, :func:`start_state`), else None
    verdict_shrink: float | None = None

    def block(self, path: str = FILE) -> dict:
        """The ``calibrated`` block of ``diagnosis.json`` (contract schema 3)."""
        out = {"path": path, "changes": self.changes, "expected_shrink": float(self.expected_shrink),
               "verdict": self.verdict}
        if self.verdict_shrink is not None:
            out["verdict_shrink"] = float(self.verdict_shrink)
        return out


def _entry(name: str, values: dict) -> tuple:
    """A checked ``[[effects]]`` spec for effect ``name`` with fitted ``values`` (a parameter the fit
    did not carry, e.g. heave_reference's lever arm on a log without an angle, is at its null value)."""
    cls = classes()[name]
    vals = {k: v for k, v in values.items() if k != "channel"}
    for f in cls.fields():  # a fit at its bound may sit a rounding outside it (exp(log(bound)))
        if f.name in vals and not isinstance(vals[f.name], str):
            lo, hi = f.metadata["bounds"]
            vals[f.name] = min(max(float(vals[f.name]), lo), hi)
    null = cls.null(None) or {}
    for f in cls.fields():
        if f.name not in vals and f.name in null:
            vals[f.name] = null[f.name]
    if "channel" in values:
        vals = {"channel": values["channel"], **vals}
    build(name, vals, f"effects[{name}]")  # the values must pass the file's own check
    return name, {k: (v if isinstance(v, str) else float(v)) for k, v in vals.items()}


def _effect_change(name: str, values: dict) -> tuple[tuple, dict]:
    spec = _entry(name, values)
    kind = classes()[name].kind
    return spec, {"kind": "effect", "name": name, "role": "reading" if kind in ("output", "heave") else "plant",
                  "parameters": spec[1]}


def _mismatch(nominal, parameters: dict):
    """The nominal with the refitted values of ``parameters`` ({"table.key": value}) in their tables,
    F_C clipped to F_S as :meth:`heavecomp.effects.candidates.ParameterMismatch.apply` does."""
    upd, changes = {}, []
    keys = {label: (table, key) for label, table, key in MISMATCH_KEYS}
    for label, value in parameters.items():
        table, key = keys[label]
        old = getattr(getattr(nominal, table), key)
        if old is None or value == old:
            continue
        upd.setdefault(table, {})[key] = float(value)
    fr = upd.get("friction", {})
    fs = fr.get("static_force", nominal.friction.static_force)
    fc = fr.get("coulomb_force", nominal.friction.coulomb_force)
    if fs is not None and fc is not None and fc > fs:  # as the fit's model: F_C clipped to F_S, moved or not
        upd.setdefault("friction", fr)["coulomb_force"] = float(fs)
    if nominal.friction.model == "none":
        upd.pop("friction", None)
    for table, kv in upd.items():
        for key, value in kv.items():
            old = getattr(getattr(nominal, table), key)
            changes.append({"kind": "parameter", "name": f"{table}.{key}", "from": float(old), "to": value,
                            "ratio": value / old if old else math.nan})
    if upd:  # the values the refit started from: a re-diagnosis refits within a box about them, not about these
        upd["anchor"] = ParameterMismatch.anchor_of(nominal)
    return nominal.replace(**upd), changes


def calibrate(nominal, diagnosis: dict) -> Calibrated:
    """The calibrated model from the nominal parameters and a diagnosis (its ``to_json()`` dict).

    Parameters
    ----------
    nominal : CMCParams
        The parameter set the diagnosis was run against (its own ``[[effects]]`` are kept).
    diagnosis : dict
        ``diagnosis.json`` content: ``verdict`` (``effect``, ``parameters``, ``shrink``, ``note``,
        ``component``, ``discovered``, ``second_effect``).

    Returns
    -------
    Calibrated
    """
    v = diagnosis["verdict"]
    eff = V.member(v)  # the effect fitted: a family's law is carried as its member class (friction_memory)
    out = Calibrated(nominal, verdict=v["effect"], expected_shrink=float(v.get("shrink", 0.0)))
    if eff in ("none", "inconclusive"):
        out.why.append(_unchanged(v))
        out.expected_shrink = 0.0
        return out
    specs = list(nominal.effects)

    def add(name, values, stack=None):
        return _add_effect(specs, out, name, values, stack)

    params = nominal
    if eff == "parameter_mismatch":
        params, changes = _mismatch(nominal, v.get("parameters", {}))
        out.changes += changes
        out.why.append("diagnosis verdict: parameter_mismatch -- the refitted nominal parameters are written into "
                       "their tables: " + (", ".join(f"{c['name']} {c['from']:.6g} -> {c['to']:.6g}"
                                                     for c in changes) or "none moved"))
    elif eff == "discovered":
        if not _add_discovered(out, v.get("discovered") or {}, add):
            return out
    elif not _add_form(out, v, add):  # the named law (its open-search form, when that fits better)
        add(eff, v.get("parameters", {}))
        role = out.changes[-1]["role"]
        out.why.append(f"diagnosis verdict: {V.label(v)} (confidence {v.get('confidence', '?')}) -- "
                       + ("a sensor that misreads: the [[effects]] entry corrects how a log is read (the plant is "
                          "unchanged)" if role == "reading" else "the effect is added at its hook with the fitted "
                                                                 "values"))
    params = _add_second(out, v.get("second_effect"), params, add)
    out.params = params.replace(effects=specs) if specs != list(params.effects) else params
    return out


def _unchanged(v: dict) -> str:
    """Why a ``none`` or ``inconclusive`` verdict leaves the nominal file as it is.

    Parameters
    ----------
    v : dict
        The diagnosis' verdict.
    """
    if v["effect"] == "none":
        return ("diagnosis verdict: none -- the log agrees with this model within the measurement noise "
                "(and the replay's response to the heave noise); nothing to change: this is the file the diagnosis ran "
                "against, unchanged")
    return (f"diagnosis verdict: inconclusive -- {v.get('note', 'no candidate explains the gap')}; "
            "nothing is changed: this is the file the diagnosis ran against, unchanged"
            + (f" (the gap lives in {v['component']})" if v.get("component") else ""))


def _add_effect(specs: list, out: Calibrated, name: str, values: dict, stack=None) -> bool:
    """Add (or replace, when the file had it) the effect ``name`` with ``values`` in ``specs``.

    A term found on the residual the file's own term leaves (``stack``: its features; the component
    equations include the file's memoryless effects, :func:`heavecomp.diagnosis.components.file_hooks`)
    is added to the file's entry of the same effect instead of replacing it (:func:`_stacked`).

    Parameters
    ----------
    specs : list
        The ``[[effects]]`` entries so far, ``(name, values)``; changed in place.
    out : Calibrated
        The calibrated model so far; its ``changes`` are extended.
    name : str
        Effect name.
    values : dict
        Its fitted parameters [SI] (a channel effect's ``channel`` included).
    stack : collection of str, optional
        The coefficients of a term to add to the file's own entry (None: a refit replaces it).

    Returns
    -------
    bool
        False when a term cannot be added to the file's entry exactly (nothing is changed).
    """
    same = [i for i, (n, vals) in enumerate(specs) if n == name and vals.get("channel") == values.get("channel")]
    if same and stack is not None:
        values = _stacked(specs[same[0]][1], values, stack)
        if values is None:
            return False
    spec, ch = _effect_change(name, values)
    if same:  # the file had this effect: the diagnosis refitted it (or added to its term)
        specs[same[0]] = spec
    else:
        specs.append(spec)
    out.changes.append(ch)
    return True


def _stacked(old: dict, new: dict, features) -> dict | None:
    """The file's term ``old`` plus the term ``new`` found on what it leaves: their ``features``'
    coefficients added, every other value (a centre or a level a feature is taken from) kept; None when
    one of those differs (two terms centred apart cannot be summed into one entry exactly).

    Parameters
    ----------
    old, new : dict
        The file's entry and the new term's values [SI].
    features : collection of str
        The new term's coefficient names.
    """
    out = dict(old)
    for k, v in new.items():
        if k in features:
            out[k] = float(old.get(k, 0.0)) + float(v)
        elif k in old and old[k] != v:
            return None
        else:
            out[k] = v
    return out


def _add_discovered(out: Calibrated, d: dict, add) -> bool:
    """Carry the open search's term as ``discovered_term`` when it has a model form at its hook.

    Parameters
    ----------
    out : Calibrated
        The calibrated model so far (extended in place).
    d : dict
        The verdict's ``discovered`` block: ``component``, ``features``, ``coefficients``, ``term``, ``shrink``.
    add : callable
        ``add(name, values)``: adds an effect entry.

    Returns
    -------
    bool
        False when the term has no model form (the nominal file is kept).
    """
    hooked = _plant_term(d)
    if hooked is not None:
        return _carry(out, add, *hooked, d)
    reading = _sensor_term(d)
    if reading is not None:
        return _carry(out, add, "sensor_term", reading, f"the channel search's misreading of {d['channel']}, a "
                                                            f"correction of how the log's {d['channel']} is read (the "
                                                            "plant is unchanged)", d)
    out.why.append(f"diagnosis verdict: discovered -- the open search's term on the "
                   f"{d.get('component', '?')} residual, {d.get('term', '')}, has no model form at its hook "
                   f"(discovered_term carries the friction features {', '.join(DISCOVERED_FEATURES)}, sensor_term "
                   "a channel's misreading with its levels, line_term / gas_term / string_term the memoryless "
                   "features of their hook); nothing is changed: this is the file the diagnosis ran against, unchanged")
    out.expected_shrink = 0.0
    return False


def _plant_term(d: dict) -> tuple | None:
    """(effect name, values, what it is) of an open-search term at a plant hook (``discovered_term`` on
    the friction, ``line_term`` / ``gas_term`` / ``string_term``), or None when it has no form there.

    Parameters
    ----------
    d : dict
        A discovered-term block: ``component``, ``features``, ``coefficients``, ``levels``.
    """
    feats = list(d.get("features", []))
    comp = d.get("component", "?")
    if comp == DISCOVERED_COMPONENT and feats and all(f in DISCOVERED_FEATURES for f in feats):
        return ("discovered_term", {f: float(d["coefficients"][f]) for f in feats},
                "the open search's term on the friction residual")
    hooked = HT.carried(comp, feats)
    levels = d.get("levels", {})
    if hooked is not None and all(k in levels for k in HT.levels_needed(feats)):
        vals = {f: float(d["coefficients"][f]) for f in feats}
        vals.update({k: float(levels[k]) for k in HT.levels_needed(feats)})  # the constants its features are centred on
        return hooked.name, vals, f"the open search's term on the {comp} residual, at the {hooked.hook} hook"
    return None


def _add_form(out: Calibrated, v: dict, add) -> bool:
    """Carry a named verdict's ``form`` (:func:`heavecomp.diagnosis.screen.named_form`: the open search's
    form of the named effect's component, which fitted it better than the named law) in place of the
    named effect, when it has a form at its hook; False: the named effect is carried.

    Parameters
    ----------
    out : Calibrated
        The calibrated model so far (extended in place).
    v : dict
        The diagnosis' verdict (``effect``, ``form``).
    add : callable
        ``add(name, values)``: adds an effect entry.
    """
    d = v.get("form") or {}
    hooked = _plant_term(d) if d.get("replaces") == V.member(v) else None
    if hooked is None:
        return False
    named = d.get("named", {})
    return _carry(out, add, *hooked, d, lead=(
        f"diagnosis verdict: {V.label(v)} (confidence {v.get('confidence', '?')}), carried in the form the open "
        f"search gave its {d.get('component', '?')} residual (held-out shrink {d.get('shrink', 0.0):.2f} against "
        f"{named.get('shrink', 0.0):.2f} for the {V.member(v)} law; a lower fit-part BIC)"))


def _carry(out: Calibrated, add, name: str, values: dict, what: str, d: dict, lead: str = "") -> bool:
    """Add the effect ``name`` with ``values`` that carries the discovered term ``d`` (``what`` it is).

    ``verdict.shrink`` is the best *named* candidate's and ``d['shrink']`` the component residual's: no
    replay shrink is promised here (0); given the log, :func:`discovered_shrink` measures it.

    Parameters
    ----------
    out : Calibrated
        The calibrated model so far (extended in place).
    add : callable
        ``add(name, values)``: adds an effect entry.
    name : str
        The carrying effect.
    values : dict
        Its parameters [SI].
    what : str
        What the term is, for the file's comment.
    d : dict
        The verdict's ``discovered`` block (or a named verdict's ``form``).
    lead : str
        The comment's start (empty: a ``discovered`` verdict's).
    """
    if not add(name, values, stack=set(d.get("features", []))):
        out.why.append(f"{lead or 'diagnosis verdict: discovered'} -- {what}, {d.get('term', '')}: the file carries "
                       f"{name} already, taken from other centres or levels, so the two cannot be added into one "
                       "entry exactly; the file's term is kept and this one is not carried")
        return False
    out.changes[-1]["component_shrink"] = float(d.get("shrink", 0.0))
    out.expected_shrink = 0.0
    out.why.append(f"{lead or 'diagnosis verdict: discovered'} -- {what}, {d.get('term', '')}, carried as effect {name} (it "
                   f"shrinks the held-out {d.get('component', '?')} equation residual by {d.get('shrink', 0.0):.2f}; "
                   "its replay shrink is measured by replaying the log)")
    return True


def _sensor_term(d: dict) -> dict | None:
    """The ``sensor_term`` values of a ``sensors`` discovered block (channel search: ``channel``,
    ``features`` ``"<channel>:<feature>"``, ``coefficients``, ``levels``), or None when it has no form
    there (no levels recorded, a feature the effect does not carry, two plays of different widths).

    Parameters
    ----------
    d : dict
        The verdict's ``discovered`` block.
    """
    if d.get("component") != "sensors" or not d.get("channel") or not d.get("levels") or not d.get("features"):
        return None
    vals = {"channel": d["channel"]}
    for f in d["features"]:
        kind = ST.base_name(f.split(":", 1)[-1])
        key = ST.COEFFICIENT.get(kind)
        if key is None or key in vals:
            return None
        vals[key] = float(d["coefficients"][f])
    vals.update({k: float(v) for k, v in d["levels"].items()})
    return vals


def _add_second(out: Calibrated, se, params, add):
    """Add the verdict's second effect (fitted jointly with the first); returns the parameters.

    Parameters
    ----------
    out : Calibrated
        The calibrated model so far (extended in place).
    se : dict or None
        The verdict's ``second_effect``.
    params : CMCParams
        The parameters so far (a second parameter mismatch refits them).
    add : callable
        ``add(name, values)``: adds an effect entry.
    """
    if not se or se.get("parameters") is None:
        return params
    if se["effect"] == "parameter_mismatch":
        params, changes = _mismatch(params, se["parameters"])
        out.changes += changes
    else:
        add(se["effect"], se["parameters"])
    out.why.append(f"second effect {se['effect']} (fitted jointly with the first, added "
                   f"{100 * se.get('added_explained', 0.0):.0f} % of the held-out gap)")
    if "shrink_joint" in se:
        out.expected_shrink = float(se["shrink_joint"])
    return params


def to_toml(cal: Calibrated, source: str = "") -> str:
    """The calibrated parameter file's text (round-trips through :func:`heavecomp.params.loads`).

    Parameters
    ----------
    cal : Calibrated
        The calibrated model (:func:`calibrate`).
    source : str
        The measured log's name, for the header comment (empty: not named).
    """
    header = "\n".join(["calibrated model written by heavecomp diagnose"
                        + (f" from {source}" if source else ""), *cal.why,
                        f"held-out shrink the diagnosis reported for it: {cal.expected_shrink:.3f}"])
    return dumps(cal.params, header=header)


def from_log(nominal, diagnosis: dict, run=None, policy=None) -> Calibrated:
    """The calibrated model ``diagnose`` writes: :func:`calibrate`, then, given the log, what only the log
    can fit (a drift's start state, :func:`start_state`; a reading's own dynamics,
    :func:`reading_dynamics`; a carried open-search term's replayed shrink, :func:`discovered_shrink`).

    Parameters
    ----------
    nominal : CMCParams
        The parameter set the diagnosis was run against.
    diagnosis : dict
        ``diagnosis.json`` content (:func:`calibrate`).
    run : MeasuredRun, optional
        The log as the diagnosis read it (None: :func:`calibrate` alone).
    policy : VerdictPolicy, optional
        The diagnosis' policy (its ``reading_dynamics_gain``; None: the defaults).
    """
    try:
        cal = calibrate(nominal, diagnosis)
    except InputError as exc:  # e.g. a refitted value outside its table's possible range: the nominal, and why
        cal = Calibrated(nominal, verdict=diagnosis["verdict"]["effect"],
                         why=[f"diagnosis verdict: {diagnosis['verdict']['effect']} -- its values cannot be written "
                              f"into a valid parameter file ({exc}); this is the file the diagnosis ran against, unchanged"])
    if run is not None and cal.changes:
        cal = start_state(cal, run, diagnosis)
        cal = reading_dynamics(cal, run, nominal, diagnosis, policy)
        if any("component_shrink" in c for c in cal.changes):  # a carried open-search term: measured by replay
            cal = discovered_shrink(cal, run, nominal, diagnosis)
    return cal


def write(nominal, diagnosis: dict, out_dir, source: str = "", run=None, policy=None) -> Calibrated:
    """Write ``out_dir/calibrated.toml`` (the model of :func:`from_log`) and return it.

    Parameters
    ----------
    nominal : CMCParams
        The parameter set the diagnosis was run against.
    diagnosis : dict
        ``diagnosis.json`` content (:func:`calibrate`).
    out_dir : str or Path
        Existing run folder the file is written into.
    source : str
        The measured log's name, for the header comment (empty: not named).
    run : MeasuredRun, optional
        The log as the diagnosis read it (:func:`from_log`).
    policy : VerdictPolicy, optional
        The diagnosis' policy (:func:`from_log`).
    """
    from pathlib import Path

    cal = from_log(nominal, diagnosis, run, policy)
    (Path(out_dir) / FILE).write_text(to_toml(cal, source), encoding="utf-8")
    return cal


# ------------------------------------------------------------------------------------ start state
def start_state(cal: Calibrated, run, diagnosis: dict) -> Calibrated:
    """The state a drifting effect of the calibrated model had reached when the log started.

    An effect whose state drifts with no steady value (:data:`START_STATE`: ``gas_leak``) counts its
    change from the log's start, but a log starts mid-operation: a leak that began before it has
    already moved the charge.  The verdict's fit left that start state out (its candidate has no such
    parameter), so the calibrated model would replay a charge that is right only at the log's first
    sample plus the drift, and the re-diagnosis would find the difference as a constant pressure
    offset.  Here the start state (``charge_drift.charge_error``, the charge at the log's start) and the
    drift rate are refitted together on the diagnosis' fit part (``split.fit`` after ``split.settle``)
    through the diagnosis' own replay (:func:`_replay`, as the re-diagnosis replays the file), every
    channel weighted by its noise floor (``diagnosis.json`` ``noise_floor``); the held-out part is
    left out of the fit and gives ``expected_shrink`` (1 - rms_after / rms_before of the verdict's
    shrink channel, nominal replay before), the verdict's own shrink kept as ``verdict_shrink``.

    Parameters
    ----------
    cal : Calibrated
        The calibrated model (:func:`calibrate`).
    run : MeasuredRun
        The log as the diagnosis read it (its time from 0 at the analysed span's start).
    diagnosis : dict
        ``diagnosis.json`` content: ``split``, ``noise_floor``, ``verdict.shrink_channel``.

    Returns
    -------
    Calibrated
        ``cal`` itself when its model has no drifting effect, else a new one with the start state added.
    """
    from scipy.optimize import least_squares

    drifting = [(i, n, v) for i, (n, v) in enumerate(cal.params.effects) if n in START_STATE]
    if not drifting:
        return cal
    i, name, vals = drifting[0]
    holder, key = START_STATE[name]
    (rate_key,) = [f.name for f in classes()[name].fields()]
    lo_h, hi_h = next(f.metadata["bounds"] for f in classes()[holder].fields() if f.name == key)
    lo_r, hi_r = next(f.metadata["bounds"] for f in classes()[name].fields() if f.name == rate_key)
    split, floor = diagnosis["split"], diagnosis.get("noise_floor", {})
    chans = [c for c in ("wob", "stroke", "pressure") if c in run.columns and floor.get(c)]
    t = run.t
    fit = (t >= float(split.get("settle", 0.0))) & (t < float(split["fit"][1]))
    base = [e for e in cal.params.effects if e[0] != holder]

    def model(x):
        fx = list(base)
        fx[i] = (name, {**vals, rate_key: float(x[1])})
        return cal.params.replace(effects=fx + [(holder, {key: float(x[0])})])

    def resid(x):
        pred = _replay(model(x), run)
        parts = []
        for c in chans:
            m = fit & np.isfinite(run[c]) & np.isfinite(pred[c])
            parts.append((pred[c][m] - run[c][m]) / float(floor[c]))
        r = np.concatenate(parts)
        return np.where(np.isfinite(r), r, 1e3)

    r0 = float(vals[rate_key])
    x0 = np.array([0.0, r0])
    sol = least_squares(resid, x0, bounds=([lo_h, lo_r], [hi_h, hi_r]), x_scale=[1e-3, max(abs(r0), 1e-6)],
                        max_nfev=START_NFEV)
    r_x0 = resid(x0)
    if float(sol.cost) >= 0.5 * float(r_x0 @ r_x0):  # the start at the log's first sample fits as well
        return cal
    spec = _entry(holder, {key: float(sol.x[0])})
    params = model([spec[1][key], sol.x[1]])
    ch = diagnosis["verdict"].get("shrink_channel", "wob")
    val = (t >= float(split["validate"][0])) & np.isfinite(run[ch])

    def rms(p):
        return float(np.sqrt(np.mean((_replay(p, run)[ch][val] - run[ch][val]) ** 2)))

    before = rms(cal.params.replace(effects=[e for e in cal.params.effects if e[0] not in (name, holder)]))
    after = rms(params)
    changes = [dict(c, parameters={**c["parameters"], rate_key: float(sol.x[1])})
               if c.get("kind") == "effect" and c["name"] == name else c for c in cal.changes]
    changes.append({"kind": "effect", "name": holder, "role": "plant", "parameters": spec[1], "start_state_of": name})
    why = (f"start state: {name} counts its change from the log's start; the charge had already moved by "
           f"{100 * spec[1][key]:+.3f} % when the log started ({holder}.{key}), refitted on the fit part with the "
           f"{rate_key} ({r0:.4g} -> {sol.x[1]:.4g} 1/s)")
    return Calibrated(params, changes, list(cal.why) + [why], 1.0 - after / before if before > 0 else
                      cal.expected_shrink, cal.verdict, verdict_shrink=cal.expected_shrink)


# ------------------------------------------------------------------------------------ reading dynamics
#: the verdict's reading effects a ``sensor_lag`` can take the place of (a factor, a delay: its special cases)
DYNAMIC_READINGS = ("sensor_gain", "sensor_delay")
#: time constants [s] of the start grid of the reading-dynamics fit (0: no lag), then refined
LAG_GRID = (0.0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 1.0, 1.4, 2.0, 3.0, 5.0)
#: delays [s] of that start grid
DELAY_GRID = (0.0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 1.0, 1.5)


def _read_through(t, m, factor, tau, delay):
    """The model's channel ``m`` at times ``t`` read by a sensor ``factor``, lag ``tau`` [s], ``delay`` [s]."""
    return SensorLag(channel="wob", factor=factor, time_constant=tau, delay=delay).measure(t, t, m)


def fit_reading(t, model, measured, fit, tau0=None, delay0=None) -> dict:
    """The linear reading of one channel, ``measured ~ g lag_tau(model)(t - t_d)``, fitted by least squares
    on the samples ``fit``: the factor exactly (linear), the time constant and the delay from a grid
    (:data:`LAG_GRID` x :data:`DELAY_GRID`, plus ``tau0`` / ``delay0``) refined by a bounded least squares.
    The delay may go down to minus one sample of the log: where the log's stamps come late, or where the
    sensor's lag is a logger's discrete filter (its output takes the current sample, half a sample ahead of
    the continuous lag of the same time constant).
    Only this channel is in the fit: a reading does not change what the plant does, so the other channels
    (and the nominal's miss on this one, the diagnosis' weights) have no say in it.

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times (uniform or not).
    model : numpy.ndarray [unit of the channel]
        The model's prediction of the true channel.
    measured : numpy.ndarray [unit of the channel]
        The recorded channel.
    fit : numpy.ndarray of bool
        The samples fitted on.
    tau0, delay0 : float, optional
        Extra start values [s] (e.g. the verdict's delay).

    Returns
    -------
    dict: ``factor`` [-], ``time_constant`` [s], ``delay`` [s], ``rms`` (fit part) [unit].
    """
    from scipy.optimize import least_squares

    ok = fit & np.isfinite(measured) & np.isfinite(model)
    y = measured[ok]
    lo = {f.name: f.metadata["bounds"] for f in SensorLag.fields()}

    def profile(tau, delay):
        r = _read_through(t, model, 1.0, tau, delay)[ok]
        den = float(r @ r)
        g = float(np.clip(r @ y / den, *lo["factor"])) if den > 0 else 0.0
        return g, g * r - y

    step = float(np.median(np.diff(t)))  # a log sample: the delay may go down to minus one (late time stamps)
    starts = [(a, b) for a in sorted(set(LAG_GRID + ((tau0,) if tau0 else ())))
              for b in sorted(set(DELAY_GRID + (-step, -0.5 * step) + ((delay0,) if delay0 else ())))]
    cost = [float(np.sum(profile(a, b)[1] ** 2)) for a, b in starts]
    x0 = np.array(starts[int(np.argmin(cost))], float)
    hi = [min(lo["time_constant"][1], 2.0 * max(LAG_GRID)), min(lo["delay"][1], 2.0 * max(DELAY_GRID))]
    sol = least_squares(lambda x: profile(x[0], x[1])[1], x0, bounds=([0.0, max(-step, lo["delay"][0])], hi),
                        x_scale=[max(x0[0], 0.01), max(abs(x0[1]), 0.01)], diff_step=1e-3, max_nfev=60)
    x = sol.x if float(np.sum(sol.fun ** 2)) <= min(cost) else x0
    g, r = profile(x[0], x[1])
    return {"factor": g, "time_constant": float(x[0]), "delay": float(x[1]), "rms": float(np.sqrt(np.mean(r * r)))}


def reading_dynamics(cal: Calibrated, run, nominal, diagnosis: dict, policy=None) -> Calibrated:
    """A reading verdict's channel read with the sensor's own dynamics (``sensor_lag``), when that reads
    the held-out log better.

    A sensor-fault verdict carries its law only: a factor (``sensor_gain``) or a pure delay
    (``sensor_delay``).  A real sensor also has a bandwidth, so the re-diagnosis with the calibrated file
    finds the rest (spent 590015: a sign flip read through a 5 Hz lag, the factor -1.019 alone leaves the
    stroke at 1.7 x its noise envelope; 590006: a first-order lag the verdict's pure delay 0.655 s matches
    at the wave period only, 6.2 x).  Here the verdict's channel's reading is refitted as a whole
    (:func:`fit_reading`: factor, first-order lag and delay jointly, on the fit part, this channel alone)
    against the replay of the calibrated plant, and carried as ``sensor_lag`` in place of the verdict's
    readings of that channel when its held-out rms is at least ``reading_dynamics_gain`` smaller than
    theirs (not when the nominal file reads that channel already: a re-diagnosis' reading stays the
    verdict's, never stacked on the file's).  Nothing else changes (the verdict stays the verdict); ``expected_shrink`` becomes the
    calibrated file's replayed held-out shrink (:func:`held_out_shrink`), the verdict's own kept as
    ``verdict_shrink``.

    Parameters
    ----------
    cal : Calibrated
        The calibrated model (:func:`calibrate`).
    run : MeasuredRun
        The log as the diagnosis read it (with the nominal file).
    nominal : CMCParams
        The parameter set the diagnosis was run against.
    diagnosis : dict
        ``diagnosis.json`` content: ``split``, ``verdict``.
    policy : VerdictPolicy, optional
        Its ``reading_dynamics_gain`` (0 or less: off); None: the defaults.

    Returns
    -------
    Calibrated
        ``cal`` itself when no reading of a verdict's channel is replaced, else the new model.
    """
    gain = (policy or DEFAULT_POLICY).reading_dynamics_gain
    new = _added(cal, nominal)
    chans = {v.get("channel") for n, v in new if n in DYNAMIC_READINGS} & set(R.CH) & set(run.columns)
    if gain <= 0 or len(chans) != 1:
        return cal
    (c,) = chans
    mine = [(n, v) for n, v in new if v.get("channel") == c]
    if any(n not in DYNAMIC_READINGS for n, _ in mine):  # e.g. an offset too: not a linear reading sensor_lag holds
        return cal
    if any(v.get("channel") == c for _, v in nominal.effects):  # the file read it already (a re-diagnosis): left
        return cal  # as the verdict says, not stacked on that reading
    base = cal.params.replace(effects=[e for e in cal.params.effects if e not in mine])
    t, y = run.t, run[c]
    split = diagnosis["split"]
    fit = (t >= float(split.get("settle", 0.0))) & (t < float(split["fit"][1]))
    val = (t >= float(split["validate"][0])) & np.isfinite(y)

    def plant(readers):  # the calibrated plant's replay of the log read through ``readers`` (its start from it)
        read, fx = _read_through_file(run, base, readers)
        lagged = tuple(e for e in fx if e.model_side)  # started as the file's replay starts
        return _replay(base, R.unlagged(read, lagged))[c]

    first = plant(mine)
    now = first
    for e in reading_effects(base.replace(effects=mine)):  # the verdict's reading of it
        now = e.measure(t, t, now)
    delay0 = next((float(v["delay"]) for n, v in mine if n == "sensor_delay"), None)
    got = fit_reading(t, first, y, fit, tau0=delay0, delay0=delay0)
    # again from the start the new reading gives (the log read through it, as the calibrated file reads it)
    model = plant([(SensorLag.name, {"channel": c, **{k: got[k] for k in ("factor", "time_constant", "delay")}})])
    got = fit_reading(t, model, y, fit, tau0=got["time_constant"], delay0=got["delay"])
    then = _read_through(t, model, got["factor"], got["time_constant"], got["delay"])
    ok = val & np.isfinite(now) & np.isfinite(then)
    rms_now = float(np.sqrt(np.mean((now[ok] - y[ok]) ** 2)))
    rms_then = float(np.sqrt(np.mean((then[ok] - y[ok]) ** 2)))
    if not rms_then <= (1.0 - gain) * rms_now:
        return cal
    vals = {"channel": c, "factor": got["factor"], "time_constant": got["time_constant"], "delay": got["delay"]}
    spec, change = _effect_change(SensorLag.name, vals)
    change["replaces"] = [n for n, _ in mine]
    params = base.replace(effects=list(base.effects) + [spec])
    changes = [ch for ch in cal.changes if not (ch.get("kind") == "effect" and ch.get("role") == "reading"
                                               and ch["parameters"].get("channel") == c)] + [change]
    shr = held_out_shrink(run, _read_through_file(run, params, [spec])[0], params, nominal, diagnosis)
    why = (f"reading dynamics: the {c} sensor read with its own dynamics (sensor_lag: factor {got['factor']:.4g}, "
           f"first-order lag {got['time_constant']:.3g} s, delay {got['delay']:.3g} s, fitted on the fit part of {c} "
           f"alone) in place of {', '.join(n for n, _ in mine)}: held-out {c} rms {rms_now:.4g} -> {rms_then:.4g}; "
           f"the lag is read on the model side (the replay's prediction read through it), the factor and delay "
           f"undone on the log")
    return Calibrated(params, changes, list(cal.why) + [why], shr["shrink"], cal.verdict,
                      verdict_shrink=cal.verdict_shrink if cal.verdict_shrink is not None else cal.expected_shrink)


# ------------------------------------------------------------------------------------ replay
def _added(cal: Calibrated, nominal) -> list:
    """The ``[[effects]]`` entries the calibrated model adds to (or changes in) the file it was fitted on."""
    return [e for e in cal.params.effects if e not in list(nominal.effects)]


def _read_through_file(run, params, effects):
    """The log ``run`` (read with the file the diagnosis ran against) read as a file ``params`` with the
    ``[[effects]]`` ``effects`` reads it: their readings undone (:func:`heavecomp.effects.spec.correct`);
    returns (that run, the reading effects as instances)."""
    fx = reading_effects(params.replace(effects=effects))
    cols, _ = correct(fx, run.t, dict(run.columns))
    return MeasuredRun(run.t, cols, run.source), fx


def _replay(params, run):
    """The diagnosis' replay of ``run`` (a :class:`~heavecomp.diagnosis.data.MeasuredRun`) with the model
    ``params`` (its plant effects included): channel -> array at the run's times."""
    d = GapDiagnoser(params)  # its settings: the replay's grid, heave and start estimated from the log, as in fit()
    rp = R.build(run, params, stuck_speed=d.stuck_speed, segment=d.segment, reinit=d.reinit, noise=R.output_noise(run))
    return rp.simulate([])


def replay_shrink(path, calibrated, nominal, diagnosis: dict, *, columns=None, units=None) -> dict:
    """Held-out shrink of the calibrated model, by replaying the log (the self-check of issue 22).

    The log at ``path`` is read twice: as it is, for the nominal model, and through the calibrated
    file (its reading effects corrected, :func:`heavecomp.effects.spec.correct`) for the calibrated
    model, each replayed by the diagnosis' own replay.  Both are compared with the log *as it was
    recorded* (the calibrated prediction read back through the sensor effects), on the diagnosis'
    held-out part (``split.validate``) of the channel its shrink is on (``verdict.shrink_channel``):
    shrink = 1 - rms_after / rms_before.

    Parameters
    ----------
    path : str or Path, or pandas.DataFrame
        The measured log, as :func:`heavecomp.diagnosis.data.load_run` takes it.
    calibrated : CMCParams
        The calibrated model (e.g. ``calibrated.toml`` loaded).
    nominal : CMCParams
        The parameter set the diagnosis was run against.
    diagnosis : dict
        ``diagnosis.json`` content: ``verdict`` (``shrink_channel``, ``shrink``), ``split.validate`` [s],
        ``calibrated.expected_shrink``.
    columns, units : dict, optional
        Contract name -> source column / unit, as :func:`~heavecomp.diagnosis.data.load_run` takes them.

    Returns
    -------
    dict: ``channel``, ``rms_before``, ``rms_after``, ``shrink`` (replayed), ``reported`` (the
    diagnosis' ``calibrated.expected_shrink`` or ``verdict.shrink``), ``agreement`` (|shrink -
    reported| / reported; 0 when both are 0).
    """
    v = diagnosis["verdict"]
    reported = float(diagnosis.get("calibrated", {}).get("expected_shrink", v.get("shrink", 0.0)))
    raw = load_run(path, nominal, columns=columns, units=units)
    fixed = load_run(path, calibrated, columns=columns, units=units)
    out = held_out_shrink(raw, fixed, calibrated, nominal, diagnosis)
    shrink = out["shrink"]
    agree = abs(shrink - reported) / abs(reported) if reported else abs(shrink)
    return dict(out, reported=reported, agreement=agree)


def as_recorded(params, t, pred: dict, channel: str, heave) -> np.ndarray:
    """A replay's prediction of ``channel`` read as the rig's sensors read it under the file ``params``: its
    reading effects applied (a model-side lag read back, a gain, offset or delay applied), so that it compares
    with the log as it was recorded.

    Parameters
    ----------
    params : CMCParams
        The file the replay ran under (its ``[[effects]]`` readings).
    t : numpy.ndarray [s]
        The run's times.
    pred : dict
        The replay's channels (:meth:`heavecomp.diagnosis.replay.Replay.simulate`).
    channel : str
        The channel read.
    heave : numpy.ndarray [m]
        The heave the replay was driven by (a reading term may read the string top's motion, heave + stroke).
    """
    out = pred[channel]
    for e in reading_effects(params):
        if getattr(e, "channel", None) == channel and e.model_side:
            out = e.read_back(t, out)  # the replay read it through the sensor's lag already
        elif getattr(e, "channel", None) == channel:
            out = e.measure(t, t, out, motion=heave + pred["stroke"])
    return out


def held_out_shrink(raw, fixed, calibrated, nominal, diagnosis: dict) -> dict:
    """Held-out shrink of the calibrated model on a log read twice (:func:`replay_shrink`).

    Parameters
    ----------
    raw : MeasuredRun
        The log read with the nominal file.
    fixed : MeasuredRun
        The same log read through the calibrated file (its reading effects corrected).
    calibrated, nominal : CMCParams
        The calibrated model and the parameter set the diagnosis was run against.
    diagnosis : dict
        ``diagnosis.json`` content: ``verdict.shrink_channel``, ``split.validate`` [s].

    Returns
    -------
    dict: ``channel``, ``rms_before``, ``rms_after``, ``shrink``.
    """
    ch = diagnosis["verdict"].get("shrink_channel", "wob")
    nom = _replay(nominal, raw)
    cal = _replay(calibrated, fixed)
    t = raw.t
    pred = as_recorded(calibrated, t, cal, ch, fixed["heave"])
    lo = float(diagnosis["split"]["validate"][0])
    y = raw[ch]
    m = (t >= lo) & np.isfinite(y) & np.isfinite(pred)
    before = float(np.sqrt(np.mean((nom[ch][m] - y[m]) ** 2)))
    after = float(np.sqrt(np.mean((pred[m] - y[m]) ** 2)))
    return {"channel": ch, "rms_before": before, "rms_after": after,
            "shrink": 1.0 - after / before if before > 0 else 0.0}


def discovered_shrink(cal: Calibrated, run, nominal, diagnosis: dict) -> Calibrated:
    """A carried open-search term's held-out shrink, measured by replaying the log (:func:`held_out_shrink`).

    The diagnosis reports the term's shrink of its component's equation residual, not of the replay, so
    the calibrated block would promise nothing (0).  The term was fitted on the fit part only, so its
    replay on the held-out part is a fair measure: it becomes ``expected_shrink`` (what replaying the file
    reproduces), the verdict's own shrink (the best named candidate's) is kept as ``verdict_shrink``.

    Parameters
    ----------
    cal : Calibrated
        The calibrated model of a ``discovered`` verdict (:func:`calibrate`).
    run : MeasuredRun
        The log as the diagnosis read it (with the nominal file).
    nominal : CMCParams
        The parameter set the diagnosis was run against.
    diagnosis : dict
        ``diagnosis.json`` content.
    """
    got = held_out_shrink(run, _read_through_file(run, cal.params, _added(cal, nominal))[0], cal.params, nominal,
                          diagnosis)
    why = (f"the carried term's held-out shrink of the {got['channel']} replay, measured by replaying the log: "
           f"{got['shrink']:.3f}")
    return Calibrated(cal.params, cal.changes, list(cal.why) + [why], got["shrink"], cal.verdict,
                      verdict_shrink=float(diagnosis["verdict"].get("shrink", 0.0)))


__all__ = ["Calibrated", "as_recorded", "calibrate", "discovered_shrink", "fit_reading", "held_out_shrink", "reading_dynamics",
           "replay_shrink", "to_toml", "write"]
