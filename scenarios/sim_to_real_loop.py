"""From a verdict to a better controller: diagnose a plant the controller does not know, calibrate, re-analyse, re-design the MPC.

For each withheld effect (a seal friction with stiction, a gas effect, a string effect and a WOB sensor
fault) the benchmark's truth plant (the generator's own truth law, never the candidate's equation the
diagnosis fits) is run passively and logged as the generator logs it; the gap diagnosis names an effect
and fits it; the calibrated model is the nominal plus what the verdict found; the frequency analysis
compares the nominal and the calibrated model; and the linear MPC, designed on (i) the nominal model,
(ii) the calibrated model (``calibrated.toml``, :func:`heavecomp.diagnosis.calibrate.from_log`, as ``diagnose`` writes it) and (iii) the true model, runs on the truth plant in the same irregular sea
with the same measurement noise.  ``recovered`` = (std_nominal - std_calibrated) / (std_nominal -
std_true): the share of the WOB-std difference between the nominal and the true-model controller that
the calibrated controller wins back (the goal is 0.8 on each plant effect).  For the sensor fault the
WOB std barely moves; what matters is the controller's own error, the offset of the true WOB mean from
the set-point, which reading the measurement through the calibrated correction removes.
"""

from __future__ import annotations

import logging
import sys

import numpy as np

from heavecomp.analysis.linear import operating_point
from heavecomp.analysis.summary import analyse
from heavecomp.benchmark import Case, generate
from heavecomp.benchmark.seeds import spent as spent_ranges
from heavecomp.benchmark.truth import TRUTH
from heavecomp.benchmark.truth.sensor_gain import sensor_gain as truth_sensor_gain
from heavecomp.closed_loop.loop import Noise, simulate_closed_loop
from heavecomp.controllers import make
from heavecomp.diagnosis.calibrate import from_log
from heavecomp.diagnosis.estimator import GapDiagnoser
from heavecomp.effects.spec import check
from heavecomp.errors import InputError
from heavecomp.effects.sensor_gain import SensorGain
from heavecomp.report.figures import save
from heavecomp.report.scenario import md_table, parse_args, run, run_cases, write_metrics, write_report

log = logging.getLogger(__name__)

#: effect -> (what it is, the truth law the generator plants)
EFFECTS = {
    "pressure_friction": ("seal friction with stiction", "energised seal: + k max(p - p_th, 0) on the friction jump"),
    "gas_heat_transfer": ("gas", "thermal gas state: adiabatic compression, Newton heat exchange (tau_th)"),
    "string_damping": ("string", "quadratic drag c_q dv abs(dv) in the string tension"),
    "sensor_gain": ("sensor fault", "WOB load cell: g x its own 5 Hz first-order lag"),
    "gas_leak": ("gas", "laminar leak of the gas mass fraction (1-3 % of the charge over the log)"),
    "gas_stiffness_mismatch": ("gas", "the nominal law with wrong values: the gas stiffness and a second parameter "
                                      "off by 30-50 %"),
    "string_stiffness_mismatch": ("string", "the nominal law with wrong values: the string stiffness and a second "
                                            "parameter off by 30-50 %"),
}
#: the benchmark law each entry withholds (default: the entry's own name)
LAW = {"gas_stiffness_mismatch": "parameter_mismatch", "string_stiffness_mismatch": "parameter_mismatch"}
#: first seed of the loop's next runs (640000+: fresh, used by no tuning or scoring set; the committed report's
#: run used 620000+, an earlier one 600000+, and 110-117 and 570000-572999 were looked at while the
#: parameter_mismatch refit was built and rebuilt; a full run refuses a spent seed,
#: :data:`heavecomp.benchmark.seeds.SPENT`)
SEED0 = 640000
#: the parameter a ``parameter_mismatch`` entry's draw must move: the benchmark draws two of gas stiffness,
#: Coulomb force, string and formation stiffness (+-30-50 %); the entry takes the first seed from
#: ``SEED0 + len(EFFECTS)`` whose draw moves it (chosen by the parameter drawn, never by its size or the
#: loop's outcome; the two entries never share a seed)
MISMATCH_OF = {"gas_stiffness_mismatch": "compensator.gas_stiffness",
               "string_stiffness_mismatch": "drill_string.stiffness"}
