"""Long generated logs with changes part-way through, for validating the monitor (issue 23 item 2).

A log of one sea (JONSWAP or the shipped Waverider buoy record through a vessel response) in which
conditions step at given times: a new WOB set-point (an operating change), a softer or stiffer
formation, the onset of a seal-friction effect, a gas leak, a WOB channel that starts to misread.
Effects use the benchmark's *truth* laws (:mod:`heavecomp.benchmark.truth`, never the candidates'
equations) and are sized like its near-noise runs: alone, over the whole log, the effect's largest
channel gap is ``size`` x the noise floor (:func:`heavecomp.benchmark.sizing.plant` with ``near``).

A plant law that is the first change is switched on at its time with the state carried on (one
continuous run, :func:`_onset`: a leak starts from the full charge).  Any other configuration (the
conditions after each change, cumulative) is simulated over the whole log from the same heave and
spliced in at its change time with a raised-cosine blend of :data:`BLEND` seconds (:data:`BLEND_OP`
for a set-point change: a driller turns the set-point over a minute); the blend is not a simulation
of the transition: the states of two runs are mixed over a few seconds.

Each change records when it is at the asked size (``t_reference``, the monitor's delay is scored
from it): a step at its time; a change that grows from nothing (:data:`GROWS`, a leak) when its
own gap, the clean channels with it less those without it on the same sea, first reaches ``size``
x the noise floor over one block (:func:`size_reached`), which may be never within the log.
"""

from __future__ import annotations

import numpy as np

from heavecomp.benchmark.case import MAX_DRAWS, parameter_sets
from heavecomp.benchmark.generate import TestRun
from heavecomp.benchmark.sizing import plant
from heavecomp.benchmark.testbed import Testbed
from heavecomp.benchmark.truth import LAWS, Part, Setting, truth_composition, TruthLaw
from heavecomp.benchmark.truth.base import Draw
from heavecomp.diagnosis.stepper import CHANNELS as SC, run_segments
from heavecomp.plants.cmc import plant_vectors

BLEND = 20.0  #: s over which two configurations are blended at an effect change (raised cosine)
BLEND_OP = 60.0  #: s over which a set-point change is blended
BLEND_HARD = 5.0  #: s over which a hardening formation stiffens (the maintainers' held-back set, issue 30)
#: change label -> the component whose residual it should move (monitor.json ``component``)
COMPONENT = {"operating": "operating_point", "formation": "string_formation", "pressure_friction": "friction",
             "position_friction": "friction", "gas_leak": "gas_spring", "sensor_gain": "sensors",
             "hardening": "string_formation"}
LABELS = tuple(COMPONENT)
LEAD = 120.0  #: s simulated before the log starts (cut: the log starts mid-operation, not at rest) [s]
NEAR = 0.1  #: the planted size is within +- this share of the asked one [-]
SIZE_WINDOW = 10.0  #: trailing window of a change's own rms when it reaches its asked size: one monitor block [s]
#: changes whose own gap grows from nothing after their time (a leak loses gas from the full charge): they
#: reach the asked size when their one-block rms does (:func:`size_reached`); every other change is planted
#: at its sized strength from its time (a step), so it is at the asked size at its time
GROWS = ("gas_leak",)


def _formation_draw(rng, setting):
    """A softer formation: its stiffness 20-40 % lower; the size knob is the drop, at most 80 %."""
    return Draw({"drop": float(rng.uniform(0.2, 0.4))}, "drop", 0.8)


#: the formation change as a truth law: wrong nominal parameters (the formation's stiffness) from its time on
FORMATION = TruthLaw("formation", "string_formation", _formation_draw,
                     changes=lambda d, nominal: {"formation": {"stiffness": nominal.formation.stiffness
                                                               * (1.0 - d["drop"])}})


def _hardening_draw(rng, setting):
    """A harder formation: its stiffness 80-120 % higher (doubled, issue 30); the size knob is the rise, at
    most x5."""
    return Draw({"rise": float(rng.uniform(0.8, 1.2))}, "rise", 4.0)


#: a formation that hardens part-way (the bit enters a harder layer): its stiffness raised from its time on
HARDENING = TruthLaw("hardening", "string_formation", _hardening_draw,
                     changes=lambda d, nominal: {"formation": {"stiffness": nominal.formation.stiffness
                                                               * (1.0 + d["rise"])}})


