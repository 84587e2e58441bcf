"""The equation error's part in the diagnosis: pre-screen, equation-error starts, the open search.

These read the component residuals (:class:`heavecomp.diagnosis.components.ComponentResiduals`,
computed from the measured signals, blind to stick-event timing) with the fit / held-out masks of the
replay context:

- :func:`prescreen` -- which candidates are replayed at all;
- :func:`equation_error_start` -- a candidate's equation-error fit as a start for its replay fit;
- :func:`skipped_row` -- the ``candidates`` row of a candidate the pre-screen did not replay;
- :func:`discover` -- the open search's best term when no named effect explains the gap;
- :func:`candidate_component` -- the component a fitted candidate lives in.
"""

from __future__ import annotations

import math
import time

import numpy as np

from heavecomp.diagnosis import components as CR
from heavecomp.diagnosis import equation_error as EE
from heavecomp.diagnosis.score_test import needs_test
from heavecomp.effects.base import COMPONENTS
from heavecomp.effects.candidates import MISMATCH_KEYS, ParameterMismatch, get
from heavecomp.errors import ParameterError

#: component of each parameter table of parameter_mismatch
TABLE_COMPONENT = {"compensator": "gas_spring", "friction": "friction", "drill_string": "string_formation",
                   "formation": "string_formation"}
#: parameters of parameter_mismatch that enter more than their table's component's equation, the verdict's
#: component first.  The top mass M_c enters the top-mass balance (its weight and inertia: the ``friction``
#: rest of that equation, :data:`heavecomp.diagnosis.components.OWN`) and, through the charge that holds the
#: WOB set-point (p_0 A = (M_c + m_b) g - W_0), the gas law as a pre-charge offset (``gas_spring``).  The
#: verdict names ``gas_spring``: the top-mass residual reads the pressure too (p A) and so carries at least
#: the gas law's noise times A, so a mass error's share is always the larger in the gas law (a 90 s planted
#: 18 % heavier mass: gas_spring 0.88, friction 0.12 of the equation-error gap)
KEY_COMPONENTS = {"compensator.moving_mass": ("gas_spring", "friction")}


def parameter_components(key) -> tuple:
    """The components whose equation residuals a ``parameter_mismatch`` parameter (``"table.key"``) enters,
    the one a verdict names first (:data:`KEY_COMPONENTS`, else its table's, :data:`TABLE_COMPONENT`).

    Parameters
    ----------
    key : str
        The parameter's name in the report (``"compensator.moving_mass"``).
    """
    return KEY_COMPONENTS.get(key) or (TABLE_COMPONENT[key.split(".")[0]],)
#: parameter_mismatch parameters no equation-error residual sees: the static friction force acts at
#: breakaway, where the top-mass balance is blind (as dwell_stiction and friction_lag: always released)
UNSEEN = ("static_force",)


