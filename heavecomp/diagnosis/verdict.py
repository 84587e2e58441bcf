"""The verdict: a pure function of the scored fits, the gap, the noise floors and the policy.

>>> v = decide(fits, gap, floors, envelope, policy, evidence)      # doctest: +SKIP
>>> v.effect, v.confidence, v.warnings                              # doctest: +SKIP

:func:`decide` reads what the diagnosis measured and never computes a fit: the joint fits of a second
effect and the open search are evidence the orchestrator gathers first, when :func:`wants_second` and
:func:`wants_discovery` say the verdict will read them.  Its steps, in order:

1. :func:`assess` -- gap over noise and over the input-noise envelope, margin to the runner-up and
   whether it survives a heave-noise redraw, the shrink channel, whether the best candidate predicts the
   held-out gap, and whether the gap is ``none``;
2. ``none``, else :func:`_short_of_min` (best explained < ``min_explained``: a second effect, the
   equation error's confirmation, or ``inconclusive``), else :func:`_named` (confidence);
3. :func:`_at_bound` -- a fitted parameter at its search bound lowers a named verdict's confidence;
4. :func:`_component` -- ``verdict.component``, the parameter_mismatch checks against the equation error
   (:func:`_refit_check`, :func:`_stationarity`) and the open search's ``discovered`` term.

Every threshold comes from the :class:`~heavecomp.diagnosis.policy.VerdictPolicy`.  A later cap on the
confidence (e.g. from log-quality flags) is one more step after :func:`_at_bound`, an isolable group a
field filled by :func:`_component`, and a ``calibrated`` block a function of the returned
:class:`Verdict` (see ``docs/diagnosis.md``).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Callable

from heavecomp.diagnosis.joint import SecondSearch
from heavecomp.diagnosis.replay import CH
from heavecomp.diagnosis.screen import candidate_component
from heavecomp.diagnosis.structure import entries
from heavecomp.errors import InputError
from heavecomp.effects.base import COMPONENTS
from heavecomp.effects.candidates import by_family, family_of, get, law_of, same_family

CONFIDENCE = ("low", "medium", "high")
#: verdicts that name no effect
NOT_NAMED = ("none", "inconclusive", "discovered")


@dataclasses.dataclass(frozen=True)
class Evidence:
    """What the verdict reads besides the fits: the equation-error ``shares`` of the gap
    (``where.components``), the pre-screen per candidate, the ``second`` effect search (None: not
    searched), the open search's ``discovered`` term (None: not run or nothing beat noise) and the
    ``stationarity`` of a component's residual (a query: component -> dict or None); ``not_observable``: the
    components no equation computable from the log's channels carries (their share is 0 by construction)."""

    shares: dict
    prescreen: dict = dataclasses.field(default_factory=dict)
    second: SecondSearch | None = None
    discovered: dict | None = None
    stationarity: Callable = lambda component: None
    not_observable: tuple = ()
    #: the practical distinguishability of the leading candidates on this log
    #: (:class:`heavecomp.diagnosis.distinguish.Distinguishability`; None: not tested)
    distinct: object = None
    #: the log carries a vessel angle (``pitch``): a heave reading's lever arm, L sin(theta), is in no column of
    #: the equation-error split, so the component table can neither support nor contradict it
    angle: bool = False


@dataclasses.dataclass(frozen=True)
class Assessment:
    """The numbers a verdict is decided on (:func:`assess`)."""

    gap_ratio: float  #: largest held-out rms over its noise floor [-]
    input_ratio: float  #: largest held-out rms over its input-noise envelope [-]
    margin: float  #: best score minus the runner-up's [-]
    spread: float  #: how far a heave-noise redraw moves the two explained shares [-]
    survives: bool  #: the margin exceeds the spread
    channel: str  #: the shrink channel
    predicts: bool  #: the best candidate predicts the held-out gap (rules out ``none``)
    is_none: bool  #: the gap is ``none``
    #: largest held-out rms the best candidate leaves, over its channel's input-noise envelope [-]: the ``none``
    #: test's measure on what the best candidate leaves (:func:`_remainder_check`)
    remainder_ratio: float = 0.0


@dataclasses.dataclass(frozen=True)
class Verdict:
    """The verdict: its ``diagnosis.json`` block (``body``: effect, confidence, parameters, shrink, ...)
    and the ``warnings`` it adds to the diagnosis."""

    body: dict
    warnings: tuple = ()
    #: the fitted effects that stand for the verdict's group, one per family, lead first (``body["group"]``
    #: names their families): what :func:`heavecomp.diagnosis.distinguish.separate_by` simulates
    members: tuple = ()

    @property
    def effect(self) -> str:
        return self.body["effect"]

    @property
    def confidence(self) -> str:
        return self.body["confidence"]

    def to_json(self) -> dict:
        return dict(self.body)


