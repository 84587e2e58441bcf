"""Figures for the real-data identification (each returns a matplotlib Figure;
save with :func:`heavecomp.report.figures.save`)."""

from __future__ import annotations

import numpy as np

from heavecomp.plants.axis import BASE_NAMES, EMPS_PUBLISHED, EMPS_UNITS
from heavecomp.report.figures import _plt
from heavecomp.report.scenario import md_table, write_report


def emps_overlay(t, measured, model_before, model_after, label_after: str):
    """Measured vs model force on the held-out part.

    Parameters
    ----------
    t : numpy.ndarray [s]
        Sample times of the held-out part.
    measured : numpy.ndarray [N]
        Measured motor force.
    model_before : numpy.ndarray [N]
        Force of the base EMPS model.
    model_after : numpy.ndarray [N]
        Force of the model with the selected effects.
    label_after : str
        The selected effects, for the legend.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    fig, (ax, axr) = plt.subplots(2, 1, figsize=(10, 5.6), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    ax.plot(t, measured, color="0.2", lw=1.2, label="measured F = g_tau v_ir")
    ax.plot(t, model_before, color="tab:blue", lw=0.9, label="EMPS model (M, F_v, F_c, offset)")
    ax.plot(t, model_after, color="tab:red", lw=0.9, ls="--", label=f"+ {label_after}")
    ax.set_ylabel("motor force F [N]")
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(alpha=0.3)
    rb = float(np.sqrt(np.mean((measured - model_before) ** 2)))
    ra = float(np.sqrt(np.mean((measured - model_after) ** 2)))
    ax.set_title(f"EMPS held-out part: the inverse model follows the force; residual rms {rb:.2f} N, "
                 f"{ra:.2f} N with the added effects", fontsize=10)
    axr.plot(t, measured - model_before, color="tab:blue", lw=0.8, label="residual, EMPS model")
    axr.plot(t, measured - model_after, color="tab:red", lw=0.8, label="residual, augmented")
    axr.set_ylabel("residual [N]")
    axr.set_xlabel("time t [s]")
    axr.legend(fontsize=8, loc="upper right")
    axr.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def emps_residual_map(v, q, r_before, r_after, where_before, where_after):
    """Residual vs velocity and vs position, with the per-bin rms before/after.

    Parameters
    ----------
    v : numpy.ndarray [m/s]
        Velocity of the held-out samples.
    q : numpy.ndarray [m]
        Position of the held-out samples.
    r_before, r_after : numpy.ndarray [N]
        Residuals of the base and of the augmented model.
    where_before, where_after : dict
        :func:`heavecomp.identification.residual.localise` of each residual (``velocity`` and
        ``position`` bins with ``lo``, ``hi`` [m/s or m], ``n``, ``rms`` [N]; ``direction``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), sharey=True)
    for ax, x, key, scale, unit in ((axes[0], v, "velocity", 1e3, "velocity q' [mm/s]"),
                                    (axes[1], q, "position", 1e3, "position q [mm]")):
        ax.plot(x * scale, r_before, ".", ms=2, color="tab:blue", alpha=0.35, label="residual, EMPS model")
        ax.plot(x * scale, r_after, ".", ms=2, color="tab:red", alpha=0.35, label="residual, augmented")
        for w, c, lab in ((where_before, "tab:blue", "bin rms before"), (where_after, "tab:red", "bin rms after")):
            mids = [0.5 * (b["lo"] + b["hi"]) * scale for b in w[key] if b["n"]]
            ax.plot(mids, [b["rms"] for b in w[key] if b["n"]], "o-", color=c, lw=1.5, label=lab)
        ax.axhline(0, color="0.5", lw=0.6)
        ax.set_xlabel(unit)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("force residual [N]")
    axes[0].legend(fontsize=7)
    d = where_before["direction"]
    vb = max((b for b in where_before["velocity"] if b["n"]), key=lambda b: b["rms"])
    qb = max((b for b in where_before["position"] if b["n"]), key=lambda b: b["rms"])
    fig.suptitle(f"Where the held-out residual lives: {d['negative']['share']:.0%} of it in the negative direction "
                 f"({d['positive']['share']:.0%} positive); largest bin rms at v = {vb['lo'] * 1e3:.0f}.."
                 f"{vb['hi'] * 1e3:.0f} mm/s and q = {qb['lo'] * 1e3:.0f}..{qb['hi'] * 1e3:.0f} mm", fontsize=10)
    fig.tight_layout()
    return fig