def prescreen(cr, shares, fitmask, valmask, names, policy) -> dict:
    """Per candidate: its component, the component's gap over noise and floor
    (:meth:`~heavecomp.diagnosis.components.ComponentResiduals.gap`), its equation-error fit on the
    component residual where it has one (:func:`heavecomp.diagnosis.equation_error.rank_effects`),
    and whether it is replayed: a plant candidate (or a heave reading, at ``heave_input``) whose component
    shows no gap
    (<= ``prescreen_gap``, or under ``prescreen_share`` of the whole gap: what a large gap elsewhere
    leaks into it; only components in :data:`heavecomp.diagnosis.components.SCREENED` and candidates
    their residual sees, ``Effect.fit.screened``) and whose equation-error columns shrink nothing held out
    (< :data:`heavecomp.diagnosis.equation_error.MIN_SHRINK`) is not.  Output and nominal candidates
    (a channel delay, the refit of the nominal's parameters) are always replayed, and so is every candidate when
    none would be; the refit releases only the parameters the equation error leaves room for
    (:func:`mismatch_room`: ``room``, ``left_out``).  ``shares``: the equation-error shares of the gap
    (``where.components``).

    Parameters
    ----------
    cr : heavecomp.diagnosis.components.ComponentResiduals
        Component residuals of the run (equation error from the measured signals).
    shares : dict
        Equation-error share of the gap [-] per component (``where.components``).
    fitmask, valmask : numpy.ndarray of bool
        Samples of the fit and held-out parts (:class:`~heavecomp.diagnosis.replay.ReplayContext`).
    names : sequence of str
        Candidate effect names.
    policy : heavecomp.diagnosis.policy.VerdictPolicy
        Decision thresholds (``prescreen_gap``, ``prescreen_share``).
    """
    gap = cr.gap()
    seen = cr.observable()  # a component no computable equation carries cannot be screened: it is replayed
    fm, vm = fitmask & cr.mask, valmask & cr.mask
    out = {}
    for n in names:
        t0 = time.perf_counter()
        cls = get(n)
        comp = cls.component() if cls.kind in ("plant", "heave") else ("sensors" if cls.kind == "output" else "")
        ee = None
        if comp in cr.residual and seen.get(comp, True):
            ranked = EE.rank_effects(cr.residual[comp], cr.signals_for(comp), [cls], fm, vm, component=comp)
            ee = ranked[0] if ranked else None
        small = gap.get(comp, 0.0) <= policy.prescreen_gap or shares.get(comp, 0.0) < policy.prescreen_share
        # a heave reading on a log with a vessel angle: the lever arm's L sin(theta) is in no column of the
        # equation-error split (z_h, dz_h, d2z_h), so the heave_input share cannot rule it out (scored 940018:
        # a 12.8 m lever arm put 98 % of the gap in string_formation and 1.6 % in heave_input, under
        # prescreen_share; the reading was not replayed and the verdict was `discovered`, low, where the code
        # before the pre-screen read it heave_reference, high)
        blind = cls.kind == "heave" and cr.angle
        quiet = (comp in CR.SCREENED and seen.get(comp, True) and cls.fit.screened and small and not blind
                 and (ee is None or ee["shrink"] < EE.MIN_SHRINK))
        replay = not (cls.kind in ("plant", "heave") and quiet)
        out[n] = {"component": comp, "component_gap": float(gap.get(comp, math.nan)), "replay": replay,
                  "equation_error": ee, "wall_time": time.perf_counter() - t0}
        if replay and needs_test(cls, comp, gap, shares, seen, ee, policy):
            out[n]["score_test"] = "pending"  # blind here: the replay's score test decides (score_test.run)
    if not any(o["replay"] for o in out.values()):
        for o in out.values():
            o["replay"] = True
    for n, o in out.items():
        if get(n).kind == "nominal" and o["replay"]:
            o.update(mismatch_room(gap, shares, seen, out, policy))
    return out


def mismatch_room(gap, shares, seen, screened, policy) -> dict:
    """Which parameters of ``parameter_mismatch`` its stepwise refit may release: those whose component's
    equation error leaves room for them (``room``, indices in field order) and, for the others, the
    evidence that left them out (``left_out``: {parameter: why}).  A parameter is left out when each of its
    components (:func:`parameter_components`) is screened (:data:`heavecomp.diagnosis.components.SCREENED`,
    observable) and shows no gap of its own, by the pre-screen's own test (gap <= ``prescreen_gap`` noise
    variances or under ``prescreen_share`` of the whole; no candidate of the component, ``screened``, shrinks
    its held-out residual by :data:`heavecomp.diagnosis.equation_error.MIN_SHRINK`): a gas stiffness that is
    off shows in the gas law's residual, a string stiffness in the lower-mass balance, a Coulomb or viscous
    force in the sliding top-mass balance, a top mass in the gas law (the charge it sets) and the top-mass
    balance.  The static friction force (:data:`UNSEEN`) acts at breakaway, which no residual sees: it is
    always released.

    Parameters
    ----------
    gap : dict
        Equation-error gap per component [noise variances] (:meth:`ComponentResiduals.gap`).
    shares : dict
        Equation-error share of the gap [-] per component (``where.components``).
    seen : dict
        Whether each component is observable (:meth:`ComponentResiduals.observable`).
    screened : dict
        The plant candidates' :func:`prescreen` entries (their equation-error fits).
    policy : heavecomp.diagnosis.policy.VerdictPolicy
        Decision thresholds (``prescreen_gap``, ``prescreen_share``).
    """
    def quiet(comp):
        small = gap.get(comp, 0.0) <= policy.prescreen_gap or shares.get(comp, 0.0) < policy.prescreen_share
        ee = [o["equation_error"]["shrink"] for n, o in screened.items()
              if o["component"] == comp and o["equation_error"] is not None and get(n).fit.screened]
        return comp in CR.SCREENED and seen.get(comp, True) and small and all(x < EE.MIN_SHRINK for x in ee)

    room, left = [], {}
    for i, (f, (key, _, _)) in enumerate(zip(ParameterMismatch.fields(), MISMATCH_KEYS)):
        comps = parameter_components(key)
        if f.name not in UNSEEN and all(quiet(c) for c in comps):
            left[key] = "; ".join(f"its component {c} shows no gap of its own (gap {gap.get(c, 0.0):.3g} noise "
                                  f"variances, {100 * shares.get(c, 0.0):.1f} % of the whole; equation-error "
                                  f"shrink under {EE.MIN_SHRINK:g})" for c in comps)
        else:
            room.append(i)
    return {"room": room, "left_out": left}