def assess(fits, gap, floors, envelope, policy) -> Assessment:
    """Gap ratios, margin and its input-noise spread, shrink channel and the ``none`` test (see
    :class:`Assessment`).  ``gap``: per channel {rms_validate} [SI]; ``floors``, ``envelope``: noise
    floor and input-noise envelope per channel [SI].

    Parameters
    ----------
    fits : list of heavecomp.diagnosis.fitting.CandidateFit
        The replayed candidates' fits, best score first.
    gap : dict
        Per channel {rms_validate: held-out rms of the nominal replay [SI]}.
    floors : dict
        Noise floor per channel [SI] (output noise and replay floor).
    envelope : dict
        Input-noise envelope per channel [SI].
    policy : heavecomp.diagnosis.policy.VerdictPolicy
        Decision thresholds.
    """
    P = policy
    best = fits[0]
    runner = rival(fits)
    chans = [c for c in CH if c in gap]  # the channels the log has (the first is the primary)
    ratio = {c: gap[c]["rms_validate"] / max(floors[c], 1e-30) for c in chans}
    margin = best.score - runner.score if runner else 1.0
    # the margin must survive the replay's own input-noise spread (issue 12 item 6): how far a
    # candidate's explained share moves when the heave is redrawn within its noise, best and runner-up
    spread = math.hypot(*(abs(r.explained_replay - r.explained_perturbed) for r in (best, runner or best)))
    # the shrink is on wob (the primary channel) unless the gap lies elsewhere (e.g. a lagging stroke
    # sensor): wob's held-out gap over its floor is under a share of the largest channel's
    first = chans[0]
    ch = first if ratio[first] >= P.shrink_channel_ratio * max(ratio.values()) else max(chans, key=ratio.get)
    # `none`: the held-out gap is no larger than measurement noise plus what the heave noise alone
    # makes of the replay (its envelope over independent draws: stick-event flips are rare but large)
    input_ratio = max(gap[c]["rms_validate"] / max(envelope[c], 1e-30) for c in chans)
    # held-out noise cannot be predicted: a candidate fitted on the fit part that shrinks the held-out
    # gap's rms on its channel has found something the noise floor estimate hides
    predicts = best.channels[ch]["shrink"] >= P.none_predicted and best.explained_perturbed >= P.min_explained
    quiet = input_ratio <= P.none_ratio or (input_ratio <= P.none_tail and best.explained < P.none_explained)
    remainder = max(best.channels[c]["rms_after"] / max(envelope[c], 1e-30) for c in chans if c in best.channels)
    return Assessment(max(ratio.values()), input_ratio, margin, spread, margin > spread, ch, predicts,
                      quiet and not predicts, remainder)


def rival(fits):
    """The runner-up of ``fits`` (best first): the best fit of another family than the best's (two laws of
    one contract class, ``friction_lag`` in time and in distance, are one answer, never rivals); None.

    Parameters
    ----------
    fits : list of heavecomp.diagnosis.fitting.CandidateFit
        The replayed candidates' fits, best score first.
    """
    return next((f for f in fits[1:] if not same_family(f.effect, fits[0].effect)), None)


def wants_second(fits, a: Assessment, policy) -> bool:
    """Whether the verdict reads a second-effect search (:func:`heavecomp.diagnosis.joint.search`).

    Parameters
    ----------
    fits : list of heavecomp.diagnosis.fitting.CandidateFit
        The replayed candidates' fits, best score first.
    a : Assessment
        The :func:`assess` result of ``fits``.
    policy : heavecomp.diagnosis.policy.VerdictPolicy
        Decision thresholds. (``min_explained``, ``second_below``).
    """
    best = fits[0].explained
    return not a.is_none and (best < policy.min_explained or best < policy.second_below)


def wants_discovery(fits, a: Assessment, policy) -> bool:
    """Whether the verdict reads the open search (:func:`heavecomp.diagnosis.screen.discover`).

    Parameters
    ----------
    fits : list of heavecomp.diagnosis.fitting.CandidateFit
        The replayed candidates' fits, best score first.
    a : Assessment
        The :func:`assess` result of ``fits``.
    policy : heavecomp.diagnosis.policy.VerdictPolicy
        Decision thresholds. (``min_explained``).
    """
    return not a.is_none and fits[0].explained < policy.min_explained


