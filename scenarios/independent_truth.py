"""Score the gap diagnosis on the independent truth (issue 30, items 5-6).

    python scenarios/independent_truth.py --seed-base N --n-per-class K --out DIR [--jobs J] [--classes a,b]

For each class of :mod:`heavecomp.independent` and each of K seeds it generates a case (a log, the
nominal file, the noise-free truth, a second log in another sea, ``truth.json``), runs
``heavecomp diagnose`` on the log as a user would (a subprocess, the command line), and scores the
answer against the truth:

- verdict: named right (the name in the truth's acceptable verdicts), or the right group (a
  ``verdict.group`` of two or three members that holds a right name), confident wrong (a wrong name at
  medium or high, outside a right group), the right component (``verdict.component``);
- shrink against the true model's, on the held-out part and the verdict's channel (wob):
  (gap_nominal - gap_calibrated) / (gap_nominal - gap_true), the nominal's gap as the diagnosis reports
  it (``rms_before``), the calibrated's from its ``expected_shrink``, the true model's the noise-free
  truth's (``shrink_vs_true``: only the output noise left); ``shrink_vs_floor`` puts the diagnosis' own
  noise floor in its place (heave-noise draws included: it over-states what a replay leaves, so that
  ratio passes 1 and is ill-conditioned near the floor: reported, not scored);
- transfer on the second log: the same ratio with the nominal and ``calibrated.toml`` replayed on it,
  by ``heavecomp replay`` when the tree has it (the true model's gap: the noise-free truth's), else by
  ``heavecomp simulate`` under the log's heave low-passed at ``HEAVE_LOWPASS_HZ`` with the calibrated
  reading corrections applied to the prediction, and the truth replayed under the same heave
  (``--transfer replay|simulate``).

Writes ``DIR/report.md`` and ``DIR/scores.json`` (one row per case) and keeps every case in
``DIR/cases/<class>_<seed>/`` (a finished case is not run again: the set resumes; ``--rescore`` scores
finished cases again from their kept logs and diagnoses).
"""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor, as_completed
import json
import math
import os
from pathlib import Path
import statistics
import subprocess
import sys
import time

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from heavecomp.errors import InputError  # noqa: E402
from heavecomp.report.scenario import parse_args, run, write_report as write_stamped  # noqa: E402
from heavecomp.independent.cases import (CLASSES, DISTRIBUTIONS, NOISE, OUT_OF_LIBRARY, make_case,  # noqa: E402
                                        truth_replay)

#: corner of the zero-phase low-pass the simulate transfer puts on the logged heave [Hz]: above the
#: wave band (a JONSWAP sea of Tp >= 6 s reaches 0.6 Hz), below the 5 Hz Nyquist, so the 2 mm heave
#: noise is not differentiated twice into the top mass's inertia. On smoke case sensor_gain 9000000
#: (second sea Hs 2.0 m, Tp 6.5 s) the truth replayed under the filtered heave leaves 4.2 kN rms of WOB
#: at 0.6 Hz (the filter cuts the sea), 0.64 kN at 1.0 Hz, 1.05 kN at 1.5 Hz, 1.9 kN at 2.5 Hz (noise)
HEAVE_LOWPASS_HZ = 1.0

NAMED_NOT = {"none", "inconclusive", "discovered"}
#: a group counts as an answer only up to this many members (issue 30, Goals)
GROUP_MAX = 3


def _cli(*args, cwd=None, timeout=3600) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    return subprocess.run([sys.executable, "-m", "heavecomp", *map(str, args)], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=timeout)


def has_replay() -> bool:
    r = _cli("replay", "--help", timeout=120)
    return r.returncode == 0


def _csv(path: Path) -> dict:
    d = np.genfromtxt(path, delimiter=",", names=True)
    return {k: np.asarray(d[k], float) for k in d.dtype.names}


def _rms(a, b, mask) -> float:
    return float(np.sqrt(np.mean((a[mask] - b[mask]) ** 2)))


def _ratio(nom, cal, true) -> float | None:
    den = nom - true
    if not (math.isfinite(nom) and math.isfinite(cal) and math.isfinite(true)) or den <= 0:
        return None
    return (nom - cal) / den


# ---- transfer ----------------------------------------------------------------------------------------

def _heave_toml(src: Path, heave_csv: Path, dst: Path) -> Path:
    from heavecomp.params import dumps, loads

    p = loads(src.read_text(), base_dir=src.parent, source=str(src))
    q = p.replace(heave={"kind": "file", "path": heave_csv.name, "hs": None, "tp": None, "gamma": None,
                         "seed": None, "ramp": None, "amplitude": None, "period": None})
    dst.write_text(dumps(q))
    return dst


