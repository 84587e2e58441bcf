"""Structural isolability: which candidate effects a sensor set can detect, and which it can tell apart.

Structural fault detection and isolation (FDI; e.g. the LiU Fault Diagnosis Toolbox, Frisk et al.)
works on the model's *structure* only: which equation each fault enters and which measured signals
each residual needs.  A fault is **detectable** when it enters a residual computable from the
available sensors; two faults are **isolable** when their signatures (the set of computable
residuals each enters) differ.  No parameter value, noise level or fault size enters: a structural
"yes" is necessary, not sufficient (a fault below the noise is still missed).

The residuals here are the ones the diagnosis computes (nothing restated):

- the **equation residuals** of :mod:`heavecomp.diagnosis.components` (gas law, lower-mass balance,
  top-mass balance), each split into its components' parts by the signals a term is a function of
  (``components.SPLIT``: e.g. in the gas law a pressure drop growing with the flow ``v`` is
  ``flow_line``, the rest (preload, stiffness at ``s``, drift) ``gas_spring``).  An equation residual
  needs every channel its equation reads (``components.READS``; the heave: :data:`HEAVE_READS`);
- the **replay residuals** (output error) of the diagnosis: the nominal model driven by the measured
  heave, compared with one measured output channel.  The replay couples every plant equation, so it
  sees every plant effect, but cannot say which equation it came from.

Which residual part each candidate enters is read from the candidate's ``hook``
(:data:`heavecomp.effects.base.HOOK_COMPONENT`: the component, then the parts of ``SPLIT`` that
carry that component) and, for a channel effect, from its channel (every equation that reads the
channel, in the part :data:`CHANNEL_PART` names, and that channel's replay).  The table
:data:`HOOK_RESIDUALS` / :func:`entries` is built from those tables, never written twice.

Two levels:

- ``"structural"`` (default, the toolbox's binary analysis): signatures over residual parts.
- ``"shape"``: also the measured signals an effect's term is a function of in an equation residual
  (traced from the candidate's own equation-error form, :meth:`heavecomp.effects.base.Effect.features`):
  two seal-friction effects in the same top-mass part are told apart when one is a function of the
  pressure and the other of the stroke position.  This is what the equation-error fit exploits; it
  needs the effect's shape to be distinct in the data, which structure alone cannot promise.

Channel effects are expanded per channel present: ``sensor_gain:wob``, ``sensor_gain:pressure``, ...

Example
-------
>>> iso = isolability(["heave", "wob", "stroke"], ["flow_loss", "gas_leak", "string_damping"])
>>> iso["detectable"], iso["groups"]
(['flow_loss', 'gas_leak', 'string_damping'], [['flow_loss', 'gas_leak', 'string_damping']])
"""

from __future__ import annotations

import functools
import itertools

from heavecomp.diagnosis.components import OWN, READS, SPLIT
from heavecomp.effects.base import HOOK_COMPONENT, SENSOR_CHANNELS
from heavecomp.effects.candidates import CANDIDATES, MISMATCH_KEYS
from heavecomp.errors import InputError, did_you_mean

#: measured channels (contract): heave is required, the others may be missing
CHANNELS = ("heave", "stroke", "pressure", "wob")
OUTPUTS = ("stroke", "pressure", "wob")  #: channels a replay residual compares
#: equations of :mod:`heavecomp.diagnosis.components` that read the measured heave (z_h, dz_h, ddz_h);
#: ``components.READS`` lists the other channels (``tests/test_diagnosis_structure.py`` checks both
#: against :func:`heavecomp.diagnosis.components.equations` by perturbing each channel)
HEAVE_READS = ("lower_mass", "top_mass")
#: the part of an equation residual a misreading of the channel lands in: the heave's columns (z_h,
#: dz_h, ddz_h) are the ``heave_input`` part; a misread stroke, pressure or WOB reads as the
#: equation's own law (a gain or offset on p is preload and stiffness in the gas law)
CHANNEL_PART = {"heave": "heave_input"}
#: ``parameter_mismatch`` refits nominal parameters: the hook each parameter table's law sits at
TABLE_HOOK = {"compensator": "gas_spring", "friction": "seal_friction", "drill_string": "string",
              "formation": "string"}