def decide(fits, gap, floors, envelope, policy, evidence: Evidence) -> Verdict:
    """The verdict on ``fits`` (:class:`~heavecomp.diagnosis.fitting.CandidateFit`, best score first);
    see the module docstring.  Pure: the same arguments give the same verdict.

    Parameters
    ----------
    fits : list of heavecomp.diagnosis.fitting.CandidateFit
        The replayed candidates' fits, best score first.
    gap : dict
        Per channel {rms_validate: held-out rms of the nominal replay [SI]}.
    floors : dict
        Noise floor per channel [SI] (output noise and replay floor).
    envelope : dict
        Input-noise envelope per channel [SI].
    policy : heavecomp.diagnosis.policy.VerdictPolicy
        Decision thresholds.
    evidence : Evidence
        What else the diagnosis found: equation-error shares, pre-screen, second-effect search, open
        search and stationarity.
    """
    a = assess(fits, gap, floors, envelope, policy)
    group, by_score = (), fits[0]
    refit_note = None
    if not a.is_none:  # the group the log cannot split, and its lead (which may explain more than the best score)
        group, fits, a = _grouped(fits, gap, floors, envelope, policy, evidence.distinct, a)
        group, fits, a, refit_note = _refit_first(group, fits, gap, floors, envelope, policy, a)
    best = fits[0]
    v = {"effect": best.effect, "confidence": "low", "parameters": best.parameters,
         "shrink": best.channels[a.channel]["shrink"], "shrink_channel": a.channel, "uncertainty": best.uncertainty,
         "explained": best.explained, "gap_to_noise": a.gap_ratio, "gap_to_input_envelope": a.input_ratio,
         "margin": a.margin, "margin_input_noise": a.spread, "predicted_shrink": best.channels[a.channel]["shrink"]}
    if a.is_none:
        return Verdict(_none(v, a, policy))
    if refit_note:
        v["refit_note"] = refit_note
    if best.explained < policy.min_explained:
        v = _short_of_min(v, fits, a, policy, evidence)
    else:
        v = _named(v, fits, a, policy, evidence)
    if refit_note and v["confidence"] != "low":
        # the mechanism led by score or by the held-out test: the parsimony decides, not the evidence, so the
        # name is not confident
        v["confidence"] = "low"
        v["refit_note"] += "; confidence low: the parsimony decides here, not the evidence"
    if evidence.distinct is not None and v["effect"] not in ("inconclusive", "discovered"):
        v["distinguishable"] = evidence.distinct.to_json()
        if len(by_family(group)) > 1:
            v["group"] = list(group)
            v["group_note"] = _group_note(group, fits, evidence.distinct)
        if len(by_family(group)) < len(group):
            v["law_note"] = _law_note(group, evidence.distinct)
        if fits[0] is not by_score and not refit_note:
            _test_lead(v, fits, a, policy, evidence.distinct, by_score)
            p = next((p for p in evidence.distinct.pairs if {p.a, p.b} == {fits[0].effect, by_score.effect}), None)
            v["lead_note"] = (f"`{fits[0].effect}` leads although `{by_score.effect}` scored higher (parsimony "
                              f"penalty): " + (f"the held-out block test prefers it (t = {p.statistic:+.2f}, "
                                               f"threshold {p.threshold:.2f})" if p and p.apart else
                                               "the log cannot tell them apart and it adds no mechanism"))
    warnings = []
    _at_bound(v, fits, warnings)
    _component(v, fits, policy, evidence, warnings)
    _remainder_check(v, a, policy, warnings)
    members = tuple(by_family(v.get("group") or [best.effect])) if v["effect"] not in NOT_NAMED else ()
    _as_family(v)
    return Verdict(v, tuple(warnings), members)


def _as_family(v) -> None:
    """The verdict in the contract's names (issue 30 item 4): an effect that is one law of a broader class
    (``fit.family``, ``fit.law``) is named by its family, with ``law`` and the fitted ``member`` beside it
    (``friction_memory`` -> ``effect: friction_lag, law: distance, member: friction_memory``); its
    ``parameters`` stay the member's.  A group keeps one name per family, each family's law the better
    fit's (the first); a group of one family is a single name."""
    name = v["effect"]
    if name in NOT_NAMED:
        return
    if law_of(name):
        v.update(effect=family_of(name), law=law_of(name), member=name)
    if v.get("group"):
        v["group_members"] = by_family(v["group"])
        laws = {family_of(m): law_of(m) for m in v["group_members"] if law_of(m)}
        if laws:  # the law each family of the group stands with (its better fit's)
            v["group_laws"] = laws
        v["group"] = [family_of(m) for m in v["group_members"]]