def _law(label):
    """The truth law of a change label (the variant of ``sensor_gain``: the WOB channel)."""
    return {"formation": FORMATION, "hardening": HARDENING}.get(label) or LAWS[label]


def long_log(changes, *, seed=0, duration=3600.0, rate=10.0, sea="jonswap", params="paper_a", size=5.0):
    """A generated log with ``changes`` = [(t [s], label), ...] (labels :data:`LABELS`).

    Returns a :class:`heavecomp.benchmark.TestRun`; ``truth["changes"]`` lists each change's
    ``t``, ``label``, ``component``, parameters and its own gap per channel (over the noise floor);
    ``t_size`` and ``size_blocks`` (:func:`size_reached`: when its own gap's one-block rms first
    reaches ``size``, and that rms block by block from its time) and ``t_reference``, when it is at the
    asked size: its time for a step, ``t_size`` for a change that grows (:data:`GROWS`; None when it
    stays below the size for the whole log). The monitor's detection delay is scored from it.

    Parameters
    ----------
    changes : list of (float, str)
        (time [s, log time], label of :data:`LABELS`) of each change.
    seed : int
        Seeds the sea, the changes' draws and sizes, and the noise.
    duration : float [s]
        Length of the log.
    rate : float [Hz]
        Logging rate.
    sea : str
        Kind of sea (:func:`heavecomp.benchmark.make_sea`).
    params : str
        Nominal parameter set (:func:`heavecomp.benchmark.parameter_sets`).
    size : float [-]
        Each effect's own largest channel gap over the noise floor, alone over the whole log.
    """
    rng = np.random.default_rng(seed)
    nominal = parameter_sets()[params]
    changes = [(float(tc) + LEAD, label) for tc, label in changes]  # on the simulation's clock
    for _ in range(MAX_DRAWS["validation"]):
        s = Testbed(nominal, rng, duration + LEAD, rate, sea, 1.0)
        parts, info = [], []
        ok = True
        for tc, label in sorted(changes):
            if label == "operating":
                w0 = nominal.operating_point.wob_setpoint
                f = float(rng.choice([-1, 1]) * rng.uniform(0.1, 0.2))
                part = Part("operating", changes={"operating_point": {"wob_setpoint": w0 * (1 + f)}})
                parts.append(part)
                info.append({"t": float(tc) - LEAD, "label": label, "component": COMPONENT[label],
                             "parameters": {"wob_setpoint": w0 * (1 + f)}})
                continue
            setting = Setting(nominal, duration + LEAD, "wob" if label == "sensor_gain" else None, s.base)
            got = plant(_law(label), rng, s, setting, near=(size * (1 - NEAR), size * (1 + NEAR)))
            if got is None:
                ok = False
                break
            drawn, part, gap = got
            parts.append(part)
            info.append({"t": float(tc) - LEAD, "label": label, "component": COMPONENT[label],
                         "parameters": {k: (v if isinstance(v, str) else float(v)) for k, v in drawn.parameters.items()},
                         "gap_channels": gap, "gap_to_noise": max(gap.values())})
        if ok:
            break
    else:
        raise RuntimeError(f"no sea of {MAX_DRAWS['validation']} carries {changes} at {size} x the noise floor")
    t = s.t
    cols = dict(s.base)
    for k, (tc, label) in enumerate(sorted(changes)):
        before = dict(cols)
        eff = parts[k].effects
        if eff and k == 0:  # a plant truth law: switched on at tc, the state carried on (no blend)
            cols = _onset(s, nominal, eff, tc)
        else:
            _, cfg = s.sim(parts[:k + 1])  # parameter changes apply on top of each other
            width = {"operating": BLEND_OP, "hardening": BLEND_HARD}.get(label, BLEND)
            w = 0.5 - 0.5 * np.cos(np.pi * np.clip((t - tc) / width, 0.0, 1.0))  # smooth: no kink in a
            cols = dict(cols)
            for c in s.OUT:
                cols[c] = (1 - w) * cols[c] + w * cfg[c]
        if label != "operating":  # when the change's own gap reaches the asked size (same sea, same floor)
            info[k].update(size_reached(t, {c: cols[c] - before[c] for c in s.OUT}, s.floor, tc, size, LEAD))
        info[k]["t_reference"] = info[k].get("t_size") if label in GROWS else info[k]["t"]
    cols["heave"] = s.base["heave"] + s.heave_noise
    cols = {c: np.asarray(y, float) for c, y in cols.items()}
    for c in s.OUT:
        cols[c] = cols[c] + rng.normal(0.0, s.noise[c], t.size)
    truth = {"label": "+".join(lab for _, lab in sorted(changes)) or "none", "changes": info, "seed": seed,
             "sea": s.info, "rate": rate, "duration": duration, "param_set": params, "noise_floor": s.floor,
             "size": size}
    return TestRun(t=t, columns=cols, nominal=nominal, truth=truth).cropped(LEAD)