CONTROLLER = "linear-mpc"
#: effects whose truth the linear MPC cannot see: a quadratic drag has no slope at rest, so the linear
#: MPC's model (linearised there) is the nominal one; the nonlinear MPC carries it over the horizon
NONLINEAR = ("string_damping",)
#: the closed loop's sea (an irregular sea the controller has to predict) and noise (the rig's sensors)
SEA = {"kind": "jonswap", "hs": 2.0, "tp": 12.0, "gamma": 3.3, "seed": 7, "amplitude": None, "period": None,
       "ramp": 20.0}
WAVE_PERIODS = ("5", "8", "12", "16", "20")
#: the linear MPC's osqp tolerance for the resolution runs (its own is 1e-4): how far the WOB std of one
#: controller moves when its QPs are solved 100 x tighter is the resolution of a difference between two
#: controllers in the same sea with the same noise (the runs are otherwise deterministic)
TIGHT_EPS = 1e-6


class TruthSensorGain(SensorGain):
    """The benchmark's sensor_gain truth law online, y_meas = g LP(y) behind a first-order lag of
    ``bandwidth`` [Hz] (:func:`heavecomp.benchmark.truth.sensor_gain.sensor_gain`, the law's own
    function), read on the channel's history so far."""

    bandwidth = 5.0

    @staticmethod
    def apply(t, tg, y, factor):
        if tg.size < 2:
            return factor * np.interp(t, tg, y)
        lagged = truth_sensor_gain(tg, {"y": y}, "y", factor, TruthSensorGain.bandwidth)["y"]
        return np.interp(t, tg, lagged)


def truth_effects(name: str, parameters: dict) -> list:
    """The truth plant's effects: the benchmark's truth-law instance with its planted parameters
    (none for a parameter mismatch: its truth is the nominal law with other values, :func:`truth_params`)."""
    if name == "parameter_mismatch":
        return []
    if name == "sensor_gain":
        e = TruthSensorGain(channel=parameters["channel"], factor=1.0 + parameters["gain_error"])
        e.bandwidth = parameters.get("bandwidth", TruthSensorGain.bandwidth)
        return [e]
    return [TRUTH[name](**parameters)]


def truth_params(nominal, name: str, parameters: dict):
    """The truth plant's parameters: the nominal ones, or for a parameter mismatch the drawn values
    (``"table.key": value`` [SI], the run's truth record)."""
    if name != "parameter_mismatch":
        return nominal
    changes = {}
    for path, value in parameters.items():
        table, key = path.split(".")
        changes.setdefault(table, {})[key] = value
    return nominal.replace(**changes)


def true_model(name: str, parameters: dict) -> tuple[list, str]:
    """The effects the true-model controller knows, and how they relate to the truth.

    The truth laws are Effect classes composed by the same mechanism as the library's, so the
    controller's casadi model traces them as they are.  The sensor's lag is no static map (the
    controller's output model takes g y + o only): its true model is the gain without the lag.  A
    parameter mismatch's true model is the true values (:func:`truth_params`), no effect."""
    if name == "parameter_mismatch":
        return [], "the true parameter values (" + ", ".join(f"{k} = {v:.4g}" for k, v in parameters.items()) + ")"
    if name == "sensor_gain":
        return ([SensorGain(channel=parameters["channel"], factor=1.0 + parameters["gain_error"])],
                "the truth's gain g as a library sensor_gain (its 5 Hz lag is not modelled)")
    return truth_effects(name, parameters), "the truth law itself (traced by casadi like a library effect)"