def emps_cutoff_sensitivity(sens: dict):
    """Estimates vs Butterworth cut-off, as % deviation from the published values.

    ``sens``: label -> output of :func:`heavecomp.identification.inverse.cutoff_sensitivity`.

    Parameters
    ----------
    sens : dict
        Label -> :func:`heavecomp.identification.inverse.cutoff_sensitivity` (``cutoff`` [Hz] and
        one list per base parameter [SI]).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    fig, axes = plt.subplots(2, 2, figsize=(10, 6.4), sharex=True)
    for ax, k in zip(axes.ravel(), BASE_NAMES):
        for label, s in sens.items():
            dev = 100.0 * (np.asarray(s[k]) / EMPS_PUBLISHED[k] - 1.0)
            ax.semilogx(s["cutoff"], dev, "o-", ms=3, label=label)
        ax.axhspan(-2, 2, color="tab:green", alpha=0.12, label="within 2 %")
        ax.axhline(0, color="0.4", lw=0.6)
        ax.set_title(f"{k} (published {EMPS_PUBLISHED[k]:g} {EMPS_UNITS[k]})", fontsize=9)
        ax.set_ylabel("deviation [%]")
        ax.grid(alpha=0.3, which="both")
    for ax in axes[1]:
        ax.set_xlabel("Butterworth cut-off of q [Hz]")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("EMPS estimates vs position-filter cut-off: on the published values once the cut-off "
                 "is above the decimation band", fontsize=10)
    fig.tight_layout()
    return fig


def seal_friction_vs_pressure(strokes: list, fits: dict):
    """Per-stroke friction vs gauge pressure, per direction, with the fitted lines.

    Parameters
    ----------
    strokes : list of dict
        Steady strokes (``SealFrictionFit.strokes_``): ``direction`` (+1/-1), ``dp`` [Pa], ``friction`` [N].
    fits : dict
        ``SealFrictionFit.fits_``: ``positive``, ``negative``, ``split`` (each ``F_C`` [N], ``C_p``
        [N/Pa]; ``split`` also ``C_p_boot`` [N/Pa]) and maybe ``file_means`` (``C_p_se`` [N/Pa]).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    fig, ax = plt.subplots(figsize=(8, 5))
    bar = 1e5
    for d, c, lab in ((1, "tab:red", "positive stroke"), (-1, "tab:blue", "negative stroke")):
        rows = [r for r in strokes if r["direction"] == d]
        ax.plot([r["dp"] / bar for r in rows], [abs(r["friction"]) for r in rows], "o", ms=4, color=c,
                alpha=0.6, label=f"|F_f| per {lab}")
        key = "positive" if d > 0 else "negative"
        f = fits[key]
        x = np.linspace(0, 7.5, 20)
        ax.plot(x, f["F_C"] + f["C_p"] * x * bar, color=c, lw=1, ls=":",
                label=f"{key}: F_C = {f['F_C']:.2f} N, C_p = {f['C_p'] * bar:.3f} N/bar")
    f = fits["split"]
    x = np.linspace(0, 7.5, 20)
    ax.plot(x, f["F_C"] + f["C_p"] * x * bar, "k-", lw=1.8,
            label=f"direction-symmetric part: F_C = {f['F_C']:.2f} N, C_p = {f['C_p'] * bar:.3f} N/bar "
                  f"(+- {f['C_p_boot'] * bar:.3f} strokes" + (f", +- {fits['file_means']['C_p_se'] * bar:.3f} files)"
                                                              if "file_means" in fits else ")"))
    ax.set_xlabel("chamber gauge pressure dp [bar]")
    ax.set_ylabel("seal friction |F_f| = |force - p A| [N]")
    ax.set_xlim(0, 7.5)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")
    ax.set_title("O-ring friction grows with pressure (paper A eq. 4, F_C + C_p dp), "
                 "much more in the positive direction", fontsize=10)
    fig.tight_layout()
    return fig