def label(v) -> str:
    """A verdict's name in words: ``friction_lag (law: distance, fitted as friction_memory)`` for a law of a
    family, else its ``effect``.

    Parameters
    ----------
    v : dict
        A verdict (``diagnosis.json``'s ``verdict``).
    """
    if v.get("law"):
        return f"{v['effect']} (law: {v['law']}, fitted as {v.get('member', v['effect'])})"
    return str(v.get("effect"))


def said(name: str) -> str:
    """An effect's name as the verdict reports it, for the words of a warning written before the verdict
    takes its family's name (:func:`_as_family`): ``friction_lag (law: distance, fitted as friction_memory)``
    for a law of a family, else ``name``.

    Parameters
    ----------
    name : str
        The fitted effect (a family's member, or any other name).
    """
    if name in NOT_NAMED or not law_of(name):
        return name
    return label({"effect": family_of(name), "law": law_of(name), "member": name})


def member(v) -> str:
    """The effect a verdict fitted (its class: ``calibrated.toml``'s entry, its parameters' units): the
    ``member`` of a family's law, else the ``effect``.

    Parameters
    ----------
    v : dict
        A verdict, or a ``second_effect`` block.
    """
    return v.get("member") or v.get("effect")


def _law_note(group, distinct) -> str:
    """Why the verdict's family carries the law it does when the log cannot tell two of its laws apart."""
    lead = group[0]
    sib = [m for m in group[1:] if same_family(m, lead)]
    stats = {p.b: p for p in distinct.pairs}
    st = "; ".join(f"{m}: t = {stats[m].statistic:+.2f} (threshold {stats[m].threshold:.2f})" for m in sib if m in stats)
    return (f"this log cannot tell the laws of {family_of(lead)} apart ({lead}, law {law_of(lead) or '-'}; "
            + ", ".join(f"{m}, law {law_of(m) or '-'}" for m in sib) + f"): one answer, the law of the better fit"
            + (f" ({st})" if st else ""))


def _grouped(fits, gap, floors, envelope, P, distinct, a):
    """The verdict's group (schema 4): the best and the leading candidates the log cannot tell from it
    (:mod:`heavecomp.diagnosis.distinguish`).  A group of two or more is named by its lead with the
    group's confidence: the runner-up the group's margin is measured to is the best candidate outside
    it.  The lead is the best fit, except that a refit of the nominal's own parameters
    (``parameter_mismatch``) in the group leads it when it explains ``min_explained``: the log does not
    need the new mechanism (issue 30 item 3: the nominal structure with other values is the simpler
    model).  Returns (group, fits reordered: lead then those outside the group, the assessment)."""
    if distinct is None or not distinct.group:
        return (), fits, a
    byname = {f.effect: f for f in fits}
    inside = [byname[m] for m in distinct.group if m in byname]
    if len(inside) == 1 and inside[0] is fits[0]:
        return tuple(distinct.group), fits, a
    pm = next((f for f in inside if f.effect == "parameter_mismatch"), None)
    others = [f for f in inside if f is not pm]
    if pm is not None and (not others or pm.explained >= max(f.explained for f in others)):
        lead = pm  # explains as much as any new mechanism the log cannot tell it from: the simpler model
    else:
        lead = others[0]  # the best of the mechanisms (a refit that explains less does not lead)
    order = [lead] + [f for f in inside if f is not lead]
    rest = [lead] + [f for f in fits if f.effect not in distinct.group]
    ag = dataclasses.replace(assess(rest, gap, floors, envelope, P), is_none=False)
    return tuple(f.effect for f in order), rest, ag


def _refit_first(group, fits, gap, floors, envelope, P, a):
    """The refit of the nominal's own parameters leads when it explains as much as the lead, a new
    mechanism, to within one parameter's parsimony penalty (``penalty``), and at least ``min_explained``
    (issue 30 item 3: the nominal structure with other values is the simpler model; a mechanism must buy
    what a parameter is charged).  The held-out block test can set the two apart on a long log while the
    mechanism explains a thousandth more: a difference the test detects is not one the log needs (the
    independent truth's gas-volume errors, 1050000/1, studied after scoring: `gas_heat_transfer`'s
    effective index explained 1.007 and 1.018 held out, the refit of k_gas 1.005 and 1.017, and the test
    preferred the index).  No new threshold: the policy's ``penalty``.  Returns (group, fits, assessment,
    note or None) as :func:`_grouped`."""
    lead = fits[0]
    pm = next((f for f in fits if f.effect == "parameter_mismatch"), None)
    if (pm is None or lead is pm or pm.explained < P.min_explained
            or pm.explained < lead.explained - P.penalty):
        return group, fits, a, None
    rest = [pm] + [f for f in fits if f is not pm]
    ag = dataclasses.replace(assess(rest, gap, floors, envelope, P), is_none=False)
    note = (f"the refit of the nominal's own parameters explains {100 * pm.explained:.1f} % of the held-out gap, "
            f"`{family_of(lead.effect)}` {100 * lead.explained:.1f} %: within one parameter's parsimony penalty "
            f"({100 * P.penalty:g} %), so the nominal structure with other values is the verdict (no new mechanism "
            f"is needed)")
    return (), rest, ag, note


