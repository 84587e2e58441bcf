"""Monitor outputs: ``monitor.json`` (diagnosis-contract.md, schema 3 section), the timeline figure and ``report.md``."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from heavecomp.diagnosis.components import UNITS
from heavecomp.diagnosis.monitor import block_gap
from heavecomp.diagnosis.verdict import label
from heavecomp.effects.base import COMPONENTS
from heavecomp.report.commands import command, span_text
from heavecomp.report.figures import _plt, save
from heavecomp.report.scenario import _clean as clean
from heavecomp.report.scenario import md_table


def timeline_figure(res, *, title=""):
    """One row per component: each block's gap/noise (:func:`heavecomp.diagnosis.monitor.block_gap`: as the
    segments' and the diagnosis' gap, the nominal replay's floor subtracted; 1: at the noise, dotted)
    against time, on a log scale; the block-mean
    WOB on top; effect changes as solid red lines, operating changes dashed.

    Parameters
    ----------
    res : heavecomp.diagnosis.monitor.MonitorResult
    title : str
        Figure title (default: a description of the rows).
    """
    plt = _plt()
    rows = 1 + len(COMPONENTS)
    fig, axes = plt.subplots(rows, 1, figsize=(11, 1.5 * rows + 1), sharex=True)
    long = res.duration > 2 * 3600
    scale, unit = (1 / 3600.0, "h") if long else (1 / 60.0, "min")
    tb = (res.t_blocks + 0.5 * res.block) * scale
    axes[0].plot(tb, res.op["wob"] * 1e-3, color="k", lw=0.8)
    axes[0].set_ylabel("WOB\nblock mean [kN]")
    gaps = block_gap(res.sums) if getattr(res, "sums", None) is not None else \
        {c: np.sqrt(np.maximum(res.stats[c], 1e-6)) for c in COMPONENTS}
    for ax, c in zip(axes[1:], COMPONENTS):
        ax.semilogy(tb, gaps[c], lw=0.7)
        ax.axhline(1.0, color="0.6", lw=0.6, ls=":")
        ax.set_ylabel(f"{c}\ngap/noise [-]", fontsize=8)
    for ch in res.changes:
        op = ch["kind"] == "operating"
        for ax in axes:
            ax.axvline(ch["t"] * scale, color="tab:orange" if op else "tab:red", ls="--" if op else "-", lw=1.0)
        if not op and ch["component"] in COMPONENTS:
            ax = axes[1 + COMPONENTS.index(ch["component"])]
            ax.annotate(f"{ch['size_to_noise']:.1f} σ", (ch["t"] * scale, 1), xycoords=("data", "axes fraction"),
                        va="top", fontsize=7, color="tab:red")
    axes[-1].set_xlabel(f"time [{unit}]")
    axes[0].set_title(title or "Gap over noise per component and block (red: effect change, orange dashed: "
                      "operating change)",
                      fontsize=10)
    fig.tight_layout()
    return fig


def write_json(res, path, extra=None) -> Path:
    """Write ``monitor.json`` (:meth:`heavecomp.diagnosis.monitor.MonitorResult.to_json`, plus ``extra``).

    Parameters
    ----------
    res : heavecomp.diagnosis.monitor.MonitorResult
    path : str or Path
        The ``monitor.json`` to write.
    extra : dict, optional
        Keys added at the top level (e.g. ``measurement``).
    """
    d = res.to_json()
    d.update(extra or {})
    return dump_json(d, path)


def dump_json(d, path) -> Path:
    """Write the JSON-ready copy of ``d`` (NaN -> null, numpy -> Python) to ``path``, indented: how
    ``monitor.json``, each segment's ``diagnosis.json`` and the fleet's JSON files are written (by ``monitor`` and
    by ``fleet``).

    Parameters
    ----------
    d : dict
        The content (``monitor.json``: :meth:`heavecomp.diagnosis.monitor.MonitorResult.to_json`).
    path : str or Path
        The file to write.

    Returns
    -------
    pathlib.Path
    """
    path = Path(path)
    path.write_text(json.dumps(clean(d), indent=2) + "\n", encoding="utf-8")
    return path


def write_segment_diagnoses(diagnoses, out) -> list:
    """Each diagnosed segment's ``diagnosis.json`` (``{index: content}``, :func:`heavecomp.diagnosis.monitor.
    diagnose_segments`) as ``out/segment_<index>/diagnosis.json``; returns the paths.

    Parameters
    ----------
    diagnoses : dict
        Segment index -> ``diagnosis.json`` content.
    out : str or Path
        Output folder.
    """
    paths = []
    for i, d in sorted(diagnoses.items()):
        sub = Path(out) / f"segment_{i}"
        sub.mkdir(parents=True, exist_ok=True)
        paths.append(dump_json(d, sub / "diagnosis.json"))
    return paths


def report_markdown(res, source="", figure="timeline.png", diagnosed=()) -> str:
    """The monitor's ``report.md``: the changes, the segments (with their verdicts) and the method.

    Parameters
    ----------
    res : heavecomp.diagnosis.monitor.MonitorResult
    source : str
        Name of the log, for the title.
    figure : str
        File name of the timeline figure, relative to the report.
    diagnosed : sequence of str
        Lines on the diagnosed segments' folders and the ``diagnose --span`` command of each (the command's
        :func:`diagnosed_lines`).
    """
    lines = [f"# Monitor — {source}" if source else "# Monitor", "",
             f"{res.duration / 3600:.2f} h of log, sensors {', '.join(res.sensors)}; statistic blocks of "
             f"{res.block:g} s. {sum(c['kind'] == 'effect' for c in res.changes)} effect change(s), "
             f"{sum(c['kind'] == 'operating' for c in res.changes)} operating change(s).", "",
             f"![timeline]({figure})", ""]
    sk = getattr(res, "skipped", None) or {}
    if sk.get("equations"):
        lines += ["**Channels missing:** left out " + "; ".join(
            f"the {e} residual (reads {', '.join(c)})" for e, c in sk["equations"].items())
            + " (the model's structure: an effect that enters only those equations cannot be seen; "
              "docs/monitoring.md, isolability per sensor set).", ""]
    if sk.get("operating_point"):
        lines += [f"**Operating point:** {sk['operating_point']}.", ""]
    for note in getattr(res, "notes", None) or []:
        lines += [f"**Note:** {note}.", ""]
    gap = getattr(res, "gap", None)
    if gap:
        c = max(gap, key=lambda k: gap[k])
        lines += [f"Gap over the whole log: largest in `{c}`, {gap[c]:.2f}x the noise (1.00: at the noise; "
                  "measured as `heavecomp diagnose` measures it, the nominal replay's floor subtracted).", ""]
    lines += ["## Changes", ""]
    if res.changes:
        lines.append(md_table(["detected t [s]", "onset [s]", "component", "size [noise σ]", "kind"],
                              [[f"{c['t']:.0f}", f"{c['onset']:.0f}", c["component"], f"{c['size_to_noise']:.1f}",
                                _kind(c)] for c in res.changes]))
    else:
        lines.append("No change: every component's residual stayed at its level over the whole log.")
    lines += ["", "`size`: the mean shift of the component's standardised block statistic between onset and "
              "detection, in its block-to-block noise σ (an operating change: of the block-mean WOB). An "
              "operating change is one the load balance carries (the mean pressure moves with the WOB, "
              "A Δp = -ΔW); a WOB that moves alone is a misreading (`sensors`).", "", "## Segments", ""]
    hdr = ["start [s]", "end [s]", "WOB set-point [kN]", "static stroke [m]", "static pressure [MPa]"] + \
          [f"{c} gap/noise [-]" for c in COMPONENTS] + ["verdict"]
    def op(s, key, scale, fmt):
        v = s["operating_point"][key]
        return "-" if v is None else format(v * scale, fmt)

    rows = [[f"{s['start']:.0f}", f"{s['end']:.0f}", op(s, "wob_setpoint", 1e-3, ".1f"),
             op(s, "static_stroke", 1.0, ".3f"), op(s, "static_pressure", 1e-6, ".3f")]
            + [f"{s['gap_to_noise'][c]:.2f}" for c in COMPONENTS] + [_verdict(s)] for s in res.segments]
    lines += [md_table(hdr, rows), "",
              "gap/noise: per component, sqrt(1 + gap) over the segment: the rms of its residual parts over their "
              "equations' noise, less the noise's own share (1.00: at the noise). Residual units: "
              + ", ".join(f"{c} {UNITS[c]}" for c in COMPONENTS) + ".", "",
              "Method: component residuals (equation error) in windows, a two-sided CUSUM per component on the "
              "log of its block statistic (docs/monitoring.md)."]
    if diagnosed:
        lines += ["", "## Diagnosed segments", "", *diagnosed]
    return "\n".join(lines) + "\n"


def diagnosed_lines(spans, log, params, out, *, columns=None, units=None) -> list:
    """The report's lines on each diagnosed segment: its folder (what ``heavecomp diagnose --span`` writes:
    ``diagnosis.json``, ``report.md``/``.html``, the figures, ``calibrated.toml``) and the command that
    diagnoses that span again.

    Parameters
    ----------
    spans : {int: (float, float)}
        Segment index -> the span diagnosed [s, log time].
    log, params : str
        The log and the parameter file as the user named them.
    out : str or Path
        The monitor's output folder as the user named it.
    columns, units : dict, optional
        The log's mapping as given on the command line (the command reads the log with ``params``).
    """
    lines = []
    for i, (a, b) in sorted(spans.items()):
        folder = Path(out) / f"segment_{i}"
        cmd = command("heavecomp", "diagnose", str(log), "--params", str(params), "--span", span_text(a, b),
                      "--out", str(folder), columns=columns, units=units)
        lines += [f"- segment {i}, {a:.0f}-{b:.0f} s: [`{folder.name}/report.md`]({folder.name}/report.md), "
                  f"`{folder.name}/calibrated.toml`; the same diagnosis: `{cmd}`"]
    return lines


def _kind(change) -> str:
    """A change's kind as the report shows it: a drift (:func:`heavecomp.diagnosis.monitor.merge_drifts`)
    with its end and rate."""
    if change.get("drift"):
        return (f"{change['kind']}: drift to {change['until']:.0f} s ({change['alarms']} alarms), "
                f"{change['rate']:+.1f} {change['rate_unit']}")
    return change["kind"]


def _verdict(segment) -> str:
    v = segment.get("verdict")
    if not v:
        return "-"
    if v["effect"] == "not_diagnosed":
        return f"not diagnosed ({v['reason']})"
    return f"{label(v)} ({v.get('confidence')}; {v.get('component') or '-'})"


def write_report(res, out, *, source="", extra=None, diagnosed=()) -> Path:
    """``monitor.json``, ``timeline.png`` and ``report.md`` in ``out`` (the HTML comes with the provenance
    stamp, :func:`heavecomp.report.provenance.finish`).

    Parameters
    ----------
    res : heavecomp.diagnosis.monitor.MonitorResult
    out : str or Path
        Output folder.
    source : str
        Name of the log, for the title.
    extra : dict, optional
        Keys added to ``monitor.json``.
    diagnosed : sequence of str
        The report's lines on the diagnosed segments (:func:`diagnosed_lines`).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_json(res, out / "monitor.json", extra)
    save(timeline_figure(res), out / "timeline.png")
    p = out / "report.md"
    p.write_text(report_markdown(res, source, diagnosed=diagnosed), encoding="utf-8")
    return p