def size_reached(t, diff, floor, tc, size, lead=0.0, window=SIZE_WINDOW):
    """When a change's own gap reaches ``size`` x the noise floor.

    The change's own gap is its effect alone on the same sea: the clean channels with the change less
    the clean channels without it. Its size at time t is the largest channel's rms over the trailing
    ``window`` (the sizing's rms, :meth:`heavecomp.benchmark.testbed.Testbed.gap`, over one monitor
    block instead of the whole log) over the channel's noise floor. A step reaches its size when it
    is planted (up to the blend); an effect that grows from nothing (a leak from the full charge)
    reaches it later, or never within the log.

    Parameters
    ----------
    t : ndarray [s]
        Simulation clock.
    diff : dict
        Channel -> the change's own gap [SI] on ``t``.
    floor : dict
        Channel -> noise floor [SI].
    tc : float [s]
        The change's time on ``t``.
    size : float [-]
        The asked size (x the noise floor).
    lead : float [s]
        Offset of the log's clock from ``t`` (the log starts at ``lead``).
    window : float [s]
        Trailing rms window.

    Returns
    -------
    dict
        ``t_size`` [s, log time, or None: never within the log], ``size_blocks`` (the own gap's
        largest-channel rms [-] over consecutive ``window`` blocks from the change on) and
        ``size_window`` [s].
    """
    dt = float(t[1] - t[0])
    n = max(1, int(round(window / dt)))
    ratio = None
    for c, d in diff.items():
        c2 = np.concatenate([[0.0], np.cumsum((np.asarray(d, float) / floor[c]) ** 2)])
        run = np.sqrt(np.maximum(c2[n:] - c2[:-n], 0.0) / n)  # trailing rms ending at sample i + n - 1
        ratio = run if ratio is None else np.maximum(ratio, run)
    ends = t[n - 1:]
    k = np.flatnonzero((ends >= tc) & (ratio >= size))
    t_size = float(ends[k[0]]) - lead if k.size else None
    blocks = [round(float(ratio[i]), 3) for i in range(int(np.searchsorted(ends, tc)) + n - 1, ratio.size, n)]
    return {"t_size": t_size, "size_blocks": blocks, "size_window": float(window)}


def _onset(sea, nominal, effects, tc):
    """Clean channels of the nominal plant until ``tc`` and of the plant with the truth laws ``effects``
    from there, one continuous run: the second part starts from the state the first reached
    (:func:`heavecomp.diagnosis.stepper.run_segments`; the effects' own states from their initial
    values: a leak starts with the full charge)."""
    comp = truth_composition(effects[0].name)
    pv = plant_vectors(nominal)
    h, n = sea.h, sea.n_steps
    ic = int(round(tc / h))
    off = run_segments(pv, comp, comp.ep([]), sea.hs, h, [(0, ic + 1)], [None], ic + 2)
    r = off[ic]
    start = (r[SC.index("stroke")], r[SC.index("stroke_velocity")], r[SC.index("lower_displacement")],
             r[SC.index("lower_velocity")], bool(r[SC.index("stuck")] > 0.5))
    on = run_segments(pv, comp, comp.ep(effects), sea.hs, h, [(ic, n)], [start], n + 1)
    on[:ic] = off[:ic]
    grid = on[::sea.out_every][:sea.t.size]
    return {c: grid[:, SC.index(c)].copy() for c in ("heave",) + sea.OUT}