def _fmt(x) -> str:
    if isinstance(x, (list, tuple)):
        return "(" + ", ".join(_fmt(v) for v in x) + ")"
    return "-" if x is None else f"{x:.4g}"


def parameters_text(params: dict, units: dict) -> str:
    """``name = value unit, ...`` of a candidate's fitted parameters (the refitted base left out).

    Parameters
    ----------
    params : dict
        Parameter name -> fitted value [SI].
    units : dict
        Parameter name -> unit.

    Returns
    -------
    str
    """
    return ", ".join(f"{k} = {_fmt(v)} {units.get(k, '')}".rstrip() for k, v in params.items()
                     if not k.startswith("base_"))


def _cell(text: str) -> str:
    """Text for a Markdown table cell (``|`` of |v| escaped)."""
    return text.replace("|", "\\|")


def withheld_terms_table(w: dict) -> str:
    """Markdown table of :func:`heavecomp.identification.study.withheld_terms` (one row per nominal
    model that lacks a published term; the first row is the control with nothing withheld).

    Parameters
    ----------
    w : dict
        :func:`heavecomp.identification.study.withheld_terms`.

    Returns
    -------
    str
        The Markdown table.
    """
    rows = []
    for r in w["rows"]:
        unit = r["unit"]
        u = r["units"]
        fitted = "; ".join(f"{k}: {_fmt(a)} -> {_fmt(b)} {u.get(k, '')}" for k, (a, b) in r["changes"].items()) or (
            parameters_text(r["parameters"], u))
        pub = r["published"].get(r["withheld"])
        rows.append((r["withheld"], f"{_fmt(pub)} {unit}" if pub is not None else "-",
                     r["expected"], f"**{r['verdict']}**", fitted or "-", f"{r['shrink']:.3f}",
                     _fmt(r["reachable_shrink"]), f"{r['rms_before']:.3f} -> {r['rms_after']:.3f}",
                     f"{r['runner_up']} ({r['runner_up_shrink']:.3f})" if r["runner_up"] else "-",
                     f"{_cell(r['discovered'])} ({r['discovered_shrink']:.3f})" if r["discovered"] else "-",
                     "control" if r["right"] is None else "yes" if r["right"] else "**no**"))
    return md_table(["withheld term", "published value [unit given]", "expected [name]", "verdict",
                     "fitted [units given]", "held-out shrink [-]", "reachable shrink [-]", "held-out rms [N]",
                     "runner-up (shrink [-])", "discovered [N] (shrink [-])", "right [yes/no]"], rows)


# ---------------------------------------------------------------- tables and reports shared by scenario and command
def emps_parameter_table(m: dict) -> str:
    """Published against identified (whole record) EMPS parameters.

    Parameters
    ----------
    m : dict
        The EMPS metrics (:func:`heavecomp.identification.study.emps_study`): ``published``,
        ``identified_whole_record``, ``stderr_whole_record`` [SI], ``relative_error`` [-].

    Returns
    -------
    str
        The Markdown table.
    """
    pub, got, se = m["published"], m["identified_whole_record"], m["stderr_whole_record"]
    return md_table(["parameter", "published", "identified (whole record)", "std. error", "deviation [%]"],
                    [(k, pub[k], got[k], se[k], 100 * m["relative_error"][k]) for k in pub], fmt="{:.4g}")


def candidates_table(m: dict) -> str:
    """The residual diagnosis' candidates: held-out rms, shrink and score.

    Parameters
    ----------
    m : dict
        The EMPS metrics; ``candidates`` with ``effect``, ``component``, ``n_parameters``,
        ``rms_after`` [N], ``shrink`` [-], ``score``.

    Returns
    -------
    str
        The Markdown table.
    """
    return md_table(["candidate", "component", "k", "held-out rms [N]", "shrink", "score (BIC-like)"],
                    [(c["effect"], c["component"], c["n_parameters"], c["rms_after"], c["shrink"], c["score"])
                     for c in m["candidates"]], fmt="{:.3f}")


