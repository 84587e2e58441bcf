"""Frequency-response figures and the ``heavecomp analyse`` outputs.

Compute first (:mod:`heavecomp.analysis.linear`, :mod:`~heavecomp.analysis.frequency`,
:mod:`~heavecomp.analysis.sweeps`, :mod:`~heavecomp.analysis.describing`), then draw:
every ``*_figure`` function takes computed data and returns a matplotlib Figure
(save it with :func:`heavecomp.report.figures.save`).
"""

from __future__ import annotations

import json
import logging
import math
from pathlib import Path

import numpy as np

from heavecomp.analysis.frequency import WAVE_BAND
from heavecomp.analysis.summary import analyse
from heavecomp.report.figures import _plt, save
from heavecomp.report.provenance import _clean, round_floats, stamp, stamp_report

log = logging.getLogger(__name__)


def _band(ax, axis="x"):
    lo, hi = WAVE_BAND
    (ax.axvspan if axis == "x" else ax.axhspan)(lo, hi, color="tab:blue", alpha=0.12,
                                                  label="wave band (periods 5-20 s)")


def bode_figure(curves: dict, *, natural_frequencies=(), k_eff_eq14: float | None = None, title: str = ""):
    """Bode plot of k_eff(omega) = -WOB/heave for several models.

    Parameters
    ----------
    curves : dict
        label -> (omega [rad/s], complex k_eff(omega) [N/m]).
    natural_frequencies : sequence [rad/s]
        Marked as vertical lines.
    k_eff_eq14 : float [N/m], optional
        Paper A eq. 14, drawn as a horizontal line.
    title : str
        Figure title ("": the default one).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    fig, (am, ap) = plt.subplots(2, 1, figsize=(8, 6), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    for label, (w, k) in curves.items():
        am.loglog(w, np.abs(k) / 1e3, lw=1.4, label=label)
        ap.semilogx(w, np.degrees(np.unwrap(np.angle(k))), lw=1.2)
    _band(am)
    _band(ap)
    if k_eff_eq14 is not None:
        am.axhline(k_eff_eq14 / 1e3, color="k", ls="--", lw=0.8, label=f"eq. 14 k_eff = {k_eff_eq14 / 1e3:.2f} kN/m")
    for i, wn in enumerate(natural_frequencies):
        for ax in (am, ap):
            ax.axvline(wn, color="tab:red", ls=":", lw=1, label=("natural frequencies" if i == 0 and ax is am else None))
    am.set_ylabel("|k_eff(w)| = |WOB/heave| [kN/m]")
    ap.set_ylabel("phase of k_eff [deg]")
    ap.set_xlabel("angular frequency w [rad/s]")
    am.set_title(title or "Heave -> WOB: the static gain (eq. 14) holds through the wave band; resonances lie above it",
                 fontsize=10)
    am.legend(fontsize=7, loc="lower left")
    for ax in (am, ap):
        ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    return fig


def map_figure(m: dict, *, marker=None, title: str = ""):
    """Lowest and second natural period over (string length, formation stiffness).

    Parameters
    ----------
    m : dict
        From :func:`heavecomp.analysis.sweeps.eigenfrequency_map`.
    marker : (length [m], k_F [N/m]), optional
        A point to mark (e.g. the paper-A set).
    title : str
        Figure title ("": the default one).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    L, kF = m["lengths"], m["formation_stiffness"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6), sharey=True)
    levels = [1, 2, 3, 5, 8, 12, 20, 40]
    for k, ax in enumerate(axes):
        T = 2 * np.pi / m["omega"][..., k]
        cs = ax.contour(L, kF / 1e3, T.T, levels=levels, colors="0.3", linewidths=0.8)
        ax.clabel(cs, fmt="%g s", fontsize=7)
        band = ((T >= 5.0) & (T <= 20.0)).T.astype(float)
        ax.contourf(L, kF / 1e3, band, levels=[0.5, 1.5], colors=["tab:blue"], alpha=0.25)
        ax.set_yscale("log")
        ax.set_xlabel("drill-string length L [m]")
        ax.set_title(f"{'lower' if k == 0 else 'upper'} natural period T_{k + 1} [s]"
                     " (shaded: inside the 5-20 s wave band)", fontsize=9)
        if marker is not None:
            ax.plot(marker[0], marker[1] / 1e3, "r*", ms=12, label="paper-A set")
            ax.legend(fontsize=8, loc="lower right")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("formation stiffness k_F [kN/m]")
    fig.suptitle(title or "Where do the CMC's eigenfrequencies meet the waves? Soft formations bring the "
                 "lower mode into the wave band", fontsize=10)
    fig.tight_layout()
    return fig