def _describe(specs) -> str:
    """One line for a model's ``[[effects]]`` specs."""
    return ", ".join(f"{n}({', '.join(f'{k}={x:.4g}' if not isinstance(x, str) else f'{k}={x}' for k, x in v.items())})"
                     for n, v in specs) or "nominal"


def _analysis(params, effects) -> dict:
    try:
        s = analyse(params, n_points=400, effects=effects)["summary"]
    except np.linalg.LinAlgError as exc:  # an integrating state (a gas leak's charge) has no DC gain
        log.warning("analyse: %s", exc)
        return {"error": f"no frequency analysis: {exc} (an effect state that integrates, e.g. a leaking charge, "
                         "leaves the linear model without a DC gain)"}
    return {"k_eff_dc": s["k_eff_dc"], "natural_frequencies": s["natural_frequencies"],
            "damping_ratios": s["damping_ratios"],
            "transmissibility": {T: s["transmissibility_at_wave_periods"][T] for T in WAVE_PERIODS}}


def _loop_metrics(res, W0: float) -> dict:
    m = res.metrics()
    w = res["wob"][res.window()]
    return {"wob_std": m["wob_std"], "wob_p2p": m["wob_p2p"], "wob_mean_error": float(np.mean(w) - W0),
            "u_rms": m["u_active_rms"], "u_max_used": m["u_active_max"] / m["u_max"],
            "saturated_share": m["saturated_steps"] / max(m["n_control_steps"], 1),
            "violations": m["violations_u_max"] + m["violations_rate"], "fallbacks": m["fallbacks"]}


def _closed_loop(plant, ctrl, model, known, duration, truth_fx, seed, tight=False):
    """One closed-loop run on the truth plant: ``ctrl`` designed on ``model`` knowing ``known``
    (``tight``: the linear MPC's QPs solved to :data:`TIGHT_EPS`)."""
    c = make(ctrl, model, effects=known)
    if tight:
        c.solver.update_settings(eps_abs=TIGHT_EPS, eps_rel=TIGHT_EPS)
    return simulate_closed_loop(plant, c, duration, effects=truth_fx, noise=Noise(seed=seed))


def _prediction(c, pressure: float) -> dict:
    """What a linear MPC ``c`` predicts with: the WOB over its horizon after a unit force and after a
    unit heave at step 0 [N/N, N/m], and its friction forecast at stroke velocities -0.5..0.5 m/s [N]."""
    m, N = c.model, c.N
    x, heave = m.Bw[:, 0].copy(), []
    for _ in range(N):
        heave.append(float(m.C[0] @ x))
        x = m.Ad @ x
    v = np.linspace(-0.5, 0.5, 41)
    return {"force": np.asarray(c.Gu[:, 0]), "heave": np.asarray(heave),
            "friction": np.asarray(c.estimation.friction.force(v, pressure))}


def model_change(reference, other) -> dict:
    """Relative change of each :func:`_prediction` part from ``reference`` to ``other`` [-]: 0 means
    the controller's model does not use what it was given."""
    return {k: float(np.linalg.norm(other[k] - reference[k]) / max(np.linalg.norm(reference[k]), 1e-300))
            for k in reference}