def equation_error_start(cr, pre, cls):
    """The fit vector candidate ``cls``'s equation-error fit (``pre``: its :func:`prescreen` entry)
    stands for (:meth:`heavecomp.effects.base.Effect.from_equation_error`), or None.

    Parameters
    ----------
    cr : heavecomp.diagnosis.components.ComponentResiduals
        Component residuals of the run (equation error from the measured signals).
    pre : dict or None
        The candidate's :func:`prescreen` entry.
    cls : type
        The candidate's effect class.
    """
    pre = pre or {}
    ee, comp = pre.get("equation_error"), pre.get("component")
    if ee is None or comp not in cr.residual:
        return None
    values = cls.from_equation_error(ee, cr.signals_for(comp))
    return cls.to_x(values) if values else None


def skipped_row(name, pre, shares, rms_before, n_params, policy) -> dict:
    """The candidates row of a candidate the pre-screen did not replay (contract fields; its
    held-out prediction is the nominal's: shrink and explained 0, score the parsimony penalty).
    ``pre``: its :func:`prescreen` entry; ``rms_before``: the held-out wob rms of the nominal [N].

    Parameters
    ----------
    name : str
        Candidate effect name.
    pre : dict
        Its :func:`prescreen` entry.
    shares : dict
        Equation-error share of the gap [-] per component.
    rms_before : float [N]
        Held-out WOB rms of the nominal replay.
    n_params : int
        The candidate's number of parameters (its parsimony penalty).
    policy : heavecomp.diagnosis.policy.VerdictPolicy
        Decision thresholds (``penalty``).
    """
    return {"effect": name, "parameters": {}, "rms_before": rms_before, "rms_after": rms_before, "shrink": 0.0,
            "score": -policy.penalty * n_params, "explained": 0.0, "n_params": n_params,
            "at_bound": [], "fit_wall_time": pre["wall_time"],
            "skipped": pre.get("reason") or (f"pre-screen: its component {pre['component']} shows no gap of its own "
                                             f"(gap {pre['component_gap']:.3g} noise variances, "
                                             f"{100 * shares.get(pre['component'], 0.0):.1f} % of the whole; "
                                             f"equation-error shrink under {EE.MIN_SHRINK:g})"),
            "equation_error": pre["equation_error"]}


def moved_most(values) -> str:
    """Component of the nominal parameter a parameter_mismatch moved most (|log multiplier|).

    Parameters
    ----------
    values : dict
        Fitted parameter_mismatch multipliers [-] by parameter.
    """
    names = {f.name: key for f, (key, _, _) in zip(ParameterMismatch.fields(), MISMATCH_KEYS)}
    k = max(values, key=lambda n: abs(math.log(max(values[n], 1e-12))))
    return parameter_components(names[k])[0] if k in names else ""


def candidate_component(effect, values, prescreened) -> str:
    """The component a fitted candidate lives in (parameter_mismatch: that of the parameter that moved
    most; ``values`` its fitted parameters, ``prescreened`` the :func:`prescreen` result).

    Parameters
    ----------
    effect : str
        Candidate effect name.
    values : dict
        Its fitted parameters [SI].
    prescreened : dict
        :func:`prescreen` result.
    """
    if effect == "parameter_mismatch":
        return moved_most(values)
    return prescreened.get(effect, {}).get("component") or get(effect).component()


def _centres(sig: dict) -> dict:
    """The constants :func:`heavecomp.diagnosis.equation_error.library` centres its ``x`` and ``rel``
    features on (``x_mean`` [m], ``rel_median`` [m]), for the signals ``sig`` has.

    Parameters
    ----------
    sig : dict
        The component's signals (:meth:`~heavecomp.diagnosis.components.ComponentResiduals.signals_for`).
    """
    out = {}
    if sig.get("x") is not None:
        out["x_mean"] = float(np.nanmean(sig["x"]))
    if sig.get("rel") is not None:
        out["rel_median"] = float(np.nanmedian(sig["rel"]))
    return out


