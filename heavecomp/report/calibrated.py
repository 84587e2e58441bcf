"""The diagnosis' calibrated model in the outputs: ``calibrated.toml``, the ``calibrated`` block of
``diagnosis.json`` (contract schema 3) and the report's "What next" section."""

from __future__ import annotations

import json
import math
from pathlib import Path

from heavecomp.diagnosis.calibrate import FILE, Calibrated, write
from heavecomp.effects.spec import field_units
from heavecomp.report.commands import command, span_text
from heavecomp.report.provenance import strip_declared


#: a refitted parameter that moved less than this share is listed as refit noise, not as a change to make
SMALL = 0.02


def _value(name: str, key: str, value) -> str:
    if isinstance(value, str):
        return f"{key} = {value}"
    unit = field_units(name).get(key, "")
    return f"{key} = {value:.4g}" + (f" {unit}" if unit and unit != "-" else "")


def what_next(cal: Calibrated, out_dir, *, run_path: str = "LOG", params_path: str = "NOMINAL.toml",
              columns=None, units=None, duration: float = 600.0, span=None) -> list[str]:
    """Markdown lines of the "What next" section: what to change (the parameter, the effect, or
    nothing), the calibrated file, and the exact commands that use it -- each one runs as printed from the
    folder the diagnosis was run in (the final output folder, the log's ``--columns``/``--units``).

    Parameters
    ----------
    cal : Calibrated
        The calibrated model (:func:`heavecomp.diagnosis.calibrate.calibrate`).
    out_dir : str or Path
        The output folder as the user named it (paths in the commands are under it; never the staging folder).
    run_path : str
        The measured log as the user named it, for the commands that read it.
    params_path : str
        The parameter file the diagnosis ran against, as the user named it.
    columns, units : dict, optional
        The log's mapping as given on the command line (carried by the commands that read the log with
        ``params_path``; ``calibrated.toml`` records it in its ``[measurement]`` table).
    duration : float [s]
        The diagnosed span's length: the simulations run as long as the log.
    span : heavecomp.diagnosis.span.Span, optional
        The stretch of the log diagnosed; not the whole log, the commands that read the log act on it
        (``--span START:END``), and ``simulate --heave-file`` (which drives the log from its start) and
        ``monitor`` (the whole log) are left out.
    """
    out = Path(out_dir)
    f = (out / FILE).as_posix()
    dur = f"{max(1.0, math.floor(duration)):g}"
    part = () if span is None or span.whole else ("--span", span_text(span.start, span.end))
    lines = ["", "## What next", ""]
    if not cal.changes:
        lines.append(f"Nothing to change in `{params_path}`: {cal.why[0] if cal.why else 'no change'}. "
                     f"`{f}` is a copy of it.")
    params = sorted((c for c in cal.changes if c["kind"] == "parameter"), key=lambda c: -abs(math.log(c["ratio"])))
    moved = [c for c in params if abs(c["ratio"] - 1.0) >= SMALL]
    for c in moved:
        lines.append(f"- Change `{c['name']}` from {c['from']:.6g} to **{c['to']:.6g}** (x {c['ratio']:.3f}).")
    if len(moved) < len(params):
        lines.append(f"- Refitted within {100 * SMALL:.0f} % (written too, so the file replays as the fit did): "
                     + ", ".join(f"`{c['name']}` x {c['ratio']:.3f}" for c in params if c not in moved) + ".")
    for c in cal.changes:
        if c["kind"] == "parameter":
            continue
        elif c["role"] == "reading":
            prm = dict(c["parameters"])
            ch = prm.pop("channel", "heave")
            lines.append(f"- The **{ch}** sensor misreads (`{c['name']}`: "
                         + ", ".join(_value(c["name"], k, v) for k, v in prm.items())
                         + "). Re-calibrate it on the rig, or keep the `[[effects]]` entry: it corrects every log read "
                           "with this file; the plant is unchanged.")
        else:
            lines.append(f"- Add the effect **`{c['name']}`** to the model: "
                         + ", ".join(_value(c["name"], k, v) for k, v in c["parameters"].items()) + ".")
    if not cal.changes:  # the file stays: what is left to do with it is to use it
        lines += ["", "Commands that use it (the controller on the rig as this file describes it"
                      + ("" if part else "; the log followed for a change") + "):", "", "```",
                  command("heavecomp", "simulate", params_path, "--duration", dur, "--controller", "linear-mpc",
                          "--out", (out / "mpc").as_posix()),
                  *(() if part else (command("heavecomp", "monitor", run_path, "--params", params_path, "--out",
                                             (out / "monitor").as_posix(), columns=columns, units=units),)),
                  "```"]
        return lines
    lines += ["", f"`{f}` is `{params_path}` with these changes (expected held-out shrink of the gap "
                  f"{cal.expected_shrink:.2f}); it records the log's column mapping and units "
                  "(`[measurement]`), and every command reads it:"]
    lines += ["", "```",
              command("heavecomp", "params", f, "-q"),
              command("heavecomp", "replay", run_path, "--params", params_path, "--params", f, *part, "--out",
                      (out / "replay").as_posix(), columns=columns, units=units),
              *(() if part else (command("heavecomp", "simulate", f, "--heave-file", run_path, "--duration", dur,
                                         "--out", (out / "calibrated_sim").as_posix()),)),
              command("heavecomp", "analyse", f, "--out", (out / "calibrated_analysis").as_posix()),
              command("heavecomp", "simulate", f, "--duration", dur, "--controller", "linear-mpc",
                      "--out", (out / "calibrated_mpc").as_posix()),
              command("heavecomp", "diagnose", run_path, "--params", f, *part, "--out",
                      (out / "rediagnosis").as_posix()),
              "```",
              "", "The replay shows the log under both files (the calibrated one should shrink the held-out gap by "
                  "the expected shrink; on a log from another day or sea state it is the test of the calibration); "
                  + ("the simulation drives the calibrated file with the log's own heave and reports its WOB error "
                     "against the log; " if not part else
                     f"the replay and the re-diagnosis act on the diagnosed span {part[1]} s, as the diagnosis did; ")
                  + "the last command re-diagnoses: it should read `none`, or a gap smaller by at "
                  "least the expected shrink."]
    return lines


