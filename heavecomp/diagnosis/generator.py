"""Withheld-effect benchmark: runs generated with an effect the diagnosis does not know.

Each effect is generated with its *truth* law (the generator's own effect classes,
:mod:`heavecomp.diagnosis.truth`, plugged into the plant's hooks), never with the candidate's
equations:

======================  =====================================  ===========================================
effect                  generated with                          fitted with (candidate)
======================  =====================================  ===========================================
friction_lag            Stribeck curve of a lagged speed w     lagged Stribeck excess force E
dwell_stiction          dF (1 - exp(-tau/tau_d))                a tau^beta
pressure_friction       k max(p - p_th, 0), p_th = 0.9 p_0      dC_p |p|
gas_heat_transfer       thermal state, gamma = 1.4, tau_th      n_eff + linear loss c_g v
flow_loss               orifice K v|v|                          laminar R v
string_damping          quadratic drag c_q dv|dv|               linear dashpot c dv
sensor_delay            first-order sensor lag (causal IIR)     pure transport delay
parameter_mismatch      nominal law, 1-2 parameters shifted     6 multipliers refitted
======================  =====================================  ===========================================

Seas are irregular (JONSWAP, random H_s, T_p, seed), the channels get white
measurement noise, and the nominal parameter set varies between runs
(:data:`PARAMETER_SETS`).  Plus runs with no effect and with two effects.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from heavecomp.diagnosis.data import check_run, heave_samples, MeasuredRun
from heavecomp.diagnosis.estimator import GapDiagnoser
from heavecomp.params import paper_a
from heavecomp.simulate import excitation
from heavecomp.diagnosis.truth import TRUTH, truth_composition
from heavecomp.plants.cmc import plant_vectors

NOISE = {"heave": 0.002, "stroke": 0.002, "pressure": 2e3, "wob": 400.0}  #: 1-sigma noise [SI]
CASES = ("none", "friction_lag", "dwell_stiction", "pressure_friction", "gas_heat_transfer", "flow_loss",
         "string_damping", "sensor_delay", "parameter_mismatch")
TWO_EFFECTS = (("dwell_stiction", "flow_loss"), ("friction_lag", "sensor_delay"), ("string_damping", "pressure_friction"))


def parameter_sets():
    """Nominal parameter sets the benchmark cycles through (paper A load case and two variants)."""
    p = paper_a("stribeck")
    return {
        "paper_a": p,
        "soft_formation": p.replace(formation={"stiffness": 4e5}, drill_string={"stiffness": 1.5e6}),
        "light_friction": p.replace(friction={"static_force": 15e3, "coulomb_force": 9e3},
                                    compensator={"gas_stiffness": 60e3}),
    }


PARAMETER_SETS = ("paper_a", "soft_formation", "light_friction")


@dataclasses.dataclass
class TestRun:
    """A generated run: arrays, the nominal parameters to diagnose against, and the truth."""

    t: np.ndarray
    columns: dict
    nominal: object
    truth: dict

    def to_run(self):
        return check_run(self.t, self.columns, params=self.nominal, source=f"generated:{self.truth['label']}")

    def to_csv(self, path):
        cols = ["t", "heave", "stroke", "pressure", "wob"]
        data = np.column_stack([self.t] + [self.columns[c] for c in cols[1:]])
        np.savetxt(path, data, delimiter=",", header=",".join(cols), comments="", fmt="%.10g")
        return path


GAP_MIN = 3.0  #: a planted effect's own gap over the noise floor (largest channel rms ratio, each half of the run) [-]
SECOND_SHARE = (0.3, 0.6)  #: the second effect's own squared gap as a share of the dominant's [-]
MAX_DRAWS = 100  #: seas / effect draws tried before giving up
STICK_MIN = 0.15  #: dwell stiction is planted only where the compensator is stuck this share of the time [-]


def _draw_effect(name, rng, params):
    """Random truth parameters of one effect (its truth law, :mod:`heavecomp.diagnosis.truth`).

    Returns ``(parameters, magnitude, cap)``: ``magnitude`` names the parameter that sets the size of
    the effect (``None``: no size knob, only a redraw changes it) and ``cap`` its largest plausible value.
    ``parameter_mismatch`` holds relative changes ``"table.key": f`` (the magnitude scales every f,
    capped at |f| <= cap).
    """
    if name == "friction_lag":
        return {"lag_time_speed": rng.uniform(0.8, 3.0)}, "lag_time_speed", 8.0
    if name == "dwell_stiction":  # static friction grows by 35-65 % of F_S over a dwell, at most doubles
        fs = params.friction.static_force
        return {"dF": rng.uniform(0.35, 0.65) * fs, "tau_d": rng.uniform(0.5, 2.0)}, "dF", fs
    if name == "pressure_friction":
        return {"k": rng.uniform(0.02, 0.04), "p_th": 0.9 * params.p0}, "k", 0.1
    if name == "gas_heat_transfer":  # nitrogen: gamma is fixed, only tau_th is drawn
        return {"gamma": 1.4, "tau_th": rng.uniform(2.0, 8.0)}, None, None
    if name == "flow_loss":
        return {"K": rng.uniform(1.5e5, 4e5)}, "K", 1e6
    if name == "string_damping":
        return {"c_q": rng.uniform(3e5, 8e5)}, "c_q", 4e6
    if name == "sensor_delay":
        ch = ("wob", "stroke", "pressure")[int(rng.integers(3))]
        return {"channel": ch, "lag_time": rng.uniform(0.3, 1.0)}, "lag_time", 2.0
    if name == "parameter_mismatch":
        keys = ("compensator.gas_stiffness", "friction.coulomb_force", "drill_string.stiffness", "formation.stiffness")
        pick = rng.choice(len(keys), size=2, replace=False)
        return {keys[i]: float(rng.choice([-1, 1]) * rng.uniform(0.3, 0.5)) for i in sorted(pick)}, "*", 0.6
    raise ValueError(name)


def _scaled(desc, magnitude, factor, cap):
    """``desc`` with its magnitude multiplied by ``factor`` (at most ``cap``); (new desc, at the cap?)."""
    out = dict(desc)
    if magnitude == "*":  # parameter_mismatch: every relative change
        for k, f in desc.items():
            out[k] = float(np.sign(f) * min(abs(f) * factor, cap))
        return out, all(abs(f) >= cap for f in out.values())
    out[magnitude] = min(desc[magnitude] * factor, cap)
    return out, out[magnitude] >= cap


def _effect_terms(name, desc, params):
    """(truth effects, extra) of an effect: the truth-law instances at the plant's hooks; extra is
    ("lag", channel, tau) for a sensor lag, ("params", changes) for wrong nominal parameters, else None."""
    if name == "sensor_delay":
        return [], ("lag", desc["channel"], desc["lag_time"])
    if name == "parameter_mismatch":
        ch = {}
        for path, f in desc.items():
            table, key = path.split(".")
            ch.setdefault(table, {})[key] = getattr(getattr(params, table), key) * (1 + f)
        return [], ("params", ch)
    return [TRUTH[name](**desc)], None


def _public(name, desc, params):
    """Truth parameters as recorded: parameter_mismatch as the wrong values the run was generated with."""
    if name != "parameter_mismatch":
        return {k: (float(v) if not isinstance(v, str) else v) for k, v in desc.items()}
    return {path: getattr(getattr(params, path.split(".")[0]), path.split(".")[1]) * (1 + f)
            for path, f in desc.items()}


class _Sea:
    """One drawn sea with its clean truth runs: simulate effect configurations and measure their
    own gap against the noise floor of this run."""

    OUT = ("stroke", "pressure", "wob")

    def __init__(self, nominal, rng, duration, rate):
        from heavecomp.diagnosis.stepper import replay_dt

        self.nominal = nominal
        self.hsig, self.tp = rng.uniform(1.5, 3.0), rng.uniform(9.0, 13.0)
        self.h = h = replay_dt(nominal, rate)
        self.out_every = max(1, int(round(1.0 / (rate * h))))
        self.n_steps = int(math.ceil(duration / h - 1e-9))
        self.phase_seed = int(rng.integers(2**31))
        self.hs = excitation.jonswap(self.hsig, self.tp, 3.3, self.phase_seed, 2 * self.tp, self.n_steps * h, 0.5 * h)
        self.t, self.base, grid = self.sim([], grid=True)
        self.heave_noise = rng.normal(0.0, NOISE["heave"], self.t.size)
        self.mask = self.t >= min(30.0, 0.1 * duration)  # the diagnosis' default settling window
        self.floor = self._floor()
        from heavecomp.diagnosis.stepper import CHANNELS as SC

        stuck = grid[:, SC.index("stuck")] > 0.5
        edges = np.diff(np.r_[0, stuck.astype(int), 0])
        dwell = (np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1)) * (self.t[1] - self.t[0])
        self.stick = {"stuck_share": float(stuck.mean()), "stick_phases": int(dwell.size),
                      "median_dwell": float(np.median(dwell)) if dwell.size else 0.0}

    def sim(self, parts, hs=None, grid=False):
        """Clean channels of the truth model with the effects ``[(name, truth effects, extra), ...]``."""
        from scipy.signal import lfilter

        from heavecomp.diagnosis.stepper import CHANNELS as SC, run_fx

        effects = []
        prm = self.nominal
        post = []
        for _, eff, extra in parts:
            effects += eff
            if extra is not None and extra[0] == "params":
                prm = prm.replace(**extra[1])
            elif extra is not None:
                post.append(extra)
        comp = truth_composition()
        out = run_fx(plant_vectors(prm), comp, comp.ep(effects), self.hs if hs is None else hs, self.h,
                     self.n_steps, self.out_every)
        cols = {c: out[:, SC.index(c)].copy() for c in ("heave",) + self.OUT}
        dt = out[1, 0] - out[0, 0]
        for _, ch, tau in post:  # first-order sensor lag (causal IIR)
            a = math.exp(-dt / tau)
            y = cols[ch]
            cols[ch] = lfilter([1 - a], [1, -a], y - y[0]) + y[0]
        return (out[:, 0].copy(), cols, out) if grid else (out[:, 0].copy(), cols)

    def _floor(self):
        """Noise floor per channel [SI]: the output noise and the residual of the nominal model replayed
        from this run's noisy, filtered heave (what a run with no effect shows to the diagnosis; exact
        stiction makes it well above the sensor noise), in quadrature."""
        run = MeasuredRun(self.t, {"heave": self.base["heave"] + self.heave_noise})
        _, rep = self.sim([], hs=heave_samples(run, self.h, self.n_steps))
        m = self.mask
        return {c: float(math.hypot(NOISE[c], np.sqrt(np.mean((rep[c][m] - self.base[c][m]) ** 2))))
                for c in self.OUT}

    def gap(self, parts):
        """Own gap of a configuration: per channel rms(with - without) / noise floor [-], and the
        largest channel's ratio in the weaker half of the run (an effect that shows in one burst
        only cannot be fitted on one part of the run and checked on the other)."""
        _, cols = self.sim(parts)
        m = self.mask
        mid = 0.5 * (self.t[m][0] + self.t[-1])

        def ratio(k):
            return {c: float(np.sqrt(np.mean((cols[c][k] - self.base[c][k]) ** 2)) / self.floor[c]) for c in self.OUT}

        return ratio(m), min(max(ratio(m & (self.t < mid)).values()), max(ratio(self.t >= mid).values()))


def _energy(g):
    """Squared noise-normalised gap summed over the channels [-]."""
    return float(sum(v * v for v in g.values()))


def _plant(name, rng, sea, nominal, target=None):
    """Draw one effect and size it on ``sea``: alone, its largest channel gap reaches :data:`GAP_MIN`
    in each half of the run (magnitude raised up to its cap); with ``target`` = (dominant energy, share), its squared gap is
    within ``share`` +- 0.05 (inside :data:`SECOND_SHARE`) of the dominant's (bisection on the magnitude).
    A dwell stiction also needs a sea in which the compensator is stuck at least :data:`STICK_MIN` of
    the time.  Returns (desc, part, gap per channel) or None when this sea cannot carry the effect."""
    desc, mag, cap = _draw_effect(name, rng, nominal)
    if name == "dwell_stiction" and sea.stick["stuck_share"] < STICK_MIN:
        return None  # a dwell effect needs time at rest: redraw the sea

    def measure(d):
        eff, extra = _effect_terms(name, d, nominal)
        part = (name, eff, extra)
        return (part,) + sea.gap([part])

    part, g, weak = measure(desc)
    if target is None:
        for _ in range(8):
            if weak >= GAP_MIN:
                return desc, part, g
            if mag is None:
                return None
            desc, capped = _scaled(desc, mag, float(np.clip(1.2 * GAP_MIN / max(weak, 1e-3), 1.25, 4.0)), cap)
            part, g, weak = measure(desc)
            if capped:
                return (desc, part, g) if weak >= GAP_MIN else None
        return None
    e_dom, share = target
    lo_s, hi_s = max(SECOND_SHARE[0], share - 0.05), min(SECOND_SHARE[1], share + 0.05)
    if mag is None:
        return (desc, part, g) if lo_s <= _energy(g) / e_dom <= hi_s else None
    f, f_lo, f_hi, d, capped = 0.0, None, None, desc, False  # log factor on the magnitude and its bracket
    for _ in range(20):
        s = _energy(g) / e_dom
        if lo_s <= s <= hi_s:
            return d, part, g
        if s < lo_s and capped:
            return None
        if s < lo_s:
            f_lo = f
        else:
            f_hi = f
        f = 0.5 * (f_lo + f_hi) if f_lo is not None and f_hi is not None else f + (1.5 if f_hi is None else -1.5)
        d, capped = _scaled(desc, mag, math.exp(f), cap)
        part, g, _ = measure(d)
    return None


def generate(effects, *, seed=0, duration=300.0, rate=50.0, param_set="paper_a", jitter=False, dropouts=False):
    """One withheld-effect run, every effect planted at a detectable strength.

    Each effect is drawn with its truth law and sized on the drawn sea: alone it must move at least
    one channel by :data:`GAP_MIN` x the noise floor in each half of the run (rms of with-minus-without
    the effect over the floor: output noise plus the residual of the nominal model replayed from this
    run's noisy, filtered heave).  Its magnitude is raised (up to a plausible cap) until it does; if it cannot,
    the sea and the effect are redrawn.  A dwell stiction is only planted in a sea where the
    compensator is stuck at least :data:`STICK_MIN` of the time (else it is invisible).  In a two-effect run the second effect is sized so that its own squared gap is a
    share of :data:`SECOND_SHARE` of the first's (the first, dominant one, is ``effects[0]``).

    Parameters
    ----------
    effects : str or tuple of str
        Case label(s) from :data:`CASES`, dominant first.
    seed : int
        Seeds the sea, the effect size and the noise.
    duration : float [s]
    rate : float [Hz]
    param_set : str
        Key of :func:`parameter_sets` — the nominal the diagnosis is given.
    jitter, dropouts : bool
        Non-uniform sampling / NaN dropouts (to exercise the loader).

    ``truth`` holds the effects (dominant first), their parameters, the sea, the noise floor per
    channel, each effect's own gap per channel (``gap_channels``) and its largest (``gap_to_noise``),
    the squared gaps (``gap_alone``), the second effect's share, the stick statistics of the
    no-effect run and how many seas were drawn.
    """
    effects = (effects,) if isinstance(effects, str) else tuple(effects)
    effects = tuple(e for e in effects if e != "none") or ("none",)
    rng = np.random.default_rng(seed)
    nominal = parameter_sets()[param_set]
    for draw in range(1, MAX_DRAWS + 1):
        sea = _Sea(nominal, rng, duration, rate)
        planted = []
        target = None
        for e in effects if effects != ("none",) else ():
            if target is not None:
                target = (target[0], float(rng.uniform(*SECOND_SHARE)))
            got = _plant(e, rng, sea, nominal, target)
            if got is None:
                break
            planted.append((e,) + got)
            target = (_energy(got[2]), None)
        else:
            break
    else:
        raise RuntimeError(f"no sea of {MAX_DRAWS} carries {'+'.join(effects)} at {GAP_MIN} x the noise floor")
    truth = {"effects": list(effects), "label": "+".join(effects), "param_set": param_set, "seed": seed,
             "parameters": {e: _public(e, d, nominal) for e, d, _, _ in planted},
             "sea": {"hs": sea.hsig, "tp": sea.tp, "phase_seed": sea.phase_seed}, "draws": draw, "noise_floor": sea.floor,
             "gap_channels": {e: g for e, _, _, g in planted},
             "gap_to_noise": {e: max(g.values()) for e, _, _, g in planted},
             "gap_alone": {e: _energy(g) for e, _, _, g in planted}, "stick": sea.stick}
    if len(planted) > 1:
        truth["second_share"] = truth["gap_alone"][effects[1]] / truth["gap_alone"][effects[0]]
    t, cols = sea.sim([p for _, _, p, _ in planted])
    cols["heave"] = cols["heave"] + sea.heave_noise
    for c in sea.OUT:
        cols[c] = cols[c] + rng.normal(0.0, NOISE[c], t.size)
    if jitter:
        tj = t + rng.uniform(-0.3, 0.3, t.size) * (t[1] - t[0])
        tj[0] = 0.0
        cols = {c: np.interp(tj, t, y) for c, y in cols.items()}
        t = tj
    if dropouts:
        for c in ("heave", "wob", "pressure"):
            i = int(rng.integers(100, t.size - 100))
            cols[c][i:i + int(rng.integers(3, 20))] = np.nan
    return TestRun(t=t, columns=cols, nominal=nominal, truth=truth)


def benchmark_cases(quick=False, seed0=1000):
    """(effects, seed, param_set) for the benchmark: every case on two of the parameter sets, plus
    two-effect runs (dominant first); seeds from ``seed0`` (the report uses 1000; others check that
    a change to the diagnosis holds beyond the reported runs).

    The sets rotate so each case meets two different ones; the offset puts the dwell-stiction runs
    on ``paper_a`` and ``soft_formation``: with the light seal of ``light_friction`` the compensator
    is rarely stuck :data:`STICK_MIN` of the time in these seas, so a dwell effect has nothing to act on.
    """
    if quick:
        return [(("none",), 100, "paper_a"), (("dwell_stiction",), 101, "soft_formation"),
                (("flow_loss",), 102, "light_friction")]
    cases = []
    k = 0
    for rep in range(2):
        for i, e in enumerate(CASES):
            cases.append(((e,), seed0 + k, PARAMETER_SETS[(i + rep + 1) % 3]))
            k += 1
    for j, pair in enumerate(TWO_EFFECTS):
        cases.append((pair, seed0 + k, PARAMETER_SETS[j % 3]))
        k += 1
    return cases


def run_benchmark(quick=False, duration=None, progress=None, n_jobs=2, max_nfev=None, seed0=1000):
    """Diagnose every benchmark case; returns rows and the summary (confusion matrix, shrink table)."""
    duration = duration or (120.0 if quick else 300.0)
    rows = []
    cases = benchmark_cases(quick, seed0)
    for i, (effects, seed, pset) in enumerate(cases):
        tr = generate(effects, seed=seed, duration=duration, param_set=pset)
        kw = {} if max_nfev is None else {"max_nfev": max_nfev}
        d = GapDiagnoser(tr.nominal, n_jobs=n_jobs, **kw).fit(tr.to_run())
        v = d.verdict_
        second = (v.get("second_effect") or {}).get("effect")
        effects = tuple(tr.truth["effects"])  # dominant first
        row = {"truth": effects[0], "truth_second": effects[1] if len(effects) > 1 else None,
               "param_set": pset, "seed": seed, "verdict": v["effect"], "confidence": v["confidence"],
               "second_effect": second, "shrink": v["shrink"], "explained": v.get("explained"),
               "gap_to_noise": v.get("gap_to_noise"), "wall_time": d.wall_time_,
               "gap_to_input_envelope": v.get("gap_to_input_envelope"),
               "truth_parameters": tr.truth["parameters"], "fitted_parameters": v.get("parameters"),
               "planted_gap": tr.truth["gap_to_noise"], "second_share": tr.truth.get("second_share"),
               "second_tried": [s["effect"] for s in d.second_tried_],
               "best_partner": max(d.second_tried_, key=lambda s: s["added_explained"])["effect"] if d.second_tried_ else None,
               "stuck_share": tr.truth["stick"]["stuck_share"], "sea": tr.truth["sea"]}
        row["correct"] = row["verdict"] == row["truth"]
        rows.append(row)
        if progress:
            progress((i + 1) / len(cases), f"{'+'.join(effects)} -> {v['effect']} ({v['confidence']}), "
                                           f"shrink {v['shrink']:.2f}")
    return rows, summarize(rows)


def summarize(rows):
    labels = list(CASES) + ["inconclusive"]
    truths = [l for l in CASES if any(r["truth"] == l for r in rows)]
    cm = {tl: {vl: 0 for vl in labels} for tl in truths}
    for r in rows:
        cm[r["truth"]][r["verdict"] if r["verdict"] in labels else "inconclusive"] += 1
    eff = [r for r in rows if r["truth"] != "none" and r["correct"]]
    shr = [r["shrink"] for r in rows if r["truth"] != "none"]
    two = [r for r in rows if r["truth_second"]]
    return {"n_runs": len(rows), "accuracy": float(np.mean([r["correct"] for r in rows])),
            "confusion": cm,
            "median_shrink_all_effect_runs": float(np.median(shr)) if shr else None,
            "median_shrink_correct": float(np.median([r["shrink"] for r in eff])) if eff else None,
            "two_effect_second_named": sum(r["second_effect"] == r["truth_second"] for r in two),
            "n_two_effect": len(two),
            "two_effect_second_tried": sum(r["truth_second"] in r["second_tried"] for r in two),
            "two_effect_second_best_partner": sum(r["truth_second"] == r["best_partner"] for r in two),
            "spurious_second": sum(r["second_effect"] is not None for r in rows if not r["truth_second"]),
            "n_single": sum(not r["truth_second"] for r in rows),
            "min_planted_gap": min((g for r in rows for g in r["planted_gap"].values()), default=None),
            "median_wall_time": float(np.median([r["wall_time"] for r in rows]))}