def _readings(toml: Path) -> tuple[list, list]:
    """The calibrated file's reading effects: (those applied to the prediction, those that cannot be)."""
    import tomllib

    fx = tomllib.loads(toml.read_text()).get("effects", [])
    done, left = [], []
    for e in fx:
        if e.get("name") in ("sensor_gain", "sensor_offset", "sensor_delay", "sensor_lag"):
            done.append(e)
        elif e.get("name") in ("heave_reference", "sensor_term"):
            left.append(e["name"])
    return done, left


def _read_through(e: dict, t: np.ndarray, y: np.ndarray) -> np.ndarray:
    """A reading effect applied to a prediction, from the contract's wording (parameter-file.md):
    y_meas = factor y (gain), y + offset (+ drift t) (offset), y(t - delay) (delay), and sensor_lag's
    first-order lag, delay and factor."""
    name = e["name"]
    if name == "sensor_gain":
        return e.get("factor", 1.0) * y
    if name == "sensor_offset":  # the offset's key is not in the contract: the one number besides drift
        off = e.get("offset", next((x for k, x in e.items() if k not in ("name", "channel", "drift")
                                    and isinstance(x, (int, float))), 0.0))
        return y + off + e.get("drift", 0.0) * (t - t[0])
    if name in ("sensor_delay", "sensor_lag"):
        tau = e.get("time_constant", 0.0)
        if tau > 0:
            out, dt = np.empty_like(y), np.diff(t, prepend=t[0])
            out[0] = y[0]
            for k in range(1, y.size):
                out[k] = out[k - 1] + (1.0 - math.exp(-dt[k] / tau)) * (y[k] - out[k - 1])
            y = out
        y = np.interp(t - e.get("delay", 0.0), t, y)
        return e.get("factor", 1.0) * y
    return y


def transfer_simulate(case: Path, tomls: dict, channel: str, window: tuple) -> dict:
    """Held-out rms of each file's prediction of the second log, by ``heavecomp simulate`` under the
    log's heave (from rest at the operating point, as the log starts) and the file's reading effects."""
    from scipy import signal

    log = _csv(case / "log_sea2.csv")
    t = log["t"]
    work = case / "transfer"
    work.mkdir(exist_ok=True)
    b, a = signal.butter(4, HEAVE_LOWPASS_HZ, fs=1.0 / float(np.median(np.diff(t))))
    heave = signal.filtfilt(b, a, log["heave"])
    np.savetxt(work / "heave2.csv", np.c_[t, heave], delimiter=",", header="t,heave", comments="", fmt="%.9g")
    out, notes = {}, []
    mask = (t >= window[0]) & (t <= window[1])
    for name, src in tomls.items():
        f = _heave_toml(src, work / "heave2.csv", work / f"{name}.toml")
        r = _cli("simulate", f, "--duration", f"{t[-1]:.3f}", "--rate", "10", "--out", work / name, cwd=work)
        if r.returncode != 0:
            notes.append(f"{name}: simulate failed: {r.stderr.strip().splitlines()[-1] if r.stderr.strip() else r.returncode}")
            out[name] = float("nan")
            continue
        sim = _csv(work / name / "timeseries.csv")
        y = np.interp(t, sim["t"], sim[channel])
        done, left = _readings(src)
        for e in done:
            if e.get("channel") == channel:
                y = _read_through(e, t, y)
        if left:
            notes.append(f"{name}: reading effects not applied by simulate: {', '.join(left)}")
        out[name] = _rms(log[channel], y, mask)
    truth = json.loads((case / "truth.json").read_text())
    tr = truth_replay(truth["seed"], truth["class"], t, heave)
    if tr is None:
        notes.append("true model: the noise-free truth (its heave channel is filtered, the log's heave is not its "
                      "input)")
        out["true"] = _rms(log[channel], _csv(case / "truth_channels_sea2.csv")[channel], mask)
    else:
        out["true"] = _rms(log[channel], tr[channel], mask)
    return {"rms": out, "notes": notes, "method": "simulate"}


