"""Withheld-effect benchmark: runs generated with an effect the diagnosis does not know.

Each effect is generated with its *truth* law (``truth_*`` terms of
:mod:`heavecomp.effects.terms`), never with the candidate's equations:

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

from heavecomp.effects import terms as T

NOISE = {"heave": 0.002, "stroke": 0.002, "pressure": 2e3, "wob": 400.0}  #: 1-sigma noise [SI]
CASES = ("none", "friction_lag", "dwell_stiction", "pressure_friction", "gas_heat_transfer", "flow_loss",
         "string_damping", "sensor_delay", "parameter_mismatch")
TWO_EFFECTS = (("dwell_stiction", "flow_loss"), ("friction_lag", "sensor_delay"), ("string_damping", "pressure_friction"))


def parameter_sets():
    """Nominal parameter sets the benchmark cycles through (paper A load case and two variants)."""
    from heavecomp.params import paper_a

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
        from heavecomp.diagnosis.data import check_run

        return check_run(self.t, self.columns, params=self.nominal, source=f"generated:{self.truth['label']}")

    def to_csv(self, path):
        cols = ["t", "heave", "stroke", "pressure", "wob"]
        data = np.column_stack([self.t] + [self.columns[c] for c in cols[1:]])
        np.savetxt(path, data, delimiter=",", header=",".join(cols), comments="", fmt="%.10g")
        return path


def _truth_effect(name, rng, params, EP):
    """Write a random truth effect into EP; returns (description, extra) with extra for output/nominal effects."""
    p0 = params.p0
    if name == "friction_lag":
        EP[T.LAG_T_TRUTH] = rng.uniform(0.8, 3.0)
        return {"lag_time_speed": EP[T.LAG_T_TRUTH]}, None
    if name == "dwell_stiction":
        EP[T.DWELL_DF_TRUTH] = rng.uniform(8e3, 15e3)
        EP[T.DWELL_TAU_TRUTH] = rng.uniform(0.5, 2.0)
        return {"dF": EP[T.DWELL_DF_TRUTH], "tau_d": EP[T.DWELL_TAU_TRUTH]}, None
    if name == "pressure_friction":
        EP[T.PF_K_TRUTH] = rng.uniform(0.02, 0.04)
        EP[T.PF_PTH_TRUTH] = 0.9 * p0
        return {"k": EP[T.PF_K_TRUTH], "p_th": EP[T.PF_PTH_TRUTH]}, None
    if name == "gas_heat_transfer":
        EP[T.TH_GAMMA_TRUTH] = 1.4
        EP[T.TH_TAU_TRUTH] = rng.uniform(2.0, 8.0)
        return {"gamma": 1.4, "tau_th": EP[T.TH_TAU_TRUTH]}, None
    if name == "flow_loss":
        EP[T.FLOW_K_TRUTH] = rng.uniform(1.5e5, 4e5)
        return {"K": EP[T.FLOW_K_TRUTH]}, None
    if name == "string_damping":
        EP[T.SD_CQ_TRUTH] = rng.uniform(3e5, 8e5)
        return {"c_q": EP[T.SD_CQ_TRUTH]}, None
    if name == "sensor_delay":
        ch = ("wob", "stroke", "pressure")[int(rng.integers(3))]
        tau = rng.uniform(0.3, 1.0)
        return {"channel": ch, "lag_time": tau}, ("lag", ch, tau)
    if name == "parameter_mismatch":
        keys = [("compensator", "gas_stiffness"), ("friction", "coulomb_force"), ("drill_string", "stiffness"),
                ("formation", "stiffness")]
        pick = rng.choice(len(keys), size=2, replace=False)
        ch, desc = {}, {}
        for i in pick:
            table, key = keys[i]
            f = float(rng.choice([-1, 1]) * rng.uniform(0.3, 0.5))
            base = getattr(getattr(params, table), key)
            ch.setdefault(table, {})[key] = base * (1 + f)
            desc[f"{table}.{key}"] = base * (1 + f)
        return desc, ("params", ch)
    if name == "none":
        return {}, None
    raise ValueError(name)


def generate(effects, *, seed=0, duration=300.0, rate=50.0, param_set="paper_a", jitter=False, dropouts=False):
    """One withheld-effect run.

    Parameters
    ----------
    effects : str or tuple of str
        Case label(s) from :data:`CASES`.  With two, ``truth["effects"]`` is reordered so the
        dominant one (larger noise-normalised gap when generated alone) comes first.
    seed : int
        Seeds the sea, the effect size and the noise.
    duration : float [s]
    rate : float [Hz]
    param_set : str
        Key of :func:`parameter_sets` — the nominal the diagnosis is given.
    jitter, dropouts : bool
        Non-uniform sampling / NaN dropouts (to exercise the loader).
    """
    from heavecomp.diagnosis.stepper import CHANNELS as SC, run_fx
    from heavecomp.diagnosis.estimator import _vectors
    from heavecomp.simulate import excitation
    from heavecomp.diagnosis.stepper import replay_dt

    effects = (effects,) if isinstance(effects, str) else tuple(effects)
    rng = np.random.default_rng(seed)
    nominal = parameter_sets()[param_set]
    truth = {"effects": list(effects), "label": "+".join(effects), "param_set": param_set, "seed": seed,
             "parameters": {}}
    parts = []
    for e in effects:
        EPe = T.zero_ep()
        desc, extra = _truth_effect(e, rng, nominal, EPe)
        truth["parameters"][e] = desc
        parts.append((e, EPe, extra))
    hsig, tp = rng.uniform(1.5, 3.0), rng.uniform(9.0, 13.0)
    truth["sea"] = {"hs": hsig, "tp": tp}
    h = replay_dt(nominal, rate)
    out_every = max(1, int(round(1.0 / (rate * h))))
    n_steps = int(math.ceil(duration / h - 1e-9))
    hs = excitation.jonswap(hsig, tp, 3.3, int(rng.integers(2**31)), 2 * tp, n_steps * h, 0.5 * h)

    def sim(sel):
        EPs = T.zero_ep()
        prm = nominal
        post = []
        for e, EPe, extra in sel:
            EPs += EPe
            if extra is not None and extra[0] == "params":
                prm = prm.replace(**extra[1])
            elif extra is not None:
                post.append(extra)
        code, FP, PP = _vectors(prm)
        out = run_fx(code, FP, PP, EPs, hs, h, n_steps, out_every)
        cols = {c: out[:, SC.index(c)].copy() for c in ("heave", "stroke", "pressure", "wob")}
        dt = out[1, 0] - out[0, 0]
        for kind, ch, tau in post:  # first-order sensor lag (causal IIR)
            from scipy.signal import lfilter

            a = math.exp(-dt / tau)
            y = cols[ch]
            cols[ch] = lfilter([1 - a], [1, -a], y - y[0]) + y[0]
        return out[:, 0].copy(), cols

    t, cols = sim(parts)
    if len(parts) > 1:  # which effect dominates: the larger noise-normalised gap on its own
        _, base = sim([])
        gaps = {}
        for part in parts:
            _, alone = sim([part])
            gaps[part[0]] = float(sum(np.mean((alone[c] - base[c]) ** 2) / NOISE[c] ** 2
                                      for c in ("stroke", "pressure", "wob")))
        truth["gap_alone"] = gaps
        truth["effects"] = sorted(gaps, key=lambda e: -gaps[e])
    for c, s in NOISE.items():
        cols[c] = cols[c] + rng.normal(0.0, s, t.size)
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


def benchmark_cases(quick=False):
    """(effects, seed, param_set) for the benchmark: every case on several parameter sets, plus two-effect runs."""
    cases = []
    if quick:
        for i, e in enumerate(("none", "dwell_stiction", "flow_loss")):
            cases.append(((e,), 100 + i, PARAMETER_SETS[i % 3]))
        return cases
    k = 0
    for rep in range(2):
        for e in CASES:
            cases.append(((e,), 1000 + k, PARAMETER_SETS[k % 3]))
            k += 1
    for pair in TWO_EFFECTS:
        cases.append((pair, 1000 + k, PARAMETER_SETS[k % 3]))
        k += 1
    return cases


def run_benchmark(quick=False, duration=None, progress=None, n_jobs=2, max_nfev=None):
    """Diagnose every benchmark case; returns rows and the summary (confusion matrix, shrink table)."""
    from heavecomp.diagnosis.estimator import GapDiagnoser

    duration = duration or (120.0 if quick else 300.0)
    rows = []
    cases = benchmark_cases(quick)
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
               "truth_parameters": tr.truth["parameters"], "fitted_parameters": v.get("parameters"),
               "sea": tr.truth["sea"]}
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
            "median_wall_time": float(np.median([r["wall_time"] for r in rows]))}
