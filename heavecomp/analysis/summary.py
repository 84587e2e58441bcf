"""Everything ``heavecomp analyse`` computes for one parameter set (data only; report/analysis.py draws)."""

from __future__ import annotations

import math

import numpy as np

from heavecomp.analysis.frequency import WAVE_BAND
from heavecomp.analysis.linear import linearise_details
from heavecomp.analysis.frequency import dc_gain, drift_states, frequency_grid, frozen, modes, response_table
from heavecomp.effects.registry import resolve
from heavecomp.effects.spec import check


def analyse(params, *, n_points: int = 1000, omega_min: float = 1e-3, omega_max: float | None = None,
            sliding_velocity: float | None = None, effects=None) -> dict:
    """Everything ``heavecomp analyse`` reports for one parameter set (no files).

    Parameters
    ----------
    params : CMCParams
        The parameter set (:class:`heavecomp.params.CMCParams`).
    n_points : int
        Number of frequencies of the grid (:func:`~heavecomp.analysis.frequency.frequency_grid`).
    omega_min : float [rad/s]
        Lowest frequency.
    omega_max : float [rad/s], optional
        Highest frequency; default 10 x the fastest pole.
    sliding_velocity : float [m/s], optional
        Also linearise about sliding at this velocity (friction models other than ``none``).
    effects : sequence, optional
        Effects at the plant's hooks (:mod:`heavecomp.effects`: instances, names or ``(name, values)``),
        linearised with the plant (:func:`heavecomp.analysis.linear.linearise_details`); None: the
        plant effects of ``params``' ``[[effects]]``.

    Returns
    -------
    dict
        ``summary`` (the analysis.json content; ``drift_states``: the effect states held at their
        operating values in the static gain and the modes,
        :func:`~heavecomp.analysis.frequency.drift_states`), ``table`` (CSV columns of the
        frictionless model), ``curves`` (label -> (omega, k_eff(omega))).
    """

    L0 = linearise_details(params, friction="none", effects=effects)
    sys = L0.sys
    w = frequency_grid(sys, n_points, omega_min, omega_max)
    drift = drift_states(sys, L0.op.xdot)  # a leaking charge: held at its present value (dc_gain)
    table = response_table(sys, w, drift)
    md = modes(frozen(sys, drift))
    k_dc = -dc_gain(sys, hold=drift)
    lo, hi = WAVE_BAND
    summary = {
        "k_eff_dc": k_dc,
        "k_eff_eq14": params.k_eff,
        "dc_gain_heave_to_wob": -k_dc,
        "natural_frequencies": md["natural_frequencies"],
        "natural_periods": [2 * math.pi / x for x in md["natural_frequencies"]],
        "damping_ratios": md["damping_ratios"],
        "damped_natural_frequencies": md["damped_natural_frequencies"],
        "poles": md["poles"],
        "drift_states": drift,
        "wave_band_rad_s": [lo, hi],
        "modes_in_wave_band": [bool(lo <= x <= hi) for x in md["natural_frequencies"]],
        "peak_k_eff": float(np.max(table["k_eff_mag"])),
        "peak_omega": float(w[np.argmax(table["k_eff_mag"])]),
        "transmissibility_at_wave_periods": {
            f"{T:g}": float(np.interp(2 * math.pi / T, w, table["transmissibility"])) for T in (5, 8, 12, 16, 20)},
        "operating_point": L0.op.as_dict(),
        "linearisation": "frictionless (friction='none'); outputs are deviations from the operating point"
                         + (f"; held at their operating values in k_eff_dc, the modes and the transmissibility's "
                            f"reference: {', '.join(drift)} (an effect state that integrates or drifts, e.g. a leaking "
                            "charge, has no static value: the gain is the one at the present charge)" if drift else ""),
        "frequency_points": int(len(w)),
        "friction_model": params.friction.model,
    }
    curves = {"frictionless": (w, -(table["wob_per_heave_mag"] * np.exp(1j * np.radians(table["wob_per_heave_phase_deg"]))))}
    if params.friction.viscous_coefficient is not None:
        Lv = linearise_details(params, friction="viscous", effects=effects)
        dv = drift_states(Lv.sys, Lv.op.xdot)
        mv = modes(frozen(Lv.sys, dv))
        tv = response_table(Lv.sys, w, dv)
        summary["viscous"] = {"viscous_coefficient": params.friction.viscous_coefficient,
                              "natural_frequencies": mv["natural_frequencies"],
                              "damping_ratios": mv["damping_ratios"], "k_eff_dc": -dc_gain(Lv.sys, hold=dv)}
        curves[f"viscous C_v = {params.friction.viscous_coefficient / 1e3:g} kN s/m"] = (
            w, -(tv["wob_per_heave_mag"] * np.exp(1j * np.radians(tv["wob_per_heave_phase_deg"]))))
    if sliding_velocity is not None and params.friction.model != "none":
        Ls = linearise_details(params, friction="sliding", velocity=sliding_velocity, effects=effects)
        dv = drift_states(Ls.sys, Ls.op.xdot)
        ms = modes(frozen(Ls.sys, dv))
        ts = response_table(Ls.sys, w, dv)
        summary["sliding"] = {"velocity": sliding_velocity, "friction_slope": Ls.friction_slope,
                              "natural_frequencies": ms["natural_frequencies"],
                              "damping_ratios": ms["damping_ratios"], "k_eff_dc": -dc_gain(Ls.sys, hold=dv)}
        curves[f"sliding at {sliding_velocity:g} m/s"] = (
            w, -(ts["wob_per_heave_mag"] * np.exp(1j * np.radians(ts["wob_per_heave_phase_deg"]))))
    summary["effects"] = accounting(params, sliding_velocity, effects)
    return {"summary": summary, "table": table, "curves": curves}