def discover(cr, fitmask, valmask, policy):
    """The open search (:func:`heavecomp.diagnosis.equation_error.open_search`) on the components with
    a gap (the ``discover_components`` largest), the best held-out shrink; None when nothing beats noise.
    A misreading of one channel consistent across the equations that read it
    (:func:`heavecomp.diagnosis.components.channel_search`) comes first: a single component's term
    explains one equation, while the same misreading seen in two is a sensor (a saturating WOB channel
    read as string_formation before; docs/diagnosis.md).

    Parameters
    ----------
    cr : heavecomp.diagnosis.components.ComponentResiduals
        Component residuals of the run (equation error from the measured signals).
    fitmask, valmask : numpy.ndarray of bool
        Samples of the fit and held-out parts (:class:`~heavecomp.diagnosis.replay.ReplayContext`).
    policy : heavecomp.diagnosis.policy.VerdictPolicy
        Decision thresholds (``discover_components``).
    """
    fm, vm = fitmask & cr.mask, valmask & cr.mask
    sensor = CR.channel_search(cr, fm, vm)
    if sensor is not None:
        return dict(sensor, unit="noise sigmas")
    gap = cr.gap()
    best = None
    for c in sorted((c for c in COMPONENTS if gap[c] > 0), key=lambda c: -gap[c])[:policy.discover_components]:
        sig = cr.signals_for(c)
        own = cr.own_features(c)  # a part of another's equation: searched on its own parts only
        d = EE.open_search(cr.residual[c], sig, fm, vm, component=c,
                           features=None if own is None else EE.library(sig, own))
        if d is not None and (best is None or d["shrink"] > best["shrink"]):
            # the constants of the x and rel features (x - mean x, rel - median rel: equation_error.library),
            # for the calibrated model's term at its hook
            best = dict(d, unit=CR.UNITS[c], levels=_centres(sig))
    return best


def _as_feature(col, lib) -> str | None:
    """The library feature a column is (up to its sign: the search fits the coefficient), or None."""
    col = np.asarray(col, float)
    for n, (f, _) in lib.items():
        ok = np.isfinite(col) & np.isfinite(f)
        if not ok.any() or not np.any(f[ok]):
            continue
        for sign in (1.0, -1.0):
            if np.allclose(col[ok], sign * f[ok], rtol=1e-9, atol=1e-12 * float(np.max(np.abs(f[ok])))):
                return n
    return None


def named_form(cr, effect, fitmask, valmask):
    """The open search's form of a named plant verdict's component, when it beats the named effect's law.

    A named effect's law may not be the one the plant follows (a laminar line, ``R v``, fitted to a
    turbulent orifice, ``K v|v|``): the verdict is right, yet its calibrated model leaves what the law
    cannot express, and the re-diagnosis finds it.  Here the component's residual is searched
    (:func:`heavecomp.diagnosis.equation_error.open_search`, the component's own library,
    :meth:`~heavecomp.diagnosis.components.ComponentResiduals.own_features`) with the named effect's
    equation-error columns as ``base`` (refitted alongside: a term only counts when it adds to the
    named law).  A term found, the form is the sparse model over the named law's columns (as library
    features) and the term's, searched again without a base (so the named column is dropped when it
    no longer pays); it is returned when its fit-part BIC is below the named law's (the held-out part
    only scores, as in the open search).

    Returns the discovered-term block (``component``, ``features``, ``coefficients``, ``term``, ``shrink``
    held out, ``unit``, ``levels``, ``bic``) with ``replaces`` (the named effect) and ``named`` (its
    equation-error ``shrink``, ``bic`` and ``coefficients``), or None: not a plant effect with an
    equation-error form, its columns not library features, no term found, or the named law's BIC lower.

    Parameters
    ----------
    cr : heavecomp.diagnosis.components.ComponentResiduals
        Component residuals of the run (against the parameter file's model).
    effect : str
        The verdict's effect name.
    fitmask, valmask : numpy.ndarray of bool
        Samples of the fit and held-out parts.
    """
    try:
        cls = get(effect)
    except ParameterError:  # none, inconclusive, discovered: no law
        return None
    comp = cls.component() if cls.kind == "plant" else ""
    if comp not in cr.residual or not cr.observable().get(comp, True):
        return None
    fm, vm = fitmask & cr.mask, valmask & cr.mask
    r, sig = cr.residual[comp], cr.signals_for(comp)
    ranked = EE.rank_effects(r, sig, [cls], fm, vm, component=comp)
    if not ranked:
        return None
    named = ranked[0]
    base = cls.features(sig, named["shape"])
    lib = EE.library(sig, cr.own_features(comp))
    found = EE.open_search(r, sig, fm, vm, base=base, component=comp, features=lib)
    if found is None:
        return None
    mapped = [_as_feature(col, lib) for col in base.values()]
    if any(m is None for m in mapped):
        return None
    names = [n for n in lib if n in set(mapped) | set(found["features"])]
    form = EE.open_search(r, sig, fm, vm, component=comp, features={n: lib[n] for n in names})
    if form is None or form["bic"] >= named["bic"]:
        return None
    return dict(form, unit=CR.UNITS[comp], levels=_centres(sig), replaces=effect,
                named={"shrink": float(named["shrink"]), "bic": float(named["bic"]),
                       "coefficients": named["coefficients"]})
