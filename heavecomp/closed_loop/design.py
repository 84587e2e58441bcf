"""Controller-design experiments: compare controllers, sweep horizon/weights/actuator, robustness.

Compute functions return plain dicts of metrics (and results for figures); the figures are
drawn by :mod:`heavecomp.report.controllers`.  Used by ``scenarios/controller_design.py``.
"""

from __future__ import annotations

import logging

from heavecomp.params import paper_a
from heavecomp.closed_loop.loop import simulate_closed_loop

log = logging.getLogger(__name__)

#: seas of the study: paper A's sine (1 m, 12 s) and the irregular sea of scenarios/irregular_sea.py
SEAS = {
    "sine": None,
    "jonswap": {"kind": "jonswap", "hs": 2.0, "tp": 12.0, "gamma": 3.3, "seed": 7, "amplitude": None,
                "period": None, "ramp": 60.0},
}
REGIMES = ("none", "rotating_eq7", "stribeck")
CONTROLLERS = ("passive", "pid", "linear-mpc", "nonlinear-mpc")
#: metrics kept per run
KEYS = ("wob_std", "wob_p2p", "u_active_max", "u_active_rms", "solve_time_ms_p50", "solve_time_ms_p99",
        "violations_u_max", "violations_rate", "solver_failures", "fallbacks", "saturated_steps",
        "preview_rmse_end_m", "heave_std", "stick_fraction")


def case_params(regime: str, sea: str, active: dict | None = None):
    """Paper A parameters for a friction regime and a sea (optionally another [active] table).

    Parameters
    ----------
    regime : str
        Friction regime of :func:`heavecomp.params.paper_a` (one of :data:`REGIMES`).
    sea : str
        Key of :data:`SEAS`.
    active : dict, optional
        Entries replacing the ``[active]`` table (actuator limits ``u_max`` [N], ``rate_max`` [N/s]).
    """
    p = paper_a(regime)
    if SEAS[sea] is not None:
        p = p.replace(heave=SEAS[sea])
    if active:
        p = p.replace(active=active)
    return p


def run_case(regime: str, sea: str, controller: str, duration: float, *, active=None, keep=False, **options):
    """One closed-loop run; returns its metrics (and the result when ``keep``).

    Parameters
    ----------
    regime : str
        Friction regime of :func:`heavecomp.params.paper_a` (one of :data:`REGIMES`).
    sea : str
        Key of :data:`SEAS`.
    controller : str
        Controller name (one of :data:`CONTROLLERS`).
    duration : float [s]
        Simulated time of each run.
    active : dict, optional
        Entries replacing the ``[active]`` table (:func:`case_params`).
    keep : bool
        Also return the closed-loop result (``(metrics, result)``).
    **options : dict
        Controller options (:func:`heavecomp.closed_loop.loop.simulate_closed_loop`; ignored for
        ``"passive"``).
    """
    p = case_params(regime, sea, active)
    res = simulate_closed_loop(p, controller, duration, **({} if controller == "passive" else options))
    m = res.metrics()
    out = {k: m.get(k) for k in KEYS}
    log.info("%-13s %-12s %-7s %s: WOB std %.2f kN, |u| max %.1f kN, p99 %.2f ms", controller, regime, sea,
             options or "", m["wob_std"] / 1e3, m["u_active_max"] / 1e3, m["solve_time_ms_p99"])
    return (out, res) if keep else out


def compare(regimes, seas, controllers, durations: dict, options: dict | None = None):
    """Metrics table[sea][regime][controller] and the results of every run, keyed (sea, regime,
    controller) (for figures).

    Parameters
    ----------
    regimes : iterable of str
        Friction regimes (of :data:`REGIMES`).
    seas : iterable of str
        Keys of :data:`SEAS`.
    controllers : iterable of str
        Controller names (of :data:`CONTROLLERS`).
    durations : dict
        sea -> simulated time of each run on it [s].
    options : dict, optional
        controller -> its options (:func:`run_case`).
    """
    table, kept = {}, {}
    for sea in seas:
        table[sea] = {}
        for reg in regimes:
            table[sea][reg] = {}
            for c in controllers:
                m, res = run_case(reg, sea, c, durations[sea], keep=True, **(options or {}).get(c, {}))
                table[sea][reg][c] = m
                kept[(sea, reg, c)] = res
    return table, kept


def sweep(regime, sea, controller, duration, name, values, **fixed):
    """Metrics for each value of one option (``name`` is a ControllerConfig field or ``u_max``/``rate_max``).

    Parameters
    ----------
    regime : str
        Friction regime of :func:`heavecomp.params.paper_a` (one of :data:`REGIMES`).
    sea : str
        Key of :data:`SEAS`.
    controller : str
        Controller name (one of :data:`CONTROLLERS`).
    duration : float [s]
        Simulated time of each run.
    name : str
        The option swept: a controller option or an ``[active]`` limit (``u_max`` [N],
        ``rate_max`` [N/s]).
    values : iterable
        Its values (in the option's unit).
    **fixed : dict
        Further options of every run (:func:`run_case`).
    """
    rows = []
    for v in values:
        if name in ("u_max", "rate_max"):
            m = run_case(regime, sea, controller, duration, active={name: v}, **fixed)
        else:
            m = run_case(regime, sea, controller, duration, **{name: v}, **fixed)
        rows.append({"value": v, **m})
    return rows


def robust_label(sea: str, name: str, value: float) -> str:
    """Key of one robustness run, e.g. ``"jonswap: friction_scale x0.7"``.

    Parameters
    ----------
    sea : str
        Key of :data:`SEAS`.
    name : str
        The controller model's scaled quantity (``friction_scale``, ``gas_stiffness_scale``).
    value : float [-]
        Its scale factor.
    """
    return f"{sea}: {name} x{value:g}"