#: how to bring seal friction (the law and its effects) into a linear analysis
FRICTION_HINT = ("--sliding-velocity V (m/s) linearises the friction law and the seal-friction effects about sliding "
                 "at V (heavecomp.analysis.linear.linearise(params, friction='sliding', velocity=V)); the "
                 "amplitude-dependent describing function of the law is "
                 "heavecomp.analysis.describing.describing_response(params, heave_amplitude, omega)")


def accounting(params, sliding_velocity: float | None = None, effects=None) -> list[dict]:
    """What the analysis did with the friction law and each of the file's ``[[effects]]``: ``kept`` (in the
    frictionless model, k_eff_dc and the modes), ``linearised`` (only in the sliding linearisation) or
    ``left out`` (with why, and how to include it).  A calibrated file whose changes are all seal friction or
    readings gives the nominal's frictionless numbers: this says so instead of nothing.

    Parameters
    ----------
    params : CMCParams
        The parameter set.
    sliding_velocity : float [m/s], optional
        The sliding linearisation's velocity (None: none was made).
    effects : sequence, optional
        As :func:`analyse` (None: the file's ``[[effects]]``).

    Returns
    -------
    list of dict
        ``item`` (``friction law`` or ``effects[i] NAME``), ``role`` and ``why`` per entry.
    """
    sliding = sliding_velocity is not None and params.friction.model != "none"
    rows = []
    f = params.friction
    if f.model != "none":
        law = f"friction law ({f.model}, F_S = {f.static_force / 1e3:.4g} kN, F_C = {f.coulomb_force / 1e3:.4g} kN)"
        rows.append({"item": law, "role": "linearised" if sliding else "left out",
                     "why": (f"linearised about sliding at {sliding_velocity:g} m/s (section 'sliding')" if sliding else
                             "seal friction is no part of the frictionless model: k_eff_dc and the modes do not "
                             f"depend on it; {FRICTION_HINT}")})
    fx = check(params) if effects is None else resolve(effects)
    for i, e in enumerate(fx):
        item = (f"effects[{i}] {e.name}" if effects is None else e.name) + (
            f" on {e.channel}" if getattr(e, "channel", None) else "")
        if e.kind != "plant":
            role, why = "left out", ("a reading (how the rig's sensors misread a log), not the plant: it changes no "
                                     "transfer function of the rig")
        elif e.hook == "seal_friction":
            role, why = (("linearised", f"seal friction, linearised about sliding at {sliding_velocity:g} m/s")
                         if sliding else ("left out", f"seal friction, no part of the frictionless model; {FRICTION_HINT}"
                                          " (the describing function takes the law only)"))
        else:
            role, why = "kept", f"at the {e.hook} hook of the linearised model"
        rows.append({"item": item, "role": role, "why": why})
    return rows


def accounting_line(rows) -> str:
    """One line of :func:`accounting` for the terminal (empty without friction or effects).

    Parameters
    ----------
    rows : list of dict
        :func:`accounting`'s rows (``analysis.json``'s ``effects``).
    """
    if not rows:
        return ""
    parts = [f"{r['item']}: {r['role']}" for r in rows]
    hint = "; to include seal friction: --sliding-velocity V" if any(
        r["role"] == "left out" and "seal friction" in r["why"] for r in rows) else ""
    return "kept, linearised or left out: " + "; ".join(parts) + hint