def transfer_replay(case: Path, tomls: dict, channel: str, window: tuple) -> dict:
    """Held-out gap of each file on the second log by ``heavecomp replay`` (the diagnosis' own replay)."""
    work = case / "transfer_replay"
    args = ["replay", case / "log_sea2.csv"]
    for src in tomls.values():
        args += ["--params", src]
    r = _cli(*args, "--out", work)
    if r.returncode != 0:
        return {"rms": {}, "notes": [f"replay failed: {r.stderr.strip()[-300:]}"], "method": "replay"}
    rep = json.loads((work / "replay.json").read_text())
    out = {}
    for (name, src), m in zip(tomls.items(), rep["models"]):
        rms_v = (m.get("rms_validate") or {}).get(channel)
        out[name] = float(rms_v) if rms_v is not None else float("nan")
    # the true model's gap: the noise-free truth's (as for the shrink; the replay's noise floor, heave-noise
    # draws included, over-states what a replay leaves: calibrated gaps fell below it on the smoke set)
    return {"rms": out, "notes": [], "method": "replay", "split": rep.get("split")}


# ---- one case -------------------------------------------------------------------------------------

def _verdict_score(truth: dict, v: dict) -> dict:
    eff, conf = v.get("effect"), v.get("confidence")
    group = v.get("group") or [eff]
    ok = set(truth.get("verdicts") or [])
    comps = set(truth.get("components") or ([truth["component"]] if truth.get("component") else []))
    right = eff in ok
    members = {str(g).split(":")[0] for g in group}  # a channel effect is named per channel: sensor_gain:wob
    right_group = (not right) and 2 <= len(group) <= GROUP_MAX and bool(ok & members)
    if truth["class"] == "none":
        right, right_group = eff == "none", False
    in_group_right = bool(ok & members) and len(group) <= GROUP_MAX
    confident_wrong = (eff not in NAMED_NOT and not right and not in_group_right and conf in ("medium", "high"))
    if truth["class"] == "none":
        confident_wrong = eff not in ("none", "inconclusive") and conf in ("medium", "high")
    return {"effect": eff, "confidence": conf, "group": group, "group_size": len(group),
            "component": v.get("component"), "right_name": right, "right_group": right_group,
            "right": right or right_group, "confident_wrong": confident_wrong,
            "right_component": (v.get("component") in comps) if comps else None,
            "separate_by": v.get("separate_by") or [], "distinguishable": v.get("distinguishable")}


