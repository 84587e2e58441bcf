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
``parameter_mismatch``            the refitted values in their tables (F_C clipped to F_S, as the fit)
a sensor effect (``sensor_gain``,   an ``[[effects]]`` entry that corrects how a log is read
``sensor_offset``, ``sensor_delay``,  (``load_run`` undoes it); the plant is left as it is
``heave_reference``)
``discovered`` (friction)         ``discovered_term`` (:mod:`heavecomp.effects.discovered_term`)
                                  with the open search's coefficients
``none``                          the nominal unchanged, a comment saying so
``inconclusive``                  the nominal unchanged, a comment saying why
================================  ============================================================

A second effect the diagnosis named (``verdict.second_effect``) is added the same way.

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
from heavecomp.diagnosis.data import load_run
from heavecomp.diagnosis import replay as R
from heavecomp.effects.candidates import MISMATCH_KEYS
from heavecomp.effects.discovered_term import COMPONENT as DISCOVERED_COMPONENT
from heavecomp.effects.discovered_term import FEATURES as DISCOVERED_FEATURES
from heavecomp.effects.spec import build, classes, reading_effects
from heavecomp.errors import InputError
from heavecomp.params import dumps

#: file name of the calibrated model in the diagnosis folder
FILE = "calibrated.toml"


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

    def block(self, path: str = FILE) -> dict:
        """The ``calibrated`` block of ``diagnosis.json`` (contract schema 3)."""
        return {"path": path, "changes": self.changes, "expected_shrink": float(self.expected_shrink),
                "verdict": self.verdict}


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
    if "coulomb_force" in fr and fs is not None:
        fr["coulomb_force"] = min(fr["coulomb_force"], fs)
    if nominal.friction.model == "none":
        upd.pop("friction", None)
    for table, kv in upd.items():
        for key, value in kv.items():
            old = getattr(getattr(nominal, table), key)
            changes.append({"kind": "parameter", "name": f"{table}.{key}", "from": float(old), "to": value,
                            "ratio": value / old if old else math.nan})
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
    eff = v["effect"]
    out = Calibrated(nominal, verdict=eff, expected_shrink=float(v.get("shrink", 0.0)))
    if eff in ("none", "inconclusive"):
        out.why.append(_unchanged(v))
        out.expected_shrink = 0.0
        return out
    specs = list(nominal.effects)

    def add(name, values):
        _add_effect(specs, out, name, values)

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
    else:
        add(eff, v.get("parameters", {}))
        role = out.changes[-1]["role"]
        out.why.append(f"diagnosis verdict: {eff} (confidence {v.get('confidence', '?')}) -- "
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
                "(and the replay's response to the heave noise); nothing to change: this is the nominal file")
    return (f"diagnosis verdict: inconclusive -- {v.get('note', 'no candidate explains the gap')}; "
            "nothing is changed: this is the nominal file"
            + (f" (the gap lives in {v['component']})" if v.get("component") else ""))


def _add_effect(specs: list, out: Calibrated, name: str, values: dict) -> None:
    """Add (or replace, when the file had it) the effect ``name`` with ``values`` in ``specs``.

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
    """
    spec, ch = _effect_change(name, values)
    same = [i for i, (n, vals) in enumerate(specs) if n == name and vals.get("channel") == spec[1].get("channel")]
    if same:  # the file had this effect: the diagnosis refitted it
        specs[same[0]] = spec
    else:
        specs.append(spec)
    out.changes.append(ch)


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
    feats = list(d.get("features", []))
    if d.get("component") == DISCOVERED_COMPONENT and feats and all(f in DISCOVERED_FEATURES for f in feats):
        add("discovered_term", {f: float(d["coefficients"][f]) for f in feats})
        out.changes[-1]["component_shrink"] = float(d.get("shrink", 0.0))
        # verdict.shrink is the best *named* candidate's; the term's own replay shrink is unknown until
        # replayed (replay_shrink): nothing is promised for it
        out.expected_shrink = 0.0
        out.why.append(f"diagnosis verdict: discovered -- the open search's term on the friction residual, "
                       f"{d.get('term', '')}, carried as effect discovered_term (it shrinks the held-out friction "
                       f"residual by {d.get('shrink', 0.0):.2f}; its replay shrink is not known until replayed)")
        return True
    out.why.append(f"diagnosis verdict: discovered -- the open search's term on the "
                   f"{d.get('component', '?')} residual, {d.get('term', '')}, has no model form at its hook "
                   f"(discovered_term carries the friction features {', '.join(DISCOVERED_FEATURES)}); "
                   "nothing is changed: this is the nominal file")
    out.expected_shrink = 0.0
    return False


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


def write(nominal, diagnosis: dict, out_dir, source: str = "") -> Calibrated:
    """Write ``out_dir/calibrated.toml`` and return the :class:`Calibrated` model.

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
    """
    from pathlib import Path

    try:
        cal = calibrate(nominal, diagnosis)
    except InputError as exc:  # e.g. a refitted value outside its table's possible range: the nominal, and why
        cal = Calibrated(nominal, verdict=diagnosis["verdict"]["effect"],
                         why=[f"diagnosis verdict: {diagnosis['verdict']['effect']} -- its values cannot be written "
                              f"into a valid parameter file ({exc}); this is the nominal file"])
    (Path(out_dir) / FILE).write_text(to_toml(cal, source), encoding="utf-8")
    return cal


# ------------------------------------------------------------------------------------ replay
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
    ch = v.get("shrink_channel", "wob")
    reported = float(diagnosis.get("calibrated", {}).get("expected_shrink", v.get("shrink", 0.0)))
    raw = load_run(path, nominal, columns=columns, units=units)
    fixed = load_run(path, calibrated, columns=columns, units=units)
    nom = _replay(nominal, raw)
    cal = _replay(calibrated, fixed)
    t = raw.t
    pred = cal[ch]
    for e in reading_effects(calibrated):  # read the calibrated prediction as the rig's sensors do
        if getattr(e, "channel", None) == ch:
            pred = e.measure(t, t, pred)
    lo = float(diagnosis["split"]["validate"][0])
    y = raw[ch]
    m = (t >= lo) & np.isfinite(y) & np.isfinite(pred)
    before = float(np.sqrt(np.mean((nom[ch][m] - y[m]) ** 2)))
    after = float(np.sqrt(np.mean((pred[m] - y[m]) ** 2)))
    shrink = 1.0 - after / before if before > 0 else 0.0
    agree = abs(shrink - reported) / abs(reported) if reported else abs(shrink)
    return {"channel": ch, "rms_before": before, "rms_after": after, "shrink": shrink, "reported": reported,
            "agreement": agree}


__all__ = ["Calibrated", "calibrate", "replay_shrink", "to_toml", "write"]
