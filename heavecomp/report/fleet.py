"""A fleet of logs: each log's result folder, the summary tables (``fleet.csv``, ``changes.csv``,
``segments.csv``, units in the headers), the timeline strips and ``report.md`` (computing is in
:mod:`heavecomp.campaign.fleet`)."""

from __future__ import annotations

import csv
from pathlib import Path

from heavecomp.campaign.fleet import RESULTS, read_json, read_task, run_fleet
from heavecomp.diagnosis.monitor import GAP_NOTABLE, gap_level
from heavecomp.diagnosis.verdict import label
from heavecomp.effects.base import COMPONENTS
from heavecomp.io.arrays import fleet_dataset
from heavecomp.report.figures import _plt, save
from heavecomp.report.monitor import dump_json, write_segment_diagnoses
from heavecomp.report.provenance import write_units_csv
from heavecomp.report.scenario import md_table

#: ``fleet.csv``: one row per log (header -> unit, for ``fleet.units.csv``)
FLEET_COLUMNS = {"log": "-", "status": "-", "reason": "-", "duration [h]": "h", "sensors": "-",
                 "segments [-]": "-", "effect changes [-]": "-", "operating changes [-]": "-",
                 "changes (t [s] component size [noise sigma])": "-",
                 "operating changes (t [s] WOB step [kN])": "-",
                 "verdicts (segment: effect, confidence, group)": "-",
                 # how far each log is from the model (issue 31): the monitor's gap/noise over the whole log, per
                 # component, its largest (the gap level) and the log's rank by it (1: the farthest)
                 "gap level [-]": "-", "gap component": "-", "gap rank [-]": "-", "notes": "-",
                 **{f"{c} gap/noise [-]": "-" for c in COMPONENTS}}
#: ``changes.csv``: one row per change
CHANGE_COLUMNS = {"log": "-", "kind": "-", "t [s]": "s", "onset [s]": "s", "component": "-",
                  "size [noise sigma]": "-", "equations": "-", "WOB step [kN]": "kN", "pressure step [MPa]": "MPa",
                  "drift until [s]": "s", "drift rate [noise sigma/h]": "1/h"}
#: ``segments.csv``: one row per segment
SEGMENT_COLUMNS = {"log": "-", "segment": "-", "start [s]": "s", "end [s]": "s", "WOB set-point [kN]": "kN",
                   "static stroke [m]": "m", "static pressure [MPa]": "MPa", "verdict": "-", "confidence": "-",
                   "verdict component": "-", "group": "-", "shrink [-]": "-", "diagnosed span [s]": "s",
                   **{f"{c} gap/noise [-]": "-" for c in COMPONENTS}}
WORST = 3  #: the fleet's report ends in the diagnose commands of at most this many logs, the farthest first
COLORS = dict(zip(COMPONENTS, ("tab:red", "tab:blue", "tab:green", "tab:brown", "tab:purple", "tab:olive")))


def write_log(folder, result) -> None:
    """One finished log's result: ``monitor.json`` and each diagnosed segment's ``segment_<i>/diagnosis.json``
    (the ``write`` of :func:`heavecomp.campaign.fleet.run_fleet`).

    Parameters
    ----------
    folder : str or os.PathLike
        The log's (staging) result folder.
    result : dict
        :func:`heavecomp.campaign.fleet.run_log`'s answer.
    """
    folder = Path(folder)
    dump_json(result["monitor"], folder / "monitor.json")
    write_segment_diagnoses({int(i): d for i, d in result["diagnoses"].items()}, folder)


def _group(folder: Path, i: int) -> str:
    d = read_json(folder / f"segment_{i}" / "diagnosis.json")
    g = ((d or {}).get("verdict") or {}).get("group")
    return "{" + ", ".join(g) + "}" if g else "-"