def label_sea(label: str) -> str:
    """The sea of a :func:`robust_label`.

    Parameters
    ----------
    label : str
        A key made by :func:`robust_label`.
    """
    return label.split(": ", 1)[0]


def robustness(seas, controllers, durations: dict, values=(0.7, 1.3)) -> dict:
    """Full static friction with the controller's friction forces and gas stiffness scaled:
    ``{controller: {robust_label: metrics}}``.

    Parameters
    ----------
    seas : iterable of str
        Keys of :data:`SEAS`.
    controllers : iterable of str
        Controller names (of :data:`CONTROLLERS`).
    durations : dict
        sea -> simulated time of each run on it [s].
    values : iterable of float [-]
        Scale factors of the controller model's friction forces and gas stiffness.
    """
    return {c: {robust_label(sea, name, v): run_case("stribeck", sea, c, durations[sea], **{name: v})
                for sea in seas for name in ("friction_scale", "gas_stiffness_scale") for v in values}
            for c in controllers}


#: the frame study's runs: label -> run_case options
FRAME_RUNS = {"model_frame = stroke": {"model_frame": "stroke"},
              "model_frame = earth": {"model_frame": "earth"},
              "model_frame = earth, perfect preview": {"preview": "perfect"}}


def frame_study(sea: str, controllers, duration: float) -> dict:
    """Full static friction with the MPC model in the stroke and the earth frame, and with a
    perfect heave preview: ``{controller: {label: metrics}}`` (labels: :data:`FRAME_RUNS`).

    Parameters
    ----------
    sea : str
        Key of :data:`SEAS`.
    controllers : iterable of str
        Controller names (of :data:`CONTROLLERS`).
    duration : float [s]
        Simulated time of each run.
    """
    return {c: {label: run_case("stribeck", sea, c, duration, **opts) for label, opts in FRAME_RUNS.items()}
            for c in controllers}


# ------------------------------------------------------------------ figures
def findings(table: dict, sweeps: dict, robust: dict, frames: dict | None = None, frame_sea: str = "jonswap") -> list[str]:
    """Plain-language findings computed from the metrics (no numbers typed in).

    Parameters
    ----------
    table : dict
        Metrics table[sea][regime][controller] of :func:`compare` (with ``"stribeck"`` and
        ``"passive"``).
    sweeps : dict
        option -> (unit, {controller: rows of :func:`sweep`}).
    robust : dict
        Result of :func:`robustness`.
    frames : dict, optional
        Result of :func:`frame_study`.
    frame_sea : str
        Sea of ``frames`` (a key of :data:`SEAS`).
    """
    out = []
    for sea in table:
        st = table[sea]["stribeck"]
        pas = st["passive"]["wob_std"]
        parts = [f"{c} {100 * st[c]['wob_std'] / pas:.0f} %" for c in st if c != "passive"]
        ok = all(st[c]["wob_std"] <= 0.2 * pas for c in ("linear-mpc", "nonlinear-mpc") if c in st)
        prev = st.get("linear-mpc", {}).get("preview_rmse_end_m")
        out.append(f"- {sea}, full static friction: WOB std relative to passive ({pas / 1e3:.1f} kN): "
                   + ", ".join(parts) + f" — the 20 % goal is {'met' if ok else 'NOT met'} by the MPCs"
                   + (f" (heave preview RMSE 1 s ahead: {prev * 100:.1f} cm)." if prev is not None else "."))
    if "u_max" in sweeps:
        rows = sweeps["u_max"][1]["linear-mpc"]
        pas = table["sine"]["stribeck"]["passive"]["wob_std"]
        good = [r["value"] for r in rows if r["wob_std"] <= 0.2 * pas]
        out.append(f"- Actuator size (sine, full static friction): the smallest u_max tried that meets the goal is "
                   + (f"{min(good) / 1e3:.0f} kN" if good else "none of those tried") + "; WOB std "
                   + ", ".join(f"{r['wob_std'] / 1e3:.1f} kN at {r['value'] / 1e3:.0f} kN" for r in rows) + ".")
    for sea in table:
        pas = table[sea]["stribeck"]["passive"]["wob_std"]
        rows = [(c, k.split(": ", 1)[-1], m["wob_std"]) for c, d in robust.items() for k, m in d.items()
                if label_sea(k) == sea]
        if rows:
            worst = max(rows, key=lambda x: x[2])
            out.append(f"- Robustness ({sea}, full static friction): the worst model error tried is {worst[1]} for "
                       f"{worst[0]}: {worst[2] / 1e3:.1f} kN WOB std = {100 * worst[2] / pas:.0f} % of passive "
                       f"({'within' if worst[2] <= 0.2 * pas else 'outside'} the 20 % goal).")
    for c, d in (frames or {}).items():
        pas = table[frame_sea]["stribeck"]["passive"]["wob_std"]
        st, ea, pf = (d.get(label) for label in FRAME_RUNS)
        if st and ea:
            out.append(f"- Prediction-model frame ({frame_sea}, full static friction, {c}): stroke frame "
                       f"{100 * st['wob_std'] / pas:.0f} % of passive, earth frame {100 * ea['wob_std'] / pas:.0f} %"
                       + (f", earth frame with a perfect heave preview {100 * pf['wob_std'] / pas:.0f} %." if pf else "."))
    viol = sum(m["violations_u_max"] + m["violations_rate"] for sea in table for reg in table[sea]
               for m in table[sea][reg].values())
    fb = sum(m["fallbacks"] for sea in table for reg in table[sea] for m in table[sea][reg].values())
    out.append(f"- Limit violations over all runs of the table: {viol}; solver fallbacks: {fb}.")
    return out