def run_case(out: Path, cls: str, seed: int, transfer: str, rescore: bool = False) -> dict:
    """Generate, diagnose and score one case (what exists is reused: a finished case's score unless
    ``rescore``, its logs and its diagnosis always)."""
    case = out / "cases" / f"{cls}_{seed}"
    done, timing = case / "score.json", case / "timings.json"
    if done.exists() and not rescore:
        return json.loads(done.read_text())
    t0 = time.time()
    secs = json.loads(timing.read_text()) if timing.exists() else {}
    if not (case / "truth.json").exists():
        make_case(seed, cls, case)
        secs["generate"] = time.time() - t0
    truth = json.loads((case / "truth.json").read_text())
    t1 = time.time()
    if not (case / "diag" / "diagnosis.json").exists():
        r = _cli("diagnose", case / "log.csv", "--params", case / "nominal.toml", "--out", case / "diag", "--quiet")
        secs["diagnose"] = time.time() - t1
        if r.returncode != 0:
            secs["diagnose_error"] = (r.stderr.strip().splitlines() or ["?"])[-1]
    timing.write_text(json.dumps(secs, indent=1))
    row = {"class": cls, "seed": seed, "in_library": truth["in_library"], "truth_component": truth["component"],
           "truth_verdicts": truth["verdicts"], "dominant": truth.get("dominant"),
           "size_to_noise": truth["size_to_noise"], "seconds_generate": secs.get("generate"),
           "seconds_diagnose": secs.get("diagnose")}
    if "diagnose_error" in secs:
        row.update(error=secs["diagnose_error"])
        done.write_text(json.dumps(row, indent=1))
        return row
    d = json.loads((case / "diag" / "diagnosis.json").read_text())
    v = d["verdict"]
    row.update(_verdict_score(truth, v))
    ch = v.get("shrink_channel") or "wob"
    noise = (d.get("noise", {}).get("output", {}) or {}).get(ch) or NOISE[ch]
    start = d.get("span", {}).get("start_s", 0.0)
    window = tuple(x + start for x in d["split"]["validate"])
    # the candidates table names the effect fitted: a family's law (friction_lag, law distance) by its member
    best = next((c for c in d.get("candidates", []) if c.get("effect") == (v.get("member") or v.get("effect"))), None)
    g_nom = d["gap"]["channels"][ch].get("rms_validate", best["rms_before"] if best else float("nan"))
    # the calibrated model's held-out shrink (a second effect's joint one), else the verdict's
    shrink_cal = (d.get("calibrated") or {}).get("expected_shrink")
    if shrink_cal is None or (v.get("effect") not in NAMED_NOT and not shrink_cal):
        shrink_cal = v.get("shrink") if v.get("effect") not in NAMED_NOT else 0.0
    g_cal = g_nom * (1.0 - float(shrink_cal or 0.0))
    log = _csv(case / "log.csv")
    mask = (log["t"] >= window[0]) & (log["t"] <= window[1])
    g_true_clean = _rms(log[ch], _csv(case / "truth_channels.csv")[ch], mask)
    floor = (d["gap"]["channels"][ch].get("noise_floor") or (d.get("noise_floor") or {}).get(ch))
    g_floor = float(floor) if floor else float("nan")
    row.update(channel=ch, noise=noise, window=list(window), gap_nominal=g_nom, gap_calibrated=g_cal,
               gap_true=g_true_clean, gap_floor=g_floor, gap_to_noise_nominal=g_nom / noise,
               shrink_verdict=v.get("shrink"), shrink_vs_true=_ratio(g_nom, g_cal, g_true_clean),
               shrink_vs_floor=_ratio(g_nom, g_cal, g_floor))
    # transfer: the second log, another sea
    cal = case / "diag" / "calibrated.toml"
    if row["right"] and cal.exists() and v.get("effect") not in NAMED_NOT:
        t2 = time.time()
        tomls = {"nominal": case / "nominal.toml", "calibrated": cal}
        tr = (transfer_replay if transfer == "replay" else transfer_simulate)(case, tomls, ch, window)
        log2 = _csv(case / "log_sea2.csv")
        m2 = (log2["t"] >= window[0]) & (log2["t"] <= window[1])
        rms = tr["rms"]
        g2_true = rms.get("true", _rms(log2[ch], _csv(case / "truth_channels_sea2.csv")[ch], m2))
        row.update(transfer_method=tr["method"], transfer_notes=tr["notes"], gap2_nominal=rms.get("nominal"),
                   gap2_calibrated=rms.get("calibrated"), gap2_true=g2_true,
                   transfer=_ratio(rms.get("nominal", float("nan")), rms.get("calibrated", float("nan")), g2_true),
                   seconds_transfer=time.time() - t2)
    row["seconds_total"] = (secs.get("generate") or 0.0) + (secs.get("diagnose") or 0.0) + row.get("seconds_transfer", 0.0)
    done.write_text(json.dumps(row, indent=1, default=float))
    return row


# ---- the set --------------------------------------------------------------------------------------

def _fmt(x, nd=2):
    return "–" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.{nd}f}"


def _med(xs):
    xs = [x for x in xs if x is not None and math.isfinite(x)]
    return (statistics.median(xs), min(xs), len(xs)) if xs else (None, None, 0)


def summarise(rows: list[dict]) -> dict:
    ok = [r for r in rows if "error" not in r]
    single = [r for r in ok if r["class"] not in OUT_OF_LIBRARY + ("two_effects", "none")]
    two = [r for r in ok if r["class"] == "two_effects"]
    none = [r for r in ok if r["class"] == "none"]
    ool = [r for r in ok if r["class"] in OUT_OF_LIBRARY]
    right = [r for r in ok if r["right"] and r["class"] not in ("none",) + OUT_OF_LIBRARY]
    sh, tr = _med([r.get("shrink_vs_true") for r in right]), _med([r.get("transfer") for r in right])

    def share(xs, key):
        return (sum(bool(r[key]) for r in xs), len(xs))
    return {
        "single_right": share(single, "right"), "single_right_name": share(single, "right_name"),
        "two_right": share(two, "right"), "none_right": share(none, "right"),
        "out_of_library_right_component": share(ool, "right_component"),
        "confident_wrong": share(ok, "confident_wrong"),
        "groups": (sum(r["group_size"] > 1 for r in ok), len(ok)),
        "groups_right_only_as_group": (sum(r["right_group"] for r in ok), len(ok)),
        "shrink_median": sh[0], "shrink_min": sh[1], "shrink_n": sh[2],
        "shrink_under_half": sum(1 for r in right if r.get("shrink_vs_true") is not None and r["shrink_vs_true"] < 0.5),
        "transfer_median": tr[0], "transfer_min": tr[1], "transfer_n": tr[2],
        "transfer_under_0.6": sum(1 for r in right if r.get("transfer") is not None and r["transfer"] < 0.6),
        "errors": [(r["class"], r["seed"], r["error"]) for r in rows if "error" in r],
        "seconds_per_case_median": statistics.median(secs) if (secs := [r["seconds_total"] for r in rows
                                                                          if r.get("seconds_total")]) else None,
    }