def collect(out_dir, keys) -> dict:
    """The fleet's results as read back from ``out_dir/logs`` (resumed logs and new ones alike).

    Parameters
    ----------
    out_dir : str or os.PathLike
        The fleet's output folder.
    keys : sequence of str
        The logs, in order.

    Returns
    -------
    dict
        ``logs`` (one dict per log: ``log``, ``status``, ``reason``, ``monitor``), and the rows of
        ``fleet`` / ``changes`` / ``segments`` (header -> cell).
    """
    logs, fleet, changes, segments = [], [], [], []
    for key in keys:
        folder = Path(out_dir) / RESULTS / key
        task = read_task(folder) or {"status": "missing", "reason": "not run (incomplete fleet: rerun to resume)"}
        mon = read_json(folder / "monitor.json") if task["status"] == "done" else None
        logs.append({"log": key, "status": task["status"], "reason": task.get("reason", ""), "monitor": mon})
        row = dict.fromkeys(FLEET_COLUMNS, "")
        row.update({"log": key, "status": task["status"], "reason": task.get("reason", "")})
        if mon is None:
            fleet.append(row)
            continue
        eff = [c for c in mon["changes"] if c["kind"] == "effect"]
        ops = [c for c in mon["changes"] if c["kind"] != "effect"]
        verdicts = []
        for i, s in enumerate(mon["segments"]):
            op = s["operating_point"]
            v = s.get("verdict") or {}
            grp = _group(folder, i) if v and v.get("effect") != "not_diagnosed" else "-"
            segments.append({"log": key, "segment": i, "start [s]": round(s["start"], 1), "end [s]": round(s["end"], 1),
                             "WOB set-point [kN]": round(op["wob_setpoint"] * 1e-3, 2),
                             "static stroke [m]": round(op["static_stroke"], 4),
                             "static pressure [MPa]": round(op["static_pressure"] * 1e-6, 4),
                             "verdict": label(v) if v else "-", "confidence": v.get("confidence") or "-",
                             "verdict component": v.get("component") or "-", "group": grp,
                             "shrink [-]": "-" if v.get("shrink") is None else round(v["shrink"], 3),
                             "diagnosed span [s]": "-" if not v.get("span") else
                             f"{v['span'][0]:.0f}-{v['span'][1]:.0f}", **gap_cells(s.get("gap_to_noise"))})
            if v:
                verdicts.append(f"{i}: {label(v)}" + ("" if v["effect"] == "not_diagnosed" else
                                                         f", {v.get('confidence')}, {grp}"))
        for c in mon["changes"]:
            changes.append({"log": key, "kind": c["kind"], "t [s]": round(c["t"], 1), "onset [s]": round(c["onset"], 1),
                            "component": c["component"], "size [noise sigma]": round(c["size_to_noise"], 2),
                            "equations": " ".join(c.get("equations") or []),
                            "WOB step [kN]": "" if c.get("wob_step") is None else round(c["wob_step"] * 1e-3, 2),
                            "pressure step [MPa]": "" if c.get("pressure_step") is None else
                            round(c["pressure_step"] * 1e-6, 4),
                            "drift until [s]": round(c["until"], 1) if c.get("drift") else "",
                            "drift rate [noise sigma/h]": round(c["rate"], 2) if c.get("drift") else ""})
        row.update({"duration [h]": round(mon["duration_s"] / 3600.0, 3), "sensors": " ".join(mon["sensors"]),
                    "segments [-]": len(mon["segments"]), "effect changes [-]": len(eff),
                    "operating changes [-]": len(ops),
                    "changes (t [s] component size [noise sigma])": "; ".join(
                        f"{c['t']:.0f} {c['component']} {c['size_to_noise']:.1f}"
                        + (f" drift to {c['until']:.0f} s" if c.get("drift") else "") for c in eff),
                    "operating changes (t [s] WOB step [kN])": "; ".join(
                        f"{c['t']:.0f} {(c.get('wob_step') or 0.0) * 1e-3:+.1f}" for c in ops),
                    "verdicts (segment: effect, confidence, group)": "; ".join(verdicts)})
        row.update(log_gap(mon), notes="; ".join(mon.get("notes") or []))
        fleet.append(row)
    rank_by_gap(fleet)
    return {"logs": logs, "fleet": fleet, "changes": changes, "segments": segments}


def gap_cells(gap) -> dict:
    """``{"<component> gap/noise [-]": value}`` of a ``gap_to_noise`` dict (a result without one: empty).

    Parameters
    ----------
    gap : {component: float} or None
    """
    return {f"{c} gap/noise [-]": round(float(gap[c]), 3) for c in COMPONENTS if c in (gap or {})}


def log_gap(mon) -> dict:
    """A log's gap cells of ``fleet.csv``: per component its gap/noise over the whole log, the largest
    (``gap level [-]``) and its component (:func:`heavecomp.diagnosis.monitor.gap_level`).  A ``monitor.json``
    written before the monitor reported the whole log's gap: the longest segment's.

    Parameters
    ----------
    mon : dict
        The log's ``monitor.json`` content.
    """
    gap = mon.get("gap_to_noise")
    if gap is None and mon.get("segments"):
        gap = max(mon["segments"], key=lambda s: s["end"] - s["start"]).get("gap_to_noise")
    if not gap:
        return {}
    lvl = gap_level(gap)
    return {"gap level [-]": round(lvl["gap_to_noise"], 3), "gap component": lvl["component"], **gap_cells(gap)}


