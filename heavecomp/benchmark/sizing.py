"""Planting one truth law on a drawn sea at a detectable (or near-noise, or second-effect) size."""

from __future__ import annotations

import math

import numpy as np

GAP_MIN = 3.0  #: a planted effect's own gap over the noise floor (largest channel rms ratio, each half of the run) [-]
SECOND_SHARE = (0.3, 0.6)  #: the second effect's own squared gap as a share of the dominant's [-]
NEAR_NOISE = (1.2, 2.0)  #: near-noise runs: the effect's largest channel gap over the floor [-]


def energy(g):
    """Squared noise-normalised gap summed over the channels [-].

    Parameters
    ----------
    g : dict
        Channel -> the effect's own gap over the noise floor (rms ratio) [-].

    Returns
    -------
    float [-]
    """
    return float(sum(v * v for v in g.values()))


def plant(law, rng, bed, setting, target=None, near=None):
    """Draw one truth law and size it on the testbed ``bed``.

    Alone, its largest channel gap reaches :data:`GAP_MIN` in each half of the run (its magnitude
    raised up to its cap); with ``target`` = (dominant energy, share), its squared gap is within
    ``share`` +- 0.05 (inside :data:`SECOND_SHARE`) of the dominant's (bisection on the magnitude);
    with ``near`` = (lo, hi), its largest channel gap over the whole run is lo..hi x the noise floor.
    A law with ``min_stuck_share`` (dwell stiction) also needs a sea in which the compensator is
    stuck at least that share of the time.

    Parameters
    ----------
    law : heavecomp.benchmark.truth.TruthLaw
    rng : numpy.random.Generator
        The case's stream (draws the law; the share of a second effect is drawn by the caller).
    bed : heavecomp.benchmark.testbed.Testbed
    setting : heavecomp.benchmark.truth.Setting
    target : (float, float) or None
        (the dominant's :func:`energy`, share [-]) for a second effect.
    near : (float, float) or None
        The near-noise band [-].

    Returns
    -------
    (Draw, Part, dict) or None
        The sized draw, what is planted, and its gap per channel [-]; None when this sea cannot carry it.
    """
    drawn = law.draw(rng, setting)
    if bed.stick["stuck_share"] < law.min_stuck_share:
        return None  # a dwell effect needs time at rest: redraw the sea

    def measure(d):
        part = law.part(d.parameters, setting.nominal)
        return (part,) + bed.gap([part])

    d = drawn
    part, g, weak = measure(d)
    if near is not None:  # near the noise floor: scale the magnitude down (or up) into the band
        for _ in range(10):
            big = max(g.values())
            if near[0] <= big <= near[1]:
                return d, part, g
            if d.magnitude is None:
                return None
            d, capped = d.scaled(float(np.clip(0.5 * (near[0] + near[1]) / max(big, 1e-3), 0.05, 4.0)))
            part, g, weak = measure(d)
            if capped and max(g.values()) < near[0]:
                return None
        return None
    if target is None:
        for _ in range(8):
            if weak >= GAP_MIN:
                return d, part, g
            if d.magnitude is None:
                return None
            d, capped = d.scaled(float(np.clip(1.2 * GAP_MIN / max(weak, 1e-3), 1.25, 4.0)))
            part, g, weak = measure(d)
            if capped:
                return (d, part, g) if weak >= GAP_MIN else None
        return None
    e_dom, share = target
    lo_s, hi_s = max(SECOND_SHARE[0], share - 0.05), min(SECOND_SHARE[1], share + 0.05)
    if drawn.magnitude is None:
        return (d, part, g) if lo_s <= energy(g) / e_dom <= hi_s else None
    f, f_lo, f_hi, capped = 0.0, None, None, False  # log factor on the magnitude and its bracket
    for _ in range(20):
        s = energy(g) / e_dom
        if lo_s <= s <= hi_s:
            return d, part, g
        if s < lo_s and capped:
            return None
        if s < lo_s:
            f_lo = f
        else:
            f_hi = f
        f = 0.5 * (f_lo + f_hi) if f_lo is not None and f_hi is not None else f + (1.5 if f_hi is None else -1.5)
        d, capped = drawn.scaled(math.exp(f))
        part, g, _ = measure(d)
    return None