def _test_lead(v, fits, a, P, distinct, by_score) -> None:
    """A lead the held-out block test prefers over the best by score: its score margin (negative: the
    penalty) is not the evidence, the test is.  When the test sets it apart from every leading candidate,
    it is medium (never high: the test's preference, not a margin of ``high_margin``) if it explains
    ``medium_explained`` outside the stick-event-noise tail."""
    rivals = [p for p in distinct.pairs if not same_family(p.a, p.b)]  # two laws of one family are no rivals
    if len(by_family(v.get("group") or [v["effect"]])) > 1 or any(not p.apart for p in rivals):
        return
    if fits[0].explained >= P.medium_explained and a.input_ratio > P.none_tail and v["confidence"] == "low":
        v["confidence"] = "medium"
        v["note"] = (f"the held-out block test sets `{fits[0].effect}` apart from every leading candidate, "
                     f"`{by_score.effect}` included: confidence medium")


def _group_note(group, fits, distinct) -> str:
    """Why the verdict is a group, in words (two laws of one family named once, by the better's)."""
    others = ", ".join(f"`{family_of(m)}`" for m in by_family(group)[1:])
    stats = {p.b: p for p in distinct.pairs}
    st = "; ".join(f"{m}: t = {stats[m].statistic:+.2f} (threshold {stats[m].threshold:.2f})"
                   for m in group if m in stats)
    lead = group[0]
    why = (" (the refit of the nominal's own parameters explains as much: no new mechanism is needed)"
           if lead == "parameter_mismatch" else "")
    return (f"this log cannot tell `{family_of(lead)}` from {others}{why}; held-out block test at a "
            f"{100 * distinct.alpha:g} % false-alarm rate: {st}; the confidence is the group's")


def _none(v, a, P) -> dict:
    """The ``none`` verdict: high within ``none_high * (1 + none_ratio)`` of the noise floor; low in the
    stick-event-noise tail (between ``none_ratio`` and ``none_tail`` x the envelope, where no candidate
    explains ``none_explained``)."""
    tail = a.input_ratio > P.none_ratio
    v.update(effect="none", parameters={}, shrink=0.0, uncertainty={},
             confidence="low" if tail else ("high" if a.gap_ratio <= P.none_high * (1 + P.none_ratio) else "medium"),
             note=(f"held-out gap {a.input_ratio:.2f} x the input-noise envelope and no candidate explains "
                   f"{100 * P.none_explained:.0f} % of it" if tail else
                   f"held-out gap within {P.none_ratio:g} x the noise floor (or the envelope of the "
                   "replay's response to the heave noise) on every channel"))
    return v


def _short_of_min(v, fits, a, P, evidence) -> dict:
    """The best candidate explains under ``min_explained`` alone: named with a second effect when the
    pair explains enough; named (low) when its own equation, fitted on its component's residual (blind
    to stick timing), shrinks that residual held out by ``discover_shrink`` in the component holding
    ``confirm_share`` of the gap; else ``inconclusive``."""
    best = fits[0]
    second = evidence.second.best if evidence.second is not None else None
    if evidence.second is not None:
        v["second_candidates"] = evidence.second.candidates()
    if second is not None and second["explained_joint"] >= P.min_explained:
        ok = second["explained_joint"] >= P.medium_explained and a.margin >= P.medium_margin and a.survives
        v.update(second_effect=second, confidence="medium" if ok else "low",
                 note=f"{best.effect} explains {100 * best.explained:.0f} % alone, "
                      f"{100 * second['explained_joint']:.0f} % with {second['effect']}")
        return v
    pre = evidence.prescreen.get(best.effect, {})
    ee = pre.get("equation_error")
    if (ee and ee["shrink"] >= P.discover_shrink and best.explained >= P.none_explained
            and evidence.shares.get(pre.get("component"), 0.0) >= P.confirm_share):
        v.update(confidence="low", confirmed_by="equation_error",
                 note=f"{best.effect} explains {100 * best.explained:.0f} % of the held-out replay gap "
                      f"and shrinks its held-out {pre['component']} residual by {100 * ee['shrink']:.0f} % "
                      "(equation error): named with low confidence")
        return v
    v.update(effect="inconclusive", confidence="low", parameters={},
             note=f"best candidate {best.effect} explains only {100 * best.explained:.0f} % of the "
                  "held-out gap above noise", best_candidate=best.effect)
    return v