def rank_by_gap(rows) -> list:
    """Rank the logs of ``fleet.csv`` by their gap level, the farthest from the model first (``gap rank [-]``
    1); a log without one (failed) has none.  Returns the ranked rows, farthest first.

    Parameters
    ----------
    rows : list of dict
        ``fleet.csv`` rows (:func:`collect`); their ``gap rank [-]`` is set.
    """
    ranked = sorted((r for r in rows if r.get("gap level [-]") not in ("", None)), key=lambda r: -r["gap level [-]"])
    for i, r in enumerate(ranked, 1):
        r["gap rank [-]"] = i
    return ranked


def diagnose_commands(summary, tasks, out, *, worst=WORST, notable=GAP_NOTABLE) -> list:
    """The ``heavecomp diagnose`` command lines of the logs farthest from the model: the first ``worst`` of
    the ranking whose gap level reaches ``notable`` (each with its parameter file, column mapping and units,
    and an output folder beside the fleet's ``out``); none when every log is near the model.

    Parameters
    ----------
    summary : dict
        :func:`collect`'s answer.
    tasks : list of heavecomp.campaign.fleet.LogTask
        The fleet's logs (their paths, parameter files, columns and units).
    out : str or os.PathLike
        The fleet's output folder as the user named it.
    worst : int
        Most commands.
    notable : float [-]
        Smallest gap level worth a diagnosis.
    """
    import shlex

    by_key = {t.key: t for t in tasks}
    out = Path(out)
    cmds = []
    for r in rank_by_gap([dict(r) for r in summary["fleet"]]):
        if len(cmds) >= worst or r["gap level [-]"] < notable or r["log"] not in by_key:
            continue
        t = by_key[r["log"]]
        words = ["heavecomp", "diagnose", t.path, "--params", t.params, "--out", str(out.parent / f"{out.name}-{t.key}")]
        if t.columns:
            words += ["--columns", ",".join(f"{k}={v}" for k, v in t.columns.items())]
        if t.units:
            words += ["--units", ",".join(f"{k}={v}" for k, v in t.units.items())]
        cmds.append(" ".join(shlex.quote(w) for w in words))
    return cmds


def to_xarray(summary, **attrs):
    """A fleet's results as an ``xarray.Dataset`` over ``log`` x ``segment`` (x ``component``) and
    ``log`` x ``change`` (:func:`heavecomp.io.arrays.fleet_dataset`; units in each variable's ``attrs``).

    Parameters
    ----------
    summary : dict or str or os.PathLike
        :func:`collect`'s dict (what :func:`run_and_report` returns), or a fleet's output folder (read
        back through ``fleet.json``'s logs).
    **attrs : str
        Dataset attributes (e.g. ``source``).
    """
    if not isinstance(summary, dict):
        keys = [e["log"] for e in read_json(Path(summary) / "fleet.json")["logs"]]
        summary = collect(summary, keys)
    return fleet_dataset(summary["logs"], attrs)


def _write_csv(path: Path, columns: dict, rows) -> None:
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=list(columns))
        w.writeheader()
        w.writerows(rows)
    write_units_csv(path, list(columns), columns)