LEVELS = ("structural", "shape")
#: sensor sets published in docs/monitoring.md (heave with every combination of the others)
SENSOR_SETS = tuple(("heave",) + c for k in (3, 2, 1, 0) for c in itertools.combinations(OUTPUTS, k))


def equation_channels() -> dict:
    """{equation: channels it reads} (``components.READS`` inverted, plus :data:`HEAVE_READS`)."""
    out = {e: ["heave"] if e in HEAVE_READS else [] for e in SPLIT}
    for ch, eqs in READS.items():
        for e in eqs:
            out[e].append(ch)
    return {e: tuple(c for c in CHANNELS if c in chs) for e, chs in out.items()}


def residuals() -> dict:
    """The residual parts and the channels each needs: ``"gas/flow_line"`` (equation/part) and
    ``"replay/wob"`` (the replay compared with one output channel)."""
    eqc = equation_channels()
    out = {f"{e}/{c}": eqc[e] for e, split in SPLIT.items() for c in split}
    out.update({f"replay/{y}": ("heave", y) for y in OUTPUTS})
    return out


def _parts_of(component):
    return tuple(f"{e}/{component}" for e, split in SPLIT.items() if component in split)


#: hook -> residual parts a term at that hook enters (from HOOK_COMPONENT and SPLIT), plus every replay
HOOK_RESIDUALS = {h: _parts_of(c) + tuple(f"replay/{y}" for y in OUTPUTS)
                  for h, c in HOOK_COMPONENT.items() if h != "channel"}


def channel_residuals(channel) -> tuple:
    """Residual parts a misreading of ``channel`` enters: every equation that reads it (in the part
    :data:`CHANNEL_PART` names, else the equation's own) and its replay (the heave: every replay).

    Parameters
    ----------
    channel : str
        A measured channel (:data:`CHANNELS`).
    """
    eqs = [e for e, chs in equation_channels().items() if channel in chs]
    part = CHANNEL_PART.get(channel)
    parts = tuple(f"{e}/{part or OWN[e]}" for e in eqs)
    return parts + tuple(f"replay/{y}" for y in OUTPUTS if channel in ("heave", y))


def _candidate_classes() -> dict:
    return dict(CANDIDATES)


def _hooks_of(cls) -> tuple:
    if cls.hook == "nominal":  # parameter_mismatch: the hooks of the laws whose parameters it refits
        return tuple(dict.fromkeys(TABLE_HOOK[table] for _, table, _ in MISMATCH_KEYS))
    return (cls.hook,)


class _Trace(dict):
    """A signal dict that records the names read from it."""

    def __init__(self, *a):
        super().__init__(*a)
        self.seen = set()

    def __getitem__(self, k):
        self.seen.add(k)
        return dict.__getitem__(self, k)

    def get(self, k, default=None):
        self.seen.add(k)
        return dict.get(self, k, default)

    def __contains__(self, k):
        self.seen.add(k)
        return dict.__contains__(self, k)


@functools.cache
def dependence(name) -> frozenset:
    """The signals a candidate's term is a function of in its equation residual, traced from its
    equation-error form (:meth:`Effect.features` on probe signals; ``y``, the channel's own reading,
    is returned as ``y``).  Empty when the effect has no equation-error form.

    Parameters
    ----------
    name : str
        A candidate effect name (:data:`heavecomp.effects.candidates.CANDIDATES`).
    """
    import numpy as np

    cls = _candidate_classes()[name]
    rng = np.random.default_rng(0)
    n = 64
    keys = ("x", "v", "a", "p", "dp", "wob", "dwob", "zh", "dzh", "ddzh", "rel", "vrel", "rest", "heave",
            "heave_velocity", "dz", "y")
    sig = {k: rng.normal(size=n) for k in keys}
    sig.update(t=np.arange(n) * 0.1, dwell=np.abs(rng.normal(size=n)), still=rng.random(n) < 0.2,
               p_gas_abs=1e6 + 1e4 * rng.normal(size=n), p_charge_abs=1e6)
    s = _Trace(sig)
    with np.errstate(all="ignore"):
        cols = cls.features(s, cls.feature_grid[0] if cls.feature_grid else None)
    return frozenset(s.seen) if cols else frozenset()