def transmissibility_map_figure(m: dict, period_index: int, *, marker=None):
    """|k_eff(omega)|/k_eff(0) at one wave period over (L, k_F) (frictionless).

    Parameters
    ----------
    m : dict
        From :func:`heavecomp.analysis.sweeps.eigenfrequency_map` (``lengths`` [m],
        ``formation_stiffness`` [N/m], ``wave_periods`` [s], ``transmissibility`` [-]).
    period_index : int
        Index of the wave period in ``m["wave_periods"]``.
    marker : (length [m], k_F [N/m]), optional
        A point to mark (e.g. the paper-A set).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    L, kF = m["lengths"], m["formation_stiffness"]
    T = m["wave_periods"][period_index]
    tr = m["transmissibility"][..., period_index]
    fig, ax = plt.subplots(figsize=(6.5, 4.6))
    pc = ax.pcolormesh(L, kF / 1e3, np.log10(tr.T), cmap="RdBu_r", vmin=-1, vmax=1, shading="auto")
    cb = fig.colorbar(pc, ax=ax)
    cb.set_label("log10 transmissibility |k_eff(w)| / k_eff(0) [-]")
    cs = ax.contour(L, kF / 1e3, tr.T, levels=[0.5, 1.1, 2, 5], colors="k", linewidths=0.7)
    ax.clabel(cs, fmt="%g", fontsize=7)
    if marker is not None:
        ax.plot(marker[0], marker[1] / 1e3, "k*", ms=12, label="paper-A set")
        ax.legend(fontsize=8)
    ax.set_yscale("log")
    ax.set_xlabel("drill-string length L [m]")
    ax.set_ylabel("formation stiffness k_F [kN/m]")
    ax.set_title(f"Heave -> WOB at a {T:g} s wave: red amplifies (resonance), blue filters", fontsize=10)
    fig.tight_layout()
    return fig


def df_figure(rows: list[dict], *, title: str = ""):
    """WOB first-harmonic amplitude vs heave amplitude: describing function, simulator, linear.

    Parameters
    ----------
    rows : list of dict
        From :func:`heavecomp.analysis.describing.compare_with_simulation`: ``friction``, ``period``
        [s], ``amplitude`` [m], ``wob_df``, ``wob_sim``, ``wob_linear`` [N]; one panel per friction.
    title : str
        Figure title ("": the default one).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    frictions = sorted({r["friction"] for r in rows})
    fig, axes = plt.subplots(1, len(frictions), figsize=(5.2 * len(frictions), 4.2), sharey=True, squeeze=False)
    for ax, fr in zip(axes[0], frictions):
        sub = [r for r in rows if r["friction"] == fr]
        for j, T in enumerate(sorted({r["period"] for r in sub})):
            rr = sorted((r for r in sub if r["period"] == T), key=lambda r: r["amplitude"])
            a = np.array([r["amplitude"] for r in rr])
            col = f"C{j}"
            ax.plot(a, [r["wob_df"] / 1e3 for r in rr], "-", color=col, label=f"describing function, T = {T:g} s")
            ax.plot(a, [r["wob_sim"] / 1e3 for r in rr], "o", color=col, ms=5, label=f"simulator, T = {T:g} s")
            ax.plot(a, [r["wob_linear"] / 1e3 for r in rr], ":", color=col, lw=1)
        ax.set_xscale("log")
        ax.set_yscale("log")
        amps = sorted({r["amplitude"] for r in sub})
        ax.set_xticks(amps, [f"{x:g}" for x in amps])
        ax.minorticks_off()
        ax.set_xlabel("heave amplitude a [m]")
        ax.set_title(f"friction: {fr} (dotted: frictionless linear)", fontsize=9)
        ax.grid(alpha=0.3, which="both")
    axes[0][0].set_ylabel("WOB first-harmonic amplitude [kN]")
    axes[0][0].legend(fontsize=7)
    fig.suptitle(title or "Amplitude-dependent heave -> WOB: friction stiffens the compensator at small heave",
                 fontsize=10)
    fig.tight_layout()
    return fig