def loop_one(key: str, *, seed: int, log_duration: float, loop_duration: float, progress=None) -> dict:
    """The loop for one withheld effect (module docstring); returns its metrics and the three runs."""
    name = LAW.get(key, key)
    tr = generate(Case(name, seed, "named", duration=log_duration, variant="wob" if name == "sensor_gain" else None))
    nominal = tr.nominal
    planted = tr.truth["parameters"][name]
    # diagnose, as the command does: the gap diagnosis, then calibrated.toml's model (from_log)
    d = GapDiagnoser(nominal, None, n_jobs=1)
    run = tr.to_run()
    d.fit(run)
    v = d.verdict_
    cal = from_log(nominal, d.to_json(), run, d.verdict_policy())  # what diagnose writes into calibrated.toml
    cal_fx = check(cal.params)  # plant effects and reading corrections, as instances
    cal_what = _describe(cal.params.effects)
    if cal.params.replace(effects=()) != nominal.replace(effects=()):
        cal_what += "; refitted: " + ", ".join(c["name"] for c in cal.changes if c.get("kind") == "parameter")
    true_fx, true_what = true_model(name, planted)
    true_plant = [e for e in true_fx if e.kind == "plant"]
    true_p = truth_params(nominal, name, planted)
    ana = {"nominal": _analysis(nominal, ()), "calibrated": _analysis(cal.params, None),
           "true": _analysis(true_p, true_plant)}
    p = true_p.replace(heave=SEA)  # the truth plant in the loop's sea
    W0 = p.operating_point.wob_setpoint
    truth_fx = truth_effects(name, planted)
    models = {"nominal": (nominal.replace(heave=SEA), ()), "calibrated": (cal.params.replace(heave=SEA), cal_fx),
              "true": (p, true_fx)}
    runs, loops, resolution = {}, {}, {}
    controllers = (CONTROLLER, "nonlinear-mpc") if key in NONLINEAR else (CONTROLLER,)
    for ctrl in controllers:
        loops[ctrl] = {}
        for label, (mp, known) in models.items():
            # the controller designed on its model (parameters and effects); the plant is the truth
            res = _closed_loop(p, ctrl, mp, known, loop_duration, truth_fx, seed)
            runs[label] = res  # the figure shows the last controller's runs
            loops[ctrl][label] = _loop_metrics(res, W0)
    # does the controller use its model? the linear MPC's predictions on the calibrated and the true model
    # against the nominal's (a fitted effect the linearisation drops leaves them unchanged)
    p_op = operating_point(nominal).y[2]
    pred = {label: _prediction(make(CONTROLLER, mp, effects=known), p_op) for label, (mp, known) in models.items()}
    uses = {label: model_change(pred["nominal"], pred[label]) for label in ("calibrated", "true")}
    # the comparison's resolution: the same sea and noise make the runs deterministic (a repeat is
    # bit-identical); what is left is the QP solver's tolerance (the linear MPC's, solved 100 x tighter)
    again = _loop_metrics(_closed_loop(p, CONTROLLER, *models["nominal"], loop_duration, truth_fx, seed), W0)
    tight = {label: _loop_metrics(_closed_loop(p, CONTROLLER, mp, known, loop_duration, truth_fx, seed, tight=True),
                                  W0)["wob_std"] for label, (mp, known) in models.items()}
    resolution = {"repeat_identical": again["wob_std"] == loops[CONTROLLER]["nominal"]["wob_std"],
                  "tight_eps": TIGHT_EPS, "wob_std_tight": tight,
                  "wob_std": max(abs(tight[k] - loops[CONTROLLER][k]["wob_std"]) for k in tight)}
    controller = controllers[-1]
    loop = loops[controller]
    out = {"kind": EFFECTS[key][0], "truth_law": EFFECTS[key][1], "law": name, "seed": seed, "planted": planted,
           "gap_to_noise": tr.truth["gap_to_noise"][name],
           "verdict": {"effect": v["effect"], "confidence": v["confidence"], "shrink": v["shrink"],
                       "parameters": v.get("parameters", {}),
                       "second_effect": (v.get("second_effect") or {}).get("effect")},
           "calibrated": cal.block(), 
           "calibrated_model": cal_what, "true_model": true_what, "analysis": ana, "controller": controller,
           "loop": loop, "loops": loops, "resolution": resolution, "model_change": uses}
    return {"metrics": summarise(out), "runs": runs, "W0": W0}