def _named(v, fits, a, P, evidence) -> dict:
    """A named verdict's confidence: high or medium by explained share and margin when the margin
    survives the heave-noise redraw; never confident in the stick-event-noise tail (<= ``none_tail`` x
    the envelope, where a candidate can fit most of that noise); the second effect when searched."""
    best = fits[0]
    if best.explained >= P.high_explained and a.margin >= P.high_margin and a.survives:
        v["confidence"] = "high"
    elif best.explained >= P.medium_explained and a.margin >= P.medium_margin and a.survives:
        v["confidence"] = "medium"
    if not a.survives:
        v["note"] = (f"margin to {(rival(fits) or best).effect} ({a.margin:.3f}) within the spread a heave-noise redraw makes "
                     f"of the explained shares ({a.spread:.3f}): confidence low")
    if a.input_ratio <= P.none_tail and v["confidence"] != "low":
        v["confidence"] = "low"
        v["note"] = (f"held-out gap only {a.input_ratio:.2f} x the input-noise envelope (runs without any effect "
                     f"reach up to {P.none_tail:g} x): confidence low")
    if evidence.second is not None and best.explained < P.second_below:
        v["second_effect"] = evidence.second.best
        v["second_candidates"] = evidence.second.candidates()
    return v


def _at_bound(v, fits, warnings) -> None:
    """A fitted parameter at its search bound (issue 14.3): the fit wanted to go further than the
    candidate allows, so the candidate probably stands in for something else (e.g. a heave channel
    with the wrong sign fitted as a 3 s sensor delay): a named verdict drops to confidence ``low``,
    says so in ``warnings`` and lists them in ``verdict.at_bound``."""
    if v["effect"] in ("none", "inconclusive") or v["effect"] != fits[0].effect or not fits[0].at_bound:
        return
    hits = list(fits[0].at_bound)
    v["at_bound"] = hits
    was = v["confidence"]
    v["confidence"] = "low"
    where = ", ".join(f"{h['parameter']} = {h['value']:.4g} at its {h['side']} search bound {h['bound']:.4g}"
                      for h in hits)
    warnings.append(f"verdict {said(v['effect'])}: fitted {where}; the effect may stand in for another "
                    f"(e.g. a channel with the wrong sign or unit) -- confidence lowered from {was} to low")


def _component(v, fits, P, evidence, warnings) -> None:
    """``verdict.component`` (every verdict but ``none``), the parameter_mismatch checks, and the open
    search's ``discovered`` term when no named effect explains ``min_explained`` of the gap: the verdict
    becomes ``discovered`` (confidence low) only when an ``inconclusive`` verdict's term shrinks its
    held-out component residual by >= ``discover_shrink``; otherwise the term is a suggestion."""
    shares = evidence.shares
    eff, best = v["effect"], fits[0]
    largest = max(COMPONENTS, key=lambda c: shares[c]) if any(shares.values()) else ""
    best_comp = candidate_component(best.effect, best.values, evidence.prescreen)
    if eff == "inconclusive":
        # a best candidate that explains a real part of the gap (>= none_explained) knows its component
        # better than the equation-error shares (both a gas heat transfer and a line loss are ~v in the
        # gas law's residual)
        if best.effect == "parameter_mismatch" and _refit_disagrees(best_comp, shares, largest, P):
            best_comp = largest  # the refit stands in (see _refit_check)
        # no candidate explains a real part of it: the equation-error table's largest component where it holds
        # confirm_share of the gap; where none does, the component whose held-out residual the open search's
        # term shrinks (a held-out test over the components with an equation gap), before the table's largest
        # (a hardening formation: heave_input 0.49 against string_formation 0.47, the term shrank the string's
        # held-out residual by 35 %) and before a candidate under none_explained (a second string mode: the
        # table empty, a sensor delay explaining 9 %)
        held = evidence.discovered["component"] if evidence.discovered else ""
        table = largest if largest and shares[largest] >= P.confirm_share else ""
        v["component"] = best_comp if best.explained >= P.none_explained and best_comp \
            else table or held or largest or best_comp
    else:
        v["component"] = best_comp
    if eff == "parameter_mismatch":
        _refit_check(v, shares, largest, P, warnings)
        _stationarity(v, evidence, warnings)
    _table_check(v, shares, largest, P, evidence.not_observable, warnings, angle=evidence.angle)
    if best.explained >= P.min_explained or evidence.discovered is None:
        return
    found = evidence.discovered
    v["discovered"] = found
    if eff == "inconclusive" and found["component"] == "sensors":
        v["component"] = "sensors"  # one channel misreads: seen in every equation that reads it
    if eff == "inconclusive" and found["shrink"] >= P.discover_shrink:
        v.update(effect="discovered", component=found["component"], confidence="low",
                 note=f"no named effect explains half the gap (best {best.effect}: "
                      f"{100 * best.explained:.0f} %); the open search's term {found['term']} shrinks the "
                      f"held-out {found['component']} residual by {100 * found['shrink']:.0f} %")