def write_analysis(params, out, *, source: str = "", **kw) -> dict:
    """Write ``analysis.json``, ``frequency_response.csv``, ``bode.png`` and ``report.md`` into ``out``.

    Returns the analysis.json content.

    Parameters
    ----------
    params : heavecomp.params.CMCParams
        The parameter set.
    out : str or os.PathLike
        Output folder (created if missing).
    source : str
        Where the set comes from, in titles (e.g. ``(rig.toml)``).
    **kw : dict
        Passed to :func:`heavecomp.analysis.summary.analyse` (``n_points``, ``omega_min`` [rad/s],
        ``omega_max`` [rad/s], ``sliding_velocity`` [m/s]).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    res = analyse(params, **kw)
    s, table = res["summary"], res["table"]

    (out / "analysis.json").write_text(json.dumps(round_floats(_clean(s)), indent=2) + "\n")
    cols = list(table)
    np.savetxt(out / "frequency_response.csv", np.column_stack([table[c] for c in cols]), delimiter=",",
               header=",".join(cols), comments="", fmt="%.10g")
    save(bode_figure(res["curves"], natural_frequencies=s["natural_frequencies"], k_eff_eq14=params.k_eff,
                     title=f"Heave -> WOB {source}: |k_eff(w)| with the wave band and the natural frequencies"),
         out / "bode.png", dpi=100)
    (out / "report.md").write_text(report_markdown(s, source))

    stamp_report(out / "report.md", stamp())
    log.info("analysis written to %s", out)
    return s


#: the CMC's two modes, ascending (linearised, frictionless: the top mass rides on the soft gas
#: spring, the lower mass on the much stiffer drill string and formation)
MODE_NAMES = ("mode 1: top mass on the gas spring", "mode 2: lower mass on drill string and formation")


def mode_rows(freqs_rad_s, damping=None) -> list[tuple]:
    """``(name, omega [rad/s], f [Hz], period [s], zeta [-])`` per mode, sorted by frequency.

    Parameters
    ----------
    freqs_rad_s : sequence of float [rad/s]
        Undamped natural frequencies.
    damping : sequence of float [-] or None
        Damping ratio of each (None: nan).

    Returns
    -------
    list of tuple
    """
    damping = list(damping) if damping is not None else [math.nan] * len(freqs_rad_s)
    names = MODE_NAMES if len(freqs_rad_s) == len(MODE_NAMES) else [f"mode {i + 1}" for i in range(len(freqs_rad_s))]
    order = np.argsort(freqs_rad_s)
    return [(names[k], float(freqs_rad_s[i]), float(freqs_rad_s[i]) / (2 * math.pi),
             2 * math.pi / float(freqs_rad_s[i]), float(damping[i])) for k, i in enumerate(order)]


def report_markdown(s: dict, source: str = "") -> str:
    """Markdown frequency-response report from an analysis.json dict.

    Parameters
    ----------
    s : dict
        The analysis.json content (:func:`write_analysis`).
    source : str
        Where the set comes from, in the heading.

    Returns
    -------
    str
    """
    inband = any(s["modes_in_wave_band"])
    modes = ["| mode | natural frequency (undamped) [rad/s] | [Hz] | natural period [s] | damping ratio [-] |",
             "|---|---|---|---|---|"]
    modes += [f"| {n} | {w:.3f} | {f:.4f} | {T:.3f} | {z:.4f} |"
              for n, w, f, T, z in mode_rows(s["natural_frequencies"], s["damping_ratios"])]
    lines = [
        f"# Frequency response heave -> WOB {source}".rstrip(),
        "",
        "Linearised CMC (frictionless, about the operating point s = 0, WOB = W_0), from the same casadi "
        "equations the simulator uses (`heavecomp.analysis.linear`).",
        "",
        "| quantity | value | unit |",
        "|---|---|---|",
        f"| k_eff_dc (DC gain heave -> WOB, sign flipped) | {s['k_eff_dc'] / 1e3:.3f} | kN/m |",
        f"| paper A eq. 14 k_eff | {s['k_eff_eq14'] / 1e3:.3f} | kN/m |",
        f"| peak abs(k_eff(w)) | {s['peak_k_eff'] / 1e3:.1f} | kN/m |",
        f"| frequency of the peak | {s['peak_omega']:.3f} | rad/s |",
        "",
        *([f"k_eff_dc, the modes and the transmissibility's reference hold {', '.join(s['drift_states'])} at the "
           "operating point: an effect state that integrates or drifts (e.g. a leaking gas charge) has no static "
           "value of its own, so the gain is the one at the present charge.", ""] if s.get("drift_states") else []),
        "Modes, sorted by frequency:",
        "",
        *modes,
        "",
        "| wave period [s] | transmissibility abs(k_eff(w))/k_eff(0) [-] |",
        "|---|---|",
        *[f"| {k} | {v:.3f} |" for k, v in s["transmissibility_at_wave_periods"].items()],
        "",
        ("A natural frequency lies **inside** the wave band (periods 5-20 s): waves excite a resonance."
         if inband else
         "Both natural frequencies lie **above** the wave band (periods 5-20 s): the heave reaches the bit "
         "quasi-statically (WOB ~ k_eff z_h, paper A eqs. 13-14) and cylinder-force disturbances are not filtered."),
        "",
        "![Bode plot](bode.png)",
        "",
    ]
    if s.get("effects"):
        lines += ["What the linear model holds of the file (friction law and `[[effects]]`):", "",
                  *[f"- {r['item']}: **{r['role']}** ({r['why']})" for r in s["effects"]], ""]
    for key, label in (("viscous", "viscous friction only"), ("sliding", "sliding linearisation")):
        if key in s:
            v = s[key]
            lines.append(f"With {label}: " + "; ".join(
                f"{n} {w:.3f} rad/s, damping ratio {z:.4f}"
                for n, w, f, T, z in mode_rows(v["natural_frequencies"], v["damping_ratios"])) + ".")
    return "\n".join(lines) + "\n"