def summarise(m: dict) -> dict:
    """``m`` with ``recovered`` per controller (``recovered_by_controller``; ``recovered``: the linear
    MPC's), ``std_difference_true`` [N] (nominal minus true-model controller), its share of the
    nominal std, ``resolved`` (the difference exceeds the resolution, the largest move of a WOB std
    when the QPs are solved 100 x tighter, and the runs repeat bit for bit), ``true_model_helps``
    (resolved and positive: only then is ``recovered`` a share of a gain) and, for a sensor fault,
    ``mean_error_removed``."""
    rec, diff = {}, {}
    for ctrl, L in m["loops"].items():
        den = L["nominal"]["wob_std"] - L["true"]["wob_std"]
        diff[ctrl] = den
        rec[ctrl] = (L["nominal"]["wob_std"] - L["calibrated"]["wob_std"]) / den if den != 0 else None
    L = m["loops"][CONTROLLER]
    res = m["resolution"]
    resolved = bool(res["repeat_identical"] and abs(diff[CONTROLLER]) > res["wob_std"])
    r, d = rec[CONTROLLER], diff[CONTROLLER]
    # how the ratio is conditioned: each of its three WOB stds moved by the resolution (worst case, first
    # order) moves it by res / |d| (|1 - r| + 1 + |r|): a small true-model worth makes a loose ratio
    bound = res["wob_std"] / abs(d) * (abs(1 - r) + 1 + abs(r)) if r is not None else None
    m.update(recovered_by_controller=rec, std_difference_by_controller=diff, recovered=r, recovered_bound=bound,
             std_difference_true=d, std_difference_share=d / L["nominal"]["wob_std"],
             resolved=resolved, true_model_helps=bool(resolved and d > 0))
    if m["kind"] == "sensor fault":
        e = {k: abs(x["wob_mean_error"]) for k, x in L.items()}
        m["mean_error_removed"] = 1.0 - e["calibrated"] / e["nominal"] if e["nominal"] > 0 else None
    return m


def mismatch_seeds(seed: int, log_duration: float) -> dict:
    """The seed of each ``parameter_mismatch`` entry (:data:`MISMATCH_OF`): the first from ``seed`` whose
    draw moves its parameter and that no other entry took (the draw is read from the generated truth)."""
    out, k = {}, seed
    while len(out) < len(MISMATCH_OF):
        drawn = generate(Case("parameter_mismatch", k, "named", duration=log_duration)).truth["parameters"]
        for key, path in MISMATCH_OF.items():
            if key not in out and path in drawn["parameter_mismatch"]:
                out[key] = k
                break
        k += 1
    return out


def build(quick: bool = False, seed: int = SEED0, jobs: int = 1, only=None) -> dict:
    """The loop for every entry of :data:`EFFECTS` (seeds ``seed`` + its index; the parameter
    mismatches at :func:`mismatch_seeds` from ``seed + len(EFFECTS)``), or two in ``quick``, or the
    entries ``only`` (their seeds as in the full run); the entries in ``jobs`` processes."""
    log_duration, loop_duration = (150.0, 60.0) if quick else (300.0, 180.0)
    names = ("pressure_friction", "sensor_gain") if quick else tuple(EFFECTS)
    if only:
        unknown = sorted(set(only) - set(EFFECTS))
        if unknown:
            raise InputError(f"sim_to_real_loop: unknown entry {unknown[0]!r} (entries: {', '.join(EFFECTS)})")
        names = tuple(n for n in EFFECTS if n in only)
    seeds = {n: seed + i for i, n in enumerate(EFFECTS)}
    if set(names) & set(MISMATCH_OF):
        seeds.update(mismatch_seeds(seed + len(EFFECTS), log_duration))
    got = {}

    def done(i, result):
        log.info("sim_to_real_loop: %s (seed %d) done", names[i], seeds[names[i]])
        got[names[i]] = result

    # every entry is independent (its own log, diagnosis and runs): ``jobs`` processes change no result
    run_cases(_entry, [(n, seeds[n]) for n in names], (log_duration, loop_duration), jobs, done)
    return {"effects": {n: got[n] for n in names}, "log_duration": log_duration, "loop_duration": loop_duration,
            "seed": seed, "seeds": {n: seeds[n] for n in names}}