def expand(candidates, sensors) -> list:
    """Candidate names with channel effects expanded to ``name:channel`` for each channel in
    ``sensors`` (a name already of that form is kept when its channel is present).

    Parameters
    ----------
    candidates : iterable of str
        Effect names, a channel effect optionally as ``name:channel``.
    sensors : iterable of str
        Channels the log has.
    """
    lib = _candidate_classes()
    out = []
    for c in candidates:
        base, _, ch = c.partition(":")
        if base not in lib:
            raise InputError(f"unknown candidate {base!r}{did_you_mean(base, lib)}; known: {', '.join(lib)}")
        if lib[base].hook != "channel":
            if ch:
                raise InputError(f"candidate {c!r}: only a channel effect names a channel")
            out.append(base)
        elif ch:
            if ch not in SENSOR_CHANNELS:
                raise InputError(f"candidate {c!r}: unknown channel {ch!r}{did_you_mean(ch, SENSOR_CHANNELS)}")
            if ch in sensors:
                out.append(c)
        else:
            out += [f"{base}:{k}" for k in CHANNELS if k in sensors and k in SENSOR_CHANNELS]
    return list(dict.fromkeys(out))


def entries(candidate) -> tuple:
    """Residual parts a candidate (``name`` or ``name:channel``) enters, whatever the sensors.

    Parameters
    ----------
    candidate : str
        ``name`` or ``name:channel``.
    """
    base, _, ch = candidate.partition(":")
    cls = _candidate_classes()[base]
    if cls.hook == "channel":
        return channel_residuals(ch)
    return tuple(dict.fromkeys(r for h in _hooks_of(cls) for r in HOOK_RESIDUALS[h]))


def check_sensors(sensors) -> tuple:
    """The sensor set in contract order; InputError naming an unknown channel or a missing heave.

    Parameters
    ----------
    sensors : iterable of str
        Channels the log has (:data:`CHANNELS`).
    """
    sensors = tuple(sensors)
    for s in sensors:
        if s not in CHANNELS:
            raise InputError(f"unknown sensor {s!r}{did_you_mean(s, CHANNELS)}; channels: {', '.join(CHANNELS)}")
    if "heave" not in sensors:
        raise InputError("sensors: 'heave' is required (the model's input)")
    return tuple(c for c in CHANNELS if c in sensors)


def computable(sensors) -> tuple:
    """Residual parts computable from ``sensors``.

    Parameters
    ----------
    sensors : iterable of str
        Channels the log has (:data:`CHANNELS`; ``heave`` required).
    """
    have = set(check_sensors(sensors))
    return tuple(r for r, need in residuals().items() if set(need) <= have)


def signature(candidate, sensors, level="structural") -> frozenset:
    """The candidate's fault signature over the computable residuals: residual names, or at
    ``level="shape"`` (residual, signals) pairs for the equation residuals.

    Parameters
    ----------
    candidate : str
        ``name`` or ``name:channel``.
    sensors : iterable of str
        Channels the log has.
    level : {"structural", "shape"}
        Residual parts only, or also the signals the term is a function of.
    """
    if level not in LEVELS:
        raise InputError(f"unknown isolability level {level!r}; levels: {', '.join(LEVELS)}")
    comp = set(computable(sensors))
    dep = dependence(candidate.partition(":")[0]) if level == "shape" else frozenset()
    return frozenset((r, dep if not r.startswith("replay/") else frozenset())
                     for r in entries(candidate) if r in comp)


def default_candidates() -> list:
    return list(_candidate_classes())