def timeline_figure(summary, *, title=""):
    """One strip per log: the log's span, its effect changes coloured by component (at detection), its
    operating changes as black ticks; a failed log is marked so.

    Parameters
    ----------
    summary : dict
        :func:`collect`'s answer.
    title : str
        Figure title (default: a description).

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _plt()
    logs = summary["logs"]
    fig, ax = plt.subplots(figsize=(10, 1.2 + 0.32 * len(logs)))
    seen = set()
    for y, lg in enumerate(logs):
        mon = lg["monitor"]
        if mon is None:
            ax.text(0.0, y, f"  {lg['status']}: {lg['reason'][:90]}", va="center", fontsize=7, color="0.4")
            continue
        ax.plot([0, mon["duration_s"] / 3600.0], [y, y], color="0.8", lw=6, solid_capstyle="butt")
        row = next((r for r in summary["fleet"] if r["log"] == lg["log"]), {})
        if row.get("gap level [-]") not in (None, "", "-"):  # how far the log is from the model, at its end
            ax.annotate(f" gap/noise {row['gap level [-]']:.2f} ({row['gap component']}), rank {row['gap rank [-]']}",
                        (mon["duration_s"] / 3600.0, y), va="center", fontsize=7,
                        color="tab:red" if row["gap level [-]"] >= GAP_NOTABLE else "0.3")
        for c in mon["changes"]:
            th = c["t"] / 3600.0
            if c["kind"] == "effect":
                lab = c["component"] if c["component"] not in seen else None
                seen.add(c["component"])
                ax.plot(th, y, "o", color=COLORS.get(c["component"], "k"), ms=7, label=lab)
            else:
                lab = "operating change" if "operating" not in seen else None
                seen.add("operating")
                ax.plot([th, th], [y - 0.3, y + 0.3], color="k", lw=1.5, label=lab)
    ax.set_yticks(range(len(logs)))
    ax.set_yticklabels([lg["log"] for lg in logs], fontsize=7)
    ax.set_ylim(len(logs) - 0.5, -0.5)
    ax.set_xlabel("time in the log [h]")
    ax.set_ylabel("log [-]")
    ax.set_xlim(left=0.0)
    if seen:
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    ax.grid(axis="x", alpha=0.3)
    ax.set_title(title or "Changes per log (dots: effect changes by component, at detection; ticks: operating "
                 "changes); each log's gap level at its end", fontsize=10)
    fig.tight_layout()
    return fig


def ranking_markdown(summary, commands=()) -> list:
    """The report's lines on how far each log is from the model: the logs ranked by their gap level, with
    each component's gap/noise, then the ``heavecomp diagnose`` commands of the farthest (``commands``,
    :func:`diagnose_commands`).

    Parameters
    ----------
    summary : dict
        :func:`collect`'s answer.
    commands : sequence of str
        The command lines to end with.
    """
    ranked = rank_by_gap([dict(r) for r in summary["fleet"]])
    if not ranked:
        return []
    cols = ["gap rank [-]", "log", "gap level [-]", "gap component"] + [f"{c} gap/noise [-]" for c in COMPONENTS]
    lines = ["## How far each log is from the model", "",
             "Each log's gap over its noise per model component over the whole log (sqrt(1 + gap), the gap as "
             "`heavecomp diagnose` measures it: the nominal replay's floor subtracted; 1.00: at the noise), ranked by "
             f"its largest, the gap level. At {GAP_NOTABLE:g} or more a log is worth a diagnosis.", "",
             md_table(cols, [[r.get(c, "-") for c in cols] for r in ranked]), "", "## What next", ""]
    if commands:
        lines += ["Diagnose the logs farthest from the model (each command carries the log's parameter file, "
                  "columns and units):", "", "```", *commands, "```"]
    else:
        lines += [f"Every log is within {GAP_NOTABLE:g}x its noise of the model: nothing to diagnose."]
    return lines


def report_markdown(summary, run_info, *, source="", figure="timeline.png", commands=()) -> str:
    """The fleet's ``report.md``: counts, the strips, the table per log, and the diagnosed segments.

    Parameters
    ----------
    summary : dict
        :func:`collect`'s answer.
    run_info : dict
        How it ran (``executor``, ``workers``, ``logs_computed``, ``logs_resumed``).
    source : str
        The folder or pattern of the logs, for the title.
    figure : str
        File name of the figure, relative to the report.
    commands : sequence of str
        The diagnose commands the report ends in (:func:`diagnose_commands`).
    """
    logs = summary["logs"]
    n_failed = sum(lg["status"] != "done" for lg in logs)
    hours = sum(lg["monitor"]["duration_s"] for lg in logs if lg["monitor"]) / 3600.0
    lines = [f"# Fleet — {source}" if source else "# Fleet", "",
             f"{len(logs)} logs ({hours:.1f} h), {len(logs) - n_failed} monitored, {n_failed} failed; "
             f"{run_info['logs_computed']} computed by this run, {run_info['logs_resumed']} resumed "
             f"({run_info['executor']}, {run_info['workers']} workers). Each log's own result: "
             f"`{RESULTS}/<log>/monitor.json` (and `segment_<i>/diagnosis.json` when diagnosed).", "",
             f"![changes per log]({figure})", "", "## Per log", ""]
    keep = [k for k in FLEET_COLUMNS if k not in ("reason", "sensors", "notes") and "gap/noise" not in k]
    lines.append(md_table(keep, [[r[k] if r[k] != "" else "-" for k in keep] for r in summary["fleet"]]))
    bad = [r for r in summary["fleet"] if r["status"] != "done"]
    if bad:
        lines += ["", "## Failed logs", "", md_table(["log", "reason"], [[r["log"], r["reason"]] for r in bad])]
    diag = [s for s in summary["segments"] if s["verdict"] != "-"]
    if diag:
        cols = ["log", "segment", "start [s]", "end [s]", "verdict", "confidence", "verdict component", "group",
                "shrink [-]"]
        lines += ["", "## Diagnosed segments", "", md_table(cols, [[s[c] for c in cols] for s in diag])]
    lines += ["", "`size`: the mean shift of the component's standardised block statistic between onset and "
              "detection, in its block-to-block noise σ; an operating change is a new set-point the load balance "
              "carries (docs/monitoring.md). `group`: the candidates the log's sensor set cannot tell apart from "
              "the verdict (docs/diagnosis.md). Tables: `fleet.csv` (one row per log), `changes.csv`, "
              "`segments.csv` (units in the headers and in `<table>.units.csv`)."]
    rank = ranking_markdown(summary, commands)
    if rank:
        lines += [""] + rank
    return "\n".join(lines) + "\n"


def write_report(out_dir, summary, run_info, *, source="", commands=()) -> Path:
    """``fleet.csv``, ``changes.csv``, ``segments.csv`` (+ ``.units.csv``), ``fleet.json``, ``timeline.png``
    and ``report.md`` in ``out_dir`` (the HTML comes with the provenance stamp).

    Parameters
    ----------
    out_dir : str or os.PathLike
        The fleet's output folder.
    summary : dict
        :func:`collect`'s answer.
    run_info : dict
        How it ran (:func:`report_markdown`).
    source : str
        The folder or pattern of the logs.
    commands : sequence of str
        The diagnose commands the report ends in (:func:`diagnose_commands`).

    Returns
    -------
    pathlib.Path
        ``report.md``.
    """
    out = Path(out_dir)
    _write_csv(out / "fleet.csv", FLEET_COLUMNS, summary["fleet"])
    _write_csv(out / "changes.csv", CHANGE_COLUMNS, summary["changes"])
    _write_csv(out / "segments.csv", SEGMENT_COLUMNS, summary["segments"])
    doc = {"schema": 1, "source": source, "run": run_info,
           "what_next": list(commands),
           "logs": [{"log": lg["log"], "status": lg["status"], "reason": lg["reason"],
                     "duration_s": lg["monitor"]["duration_s"] if lg["monitor"] else None,
                     "gap_to_noise": (lg["monitor"] or {}).get("gap_to_noise"),
                     "gap_level": (lg["monitor"] or {}).get("gap_level"),
                     "changes": lg["monitor"]["changes"] if lg["monitor"] else [],
                     "segments": lg["monitor"]["segments"] if lg["monitor"] else []} for lg in summary["logs"]]}
    dump_json(doc, out / "fleet.json")
    save(timeline_figure(summary), out / "timeline.png")
    p = out / "report.md"
    p.write_text(report_markdown(summary, run_info, source=source, commands=commands), encoding="utf-8")
    return p


def run_and_report(tasks, out_dir, settings, *, source="", final_out=None, **kw):
    """:func:`heavecomp.campaign.fleet.run_fleet` (each log's result by :func:`write_log`), then the summary
    and the report.  Returns ``(FleetRun, summary)``.

    Parameters
    ----------
    tasks : list of heavecomp.campaign.fleet.LogTask
    out_dir : str or os.PathLike
        Output folder (rerunning into it resumes).
    settings : heavecomp.campaign.fleet.Settings
    source : str
        The folder or pattern of the logs, for the report.
    final_out : str or os.PathLike, optional
        The output folder as the user named it, for the printed commands (default ``out_dir``; the command
        line runs into a staging folder).
    **kw : dict
        Passed to :func:`heavecomp.campaign.fleet.run_fleet` (``workers``, ``scheduler``, ``client``,
        ``progress``, ``limit``).
    """
    info = run_fleet(tasks, out_dir, settings, write_log, **kw)
    summary = collect(out_dir, info.keys)
    run_info = {"executor": info.executor, "workers": info.workers, "logs_computed": info.n_computed,
                "logs_resumed": info.n_skipped, "logs_failed": info.n_failed, "wall_time_s": round(info.wall_time, 2)}
    summary["what_next"] = diagnose_commands(summary, tasks, final_out or out_dir)
    write_report(out_dir, summary, run_info, source=source, commands=summary["what_next"])
    return info, summary