def candidate_parameters_table(m: dict) -> str:
    """Each candidate's fitted parameters (SI, with units).

    Parameters
    ----------
    m : dict
        The EMPS metrics; ``candidates`` with ``effect``, ``parameters`` [SI] and ``units``.

    Returns
    -------
    str
        The Markdown table.
    """
    return md_table(["candidate", "parameters"],
                    [(c["effect"], parameters_text(c["parameters"], c["units"])) for c in m["candidates"]])


def seal_fits_table(m: dict) -> str:
    """The seal friction fits: F_C, C_p with its standard errors and interval.

    Parameters
    ----------
    m : dict
        The seal metrics (:func:`heavecomp.identification.study.seal_study`); ``fits``: name ->
        ``F_C`` [N], ``C_p_N_per_bar``, its standard errors and ``C_p_ci95`` [N/Pa], ``rms`` [N],
        ``n_strokes``.

    Returns
    -------
    str
        The Markdown table.
    """
    return md_table(["fit", "F_C [N]", "C_p [N/bar]", "LS std. err. [N/bar]", "bootstrap std [N/bar]",
                     "95 % interval [N/bar]", "rms [N]", "strokes"],
                    [(k, f["F_C"], f["C_p_N_per_bar"], f["C_p_se_N_per_bar"], f["C_p_boot_N_per_bar"] or "-",
                      "{:.3f} .. {:.3f}".format(*(x * 1e5 for x in f["C_p_ci95"])) if f["C_p_ci95"] else "-",
                      f["rms"], f["n_strokes"]) for k, f in m["fits"].items()], fmt="{:.3f}")


def emps_report(out, m: dict, source: str) -> None:
    """``report.md`` (+ ``report.html``) of ``heavecomp identify emps`` (figures already in ``out``).

    Parameters
    ----------
    out : str or os.PathLike
        Output folder.
    m : dict
        The EMPS metrics (:func:`heavecomp.identification.study.emps_study`).
    source : str
        The data file's name, in the title.
    """
    sel = m["selection"]
    write_report(out, f"EMPS axis identification — {source}", [
        f"Inverse-model least squares on the whole record ({m['settings']}); the residual diagnosis fits "
        f"t < {m['split']['fit'][1]:g} s and scores on the rest.",
        emps_parameter_table(m), "![cut-off](cutoff_sensitivity.png)",
        f"Held-out rms residual of the base model: {m['baseline_fit_part']['rms_validate']:.3f} N.",
        "![map](residual_map.png)", "## Candidates (held-out part)", candidates_table(m),
        candidate_parameters_table(m),
        "Forward selection: " + ("; ".join(f"{' + '.join(s['effects'])}: shrink {s['shrink']:.3f}" for s in sel)
                                 or "none"),
        "![overlay](overlay.png)", "## Withheld published terms", withheld_terms_table(m["withheld_terms"]),
    ])


def seal_report(out, m: dict, n_strokes: int) -> None:
    """``report.md`` (+ ``report.html``) of ``heavecomp identify seal`` (figure already in ``out``).

    Parameters
    ----------
    out : str or os.PathLike
        Output folder.
    m : dict
        The seal metrics (:func:`heavecomp.identification.study.seal_study`).
    n_strokes : int
        Steady strokes the fit used.
    """
    write_report(out, "Seal friction against pressure", [
        f"**C_p = {m['C_p_N_per_bar']:.3f} +- {m['C_p_uncertainty_N_per_bar']:.3f} N/bar**, "
        f"F_C = {m['F_C_N']:.2f} N over {n_strokes} steady strokes (headline fit: `{m['headline_fit']}`).",
        seal_fits_table(m), "![friction vs pressure](friction_vs_pressure.png)",
        "## Withheld published term", withheld_terms_table(m["withheld_terms"]),
    ])