def write_report(out: Path, rows: list[dict], args, transfer: str) -> None:
    s = summarise(rows)
    lines = [
        f"Generated by `python scenarios/independent_truth.py --seed-base {args.seed_base} --n-per-class "
        f"{args.n_per_class} --out {args.out}"
        + (f" --classes {args.classes}" if set(args.classes.split(",")) != set(CLASSES) else "")
        + "` (heavecomp.independent, clean room; issue 30 items 5-6). "
        f"Transfer by `{transfer}`. {len(rows)} cases.",
        "",
        "## Against the goals (issue 30)",
        "",
        "| goal | target | result |",
        "|---|---|---|",
        f"| single effects named right or right group (group <= {GROUP_MAX}) | >= 95 % | "
        f"{s['single_right'][0]}/{s['single_right'][1]} (by name alone {s['single_right_name'][0]}) |",
        f"| dominant of two effects | >= 75 % | {s['two_right'][0]}/{s['two_right'][1]} |",
        f"| confident wrong (a wrong name at medium/high) | 0 | {s['confident_wrong'][0]}/{s['confident_wrong'][1]} |",
        f"| `none` on no-effect logs | 100 % | {s['none_right'][0]}/{s['none_right'][1]} |",
        f"| out-of-library: right component | >= 90 % | {s['out_of_library_right_component'][0]}/"
        f"{s['out_of_library_right_component'][1]} |",
        f"| median shrink of right verdicts / true model's | >= 0.85, none < 0.5 | {_fmt(s['shrink_median'])} "
        f"(min {_fmt(s['shrink_min'])}, {s['shrink_under_half']} under 0.5, n = {s['shrink_n']}) |",
        f"| median transfer (second sea) | >= 0.85, none < 0.6 | {_fmt(s['transfer_median'])} "
        f"(min {_fmt(s['transfer_min'])}, {s['transfer_under_0.6']} under 0.6, n = {s['transfer_n']}) |",
        f"| verdicts that were groups | report | {s['groups'][0]}/{s['groups'][1]} "
        f"({s['groups_right_only_as_group'][0]} right only as a group) |",
        "",
        "Shrink ratio = (gap_nominal − gap_calibrated) / (gap_nominal − gap_true) on the held-out part, the "
        "verdict's channel [N for wob]; gap_true: the noise-free truth's (only the output noise left); "
        "`vs floor`: the diagnosis' own noise floor in its place (heave-noise draws included; it over-states "
        "what a replay leaves, so the ratio passes 1 near the floor: shown, not scored). Transfer: the same "
        "ratio on the second log (another sea), the calibrated file against the nominal; the true model: "
        "the truth replayed under the same heave (`simulate`) or the noise-free truth (`replay`).",
        "",
        "## Per class",
        "",
        "| class | n | right (name / group) | confident wrong | right component | verdicts (confidence) [group] | "
        "shrink / true (median, min) | vs floor | transfer (median, min) | size/noise, largest channel (median) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for cls in CLASSES:
        rs = [r for r in rows if r["class"] == cls and "error" not in r]
        if not rs:
            continue
        verd = ", ".join(f"{r['effect']} ({r['confidence']})" + (f" [{'/'.join(r['group'])}]" if r["group_size"] > 1 else "")
                         for r in rs)
        sh = _med([r.get("shrink_vs_true") for r in rs if r["right"]])
        cl = _med([r.get("shrink_vs_floor") for r in rs if r["right"]])
        tr = _med([r.get("transfer") for r in rs if r["right"]])
        rc = [r["right_component"] for r in rs if r["right_component"] is not None]
        lines.append(
            f"| {cls} | {len(rs)} | {sum(r['right_name'] for r in rs)} / {sum(r['right_group'] for r in rs)} | "
            f"{sum(r['confident_wrong'] for r in rs)} | {sum(rc)}/{len(rc)} | {verd} | {_fmt(sh[0])}, {_fmt(sh[1])} | "
            f"{_fmt(cl[0])} | {_fmt(tr[0])}, {_fmt(tr[1])} | "
            f"{_fmt(statistics.median(max(r['size_to_noise'].values()) for r in rs), 1)} |")
    seps = [(r["class"], r["seed"], r["separate_by"]) for r in rows if r.get("separate_by")]
    if seps:
        lines += ["", "## What would separate the groups (the diagnosis' `separate_by`)", ""]
        lines += [f"- {c} {sd}: " + "; ".join(map(str, sb)) for c, sd, sb in seps]
    notes = [(r["class"], r["seed"], n) for r in rows for n in r.get("transfer_notes", [])]
    if notes:
        lines += ["", "## Transfer notes", ""] + [f"- {c} {sd}: {n}" for c, sd, n in notes]
    if s["errors"]:
        lines += ["", "## Errors", ""] + [f"- {c} {sd}: {e}" for c, sd, e in s["errors"]]
    lines += ["", "## Classes and the distributions drawn from", "", "| class | drawn from |", "|---|---|"]
    lines += [f"| {k} | {v} |" for k, v in DISTRIBUTIONS.items()]
    lines += ["", f"Noise (1 sigma, white): heave {NOISE['heave'] * 1e3:g} mm, stroke {NOISE['stroke'] * 1e3:g} mm, "
              f"pressure {NOISE['pressure'] / 1e3:g} kPa, wob {NOISE['wob']:g} N; 600 s logs at 10 Hz from rest.",
              "", f"Time per case (median, wall, generate + diagnose + transfer): "
              f"{_fmt(s['seconds_per_case_median'], 0)} s."]
    write_stamped(out, "Independent truth: the diagnosis scored on physics it did not write", ["\n".join(lines)])
    (out / "scores.json").write_text(json.dumps({"summary": s, "rows": rows}, indent=1, default=float))


def _extra(p) -> None:
    p.add_argument("--seed-base", type=int, default=None, help="first case seed (required; never a spent one)")
    p.add_argument("--n-per-class", type=int, default=None, help="cases per class (default 1 with --quick, else 5)")
    p.add_argument("--jobs", type=int, default=1, help="parallel cases (default 1)")
    p.add_argument("--classes", default=",".join(CLASSES), help="comma-separated subset of the classes")
    p.add_argument("--rescore", action="store_true", help="score finished cases again (their logs and diagnoses kept)")
    p.add_argument("--transfer", choices=("auto", "replay", "simulate"), default="auto",
                   help="how the second log is replayed (auto: heavecomp replay when the tree has it)")


def main(argv=None) -> int:
    args = parse_args(argv, "independent_truth", __doc__, extra=_extra)
    if args.seed_base is None:
        raise InputError("--seed-base: required (a seed base no earlier set used; e.g. 9000000 for a smoke run)")
    if args.n_per_class is None:
        args.n_per_class = 1 if args.quick else 5
    classes = [c.strip() for c in args.classes.split(",") if c.strip()]
    bad = [c for c in classes if c not in CLASSES]
    if bad:
        raise InputError(f"--classes: unknown {', '.join(bad)}; known: {', '.join(CLASSES)}")
    if args.n_per_class < 1 or args.jobs < 1:
        raise InputError("--n-per-class and --jobs must be >= 1")
    transfer = args.transfer if args.transfer != "auto" else ("replay" if has_replay() else "simulate")
    todo = [(c, args.seed_base + k) for k in range(args.n_per_class) for c in classes]
    rows = []
    with ProcessPoolExecutor(max_workers=args.jobs) as ex:
        futs = {ex.submit(run_case, args.out, c, s, transfer, args.rescore): (c, s) for c, s in todo}
        for f in as_completed(futs):
            c, s = futs[f]
            try:
                r = f.result()
            except Exception as e:  # a case that breaks is reported, the set goes on
                r = {"class": c, "seed": s, "error": f"{type(e).__name__}: {e}", "seconds_generate": float("nan"),
                     "size_to_noise": {"wob": float("nan")}}
            rows.append(r)
            print(f"[{len(rows)}/{len(todo)}] {c} {s}: {r.get('effect', r.get('error'))} ({r.get('confidence', '')}) "
                  f"right={r.get('right')} shrink/true={_fmt(r.get('shrink_vs_true'))} "
                  f"transfer={_fmt(r.get('transfer'))} {r.get('seconds_total', 0):.0f} s", flush=True)
            write_report(args.out, sorted(rows, key=lambda r: (CLASSES.index(r["class"]), r["seed"])), args, transfer)
    return 0


if __name__ == "__main__":
    raise SystemExit(run(main))
