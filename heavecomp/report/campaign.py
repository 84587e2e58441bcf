"""Figures and the markdown report of a campaign (computing is in :mod:`.stats`)."""

from __future__ import annotations

import json
import logging
import math
from pathlib import Path

import numpy as np

from heavecomp.report.figures import REGIME_COLORS, REGIME_LABELS, _plt, save
from heavecomp.campaign.tables import check_parquet, export_parquet
from heavecomp.campaign.execute import read_table, run_campaign
from heavecomp.report.provenance import _clean, declare_units, stamp, stamp_report

log = logging.getLogger(__name__)


def _label(key, g, multi_variant):
    lab = REGIME_LABELS.get(g["regime"], g["regime"])
    return f"{lab} [{g['variant']}]" if multi_variant else lab


def plot_long_term(st: dict, *, title=None):
    """Long-term P(|dW| > x) and cycle-peak exceedance per regime (log scale).

    Parameters
    ----------
    st : dict
        The campaign statistics (:func:`heavecomp.campaign.stats.statistics`).
    title : str or None
        Figure title (None: the default one).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.3))
    x = np.asarray(st["x_abs"]) / 1e3
    multi = len({g["variant"] for g in st["groups"].values()}) > 1
    for key, g in st["groups"].items():
        c = REGIME_COLORS.get(g["regime"]) if not multi else None
        lt = g["long_term"]
        ax.semilogy(x, np.maximum(lt["exceed_abs"], 1e-9), color=c, label=_label(key, g, multi))
        if lt["exceed_peak"]:
            ax2.semilogy(x, np.maximum(lt["exceed_peak"], 1e-9), color=c, label=_label(key, g, multi))
    b = st["band_half_width"] / 1e3
    for a, what in ((ax, "fraction of time with |WOB - W0| > x"), (ax2, "fraction of WOB cycles with peak |WOB - W0| > x")):
        a.axvline(b, color="k", ls="--", lw=0.8, label=f"tolerance band +-{b:.0f} kN")
        a.set_xlabel("WOB deviation x [kN]")
        a.set_ylabel(what + " [-]")
        a.set_ylim(1e-5, 1.2)
        a.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    ax.set_title("long-term, time fraction", fontsize=10)
    ax2.set_title("long-term, cycle peaks (weighted by p_s x cycle rate)", fontsize=10)
    fig.suptitle(title or "Long-term WOB exceedance over the scatter diagram: friction widens the tail", fontsize=11)
    fig.tight_layout()
    return fig


def _panel_groups(st, max_panels=4):
    """Groups drawn as panels: all, or (many variants) the regimes of the first variant."""
    groups = list(st["groups"].items())
    if len(groups) <= max_panels:
        return groups, ""
    first = groups[0][1]["variant"]
    return [(k, g) for k, g in groups if g["variant"] == first], f" (variant {first} only; all in statistics.json)"


def plot_short_term(st: dict, *, title=None):
    """Short-term P(|dW| > x) per sea state, one panel per regime, coloured by H_s.

    Parameters
    ----------
    st : dict
        The campaign statistics (:func:`heavecomp.campaign.stats.statistics`).
    title : str or None
        Figure title (None: the default one).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    groups, note = _panel_groups(st)
    fig, axes = plt.subplots(1, len(groups), figsize=(4.2 * len(groups), 4), sharey=True, squeeze=False)
    x = np.asarray(st["x_abs"]) / 1e3
    hs_all = sorted({s["hs"] for _, g in groups for s in g["short_term"]})
    cmap = plt.get_cmap("viridis")
    for ax, (key, g) in zip(axes[0], groups):
        for s in g["short_term"]:
            c = cmap(hs_all.index(s["hs"]) / max(1, len(hs_all) - 1))
            ax.semilogy(x, np.maximum(s["exceed_abs"], 1e-9), color=c, lw=0.8, alpha=0.8)
        ax.axvline(st["band_half_width"] / 1e3, color="k", ls="--", lw=0.8)
        ax.set_title(REGIME_LABELS.get(g["regime"], g["regime"]) + f" [{g['variant']}]", fontsize=8)
        ax.set_xlabel("WOB deviation x [kN]")
        ax.set_ylim(1e-5, 1.2)
        ax.grid(alpha=0.3, which="both")
    axes[0][0].set_ylabel("P(|WOB - W0| > x) in the sea state [-]")
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(min(hs_all), max(hs_all)))
    fig.colorbar(sm, ax=axes[0].tolist(), label="platform heave H_s [m]")
    fig.suptitle(title or "Short-term WOB exceedance per sea state (one line per H_s x T_p cell): "
                 "H_s sets the tail" + note, fontsize=10)
    return fig