def isolability(sensors, candidates=None, level="structural") -> dict:
    """For the sensor set ``sensors``: which candidates are detectable, which cannot be told apart.

    Parameters
    ----------
    sensors : iterable of str
        Channels the log has (:data:`CHANNELS`; ``heave`` required).
    candidates : iterable of str, optional
        Effect names (default: every candidate of the gap diagnosis); a channel effect is expanded to
        ``name:channel`` for each channel present.
    level : {"structural", "shape"}

    Returns
    -------
    dict: ``detectable`` (candidates entering a computable residual), ``groups`` (lists of detectable
    candidates with equal signatures, in candidate order; a candidate alone is isolable),
    ``undetectable``, ``sensors``, ``residuals`` (the computable residual parts), ``level``.
    """
    sensors = check_sensors(sensors)
    cands = expand(default_candidates() if candidates is None else candidates, sensors)
    sig = {c: signature(c, sensors, level) for c in cands}
    det = [c for c in cands if sig[c]]
    groups: dict = {}
    for c in det:
        groups.setdefault(sig[c], []).append(c)
    return {"detectable": det, "groups": list(groups.values()), "undetectable": [c for c in cands if not sig[c]],
            "sensors": list(sensors), "residuals": list(computable(sensors)), "level": level}


def group_of(effect, iso) -> list:
    """The group of ``effect`` in an :func:`isolability` answer: ``[effect]`` when it is isolable, the
    members it cannot be told from otherwise, ``[]`` when the sensor set cannot detect it.  A channel
    effect given without its channel (``sensor_gain``) matches every ``sensor_gain:*`` group.

    Parameters
    ----------
    effect : str
        An effect name, or ``name:channel``.
    iso : dict
        An :func:`isolability` answer.
    """
    for g in iso["groups"]:
        if effect in g or any(m.partition(":")[0] == effect and ":" not in effect for m in g):
            return list(g)
    return []


def signature_matrix(sensors, candidates=None) -> tuple:
    """(residual names, {candidate: [0/1 per residual]}) over the computable residuals.

    Parameters
    ----------
    sensors : iterable of str
        Channels the log has.
    candidates : iterable of str, optional
        Effect names (default: every candidate of the gap diagnosis).
    """
    sensors = check_sensors(sensors)
    res = computable(sensors)
    cands = expand(default_candidates() if candidates is None else candidates, sensors)
    return res, {c: [int(r in entries(c)) for r in res] for c in cands}


def markdown(level_notes=True) -> str:
    """The isolability tables of every sensor set of :data:`SENSOR_SETS` (docs/monitoring.md).

    Parameters
    ----------
    level_notes : bool
        Add the shape-level notes under each table.
    """
    lines = []
    for s in SENSOR_SETS:
        st, sh = isolability(s), isolability(s, level="shape")
        lines += [f"#### Sensors: {', '.join(s)}", "",
                  f"Computable residuals: {', '.join(f'`{r}`' for r in st['residuals']) or 'none'}.", "",
                  "| level | detectable | groups that cannot be told apart (2+) | isolable | undetectable |",
                  "|---|---|---|---|---|"]
        for iso in (st, sh):
            multi = [g for g in iso["groups"] if len(g) > 1]
            single = [g[0] for g in iso["groups"] if len(g) == 1]
            lines.append(f"| {iso['level']} | {len(iso['detectable'])} | "
                         + ("; ".join("{" + ", ".join(g) + "}" for g in multi) or "-") + " | "
                         + (", ".join(single) or "-") + " | " + (", ".join(iso["undetectable"]) or "-") + " |")
        lines.append("")
    s = SENSOR_SETS[0]
    res, mat = signature_matrix(s)
    lines += ["#### Fault signature matrix (all four channels, structural)", "",
              "| candidate | " + " | ".join(f"`{r}`" for r in res) + " |",
              "|---|" + "---|" * len(res)]
    lines += [f"| {c} | " + " | ".join("x" if v else "" for v in row) + " |" for c, row in mat.items()]
    lines += ["", "Residual parts and the channels they need:", "",
              "| residual | channels |", "|---|---|"]
    lines += [f"| `{r}` | {', '.join(need)} |" for r, need in residuals().items()]
    return "\n".join(lines) + "\n"