def _table_check(v, shares, largest, P, not_observable=(), warnings=None, angle=False) -> None:
    """One verdict, one component (issue 23 item 4): ``verdict.component`` is the component of the effect
    the held-out replay fit named (that fit is what was scored), while the component table
    (``where.components``) splits the equation residuals by their terms.  The two can disagree by the
    measure :func:`_refit_check` uses (the table's largest component holds ``refit_share`` of the gap, the
    verdict's under ``second_share``).  The verdict keeps its component and says why in
    ``verdict.component_table`` {``largest``, ``share``, ``verdict_share``, ``reason``}: an effect its own
    equation residual is blind to (``Effect.fit.screened`` false: dwell stiction and frictional lag act at
    breakaway and reversals, which the top-mass balance leaves out; string damping hides in the
    lower-mass balance's noise) leaves the table to what that equation does see; otherwise the table's
    component may hold a second effect or what the equation split leaks (a parameter_mismatch whose refit
    disagrees has already taken the table's component, :func:`_refit_check`).  A verdict's component that
    is not observable with the log's channels (``not_observable``) has a share of 0 by construction."""
    comp = v.get("component")
    if v["effect"] == "none" or not comp or not _refit_disagrees(comp, shares, largest, P):
        return
    named = v["effect"] not in ("inconclusive", "discovered")
    blind = angle and named and get(v["effect"]).kind == "heave"  # the split has no column for the lever arm
    if comp in not_observable:
        reason = (f"{comp.replace('_', ' ')} is not observable with this log's channels (every equation that carries "
                  "it reads a channel the log does not have): the table cannot show it, the replay fit does")
    elif blind:
        reason = (f"the log carries a vessel angle, and {v['effect']}'s lever arm (L sin(theta)) is in no column of the "
                  f"equation-error split: the table puts what it moves in {largest.replace('_', ' ')} and can neither "
                  "support nor contradict it; the held-out replay fit places the gap in the heave input")
    elif named and not get(v["effect"]).fit.screened:
        reason = (f"the {comp.replace('_', ' ')} equation residual is blind to {v['effect']} (it acts where that "
                  f"equation is left out or hides in its noise); the held-out replay fit places the gap in "
                  f"{comp.replace('_', ' ')}")
    elif named:
        reason = (f"the held-out replay fit of {v['effect']} explains {100 * v.get('explained', 0.0):.0f} % of the gap; "
                  f"the equation error puts {100 * shares[largest]:.0f} % in {largest.replace('_', ' ')}: a second "
                  f"effect there, or what the equation split leaks into it")
    else:
        reason = (f"the best candidate, which explains a real part of the held-out gap, lives in "
                  f"{comp.replace('_', ' ')}; the equation error puts {100 * shares[largest]:.0f} % in "
                  f"{largest.replace('_', ' ')}")
    v["component_table"] = {"largest": largest, "share": float(shares[largest]),
                            "verdict_share": float(shares.get(comp, 0.0)), "reason": reason}
    # the confidence never outruns the evidence (issue 30 item 2): a named verdict the equation-error table
    # does not support is at most low, and says why
    if named and not blind and comp not in not_observable and largest not in _lands_in(v) and v["confidence"] != "low":
        was = v["confidence"]
        v["confidence"] = "low"
        if warnings is not None:
            warnings.append(f"verdict {said(v['effect'])}: its component {comp.replace('_', ' ')} holds "
                            f"{100 * shares.get(comp, 0.0):.0f} % of the equation-error gap, "
                            f"{largest.replace('_', ' ')} {100 * shares[largest]:.0f} % ({reason}) -- confidence "
                            f"lowered from {was} to low")