def plot_band_maps(st: dict, campaign, *, title=None):
    """Fraction of time outside the tolerance band on the H_s x T_p grid, per regime.

    Parameters
    ----------
    st : dict
        The campaign statistics (:func:`heavecomp.campaign.stats.statistics`).
    campaign : heavecomp.campaign.spec.Campaign
        Its scatter diagram gives the H_s [m] x T_p [s] grid.
    title : str or None
        Figure title (None: the default one).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    groups, note = _panel_groups(st)
    hs, tp = campaign.scatter.hs, campaign.scatter.tp
    fig, axes = plt.subplots(1, len(groups), figsize=(3.8 * len(groups), 3.6), squeeze=False)
    for ax, (key, g) in zip(axes[0], groups):
        M = np.full((len(hs), len(tp)), np.nan)
        for s in g["short_term"]:
            M[hs.index(s["hs"]), tp.index(s["tp"])] = s["frac_outside_band"]
        im = ax.imshow(M, origin="lower", aspect="auto", cmap="magma_r", vmin=0, vmax=1,
                       extent=(-0.5, len(tp) - 0.5, -0.5, len(hs) - 0.5))
        for i in range(len(hs)):
            for j in range(len(tp)):
                if np.isfinite(M[i, j]):
                    ax.text(j, i, f"{100 * M[i, j]:.0f}", ha="center", va="center", fontsize=6,
                            color="w" if M[i, j] > 0.5 else "k")
        ax.set_xticks(range(len(tp)), [f"{t:g}" for t in tp])
        ax.set_yticks(range(len(hs)), [f"{h:g}" for h in hs])
        ax.set_xlabel("peak period T_p [s]")
        ax.set_title(REGIME_LABELS.get(g["regime"], g["regime"]) + f" [{g['variant']}]", fontsize=8)
    axes[0][0].set_ylabel("platform heave H_s [m]")
    fig.colorbar(im, ax=axes[0].tolist(), label="time outside the band [-] (cells: %)")
    fig.suptitle(title or f"Share of time with WOB outside W0 +- {st['band_half_width'] / 1e3:.0f} kN per sea state"
                 + note, fontsize=10)
    return fig


#: units of the long-term statistics of one regime/variant group (made by heavecomp.campaign.stats)
LONG_TERM_UNITS = {"frac_outside_band": "-", "p_leave_exposure": "-", "band_exits_per_hour": "1/h",
                   "wob_std_rms": "N", "stick_fraction": "-", "dev_exceeded_1e-2": "N", "dev_exceeded_1e-3": "N",
                   "dev_max_in_exposure": "N", "frac_outside_ratio_to_none": "-"}


def summary(st: dict) -> dict:
    """The headline numbers (metrics.json of the scenario/CLI), each with its unit declared beside it.

    Parameters
    ----------
    st : dict
        The campaign statistics (:func:`heavecomp.campaign.stats.statistics`).

    Returns
    -------
    dict
    """
    out = declare_units({"band_half_width_N": st["band_half_width"], "exposure_s": st["exposure"],
                         "n_runs": st["n_runs"], "long_term": {}},
                        {"band_half_width_N": "N", "exposure_s": "s", "n_runs": "count"})
    for key, g in st["groups"].items():
        lt = g["long_term"]
        out["long_term"][key] = declare_units({k: lt[k] for k in (
            "frac_outside_band", "p_leave_exposure", "band_exits_per_hour", "wob_std_rms", "stick_fraction",
            "dev_exceeded_1e-2", "dev_exceeded_1e-3", "dev_max_in_exposure")}, LONG_TERM_UNITS)
    out["regime_effect"] = {key: declare_units(dict(e), {k: LONG_TERM_UNITS[k] for k in e if k in LONG_TERM_UNITS})
                            for key, e in st["regime_effect"].items()}
    return out


def _f(x, scale=1.0, fmt="{:.3g}"):
    return "n/a" if x is None or (isinstance(x, float) and not math.isfinite(x)) else fmt.format(x * scale)


def write_report(out_dir, campaign, st: dict, run_info=None) -> Path:
    """``report.md``, ``statistics.json``, ``metrics.json`` and the figures into ``out_dir``.

    Parameters
    ----------
    out_dir : str or os.PathLike
        The campaign's results folder (exists).
    campaign : heavecomp.campaign.spec.Campaign
    st : dict
        The campaign statistics (:func:`heavecomp.campaign.stats.statistics`).
    run_info : dict or None
        Executor, workers, run counts and wall time [s], written to the untracked ``timings.json``.

    Returns
    -------
    pathlib.Path
        The ``report.md`` written.
    """
    out = Path(out_dir)
    figs = []
    if campaign.outputs.figures:
        save(plot_long_term(st), out / "exceedance_long_term.png", dpi=100)
        save(plot_short_term(st), out / "exceedance_short_term.png", dpi=80)
        save(plot_band_maps(st, campaign), out / "band_by_sea_state.png", dpi=90)
        figs = ["exceedance_long_term.png", "exceedance_short_term.png", "band_by_sea_state.png"]
    (out / "statistics.json").write_text(json.dumps(_clean(st, digits=5)) + "\n")
    m = summary(st)
    if run_info is not None:  # executor, workers, resumed runs, wall time: differ on every re-run
        (out / "timings.json").write_text(json.dumps(_clean({"execution": run_info}), indent=2) + "\n")
    (out / "metrics.json").write_text(json.dumps(_clean(m), indent=2) + "\n")
    b = st["band_half_width"] / 1e3
    T = st["exposure"]
    rows = []
    for key, g in st["groups"].items():
        lt = g["long_term"]
        rows.append(f"| {REGIME_LABELS.get(g['regime'], g['regime'])} | {g['variant']} | "
                    f"{_f(lt['wob_std_rms'], 1e-3)} | {_f(lt['frac_outside_band'], 100)} | "
                    f"{_f(lt['p_leave_exposure'])} | {_f(lt['band_exits_per_hour'])} | "
                    f"{_f(lt['dev_exceeded_1e-2'], 1e-3)} | {_f(lt['dev_exceeded_1e-3'], 1e-3)} | "
                    f"{_f(lt['dev_max_in_exposure'], 1e-3)} | "
                    f"{_f(lt['stick_fraction'], 100)} |")
    s = campaign.settings
    text = [f"# Sea-state campaign `{s.name}`", "",
            f"{st['n_runs']} runs: {sum(1 for _ in campaign.scatter.cells())} sea states x "
            f"{len(campaign.regimes)} friction regimes x {len(campaign.variants)} variant(s) x {s.seeds} seed(s), "
            f"{s.duration:g} s each (statistics after a fade-in of {s.ramp_periods:g} T_p), base set `{s.base}`.",
            "", f"Scatter diagram (platform heave): {campaign.scatter.note or 'as given'}.", "",
            f"## Long-term result (weighted by the scatter diagram), band W0 +- {b:.0f} kN", "",
            f"| regime | variant | RMS WOB std [kN] | time outside band [%] | P(leave band within {T:g} s) | "
            "band exits per hour | dW exceeded 1 % of time [kN] | dW exceeded 0.1 % of time [kN] | "
            f"most probable max abs(dW) in {T:g} s [kN] | stuck [%] |",
            "|---|---|---|---|---|---|---|---|---|---|", *rows, "",
            *_variant_lines(campaign),
            "## Method", "",
            "Each run is the exact stick-slip simulation of `heavecomp.simulate` (same stepper, step and JONSWAP "
            "heave; the batch path is tested against single runs). WOB is sampled at "
            f"{s.rate:g} Hz after the fade-in; per run a histogram of dW = WOB - W0 and of the cycle peaks "
            "(max |dW| between zero up-crossings) is kept. Seeds of a sea state are pooled (short-term); the "
            "long-term curves weight sea states by their probability (cycle peaks by probability x cycle rate); "
            "the most probable maximum in the exposure T is the level exceeded by 1 of the nu T expected cycle peaks. "
            "P(leave the band within T) = 1 - exp(-lambda T) from the sampled band-exit rate lambda (Poisson "
            "assumption; the empirical per-run fraction is in statistics.json as a check). All regimes see the same "
            "heave realisations (paired comparison).", ""]
    for f in figs:
        text += [f"![{f}]({f})", ""]
    path = out / "report.md"
    path.write_text("\n".join(text))

    stamp_report(path, stamp(params_file="campaign.toml"))
    return path


def _variant_lines(campaign):
    if len(campaign.variants) <= 1 and not campaign.variants[0].overrides:
        return []
    keys = list(dict(campaign.variants[0].overrides))
    lines = ["## Variants", "", "| variant | " + " | ".join(f"`{k}`" for k in keys) + " |",
             "|---|" + "---|" * len(keys)]
    for v in campaign.variants:
        d = dict(v.overrides)
        lines.append(f"| {v.name} | " + " | ".join(f"{d[k]:.6g}" for k in keys) + " |")
    return lines + [""]


def run_and_report(campaign, out_dir, **kw):
    """:func:`run_campaign`, then (when every run is in the table) the statistics,
    ``report.md``, ``metrics.json``, ``statistics.json``, figures and, if asked,
    ``runs.parquet``.  Returns ``(CampaignRun, statistics dict or None)``.

    Parameters
    ----------
    campaign : heavecomp.campaign.spec.Campaign
    out_dir : str or os.PathLike
        Results folder (created; rerunning into it resumes).
    **kw : dict
        Passed to :func:`heavecomp.campaign.execute.run_campaign` (``workers``, ``scheduler``,
        ``client``, ``progress``, ``limit``).
    """
    from heavecomp.campaign import stats

    if campaign.outputs.format == "parquet":
        check_parquet()  # before the runs, not after

    info = run_campaign(campaign, out_dir, **kw)
    if not info.complete:
        log.info("campaign incomplete (%d of %d runs); rerun to resume", info.n_skipped + info.n_simulated,
                 info.n_total)
        return info, None
    table = read_table(info.table_path, campaign)
    st = stats.statistics(campaign, table)
    run_info = {"executor": info.executor, "workers": info.workers, "runs_simulated": info.n_simulated,
                "runs_resumed": info.n_skipped, "wall_time_s": round(info.wall_time, 2)}
    write_report(info.out_dir, campaign, st, run_info)
    if campaign.outputs.format == "parquet":
        export_parquet(table, info.out_dir, campaign.outputs.deviation_max, campaign.outputs.bins)
    return info, st