def _entry(item, log_duration, loop_duration, n_jobs):
    """:func:`loop_one` for ``item`` = (entry, seed) (a module-level task for :func:`run_cases`)."""
    name, seed = item
    log.info("sim_to_real_loop: %s (seed %d)", name, seed)
    out = loop_one(name, seed=seed, log_duration=log_duration, loop_duration=loop_duration)
    # what the figure reads of each run (a light result to hand back from a worker process)
    out["runs"] = {label: {"t": np.asarray(res["t"]), "wob": np.asarray(res["wob"])} for label, res in out["runs"].items()}
    return out


def _figure(r: dict, title: str):
    from heavecomp.report.figures import pyplot

    names = list(r["effects"])
    fig, axes = pyplot().subplots(len(names), 1, figsize=(10, 2.6 * len(names)), sharex=True)
    axes = np.atleast_1d(axes)
    for ax, name in zip(axes, names):
        e = r["effects"][name]
        for label, res in e["runs"].items():
            t = res["t"]
            k = t >= t[-1] - 60.0
            ax.plot(t[k], (res["wob"][k] - e["W0"]) / 1e3, lw=0.9, label=f"MPC on the {label} model")
        ax.set_ylabel("WOB - W_0 [kN]")
        ax.set_title(f"{name} ({e['metrics']['kind']}), {e['metrics']['controller']}: verdict "
                     f"{e['metrics']['verdict']['effect']}", fontsize=9)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, ncol=3)
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


def main(argv=None) -> int:
    def extra(p):
        p.add_argument("--jobs", type=int, default=1, help="entries run in this many processes (default 1)")
        p.add_argument("--seed", type=int, default=SEED0, help=f"first seed of the runs (default {SEED0}: fresh)")
        p.add_argument("--effect", action="append", choices=tuple(EFFECTS),
                       help="run only this entry (repeatable; its seed as in the full run)")

    args = parse_args(argv, "sim_to_real_loop", __doc__, extra)
    if not args.quick and not args.effect:  # a full run is a scoring run: fresh seeds only (--effect: study)
        used = spent_ranges(range(args.seed, args.seed + len(EFFECTS) + 100))
        if used:
            print(f"--seed {args.seed}: seeds in a spent range ({', '.join(used)}); choose a fresh one "
                  "(--effect NAME studies one entry on any seed)", file=sys.stderr)
            return 2
    write(build(args.quick, seed=args.seed, jobs=max(1, args.jobs), only=args.effect), args.out, args.quick)
    return 0