def _lands_in(v) -> set:
    """The components of the equation residuals the verdict's effect enters by structure
    (:func:`heavecomp.diagnosis.structure.entries`): a stroke misread by an offset lands in the gas law's,
    the lower- and top-mass balances' own laws, never in a ``sensors`` part of its own, so a table that puts
    the gap in the gas spring does not disagree with it."""
    name = v["effect"]
    channel = (v.get("parameters") or {}).get("channel")
    try:
        parts = entries(f"{name}:{channel}" if channel else name)
    except (KeyError, InputError):
        return set()
    return {p.split("/", 1)[1] for p in parts if not p.startswith("replay/")}


def _refit_disagrees(moved, shares, largest, P) -> bool:
    """The parameter_mismatch refit moved a parameter of component ``moved`` most, where the equation
    error sees under ``second_share`` of the gap, while ``largest`` holds ``refit_share`` of it."""
    return bool(largest) and shares[largest] >= P.refit_share and shares.get(moved, 0.0) < P.second_share


def _refit_check(v, shares, largest, P, warnings) -> None:
    """The refit of the nominal's parameters can bend any gap into the nominal's parameters; when the parameter it
    moved most is of a component where the equation error sees (almost) no gap, while another holds
    most of it, the two readings disagree: the gap lives where the equations put it, and the refit is a
    stand-in (confidence low, the component the equation error's).  A mismatch in two components
    agrees with the equations in both."""
    if not _refit_disagrees(v["component"], shares, largest, P):
        return
    moved = v["component"]
    v.update(component=largest, confidence="low", refit_component=moved)
    warnings.append(f"verdict parameter_mismatch: the refit moved a {moved} parameter most, but "
                    f"{100 * shares[largest]:.0f} % of the equation-error gap lies in {largest}; the refit "
                    "may stand in for an unmodelled effect there -- confidence low")


def _remainder_check(v, a, P, warnings) -> None:
    """A ``parameter_mismatch`` verdict says the nominal's structure explains the log once its values are
    changed (issue 30 item 3: no new mechanism).  That claim has a test of its own: what the refit leaves
    held out must pass the test that reads a log ``none`` (its largest held-out rms within ``none_ratio``
    x the input-noise envelope).  Where the refit leaves more, the nominal structure with other values
    does not explain the log: it may stand in for an effect no candidate carries (a hysteretic string
    refitted as a softer string and a weaker seal explained 87 % of its gap, at 2.7 x the noise after),
    so the verdict is at most low and says how far it is from ``none`` (``remainder_to_input_envelope``).
    A named mechanism makes no such claim (its law may carry only part of the effect) and keeps its
    confidence; the ratio is reported for every named verdict."""
    if v["effect"] in ("none", "inconclusive"):
        return
    v["remainder_to_input_envelope"] = a.remainder_ratio
    if v["effect"] != "parameter_mismatch" or v["confidence"] == "low" or a.remainder_ratio <= P.none_ratio:
        return
    was = v["confidence"]
    v["confidence"] = "low"
    warnings.append(f"verdict parameter_mismatch: the refit of the nominal's own parameters leaves a held-out gap "
                    f"{a.remainder_ratio:.2f} x the input-noise envelope (a log reads `none` within "
                    f"{P.none_ratio:g} x): the nominal structure with other values does not explain the log, "
                    f"and the refit may stand in for an effect no candidate carries -- confidence lowered from "
                    f"{was} to low")


def _stationarity(v, evidence, warnings) -> None:
    """A parameter mismatch is a *constant* error of the nominal's parameters: its component's
    equation residual keeps its coefficients over the run
    (:meth:`~heavecomp.diagnosis.components.ComponentResiduals.stationarity`).  When they move, the
    refit averages a time-varying effect (a seal that warms and loses a third of its friction over the
    first minutes): confidence low, ``verdict.stationarity`` and a warning say which moved."""
    st = evidence.stationarity(v["component"])
    if st is None:
        return
    v["stationarity"] = st
    if not st["drifting"]:
        return
    was = v["confidence"]
    v["confidence"] = "low"
    moved = ", ".join(f"{c['feature']}: {min(c['value']):.4g} to {max(c['value']):.4g} {c['unit']}"
                      for c in st["coefficients"] if c["feature"] in st["drifting"])
    warnings.append(f"verdict parameter_mismatch: the {v['component']} residual's coefficients move over "
                    f"the run ({moved}; {len(st['windows'])} windows), "
                    f"so the mismatch is not constant; a time-varying effect may be averaged -- "
                    f"confidence lowered from {was} to low")