def write_calibrated(params, out_dir, *, run_path: str, params_path: str, run=None, policy=None, shown_dir=None,
                     columns=None, units=None, span=None) -> Calibrated:
    """Write ``out_dir/calibrated.toml`` from ``out_dir/diagnosis.json``, add the ``calibrated`` block to
    ``diagnosis.json`` and the "What next" section to ``report.md``; returns the :class:`Calibrated`.

    Parameters
    ----------
    params : CMCParams
        The nominal parameters the diagnosis was run against.
    out_dir : str or Path
        The diagnosis run folder (with ``diagnosis.json``, and ``report.md`` if written).
    run_path : str
        The measured log as the user named it (header comment and commands).
    params_path : str
        The nominal parameter file as the user named it.
    run : MeasuredRun, optional
        The log as the diagnosis read it (a drifting effect's start state is fitted on it,
        :func:`heavecomp.diagnosis.calibrate.start_state`).
    policy : VerdictPolicy, optional
        The diagnosis' policy (None: the defaults).
    shown_dir : str or Path, optional
        The output folder as the user named it, in the printed commands (default ``out_dir``; a command
        writing into a staging folder passes its final folder).
    columns, units : dict, optional
        The log's mapping as given on the command line (:func:`what_next`).
    span : heavecomp.diagnosis.span.Span, optional
        The stretch of the log diagnosed (:func:`what_next`).
    """
    out = Path(out_dir)
    jpath = out / "diagnosis.json"
    d = json.loads(jpath.read_text(encoding="utf-8"))
    # the fitted values without the unit declarations the writer put beside them (provenance strips those
    # when the run folder is finished, after this)
    cal = write(params, strip_declared(d), out, source=f"{run_path} against {params_path}", run=run, policy=policy)
    d["calibrated"] = cal.block(FILE)
    jpath.write_text(json.dumps(d, indent=2) + "\n", encoding="utf-8")
    md = out / "report.md"
    if md.is_file():
        md.write_text(md.read_text(encoding="utf-8").rstrip("\n") + "\n"
                      + "\n".join(what_next(cal, out if shown_dir is None else shown_dir, run_path=run_path,
                                             params_path=params_path, columns=columns, units=units,
                                             duration=run.duration if run is not None else 600.0, span=span))
                      + "\n",
                      encoding="utf-8")
    return cal