def write(r: dict, out, quick: bool) -> None:
    """metrics.json, wob_loop.png and report.md (+ html) in ``out`` from :func:`build`'s result."""
    M = {n: summarise(e["metrics"]) for n, e in r["effects"].items()}
    save(_figure(r, "WOB on the truth plant, last 60 s: the MPC designed on the nominal, calibrated and true model"),
         out / "wob_loop.png", dpi=100)
    rows = []
    for n, m in M.items():
        for ctrl, L in m["loops"].items():
            rec = m["recovered_by_controller"][ctrl]
            for label in ("nominal", "calibrated", "true"):
                x = L[label]
                rows.append((n, ctrl, label, x["wob_std"] / 1e3, x["wob_p2p"] / 1e3, x["wob_mean_error"] / 1e3,
                             x["u_rms"] / 1e3, 100 * x["u_max_used"], 100 * x["saturated_share"], x["violations"],
                             (f"{rec:.2f}" if rec is not None else "-") if label == "calibrated" else ""))
    verdicts = [(n, m["kind"], m["truth_law"], f"{m['gap_to_noise']:.3g}", m["verdict"]["effect"], m["verdict"]["confidence"],
                 m["calibrated_model"], m["true_model"]) for n, m in M.items()]
    ana_rows = [(n, label, a["k_eff_dc"] / 1e3, ", ".join(f"{f:.3g}" for f in a["natural_frequencies"]),
                 ", ".join(f"{a['transmissibility'][T]:.3g}" for T in WAVE_PERIODS)) if "error" not in a else
                (n, label, "-", "-", a["error"])
                for n, m in M.items() for label, a in m["analysis"].items()]
    sections = [__doc__.strip(),
                f"Passive logs of {r['log_duration']:g} s (the generator's sea, 50 Hz, its noise); closed-loop runs of "
                f"{r['loop_duration']:g} s in a JONSWAP sea (H_s 2 m, T_p 12 s), the rig's sensor noise, "
                f"statistics after the fade-in; seeds from {r['seed']} by position (fresh: no tuning or scoring set "
                f"used them), the two parameter mismatches at the first seeds from {r['seed'] + len(EFFECTS)} whose "
                f"draw moves the gas stiffness ({r['seeds'].get('gas_stiffness_mismatch', '-')}) and the string "
                f"stiffness ({r['seeds'].get('string_stiffness_mismatch', '-')}).",
                "## What the diagnosis found and what each controller knows",
                md_table(["effect", "kind", "truth law", "gap / noise", "verdict", "confidence", "calibrated model",
                          "true model (controller)"], verdicts),
                "## Frequency analysis: nominal, calibrated and true model (frictionless linearisation)",
                "A seal-friction effect does not enter the frictionless linearisation, and a quadratic drag has no "
                "slope at rest: their rows equal the nominal's by construction.",
                md_table(["effect", "model", "k_eff at DC [kN/m]", "natural frequencies [rad/s]",
                          "transmissibility at " + ", ".join(WAVE_PERIODS) + " s [-]"], ana_rows, fmt="{:.4g}"),
                "## The loop: the MPC on the truth plant",
                "The linear MPC on every effect; on the string effect also the nonlinear MPC: its truth, a "
                "quadratic drag, has no slope at rest, where the linear MPC linearises its model, so the linear MPC "
                "designed on the true model is the nominal one; the nonlinear MPC carries the drag over its horizon "
                "(the figure shows the nonlinear MPC for it). `recovered` = (std_nominal - std_calibrated) / "
                "(std_nominal - std_true) per controller.",
                md_table(["effect", "controller", "designed on", "WOB std [kN]", "WOB p2p [kN]", "mean WOB error [kN]",
                          "rms force [kN]", "peak force [% of u_max]", "steps at a limit [%]", "commands beyond a limit",
                          "recovered"], rows,
                         fmt="{:.3g}"),
                "![WOB per controller](wob_loop.png)"]
    sections += ["## Does the controller use its model?",
                 "Relative change of what the linear MPC predicts with, against the controller designed on the "
                 "nominal model: the WOB over its horizon after a unit force and after a unit heave, and its friction "
                 "forecast at stroke velocities -0.5..0.5 m/s. 0 means the model given to it changes nothing it "
                 "predicts (the effect is dropped by its linearisation at rest, or is not in its friction).",
                 md_table(["effect", "model", "WOB per force", "WOB per heave", "friction forecast"],
                          [(n, label, *(f"{m['model_change'][label][k]:.2g}" for k in ("force", "heave", "friction")))
                           for n, m in M.items() for label in ("calibrated", "true")])]
    findings = []
    for n, m in M.items():
        L = m["loops"][CONTROLLER]
        kn = {k: x["wob_std"] / 1e3 for k, x in L.items()}
        res = m["resolution"]
        line = (f"- {n} (withheld {m['law']}, seed {m['seed']}; verdict {m['verdict']['effect']}): WOB std with the "
                f"linear MPC designed on the nominal / calibrated / true model {kn['nominal']:.4g} / "
                f"{kn['calibrated']:.4g} / {kn['true']:.4g} kN; the true model is worth "
                f"{m['std_difference_true']:.3g} N ({100 * m['std_difference_share']:.2g} % of the nominal std), the "
                f"resolution is {res['wob_std']:.2g} N (a repeat is {'bit-identical' if res['repeat_identical'] else 'NOT identical'})")
        if m["kind"] == "sensor fault":
            e = {k: x["wob_mean_error"] / 1e3 for k, x in L.items()}
            line += (f"; the controller's own error, the mean WOB off the set-point, {e['nominal']:.3g} / "
                     f"{e['calibrated']:.3g} / {e['true']:.3g} kN: reading the WOB through the diagnosed gain removes "
                     f"{100 * m['mean_error_removed']:.0f} % of it.")
        elif not m["resolved"]:
            line += ": the difference is within the resolution, so there is nothing to recover."
        elif not m["true_model_helps"]:
            line += (f": the true model makes the WOB std worse (resolved), so `recovered` "
                     f"({'-' if m['recovered'] is None else format(m['recovered'], '.2f')}) is no share of a gain.")
        else:
            line += (f": recovered {m['recovered']:.2f} +- {m['recovered_bound']:.2g}"
                     + (" (goal 0.8 met)" if m["recovered"] >= 0.8 else " (goal 0.8 **not** met)") + ".")
        for ctrl, rec in m["recovered_by_controller"].items():
            if ctrl != CONTROLLER:
                Lc = m["loops"][ctrl]
                line = line.rstrip(".") + (f"; with the {ctrl}: {Lc['nominal']['wob_std'] / 1e3:.3g} / "
                                           f"{Lc['calibrated']['wob_std'] / 1e3:.3g} / {Lc['true']['wob_std'] / 1e3:.3g} kN "
                                           f"({Lc['true']['violations']} commands beyond a limit with the true model).")
        findings.append(line)
    sections += ["## Findings", "\n".join(findings),
                 "Resolution: the three controllers run in the same sea with the same sensor noise, so a run repeats bit "
                 "for bit and a difference of WOB std between two of them is no sampling spread; what limits it is the "
                 f"QP solver's tolerance (osqp 1e-4): each linear MPC is run again with its QPs solved to {TIGHT_EPS:g}, "
                 "and the largest move of a WOB std is the resolution. A difference beyond it is real for this sea; "
                 "whether its size carries to another sea is a separate question the scenario does not answer. "
                 "`recovered` +- b: moving each of its three WOB stds by the resolution moves the ratio by at most b "
                 "= resolution / |std_nominal - std_true| x (|1 - recovered| + 1 + |recovered|) (first order): where "
                 "the true model is worth little against the nominal std (a few N of several kN) the ratio is a "
                 "ratio of two small differences, resolved for this sea but no guide to its size in another.",
                 "Where the true model is worth little: the MPCs' observer estimates a force disturbance at the "
                 "control rate, and a gas-law error (a thermal state relaxing in seconds, a charge leaking over "
                 "minutes) is slow against it, so most of it is absorbed there whether the model knows the law or "
                 "not. The linear MPC linearises its model at rest: a leak's constant rate is an affine term the "
                 "linearisation drops (the charge state it adds has no process noise in the observer, so it stays "
                 "where it starts), and a quadratic drag has no slope at rest, so for both the linear model is the "
                 "nominal one. The nonlinear MPC that carries the non-smooth drag over its horizon does worse than the "
                 "nominal one; the candidate the diagnosis fits instead, a linear dashpot, is a damping the "
                 "linearisation keeps, and it helps both MPCs. Where the model matters at the benchmark's own sizes is "
                 "a wrong stiffness: the parameter_mismatch draws (30-50 % on the gas spring or the string) change "
                 "k_eff and the modes the MPC predicts with. Effects keep the benchmark's own sizes (the generator's "
                 "draw, sized only to be detectable in the passive log); none is enlarged here."]
    write_metrics(out, {"effects": M, "controller": CONTROLLER, "log_duration": r["log_duration"],
                             "loop_duration": r["loop_duration"], "seed": r["seed"], "quick": quick,
                             "goal": {"recovered_min": 0.8}})
    write_report(out, "From a verdict to a calibrated controller: the loop on plants the controller does not know",
                 sections)


if __name__ == "__main__":
    sys.exit(run(main))
