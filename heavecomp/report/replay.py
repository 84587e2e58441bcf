"""Replay outputs (``heavecomp replay``): ``replay.json`` (diagnosis-contract.md, schema 4), ``overlay.png``
(the log against every file) and ``report.md`` with the table that ranks the files."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from heavecomp.report.diagnosis import CH_UNITS
from heavecomp.report.figures import _plt, envelope, save
from heavecomp.report.scenario import md_table

#: colours of the models, in the order the files were given
COLOURS = ("tab:red", "tab:green", "tab:blue", "tab:orange", "tab:purple", "tab:brown", "tab:pink", "tab:olive")


def _short(name: str) -> str:
    """A file's name in legends: its last two path parts (``diagA/calibrated.toml``)."""
    parts = Path(name).parts
    return "/".join(parts[-2:]) if len(parts) > 1 else name


def fig_overlay(cmp, window=None):
    """The log against every file's replay: one panel per measured channel, the heave on top and the primary
    channel's residual (model minus log) at the bottom; the held-out part shaded.

    Parameters
    ----------
    cmp : heavecomp.diagnosis.compare.ReplayComparison
        The replays.
    window : tuple (start, end) [s] or None
        Time shown (None: the whole replayed span; long spans are drawn as min/max envelopes).
    """
    plt = _plt()
    t = cmp.t
    lo, hi = (float(t[0]), float(t[-1])) if window is None else window
    m = (t >= lo) & (t <= hi)
    rows = ["heave", *cmp.channels, "residual"]
    fig, axs = plt.subplots(len(rows), 1, figsize=(12, 1.9 * len(rows) + 0.6), sharex=True)

    def draw(ax, y, **kw):
        tt, yy = envelope(t[m], y[m])
        ax.plot(tt, yy, **kw)

    va, vb = cmp.split["validate"]
    for ax, row in zip(axs, rows):
        if va < hi and vb > lo:
            ax.axvspan(max(va, lo), min(vb, hi), color="0.93", zorder=0)
        ax.grid(alpha=0.3)
        if row == "heave":
            draw(ax, cmp.measured["heave"], color="0.3", lw=0.7, label="log")
            ax.set_ylabel("heave [m]")
            continue
        if row == "residual":
            c = cmp.primary
            unit, sc = CH_UNITS[c]
            for k, mod in enumerate(cmp.models):
                draw(ax, (mod.pred[c] - cmp.measured[c]) * sc, color=COLOURS[k % len(COLOURS)], lw=0.7,
                     label=f"{_short(mod.name)} − log")
            ax.set_ylabel(f"{c} residual [{unit}]")
            ax.legend(fontsize=7, loc="upper right")
            continue
        unit, sc = CH_UNITS[row]
        draw(ax, cmp.measured[row] * sc, color="0.4", lw=0.8, label="log")
        for k, mod in enumerate(cmp.models):
            draw(ax, mod.pred[row] * sc, color=COLOURS[k % len(COLOURS)], lw=0.9, ls="-" if k == 0 else "--",
                 label=_short(mod.name))
        ax.set_ylabel(f"{row} [{unit}]")
    axs[1].legend(fontsize=7, loc="upper right")
    axs[-1].set_xlabel("time t [s] (from the replayed span's start; shaded: held-out part)")
    axs[0].set_title(f"{Path(cmp.source).name} replayed under {len(cmp.models)} file(s)"
                     + (f", {lo:g}-{hi:g} s" if window is not None else ", the whole span"), fontsize=10)
    fig.tight_layout()
    return fig


def ranking_table(cmp) -> str:
    """The Markdown table ranking the files (best first).

    Parameters
    ----------
    cmp : heavecomp.diagnosis.compare.ReplayComparison
        The replays.
    """
    pc = cmp.primary
    unit, sc = CH_UNITS[pc]
    by = {m.name: m for m in cmp.models}
    rows = []
    for i, name in enumerate(cmp.ranking()):
        mod = by[name]
        rows.append([str(i + 1), f"`{name}`", f"{mod.rms_validate[pc] * sc:.4g}",
                     *(f"{mod.gap_to_noise_validate[c]:.2f}" for c in cmp.channels),
                     f"{mod.gap_to_noise[pc]:.2f}", f"{cmp.shrink(mod):+.2f}"])
    return md_table(["rank", "parameter file", f"{pc} rms held-out [{unit}]",
                     *(f"{c} gap/noise held-out [-]" for c in cmp.channels), f"{pc} gap/noise whole [-]",
                     f"{pc} shrink vs first file [-]"], rows)


def write_report(cmp, out_dir, *, window=None, commands=()) -> dict:
    """Write ``replay.json``, ``overlay.png`` and ``report.md`` into ``out_dir``; returns the JSON content.

    Parameters
    ----------
    cmp : heavecomp.diagnosis.compare.ReplayComparison
        The replays.
    out_dir : str or Path
        The output folder (created if missing).
    window : tuple (start, end) [s] or None
        The overlay's zoom (None: the whole span).
    commands : sequence of str
        Commands the report suggests (already naming the final folders).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    d = cmp.to_json()
    (out / "replay.json").write_text(json.dumps(d, indent=2) + "\n", encoding="utf-8")
    save(fig_overlay(cmp, window), out / "overlay.png", dpi=90)
    sp = cmp.split
    best = d["ranking"][0]
    lines = [f"# Replay of {cmp.source} under {len(cmp.models)} parameter file(s)", "",
             f"Best on the held-out {cmp.primary}: **`{best}`**. Each file replays the log as the diagnosis does "
             "(the same span, heave pre-processing, start-state estimate, split and noise floor; the file's own "
             "plant and reading effects). A gap/noise of about 1 means the file explains the log to within the "
             "measurement noise.", "",
             ranking_table(cmp), "",
             f"Split: fit {sp['fit'][0]:.0f}-{sp['fit'][1]:.0f} s, held out {sp['validate'][0]:.0f}-"
             f"{sp['validate'][1]:.0f} s; first {sp['settle']:.0f} s excluded (start-up). Span: "
             f"{cmp.span.get('reason', 'the whole log')}.", "",
             "gap/noise: rms of the replay minus the log over the channel's noise floor (output noise and what the "
             "heave noise makes of the replay). The shrink is 1 - rms / rms of the first file on the held-out part: "
             "with the nominal first and a calibrated file second, the shrink the diagnosis reported "
             "(`calibrated.expected_shrink`) when the log is the one it was fitted on; on another log (another day, "
             "another sea state) it is the test of the calibrated model.", ""]
    for m in cmp.models:
        for w in m.warnings:
            lines.append(f"> `{m.name}`: {w}")
    lines += ["", "## The log against every file", "", "![overlay](overlay.png)", ""]
    if commands:
        lines += ["## What next", "", "```", *commands, "```", ""]
    (out / "report.md").write_text("\n".join(lines), encoding="utf-8")
    return d


__all__ = ["fig_overlay", "ranking_table", "write_report"]
